//! Incompressibility, the known answer of every flow: ρ = ρ0 everywhere at every step.
//!
//! The error is the largest over the steps of the `stats.csv` density error, the mean over the
//! fluid of |ρ/ρ0 − 1| (the violent impact of `tests/stability.rs` bounds it by 1%). Details:
//! the mean of that error over the steps (the steadier figure of a chaotic flow, whose worst
//! step is one draw of its trajectory) and the particles put back from beyond a wall face over
//! the run (`penetrations`).

use super::{Case, Measured, ValidationError};
use crate::io::stats::read_column;
use std::path::Path;

pub const DETAILS: [&str; 2] = ["density_error_mean", "penetrations"];

pub fn measure(run_dir: &Path) -> Result<Measured, ValidationError> {
    // Steps whose support held no fluid particle at all report NaN: nothing was measured.
    let errors: Vec<f64> = read_column(run_dir, "density_error")?
        .into_iter()
        .filter(|e| !e.is_nan())
        .collect();
    if errors.is_empty() {
        return Err(ValidationError::Run {
            case: Case::Density,
            dir: run_dir.to_owned(),
            message: "its stats.csv holds no step with a density error".into(),
        });
    }
    let worst = errors.iter().copied().fold(0.0, f64::max);
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let penetrations = read_column(run_dir, "penetrations")?.iter().sum::<f64>();
    Ok(Measured::new(worst, &DETAILS, &[mean, penetrations]))
}
