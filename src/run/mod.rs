//! A whole run: scene → simulation → frames, index, statistics and checkpoints in the output
//! directory. `run` starts one; `resume` continues one from a checkpoint, bit for bit as if it
//! had never stopped.

mod output;
pub(crate) mod progress;
pub mod resume;
mod stop;

use crate::io::bodies_csv::BodiesWriter;
use crate::io::checkpoint::{Checkpoint, CheckpointError, RunState};
use crate::io::checkpoint_folder;
use crate::io::frames::{FrameInfo, FrameWriter};
use crate::io::probes::ProbesWriter;
use crate::io::stats::StatsWriter;
use crate::io::stats::StepStats;
use crate::io::surface_files::SurfaceWriter;
use crate::io::{prepare_output_dir, xdmf, OutputError};
use crate::math::reduce::in_pool;
use crate::particles::Particles;
use crate::run::output::Output;
use crate::run::progress::Progress;
use crate::run::resume::{ResumeError, ResumeOptions};
pub use crate::run::stop::StopSignal;
use crate::scene::Scene;
use crate::simulation::{NoFluid, NumericalFailure, Simulation};
use crate::step::timings::Timings;
use crate::surface;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Instant;

/// Frame times within this many output intervals of the end time are the end time.
const FRAME_TIME_ROUNDING: f64 = 1e-6;

#[derive(Clone, Debug)]
pub struct RunOptions {
    pub out: PathBuf,
    /// Simulated time to stop at (default: the scene's `end_time`).
    pub until: Option<f64>,
    /// Replace a run already in `out`.
    pub overwrite: bool,
    /// No progress display.
    pub quiet: bool,
    pub stop: StopSignal,
}

