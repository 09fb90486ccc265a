//! Progress of a run: an indicatif bar on a terminal, plain periodic lines otherwise.

use crate::io::stats::StepStats;
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Seconds between plain progress lines when stderr is not a terminal.
const LINE_INTERVAL: Duration = Duration::from_secs(10);

pub enum Progress {
    Bar {
        bar: ProgressBar,
        end: f64,
        last: Instant,
        last_step: u64,
    },
    Lines {
        start: Instant,
        end: f64,
        last: Instant,
        last_step: u64,
        start_time: f64,
        /// Whether a line has been printed: the first comes after the first step, so that a
        /// batch log shows at once where the run is going.
        printed: bool,
    },
    Quiet,
}

impl Progress {
    /// A bar if stderr is a terminal, else plain lines; `quiet` shows nothing. A resumed run
    /// starts at `start_time` and `start_step`.
    pub fn new(start_time: f64, start_step: u64, end: f64, quiet: bool) -> Self {
        let now = Instant::now();
        if quiet {
            Progress::Quiet
        } else if std::io::stderr().is_terminal() {
            let bar = ProgressBar::new(1_000_000);
            bar.set_style(
                ProgressStyle::with_template("{bar:30} {msg} | ETA {eta}").expect("valid template"),
            );
            bar.set_position(((start_time / end) * 1e6) as u64);
            Progress::Bar {
                bar,
                end,
                last: now,
                last_step: start_step,
            }
        } else {
            Progress::Lines {
                start: now,
                end,
                last: now,
                last_step: start_step,
                start_time,
                printed: false,
            }
        }
    }

    pub fn update(&mut self, s: &StepStats) {
        let now = Instant::now();
        match self {
            Progress::Bar {
                bar,
                end,
                last,
                last_step,
            } => {
                let elapsed = now.duration_since(*last).as_secs_f64();
                if elapsed > 0.2 {
                    let rate = (s.step - *last_step) as f64 / elapsed;
                    bar.set_message(message(s, *end, rate));
                    bar.set_position(((s.time / *end).min(1.0) * 1e6) as u64);
                    (*last, *last_step) = (now, s.step);
                }
            }
            Progress::Lines {
                start,
                end,
                last,
                last_step,
                start_time,
                printed,
            } => {
                if !*printed || now.duration_since(*last) >= LINE_INTERVAL {
                    let rate =
                        (s.step - *last_step) as f64 / now.duration_since(*last).as_secs_f64();
                    let wall = now.duration_since(*start).as_secs_f64();
                    let done = (s.time - *start_time) / (*end - *start_time);
                    let eta = wall * (1.0 - done) / done.max(1e-12);
                    eprintln!("{} | ETA {:.0} s", message(s, *end, rate), eta);
                    (*last, *last_step, *printed) = (now, s.step, true);
                }
            }
            Progress::Quiet => {}
        }
    }

    pub fn finish(&self) {
        if let Progress::Bar { bar, .. } = self {
            bar.finish_and_clear();
        }
    }
}

fn message(s: &StepStats, end: f64, steps_per_second: f64) -> String {
    format!(
        "t = {:.4}/{end:?} s | step {} | {:.1} steps/s | dt {:.2e} s | PPE {} it",
        s.time, s.step, steps_per_second, s.dt, s.ppe_iterations
    )
}
