//! The `isph` command line: parses arguments and calls the library.

use anyhow::{bail, Context};
use clap::{Parser, Subcommand};
use isph::bench::{self, BenchOptions, Schedule};
use isph::io::surface_files;
use isph::render::{self, ColorField, FrameChoice, RenderOptions};
use isph::resume::{self, ResumeOptions};
use isph::scene::SurfaceRequest;
use isph::study::{plot, StudyOptions};
use isph::tools::surface::{surface_run, FrameOutcome, SurfaceOptions};
use isph::Plan;
use isph::RunReport;
use isph::Scene;
use isph::{run, RunError, RunOptions, StopSignal};
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::flag;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// `print!` to stdout, where a reader that has gone away (`isph plan x | head -2`) is not an
/// error: the output is dropped, the command carries on (a run still writes its checkpoint).
macro_rules! out {
    ($($arg:tt)*) => { write_stdout(format_args!($($arg)*)) };
}

/// `println!` to stdout, as `out!`.
macro_rules! outln {
    ($($arg:tt)*) => { write_stdout(format_args!("{}\n", format_args!($($arg)*))) };
}

fn write_stdout(text: std::fmt::Arguments) {
    match std::io::stdout().write_fmt(text) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            eprintln!("warning: writing to stdout: {e}")
        }
        _ => {}
    }
}