/// A checkpoint on disk that a run wrote or started from.
#[derive(Clone, Debug, PartialEq)]
pub struct Saved {
    pub path: PathBuf,
    pub step: u64,
    pub time: f64,
}

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(transparent)]
    NoFluid(#[from] NoFluid),
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    #[error(transparent)]
    Resume(#[from] ResumeError),
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    #[error("{failure}; the frames and statistics up to the last good step are in {}; {}", out.display(), last_good(last_checkpoint.as_ref(), out))]
    Numerical {
        failure: NumericalFailure,
        out: PathBuf,
        /// The newest checkpoint on disk: a state from before the failure.
        last_checkpoint: Option<Saved>,
    },
    #[error("stopped by {} after step {} (t = {} s); the state is saved in {}, the frames and statistics are flushed: `isph resume {}` continues the run", signal_name(*signal), saved.step, saved.time, saved.path.display(), out.display())]
    Interrupted {
        signal: usize,
        saved: Saved,
        out: PathBuf,
    },
}

fn signal_name(signal: usize) -> String {
    match signal as i32 {
        signal_hook::consts::SIGINT => "SIGINT".into(),
        signal_hook::consts::SIGTERM => "SIGTERM".into(),
        s => format!("signal {s}"),
    }
}

fn last_good(saved: Option<&Saved>, out: &Path) -> String {
    match saved {
        Some(s) => format!(
            "the newest checkpoint, {} (step {}, t = {} s), holds a state from before the failure: `isph resume {}` continues from it (add --force if you change the scene)",
            s.path.display(),
            s.step,
            s.time,
            out.display()
        ),
        None => "no checkpoint was written before the failure (set `[checkpoint] interval` to keep recent states)".into(),
    }
}

/// What a run (or the part of it this process ran) did.
#[derive(Clone, Debug)]
pub struct RunSummary {
    /// Steps taken by this process.
    pub steps: u64,
    pub time: f64,
    /// Every frame of the run, including those written before a resume.
    pub frames: Vec<FrameInfo>,
    /// Wall-clock seconds of this process.
    pub wall_seconds: f64,
    pub mean_ppe_iterations: f64,
    pub last: Option<StepStats>,
    /// The checkpoint of the final state.
    pub checkpoint: Saved,
    /// Time spent in each stage of the step by this process.
    pub timings: Timings,
}

pub fn run(scene: &Scene, opts: &RunOptions) -> Result<RunSummary, RunError> {
    in_pool(|| match scene.dimensions {
        2 => run_in::<2>(scene, opts),
        3 => run_in::<3>(scene, opts),
        d => unreachable!("scene validation admits 2 or 3 dimensions, not {d}"),
    })
}

fn run_in<const D: usize>(scene: &Scene, opts: &RunOptions) -> Result<RunSummary, RunError> {
    scene.check_stop_time(opts.until.unwrap_or(scene.end_time))?;
    let sim = Simulation::<D>::new(scene)?;
    prepare_output_dir(&opts.out, opts.overwrite)?;
    let output = Output {
        dir: opts.out.clone(),
        frames_out: FrameWriter::create(&opts.out, D, scene.spacing)?,
        stats: StatsWriter::create(&opts.out)?,
        frames: Vec::new(),
        surfaces: match scene.surface {
            Some(settings) => Some((SurfaceWriter::create(&opts.out)?, settings)),
            None => None,
        },
        probes: if scene.probes.is_empty() {
            None
        } else {
            Some(ProbesWriter::create(&opts.out, &scene.probes)?)
        },
        bodies: if scene.bodies.is_empty() {
            None
        } else {
            Some(BodiesWriter::create(&opts.out)?)
        },
    };
    let mut driver = Driver::new(scene, sim, output, None, opts.until, opts.quiet, &opts.stop);
    // Frame 0: the initial state.
    driver.write_frame_if_due()?;
    driver.drive()
}

/// Continues the run of `checkpoint` in its output directory (see `resume::prepare` for what is
/// checked and what in the directory is replaced).
pub fn resume(checkpoint: &Checkpoint, opts: &ResumeOptions) -> Result<RunSummary, RunError> {
    in_pool(|| match checkpoint.dimensions() {
        2 => resume_in::<2>(checkpoint, opts),
        3 => resume_in::<3>(checkpoint, opts),
        d => unreachable!("a checkpoint that opened holds 2 or 3 dimensions, not {d}"),
    })
}

fn resume_in<const D: usize>(
    checkpoint: &Checkpoint,
    opts: &ResumeOptions,
) -> Result<RunSummary, RunError> {
    // Every check, the particles' and the bodies' too, comes before the cut-back changes a
    // file: a refused resume leaves the run as it was.
    let checked = resume::check(checkpoint, opts)?;
    let mut sim = Simulation::<D>::new(&checked.scene)?;
    let mut restored = Particles::default();
    checkpoint.restore(&mut restored)?;
    resume::check_particles(checkpoint, &checked.scene.path, &sim.particles, &restored)?;
    sim.particles = restored;
    checkpoint.restore_bodies(&mut sim.bodies)?;
    let start = resume::cut_back(checked)?;
    sim.time = checkpoint.state.time;
    sim.step = checkpoint.state.step;
    sim.last_dt = (checkpoint.state.dt > 0.0).then_some(checkpoint.state.dt);
    Driver::new(
        &start.scene,
        sim,
        start.output,
        Some(checkpoint),
        opts.until,
        opts.quiet,
        &opts.stop,
    )
    .drive()
}

/// A run in progress: the simulation and everything the run carries from step to step.
struct Driver<'a, const D: usize> {
    /// The end time as the user wrote it (`--until` or `end_time`), for the progress line.
    requested_end: f64,
    scene: &'a Scene,
    sim: Simulation<D>,
    end: f64,
    output: Output,
    /// The next frame falls at `next_output × output_interval`, or at the end time before it.
    next_output: u64,
    /// Wall-clock seconds the run had taken before this process continued it.
    wall_before: f64,
    started: Instant,
    /// The newest checkpoint on disk.
    last_saved: Option<Saved>,
    /// When this process last wrote a checkpoint (or started).
    last_saved_at: Instant,
    /// The first simulated time at which a checkpoint is due (`[checkpoint] interval`).
    next_checkpoint_time: Option<f64>,
    quiet: bool,
    stop: StopSignal,
}

/// Steps beyond which `isph run` warns at start that the run is very long.
const MANY_STEPS: f64 = 1.0e7;

/// `time`, or the multiple k × `interval` (k ≥ 1) within `FRAME_TIME_ROUNDING` intervals of it, as
/// the frames' schedule computes it: a run ends on the frame it lands on anyway. So a run stopped
/// at `--until 0.3` and resumed takes the very steps of one that ran through that frame, scheduled
/// at 3 × 0.1 = 0.30000000000000004 (landing on 0.3 itself, the steps before it would differ in
/// their last bits, and the continued run from there on).
fn on_frame(time: f64, interval: f64) -> f64 {
    let k = (time / interval).round();
    let multiple = k * interval;
    if k >= 1.0 && (multiple - time).abs() <= FRAME_TIME_ROUNDING * interval {
        multiple
    } else {
        time
    }
}

/// The index of the next scheduled frame of a run resumed at `time` whose checkpoint scheduled
/// frame `stored` next: that one where it is the next multiple of `interval` after `time`, as
/// it always is when the output interval is the checkpoint's. A forced resume with another
/// interval (`isph resume --force`) counts the frames of the old one in `stored`, which would
/// put the next frame long past or, worse, before `time`, and the step towards it backwards: it
/// takes the first multiple of the new interval after `time`.
fn resumed_next_output(stored: u64, time: f64, interval: f64) -> u64 {
    let rounding = FRAME_TIME_ROUNDING * interval;
    let scheduled = |k: u64| k as f64 * interval;
    let is_next = stored >= 1
        && scheduled(stored - 1) <= time + rounding
        && scheduled(stored) > time - rounding;
    if is_next {
        stored
    } else {
        ((time + rounding) / interval).floor() as u64 + 1
    }
}

