//! Wall-clock time spent in each stage of the step, accumulated over a run (for the run summary
//! and the cost of each effect), by the stage's name (`Stage::name`).

use std::time::Duration;

/// Accumulated time and number of runs per stage, in the order the stages were listed.
#[derive(Clone, Debug, PartialEq)]
pub struct Timings {
    stages: Vec<StageTime>,
}

#[derive(Clone, Debug, PartialEq)]
struct StageTime {
    name: &'static str,
    spent: Duration,
    runs: u64,
}

impl Timings {
    /// No time yet in the stages `names`, in the order of the step (`Step::stages`).
    pub fn new(names: impl IntoIterator<Item = &'static str>) -> Self {
        let stages = names
            .into_iter()
            .map(|name| StageTime {
                name,
                spent: Duration::ZERO,
                runs: 0,
            })
            .collect();
        Self { stages }
    }

    fn entry(&mut self, stage: &str) -> &mut StageTime {
        self.stages
            .iter_mut()
            .find(|s| s.name == stage)
            .expect("a stage of the step (`Timings::new`)")
    }

    /// Counts one run of `stage` that took `d`.
    pub fn add(&mut self, stage: &'static str, d: Duration) {
        let entry = self.entry(stage);
        entry.spent += d;
        entry.runs += 1;
    }

    /// Adds `d` to `stage` without counting a run: the part of a stage done elsewhere in the
    /// same step (the diagnostics' pair loop inside the step, their sums after it).
    pub fn add_part(&mut self, stage: &'static str, d: Duration) {
        self.entry(stage).spent += d;
    }

    /// The stages' names, in order.
    pub fn names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.stages.iter().map(|s| s.name)
    }

    pub fn get(&self, stage: &str) -> Duration {
        self.stages
            .iter()
            .find(|s| s.name == stage)
            .map_or(Duration::ZERO, |s| s.spent)
    }

    /// How many times `stage` has run.
    pub fn runs(&self, stage: &str) -> u64 {
        self.stages
            .iter()
            .find(|s| s.name == stage)
            .map_or(0, |s| s.runs)
    }

    pub fn total(&self) -> Duration {
        self.stages.iter().map(|s| s.spent).sum()
    }
}

impl std::fmt::Display for Timings {
    /// The share of the step time of each stage that ran, in percent.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let total = self.total().as_secs_f64().max(f64::MIN_POSITIVE);
        let shares: Vec<String> = self
            .stages
            .iter()
            .filter(|s| s.runs > 0)
            .map(|s| format!("{} {:.0}%", s.name, 100.0 * s.spent.as_secs_f64() / total))
            .collect();
        write!(f, "{}", shares.join(", "))
    }
}
