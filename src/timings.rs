//! Wall-clock time spent in each stage of the step, accumulated over a run (for `isph bench`
//! and the progress report).

use std::time::Duration;

/// The stages of a step, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// Sorting the particles by cell.
    CellList,
    Density,
    /// Kernel corrections, free surface, PPE roles.
    FreeSurface,
    /// Eddy viscosity, viscous and body forces.
    Predictor,
    /// PPE assembly (source, row vectors) and the BiCGSTAB solve.
    PressureSolve,
    Corrector,
    Shifting,
    Advection,
}

impl Stage {
    pub const ALL: [Stage; 8] = [
        Stage::CellList,
        Stage::Density,
        Stage::FreeSurface,
        Stage::Predictor,
        Stage::PressureSolve,
        Stage::Corrector,
        Stage::Shifting,
        Stage::Advection,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Stage::CellList => "cell list",
            Stage::Density => "density",
            Stage::FreeSurface => "free surface",
            Stage::Predictor => "predictor",
            Stage::PressureSolve => "pressure solve",
            Stage::Corrector => "corrector",
            Stage::Shifting => "shifting",
            Stage::Advection => "advection",
        }
    }
}

/// Accumulated time per stage.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timings {
    spent: [Duration; Stage::ALL.len()],
}

impl Timings {
    pub fn add(&mut self, stage: Stage, d: Duration) {
        self.spent[stage as usize] += d;
    }

    pub fn get(&self, stage: Stage) -> Duration {
        self.spent[stage as usize]
    }

    pub fn total(&self) -> Duration {
        self.spent.iter().sum()
    }
}

impl std::fmt::Display for Timings {
    /// Each stage's share of the step time, in percent.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let total = self.total().as_secs_f64().max(f64::MIN_POSITIVE);
        let shares: Vec<String> = Stage::ALL
            .iter()
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