impl<'a, const D: usize> Driver<'a, D> {
    /// A driver for `sim`, fresh or continuing from `resumed`.
    fn new(
        scene: &'a Scene,
        sim: Simulation<D>,
        output: Output,
        resumed: Option<&Checkpoint>,
        until: Option<f64>,
        quiet: bool,
        stop: &StopSignal,
    ) -> Self {
        let state = resumed.map(|c| &c.state);
        let now = Instant::now();
        let mut driver = Self {
            scene,
            requested_end: until.unwrap_or(scene.end_time),
            end: on_frame(until.unwrap_or(scene.end_time), scene.output_interval),
            output,
            next_output: state.map_or(0, |s| {
                resumed_next_output(s.next_output, s.time, scene.output_interval)
            }),
            wall_before: state.map_or(0.0, |s| s.wall_seconds),
            started: now,
            last_saved: resumed.map(|c| Saved {
                path: c.path().to_owned(),
                step: c.state.step,
                time: c.state.time,
            }),
            last_saved_at: now,
            next_checkpoint_time: None,
            quiet,
            stop: Arc::clone(stop),
            sim,
        };
        driver.next_checkpoint_time = driver.checkpoint_time_after(driver.sim.time);
        driver
    }

    fn wall_seconds(&self) -> f64 {
        self.wall_before + self.started.elapsed().as_secs_f64()
    }

    /// The first multiple of `[checkpoint] interval` after `time`.
    fn checkpoint_time_after(&self, time: f64) -> Option<f64> {
        let interval = self.scene.checkpoint.interval?;
        Some(((time / interval).floor() + 1.0) * interval)
    }

    /// The next frame's time, and whether writing it there is the scheduled frame
    /// `next_output × output_interval`: the scheduled time, or the end time if it comes first.
    /// A scheduled time within `FRAME_TIME_ROUNDING` intervals of the end time is the end time
    /// (0.03 × 11 = 0.32999999999999996 against an end time of 0.33), so that no step is
    /// shortened to a sliver between the two: the pressure solve divides by Δt, and a step of
    /// order 1e-17 s blows the flow up (docs/stabilisation.md, "A short step relaxes less").
    fn next_frame(&self) -> (f64, bool) {
        let interval = self.scene.output_interval;
        let scheduled = self.next_output as f64 * interval;
        let rounding = FRAME_TIME_ROUNDING * interval;
        if scheduled <= self.sim.time || scheduled < self.end - rounding {
            (scheduled, true)
        } else {
            (self.end, scheduled <= self.end + rounding)
        }
    }

    /// The time the next step goes towards: the next frame's, or a body's release before it
    /// (`Bodies::next_release_after`). A release within `FRAME_TIME_ROUNDING` intervals of the
    /// frame's time shares its landing, the later of the two, and one as close after the
    /// present time takes effect at the end of the next step, so that no step is a sliver.
    fn next_target(&self) -> f64 {
        let (frame, _) = self.next_frame();
        let rounding = FRAME_TIME_ROUNDING * self.scene.output_interval;
        match self.sim.bodies.next_release_after(self.sim.time + rounding) {
            Some(release) if release < frame - rounding => release,
            Some(release) if release <= frame + rounding => release.max(frame),
            _ => frame,
        }
    }

    /// Writes a frame when the simulation has reached the next frame time.
    fn write_frame_if_due(&mut self) -> Result<(), RunError> {
        let (target, scheduled) = self.next_frame();
        if self.sim.time < target {
            return Ok(());
        }
        let o = &mut self.output;
        let index = o.frames.len();
        let (p, pos) = (&self.sim.particles, self.sim.present_positions());
        let frame = o
            .frames_out
            .write(index, p, &pos, self.sim.time, self.sim.step)?;
        o.frames.push(frame);
        xdmf::write(&o.dir, &o.frames)?;
        if let Some(bodies) = &mut o.bodies {
            bodies.rows(self.sim.time, &self.sim.bodies)?;
            bodies.flush()?;
        }
        if let Some((writer, settings)) = &mut o.surfaces {
            let points = output::fluid_points(p, &pos, self.scene.spacing);
            // A surface that cannot be built (the fluid spread over more cubes than allowed)
            // is not worth a run that may have days behind it: the frame goes without one.
            match surface::reconstruct(&points, settings) {
                Ok(mesh) => {
                    writer.write(index, self.sim.time, &mesh, settings.obj)?;
                }
                Err(e) => eprintln!(
                    "warning: frame {index} (t = {} s) has no surface: {e}",
                    self.sim.time
                ),
            }
        }
        o.stats.flush()?;
        if let Some(probes) = &mut o.probes {
            probes.flush()?;
        }
        // A frame at the end time before the scheduled one leaves that one due.
        if scheduled {
            self.next_output += 1;
        }
        Ok(())
    }