#[derive(Parser)]
#[command(
    name = "isph",
    version,
    about = "Stabilised incompressible SPH solver for free-surface flows"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a scene, writing particles.h5, particles.xdmf and stats.csv.
    Run {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output directory [default: out/<scene name>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Stop at this simulated time [s] instead of the scene's end_time.
        #[arg(long)]
        until: Option<f64>,
        /// Worker threads [default: all cores]. Results are bit-identical for any count.
        #[arg(long)]
        threads: Option<usize>,
        /// Replace a run already in the output directory.
        #[arg(long)]
        overwrite: bool,
        /// No progress display.
        #[arg(long, short)]
        quiet: bool,
        /// Print only what this process measured of itself (peak memory), as TOML: how
        /// `isph study` runs each point.
        #[arg(long, hide = true)]
        report: bool,
    },
    /// Continue a run from a checkpoint, in the run's output directory.
    Resume {
        /// A checkpoint file, or a run's output directory (or its checkpoints/ folder): then
        /// the newest valid checkpoint in it.
        checkpoint: PathBuf,
        /// Stop at this simulated time [s] instead of the scene's end_time.
        #[arg(long)]
        until: Option<f64>,
        /// Continue even though the scene's settings have changed since the checkpoint was
        /// written (not its particles: a changed spacing, fluid block, container, obstacle or
        /// body is refused)
        #[arg(long)]
        force: bool,
        /// Scene file to use instead of the one the checkpoint names (e.g. after moving it).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Worker threads [default: all cores]. Results are bit-identical for any count.
        #[arg(long)]
        threads: Option<usize>,
        /// No progress display.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Print the stages, particle counts and memory of a scene without running it.
    Plan { scene: PathBuf },
    /// Reconstruct the water surface of a run's frames (marching cubes in 3D, marching
    /// squares in 2D) into surface.h5 + surface.xdmf and one PLY file per frame under
    /// surface/ (docs/surface.md).
    Surface {
        /// The run's output directory.
        run: PathBuf,
        /// Frames: `all`, `last`, or numbers and inclusive ranges, comma-separated (`0,10..20`).
        #[arg(long, default_value = "all")]
        frames: String,
        /// Density kernel: rectangular, quadric, quartic or gaussian (Eq. 28–31) [default: quartic].
        #[arg(long)]
        kernel: Option<String>,
        /// Kernel radius, in particle spacings [default: the kernel's own, docs/surface.md].
        #[arg(long)]
        radius: Option<f64>,
        /// The most cubes over the particles' box (the paper's rule).
        #[arg(long, conflicts_with = "cube_size")]
        max_cubes: Option<i64>,
        /// Cube edge, in particle spacings [default: 0.5].
        #[arg(long)]
        cube_size: Option<f64>,
        /// Iso-value of the density, which is 1 inside the fluid [default: 0.5].
        #[arg(long)]
        iso: Option<f64>,
        /// Also write each mesh as a Wavefront OBJ file.
        #[arg(long)]
        obj: bool,
        /// Directory for the surface files [default: the run's].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Replace surface files already there.
        #[arg(long)]
        overwrite: bool,
        /// Worker threads [default: all cores]. The meshes are byte-identical for any count.
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Draw a run's frames as PNG pictures: 2D particles coloured by a field, or the 3D water
    /// surface shaded (docs/render.md).
    Render {
        /// The run's output directory.
        run: PathBuf,
        /// The frame to draw (0 is the initial state) [default: the last].
        #[arg(long, conflicts_with = "all")]
        frame: Option<usize>,
        /// Draw every frame, as a numbered sequence frame_000000.png, … in the -o directory.
        #[arg(long)]
        all: bool,
        /// The field that colours the picture: pressure, speed, fluid or body.
        #[arg(long, default_value = "pressure")]
        color: String,
        /// Picture size in pixels, WIDTHxHEIGHT.
        #[arg(long, default_value = "1920x1080")]
        size: String,
        /// A .png file (one frame) or a directory.
        #[arg(short, long)]
        output: PathBuf,
        /// Worker threads [default: all cores]. The pictures are byte-identical for any count.
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Run a scene over a grid of settings, measure each run's error against a reference and
    /// plot error against wall time with its Pareto front (docs/study-format.md). Resumable:
    /// points already in OUT/study.csv are not run again.
    Study {
        /// Study file (TOML).
        study: PathBuf,
        /// Output directory [default: out/study-<study file name>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads of each run [default: all cores].
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Measure the error of a finished run against a reference solution or experiment
    /// (the error measures of `isph study`, docs/study-format.md).
    Measure {
        /// The error measure: hydrostatic, dam_break_front, poiseuille, taylor_green, lobovsky_pressure, cylinder_array, wave_flume or density.
        measure: String,
        /// The scene the run was made from.
        scene: PathBuf,
        /// The run's output directory.
        run: PathBuf,
    },
    /// Time the 3D dam break of scenes/dam_break_3d.toml at several particle counts and thread
    /// counts: time per step by stage, PPE iterations, pair throughput, peak memory, parallel
    /// efficiency (docs/performance.md). Each point runs in a process of its own.
    Bench {
        /// Wanted fluid-particle counts; each takes the spacing 0.1 m/k (k whole) that comes
        /// closest.
        #[arg(long, value_delimiter = ',', default_value = "1e4,1e5,1e6")]
        sizes: Vec<f64>,
        /// Thread counts [default: 1 up to the number of cores].
        #[arg(long, value_delimiter = ',')]
        threads: Vec<usize>,
        /// Steps timed at each point.
        #[arg(long, default_value_t = 3)]
        steps: usize,
        /// Untimed steps before them (the first step from rest solves the PPE from zero).
        #[arg(long, default_value_t = 1)]
        warmup: usize,
        /// The kernel (solver.kernel: quintic, wendland_c2, wendland_c4), at its default h/dx.
        #[arg(long, default_value = "quintic")]
        kernel: String,
        /// Also write the results to this CSV file.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Measure the one point given by --sizes and --threads in this process and print it
        /// as TOML: how `isph bench` runs each point.
        #[arg(long, hide = true)]
        child: bool,
    },
}

fn main() {
    if let Err(e) = dispatch(Cli::parse()) {
        match e.downcast_ref::<RunError>() {
            // Stopped on request, with a checkpoint: the exit code a shell gives a process
            // ended by that signal.
            Some(RunError::Interrupted { signal, .. }) => {
                eprintln!("{e}");
                std::process::exit(128 + *signal as i32);
            }
            _ => {
                eprintln!("error: {}", paragraph(&e));
                std::process::exit(1);
            }
        }
    }
}

/// The error with its causes, each cause only where the message does not already hold it (the
/// library's errors name their cause in their own message).
fn paragraph(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1).map(|c| c.to_string()) {
        if !text.contains(&cause) {
            text = format!("{text}: {cause}");
        }
    }
    text
}

fn dispatch(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Run {
            scene,
            out,
            until,
            threads,
            overwrite,
            quiet,
            report,
        } => {
            start_threads(threads)?;
            check_until(until)?;
            let scene = Scene::load(&scene)?;
            let out = out.unwrap_or_else(|| PathBuf::from("out").join(&scene.name));
            let stop = stop_on_signals()?;
            let opts = RunOptions {
                out: out.clone(),
                until,
                overwrite,
                quiet,
                stop,
            };
            let summary = run(&scene, &opts)?;
            if report {
                out!("{}", RunReport::of_this_process()?.to_toml());
                return Ok(());
            }
            outln!(
                "{}: {} steps to t = {} s in {:.1} s wall ({:.1} PPE iterations/step), {} frames in {}, checkpoint {}",
                scene.name,
                summary.steps,
                printed(summary.time),
                summary.wall_seconds,
                summary.mean_ppe_iterations,
                summary.frames.len(),
                out.display(),
                summary.checkpoint.path.display()
            );
            outln!("time per stage: {}", summary.timings);
            Ok(())
        }
        Command::Resume {
            checkpoint,
            until,
            force,
            scene,
            threads,
            quiet,
        } => {
            start_threads(threads)?;
            check_until(until)?;
            let located = resume::locate(&checkpoint)?;
            for skipped in &located.skipped {
                eprintln!("warning: skipped: {skipped}");
            }
            let stop = stop_on_signals()?;
            let opts = ResumeOptions {
                until,
                force,
                scene,
                quiet,
                stop,
            };
            let summary = isph::resume(&located.checkpoint, &opts)?;
            let state = &located.checkpoint.state;
            outln!(
                "resumed {} at step {} (t = {} s, last Δt = {:e} s): {} more steps to t = {} s in {:.1} s wall ({:.1} PPE iterations/step), {} frames in all, checkpoint {}",
                located.checkpoint.path().display(),
                state.step,
                printed(state.time),
                state.dt,
                summary.steps,
                printed(summary.time),
                summary.wall_seconds,
                summary.mean_ppe_iterations,
                summary.frames.len(),
                summary.checkpoint.path.display()
            );
            outln!("time per stage: {}", summary.timings);
            Ok(())
        }
        Command::Surface {
            run,
            frames,
            kernel,
            radius,
            max_cubes,
            cube_size,
            iso,
            obj,
            out,
            overwrite,
            threads,
        } => {
            start_threads(threads)?;
            let request = SurfaceRequest {
                kernel,
                radius,
                cube_size,
                max_cubes,
                iso,
                obj: Some(obj),
            };
            let settings = request
                .settings()
                .map_err(|(key, what)| anyhow::anyhow!("--{} {what}", key.replace('_', "-")))?;
            let opts = SurfaceOptions {
                frames: Some(frames),
                settings,
                out,
                overwrite,
            };
            let done = surface_run(&run, &opts, |outcome| {
                match outcome {
                FrameOutcome::Built(f) => outln!(
                    "frame {} (t = {} s): {} cells, {} vertices, encloses {:.6e} {} (the particles: {:.6e}), {:.3} s",
                    f.frame,
                    printed(f.time),
                    f.cells,
                    f.vertices,
                    f.enclosed,
                    if f.dimensions == 3 { "m³" } else { "m²" },
                    f.fluid,
                    f.seconds
                ),
                FrameOutcome::Skipped { frame, reason } => {
                    eprintln!("warning: frame {frame} has no surface: {reason}")
                }
            }
            })?;
            let dir = opts.out.unwrap_or(run);
            outln!(
                "written: {} surfaces to {} and {} (meshes in {})",
                done.len(),
                dir.join(surface_files::FILE_NAME).display(),
                dir.join(surface_files::INDEX_NAME).display(),
                dir.join(surface_files::MESH_DIR).display()
            );
            Ok(())
        }
        Command::Render {
            run,
            frame,
            all,
            color,
            size,
            output,
            threads,
        } => {
            start_threads(threads)?;
            let color = ColorField::from_name(&color).ok_or_else(|| {
                anyhow::anyhow!(
                    "--color {color}: not a field; one of {}",
                    ColorField::NAMES.join(", ")
                )
            })?;
            let size = render::parse_size(&size).ok_or_else(|| {
                anyhow::anyhow!("--size {size}: give WIDTHxHEIGHT in pixels, e.g. 1920x1080")
            })?;
            let frames = match (frame, all) {
                (Some(k), _) => FrameChoice::One(k),
                (None, true) => FrameChoice::All,
                (None, false) => FrameChoice::Last,
            };
            let opts = RenderOptions {
                frames,
                color,
                size,
                output,
            };
            let written = render::render_run(&run, &opts)?;
            match written.as_slice() {
                [one] => outln!("written: {}", one.display()),
                many => outln!(
                    "written: {} pictures in {}",
                    many.len(),
                    opts.output.display()
                ),
            }
            Ok(())
        }
        Command::Plan { scene } => {
            let scene = Scene::load(&scene)?;
            outln!("{}", Plan::new(&scene)?);
            Ok(())
        }
        Command::Measure {
            measure,
            scene,
            run,
        } => {
            let case: isph::validation::Case = measure.parse()?;
            let scene = Scene::load(&scene)?;
            let measured = isph::validation::measure(case, &scene, &run)?;
            outln!("error = {:e}", measured.error);
            for (name, value) in &measured.details {
                outln!("{name} = {value:e}");
            }
            Ok(())
        }
        Command::Study {
            study,
            out,
            threads,
        } => {
            if threads == Some(0) {
                bail!("--threads must be at least 1");
            }
            let exe = std::env::current_exe().context("locating the isph executable")?;
            let opts = StudyOptions { out, threads };
            let summary = isph::study::run(&study, &opts, &exe, |line| eprintln!("{line}"))?;
            out!("{}", plot::table(&summary.outcomes));
            if summary.complete {
                outln!(
                    "written: {} and {}",
                    summary.csv().display(),
                    summary.svg().display()
                );
            } else {
                outln!(
                    "{} of the study's points are done (the others are being run by another isph study); {} is written when all are",
                    summary.outcomes.len(),
                    summary.svg().display()
                );
            }
            Ok(())
        }
        Command::Bench {
            sizes,
            threads,
            steps,
            warmup,
            kernel,
            csv,
            child,
        } => {
            let threads = if threads.is_empty() {
                bench::default_threads()
            } else {
                threads
            };
            let schedule = Schedule { warmup, steps };
            let opts = BenchOptions::new(&sizes, &threads, schedule, &kernel, csv)?;
            if child {
                return bench_child(&opts);
            }
            let exe = std::env::current_exe().context("locating the isph executable")?;
            let rows = bench::run(&opts, &exe, |line| eprintln!("{line}"))?;
            out!("{}", bench::table(&rows, opts.schedule, opts.kernel));
            if let Some(csv) = &opts.csv {
                outln!("written: {}", csv.display());
            }
            Ok(())
        }
    }
}

/// One point of `isph bench`, measured in this process on a pool of the requested size.
fn bench_child(opts: &BenchOptions) -> anyhow::Result<()> {
    let (&[size], &[threads]) = (opts.sizes.as_slice(), opts.threads.as_slice()) else {
        bail!("--child measures one point: give one size and one thread count");
    };
    start_threads(Some(threads))?;
    let m = bench::measure_point(size, opts.schedule, opts.kernel)?;
    out!("{}", m.to_toml());
    Ok(())
}

fn start_threads(threads: Option<usize>) -> anyhow::Result<()> {
    if let Some(n) = threads {
        if n == 0 {
            bail!("--threads must be at least 1");
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("starting the thread pool")?;
    }
    Ok(())
}

fn check_until(until: Option<f64>) -> anyhow::Result<()> {
    if let Some(t) = until {
        if !(t.is_finite() && t > 0.0) {
            bail!("--until {t:?}: the stop time must be a positive number of seconds");
        }
    }
    Ok(())
}

/// SIGINT and SIGTERM stop a run after its current step, with a checkpoint; a second one ends
/// the process at once (the checkpoints already on disk stay valid).
fn stop_on_signals() -> anyhow::Result<StopSignal> {
    let stop = StopSignal::default();
    let stopping = Arc::new(AtomicBool::new(false));
    for signal in [SIGINT, SIGTERM] {
        flag::register_conditional_shutdown(signal, 128 + signal, Arc::clone(&stopping))
            .and_then(|_| flag::register(signal, Arc::clone(&stopping)))
            .and_then(|_| flag::register_usize(signal, Arc::clone(&stop), signal as usize))
            .context("installing the SIGINT/SIGTERM handlers")?;
    }
    Ok(stop)
}

/// A simulated time for a person to read, rounded to the picosecond: a run ends on its last
/// frame as the schedule computes it, 3 × 0.1 = 0.30000000000000004 s, printed 0.3 s.
fn printed(time: f64) -> f64 {
    (time * 1e12).round() / 1e12
}
