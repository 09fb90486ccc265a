//! `stats.csv`: one row per time step.

use super::OutputError;
use crate::simulation::StepStats;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

pub const FILE_NAME: &str = "stats.csv";

pub const HEADER: &str =
    "step,time,dt,ppe_iterations,ppe_residual,max_speed,kinetic_energy,density_error,penetrations,wall_seconds";

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

    fn line(&mut self, args: std::fmt::Arguments) -> Result<(), OutputError> {
        writeln!(self.out, "{args}").map_err(|source| OutputError::Write {
            path: self.path.clone(),
            source,
        })
    }

    /// One row; `wall_seconds` is the wall-clock time since the run started.
    pub fn row(&mut self, s: &StepStats, wall_seconds: f64) -> Result<(), OutputError> {
        self.line(format_args!(
            "{},{:e},{:e},{},{:e},{:e},{:e},{:e},{},{:.3}",
            s.step,
            s.time,
            s.dt,
            s.ppe_iterations,
            s.ppe_residual,
            s.max_speed,
            s.kinetic_energy,
            s.density_error,
            s.penetrations,
            wall_seconds
        ))
    }

    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.out.flush().map_err(|source| OutputError::Write {
            path: self.path.clone(),
            source,
        })
    }
}
