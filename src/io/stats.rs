//! `stats.csv`: one row per time step.

use super::csv::{end_of_row, CsvWriter, CutAt};
use super::OutputError;
use std::path::Path;

/// What one step measured: a row of `stats.csv` (without the wall time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepStats {
    pub step: u64,
    pub time: f64,
    pub dt: f64,
    pub ppe_iterations: usize,
    pub ppe_residual: f64,
    pub max_speed: f64,
    pub kinetic_energy: f64,
    pub density_error: f64,
    pub penetrations: usize,
    pub disorder: f64,
    pub compression: f64,
}

pub const FILE_NAME: &str = "stats.csv";

pub const HEADER: &str =
    "step,time,dt,ppe_iterations,ppe_residual,max_speed,kinetic_energy,density_error,penetrations,wall_seconds,disorder,compression";

pub struct StatsWriter(CsvWriter);

impl StatsWriter {
    pub fn create(dir: &Path) -> Result<Self, OutputError> {
        CsvWriter::create(dir.join(FILE_NAME), HEADER).map(Self)
    }

    /// Continues the stats.csv of `dir` after its first `length` bytes (see `end_of_step`).
    pub fn append_at(dir: &Path, length: u64) -> Result<Self, OutputError> {
        CsvWriter::append_at(dir.join(FILE_NAME), length).map(Self)
    }

    /// One row; `wall_seconds` is the wall-clock time since the run started.
    pub fn row(&mut self, s: &StepStats, wall_seconds: f64) -> Result<(), OutputError> {
        self.0.line(format_args!(
            "{},{:e},{:e},{},{:e},{:e},{:e},{:e},{},{:.3},{:e},{:e}",
            s.step,
            s.time,
            s.dt,
            s.ppe_iterations,
            s.ppe_residual,
            s.max_speed,
            s.kinetic_energy,
            s.density_error,
            s.penetrations,
            wall_seconds,
            s.disorder,
            s.compression
        ))
    }

    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.0.flush()
    }

    /// Flushes and fsyncs (before a checkpoint that counts on the rows).
    pub fn sync(&mut self) -> Result<(), OutputError> {
        self.0.sync()
    }
}

/// Length in bytes of the stats.csv of `dir` up to and including the row of `step` (the header
/// alone for step 0). Refuses a file with another header or without that row.
pub fn end_of_step(dir: &Path, step: u64) -> Result<u64, OutputError> {
    let (first_field, what) = (step.to_string(), format!("the checkpoint's step {step}"));
    let at = match step {
        0 => CutAt::Header,
        _ => CutAt::Row {
            first_field: &first_field,
            what: &what,
        },
    };
    end_of_row(&dir.join(FILE_NAME), HEADER, at)
}

/// Column `name` of the stats.csv of `dir`, one value per step.
pub fn read_column(dir: &Path, name: &str) -> Result<Vec<f64>, OutputError> {
    let path = dir.join(FILE_NAME);
    let text = std::fs::read_to_string(&path).map_err(|source| OutputError::Read {
        path: path.clone(),
        source,
    })?;
    let mismatch = |what: String| OutputError::Malformed {
        path: path.clone(),
        what,
    };
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default();
    let col = header
        .split(',')
        .position(|c| c == name)
        .ok_or_else(|| mismatch(format!("its header `{header}` has no column `{name}`")))?;
    lines
        .enumerate()
        .map(|(k, line)| {
            line.split(',')
                .nth(col)
                .and_then(|v| v.parse::<f64>().ok())
                .ok_or_else(|| mismatch(format!("row {} has no number in `{name}`", k + 1)))
        })
        .collect()
}
