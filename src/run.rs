//! A whole run: scene → simulation → frames, index and statistics in the output directory.

use crate::io::frames::{FrameInfo, FrameWriter};
use crate::io::stats::StatsWriter;
use crate::io::{prepare_output_dir, xdmf, OutputError};
use crate::progress::Progress;
use crate::scene::Scene;
use crate::simulation::{NoFluid, NumericalFailure, Simulation, StepStats};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct RunOptions {
    pub out: PathBuf,
    /// Simulated time to stop at (default: the scene's `end_time`).
    pub until: Option<f64>,
    /// Replace a run already in `out`.
    pub overwrite: bool,
    /// No progress display.
    pub quiet: bool,
}

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(transparent)]
    NoFluid(#[from] NoFluid),
    #[error("{failure}; the frames and statistics up to the last good step are in {}", out.display())]
    Numerical {
        failure: NumericalFailure,
        out: PathBuf,
    },
}

/// What a finished run did.
#[derive(Clone, Debug)]
pub struct RunSummary {
    pub steps: u64,
    pub time: f64,
    pub frames: Vec<FrameInfo>,
    pub wall_seconds: f64,
    pub mean_ppe_iterations: f64,
    pub last: Option<StepStats>,
}

pub fn run(scene: &Scene, opts: &RunOptions) -> Result<RunSummary, RunError> {
    match scene.dimensions {
        2 => run_in::<2>(scene, opts),
        3 => run_in::<3>(scene, opts),
        d => unreachable!("scene validation admits 2 or 3 dimensions, not {d}"),
    }
}

fn run_in<const D: usize>(scene: &Scene, opts: &RunOptions) -> Result<RunSummary, RunError> {
    let mut sim = Simulation::<D>::new(scene)?;
    prepare_output_dir(&opts.out, opts.overwrite)?;
    let mut frames_out = FrameWriter::create(&opts.out)?;
    let mut stats = StatsWriter::create(&opts.out)?;
    let end = opts.until.unwrap_or(scene.end_time);
    let interval = scene.output_interval;
    let started = Instant::now();
    let mut progress = Progress::new(sim.time, end, opts.quiet);

    let mut frames = vec![frames_out.write(0, &sim.particles, sim.time, sim.step)?];
    xdmf::write(&opts.out, &frames)?;
    let (mut ppe_total, mut last) = (0u64, None);
    while sim.time < end {
        // Frames fall exactly on multiples of the output interval, and on the end time.
        let next_frame = (frames.len() as f64 * interval).min(end);
        let step = match sim.advance_towards(next_frame) {
            Ok(s) => s,
            Err(failure) => {
                stats.flush()?;
                progress.finish();
                return Err(RunError::Numerical {
                    failure,
                    out: opts.out.clone(),
                });
            }
        };
        stats.row(&step, started.elapsed().as_secs_f64())?;
        ppe_total += step.ppe_iterations as u64;
        progress.update(&step);
        if sim.time >= next_frame {
            frames.push(frames_out.write(frames.len(), &sim.particles, sim.time, sim.step)?);
            xdmf::write(&opts.out, &frames)?;
            stats.flush()?;
        }
        last = Some(step);
    }
    stats.flush()?;
    progress.finish();
    Ok(RunSummary {
        steps: sim.step,
        time: sim.time,
        frames,
        wall_seconds: started.elapsed().as_secs_f64(),
        mean_ppe_iterations: ppe_total as f64 / sim.step.max(1) as f64,
        last,
    })
}
