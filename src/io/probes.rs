//! `probes.csv`: one row per time step, `time` and then the columns of the scene's probes
//! (`scene::Probe::columns`), in the order of the scene's `[[probe]]` sections.

use super::csv::{end_of_row, CsvWriter, CutAt};
use super::OutputError;
use crate::scene::Probe;
use std::path::Path;

pub const FILE_NAME: &str = "probes.csv";

/// The header of the probes.csv of `probes`.
pub fn header(probes: &[Probe]) -> String {
    let columns: Vec<String> = probes.iter().flat_map(Probe::columns).collect();
    format!("time,{}", columns.join(","))
}

pub struct ProbesWriter(CsvWriter);

impl ProbesWriter {
    pub fn create(dir: &Path, probes: &[Probe]) -> Result<Self, OutputError> {
        CsvWriter::create(dir.join(FILE_NAME), &header(probes)).map(Self)
    }

    /// Continues the probes.csv of `dir` after its first `length` bytes (see `end_of_time`).
    pub fn append_at(dir: &Path, length: u64) -> Result<Self, OutputError> {
        CsvWriter::append_at(dir.join(FILE_NAME), length).map(Self)
    }

    /// One row: the time, then the probes' values in the header's order (printed so that they
    /// read back to the same bits).
    pub fn row(&mut self, time: f64, values: &[f64]) -> Result<(), OutputError> {
        let mut line = format!("{time:e}");
        for v in values {
            line += &format!(",{v:e}");
        }
        self.0.line(format_args!("{line}"))
    }

    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.0.flush()
    }

    /// Flushes and fsyncs (before a checkpoint that counts on the rows).
    pub fn sync(&mut self) -> Result<(), OutputError> {
        self.0.sync()
    }
}

/// Length in bytes of the probes.csv of `dir` up to and including the row of the checkpoint at
/// `step`, simulated time `time` (the header alone for step 0). Refuses a file whose header is
/// not that of `probes`, or without that row.
pub fn end_of_time(dir: &Path, probes: &[Probe], step: u64, time: f64) -> Result<u64, OutputError> {
    let (first_field, what) = (
        format!("{time:e}"),
        format!("the checkpoint's t = {time:?} s"),
    );
    let at = match step {
        0 => CutAt::Header,
        _ => CutAt::Row {
            first_field: &first_field,
            what: &what,
        },
    };
    end_of_row(&dir.join(FILE_NAME), &header(probes), at)
}

/// The probes.csv of `dir`: its column names (`time` first) and its rows.
pub fn read(dir: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), OutputError> {
    let path = dir.join(FILE_NAME);
    let text = std::fs::read_to_string(&path).map_err(|source| OutputError::Read {
        path: path.clone(),
        source,
    })?;
    let mut lines = text.lines();
    let columns: Vec<String> = lines
        .next()
        .unwrap_or_default()
        .split(',')
        .map(str::to_owned)
        .collect();
    let rows = lines
        .enumerate()
        .map(|(k, line)| {
            let row: Option<Vec<f64>> = line.split(',').map(|v| v.parse().ok()).collect();
            row.filter(|r| r.len() == columns.len())
                .ok_or_else(|| OutputError::Malformed {
                    path: path.clone(),
                    what: format!("row {} does not hold {} numbers", k + 1, columns.len()),
                })
        })
        .collect::<Result<_, _>>()?;
    Ok((columns, rows))
}