    fn checkpoint_due(&self) -> bool {
        let by_time = self
            .next_checkpoint_time
            .is_some_and(|t| self.sim.time >= t);
        let by_wall =
            self.last_saved_at.elapsed().as_secs_f64() >= self.scene.checkpoint.wall_interval;
        by_time || by_wall
    }

    /// Writes a checkpoint of the current state, unless the newest one already holds it. The
    /// frames and rows it counts are made durable first.
    fn checkpoint(&mut self) -> Result<Saved, RunError> {
        if let Some(saved) = self.last_saved.as_ref().filter(|s| s.step == self.sim.step) {
            return Ok(saved.clone());
        }
        self.output.stats.sync()?;
        if let Some(probes) = &mut self.output.probes {
            probes.sync()?;
        }
        if let Some(bodies) = &mut self.output.bodies {
            bodies.sync()?;
        }
        self.output.frames_out.sync()?;
        let scene_path =
            std::path::absolute(&self.scene.path).unwrap_or_else(|_| self.scene.path.clone());
        let state = RunState {
            step: self.sim.step,
            time: self.sim.time,
            dt: self.sim.last_dt.unwrap_or(0.0),
            wall_seconds: self.wall_seconds(),
            frames_written: self.output.frames.len() as u64,
            next_output: self.next_output,
            scene_hash: self.scene.content_hash(),
            scene_path,
        };
        let path = checkpoint_folder::save(
            &checkpoint_folder::folder(&self.output.dir),
            &state,
            &mut self.sim.particles,
            &self.sim.bodies.states(),
            self.scene.checkpoint.keep,
        )?;
        let saved = Saved {
            path,
            step: state.step,
            time: state.time,
        };
        self.last_saved = Some(saved.clone());
        self.last_saved_at = Instant::now();
        self.next_checkpoint_time = self.checkpoint_time_after(state.time);
        Ok(saved)
    }

    /// Warns, on stderr, when the first time step puts the end more than `MANY_STEPS` steps
    /// away, naming the condition that sets Δt: a run that would take that long is more likely
    /// a mistyped viscosity or spacing than a wish.
    fn warn_of_a_long_run(&self) {
        // A collapsing step is the first step's to report.
        let Ok((dt, limit)) = self.sim.time_step_limit() else {
            return;
        };
        let steps = (self.end - self.sim.time) / dt;
        if steps > MANY_STEPS {
            eprintln!(
                "warning: the first time step is {dt:.3e} s, set by {}: reaching t = {:?} s takes about {steps:.1e} steps",
                limit.describe(),
                self.requested_end
            );
        }
    }

    fn drive(mut self) -> Result<RunSummary, RunError> {
        self.warn_of_a_long_run();
        let mut progress =
            Progress::new(self.sim.time, self.sim.step, self.requested_end, self.quiet);
        let (mut steps, mut ppe_total, mut last) = (0u64, 0u64, None);
        while self.sim.time < self.end {
            let step = match self.sim.advance_towards(self.next_target()) {
                Ok(s) => s,
                Err(failure) => {
                    self.output.stats.flush()?;
                    if let Some(probes) = &mut self.output.probes {
                        probes.flush()?;
                    }
                    progress.finish();
                    return Err(RunError::Numerical {
                        failure,
                        out: self.output.dir.clone(),
                        last_checkpoint: self.last_saved.clone(),
                    });
                }
            };
            steps += 1;
            ppe_total += step.ppe_iterations as u64;
            self.output.stats.row(&step, self.wall_seconds())?;
            if let Some(probes) = &mut self.output.probes {
                probes.row(
                    self.sim.time,
                    &self
                        .sim
                        .probe_values(&self.scene.probes, &self.scene.container),
                )?;
            }
            progress.update(&step);
            self.write_frame_if_due()?;
            if self.checkpoint_due() {
                self.checkpoint()?;
            }
            let signal = self.stop.load(Ordering::Relaxed);
            if signal != 0 {
                let saved = self.checkpoint()?;
                progress.finish();
                return Err(RunError::Interrupted {
                    signal,
                    saved,
                    out: self.output.dir,
                });
            }
            last = Some(step);
        }
        let checkpoint = self.checkpoint()?;
        progress.finish();
        Ok(RunSummary {
            steps,
            time: self.sim.time,
            frames: self.output.frames,
            wall_seconds: self.started.elapsed().as_secs_f64(),
            mean_ppe_iterations: ppe_total as f64 / steps.max(1) as f64,
            last,
            checkpoint,
            timings: self.sim.timings.clone(),
        })
    }
}
