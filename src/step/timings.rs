//! Wall-clock time spent in each stage of the step, accumulated over a run (for the run summary
//! and the cost of each effect).

use std::time::Duration;

/// The stages of a step, in order. Which of them a scene runs is `step::stages`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Sorting the particles by cell.
    CellList,
    Density,
    /// Support moments, free surface, PPE roles.
    FreeSurface,
    /// The kernel gradient corrections L_i and L'_i (effect `kernel_correction`).
    KernelCorrection,
    /// Smagorinsky eddy viscosity (effect `les`).
    EddyViscosity,
    /// Viscous and body forces (and the log-law wall shear with LES).
    Predictor,
    /// PPE assembly (source, row vectors) and the BiCGSTAB solve.
    PressureSolve,
    Corrector,
    /// The pressures of the wall particles, for output.
    WallPressure,
    /// Particle shifting (effect `shifting`).
    Shifting,
    Advection,
    /// Max speed, kinetic energy, penetrations of `stats.csv`.
    Diagnostics,
}

impl Stage {
    pub const ALL: [Stage; 12] = [
        Stage::CellList,
        Stage::Density,
        Stage::FreeSurface,
        Stage::KernelCorrection,
        Stage::EddyViscosity,
        Stage::Predictor,
        Stage::PressureSolve,
        Stage::Corrector,
        Stage::WallPressure,
        Stage::Shifting,
        Stage::Advection,
        Stage::Diagnostics,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Stage::CellList => "cell list",
            Stage::Density => "density",
            Stage::FreeSurface => "free surface",
            Stage::KernelCorrection => "kernel correction",
            Stage::EddyViscosity => "eddy viscosity",
            Stage::Predictor => "predictor",
            Stage::PressureSolve => "pressure solve",
            Stage::Corrector => "corrector",
            Stage::WallPressure => "wall pressure",
            Stage::Shifting => "shifting",
            Stage::Advection => "advection",
            Stage::Diagnostics => "diagnostics",
        }
    }
}

/// Accumulated time and number of runs per stage.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timings {
    spent: [Duration; Stage::ALL.len()],
    runs: [u64; Stage::ALL.len()],
}

impl Timings {
    /// Counts one run of `stage` that took `d`.
    pub fn add(&mut self, stage: Stage, d: Duration) {
        self.spent[stage as usize] += d;
        self.runs[stage as usize] += 1;
    }

    /// Adds `d` to `stage` without counting a run: the part of a stage done elsewhere in the
    /// same step (the diagnostics' pair loop inside the step, their sums after it).
    pub fn add_part(&mut self, stage: Stage, d: Duration) {
        self.spent[stage as usize] += d;
    }

    pub fn get(&self, stage: Stage) -> Duration {
        self.spent[stage as usize]
    }

    /// How many times `stage` has run.
    pub fn runs(&self, stage: Stage) -> u64 {
        self.runs[stage as usize]
    }

    pub fn total(&self) -> Duration {
        self.spent.iter().sum()
    }
}

impl std::fmt::Display for Timings {
    /// The share of the step time of each stage that ran, in percent.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let total = self.total().as_secs_f64().max(f64::MIN_POSITIVE);
        let shares: Vec<String> = Stage::ALL
            .iter()
            .filter(|&&s| self.runs(s) > 0)
            .map(|&s| {
                format!(
                    "{} {:.0}%",
                    s.name(),
                    100.0 * self.get(s).as_secs_f64() / total
                )
            })
            .collect();
        write!(f, "{}", shares.join(", "))
    }
}
