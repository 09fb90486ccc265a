//! `stats.csv`: one row per time step.

use super::OutputError;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

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
}

pub const FILE_NAME: &str = "stats.csv";

pub const HEADER: &str =
    "step,time,dt,ppe_iterations,ppe_residual,max_speed,kinetic_energy,density_error,penetrations,wall_seconds,disorder";

pub struct StatsWriter {
    out: BufWriter<File>,
    path: PathBuf,
}

impl StatsWriter {
    pub fn create(dir: &Path) -> Result<Self, OutputError> {
        let path = dir.join(FILE_NAME);
        let file = File::create(&path).map_err(|source| OutputError::Write {
            path: path.clone(),
            source,
        })?;
        let mut w = Self {
            out: BufWriter::new(file),
            path,
        };
        w.line(format_args!("{HEADER}"))?;
        Ok(w)
    }

    /// Continues the stats.csv of `dir` after its first `length` bytes (see `end_of_step`):
    /// the rows after them are cut off first, durably, so a kill at any instant leaves a prefix.
    pub fn append_at(dir: &Path, length: u64) -> Result<Self, OutputError> {
        let path = dir.join(FILE_NAME);
        let err = |source| OutputError::Write {
            path: path.clone(),
            source,
        };
        let mut file = OpenOptions::new().write(true).open(&path).map_err(err)?;
        file.set_len(length).map_err(err)?;
        file.sync_data().map_err(err)?;
        file.seek(SeekFrom::End(0)).map_err(err)?;
        Ok(Self {
            out: BufWriter::new(file),
            path,
        })
    }

    fn line(&mut self, args: std::fmt::Arguments) -> Result<(), OutputError> {
        writeln!(self.out, "{args}").map_err(|source| OutputError::Write {
            path: self.path.clone(),
            source,
        })
    }

    /// One row; `wall_seconds` is the wall-clock time since the run started.
    pub fn row(&mut self, s: &StepStats, wall_seconds: f64) -> Result<(), OutputError> {
        self.line(format_args!(
            "{},{:e},{:e},{},{:e},{:e},{:e},{:e},{},{:.3},{:e}",
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
            s.disorder
        ))
    }

    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.out.flush().map_err(|source| OutputError::Write {
            path: self.path.clone(),
            source,
        })
    }

    /// Flushes and fsyncs, so the rows written so far survive a crash (before a checkpoint
    /// that counts on them).
    pub fn sync(&mut self) -> Result<(), OutputError> {
        self.flush()?;
        self.out
            .get_ref()
            .sync_data()
            .map_err(|source| OutputError::Write {
                path: self.path.clone(),
                source,
            })
    }
}

/// Length in bytes of the stats.csv of `dir` up to and including the row of `step` (the header
/// alone for step 0). Refuses a file with another header or without that row.
pub fn end_of_step(dir: &Path, step: u64) -> Result<u64, OutputError> {
    let path = dir.join(FILE_NAME);
    let text = std::fs::read(&path).map_err(|source| OutputError::Read {
        path: path.clone(),
        source,
    })?;
    let mismatch = |what: String| OutputError::Mismatch {
        path: path.clone(),
        what,
    };
    // A row cut short by a kill can only be the last line: only complete lines count.
    let mut lines = text
        .split_inclusive(|&b| b == b'\n')
        .filter(|l| l.ends_with(b"\n"));
    let header = lines.next().unwrap_or_default();
    if header != format!("{HEADER}\n").as_bytes() {
        return Err(mismatch(format!(
            "its first line is `{}`, not the header `{HEADER}` this isph writes",
            String::from_utf8_lossy(header).trim_end()
        )));
    }
    let mut end = header.len() as u64;
    let mut last = 0;
    if step == 0 {
        return Ok(end);
    }
    for line in lines {
        end += line.len() as u64;
        let row_step = std::str::from_utf8(line)
            .ok()
            .and_then(|l| l.split(',').next())
            .and_then(|s| s.parse::<u64>().ok());
        if row_step == Some(step) {
            return Ok(end);
        }
        last = row_step.unwrap_or(last);
    }
    Err(mismatch(format!(
        "it has no row for the checkpoint's step {step} (its last complete row is step {last})"
    )))
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
