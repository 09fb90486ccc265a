//! The `isph` command line: parses arguments and calls the library.

use anyhow::{bail, Context};
use clap::{Parser, Subcommand};
use isph::plan::Plan;
use isph::run::{run, RunOptions};
use isph::scene::Scene;
use std::path::PathBuf;

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
    },
    /// Continue a run from a checkpoint.
    Resume {
        checkpoint: PathBuf,
        #[arg(long)]
        until: Option<f64>,
    },
    /// Print the stages, particle counts and memory of a scene without running it.
    Plan { scene: PathBuf },
}

fn main() {
    if let Err(e) = dispatch(Cli::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn dispatch(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Run { scene, out, until, threads, overwrite, quiet } => {
            if let Some(n) = threads {
                if n == 0 {
                    bail!("--threads must be at least 1");
                }
                rayon::ThreadPoolBuilder::new().num_threads(n).build_global().context("starting the thread pool")?;
            }
            if let Some(t) = until {
                if !(t.is_finite() && t > 0.0) {
                    bail!("--until {t}: the stop time must be a positive number of seconds");
                }
            }
            let scene = Scene::load(&scene)?;
            let out = out.unwrap_or_else(|| PathBuf::from("out").join(&scene.name));
            let summary = run(&scene, &RunOptions { out: out.clone(), until, overwrite, quiet })?;
            println!(
                "{}: {} steps to t = {} s in {:.1} s wall ({:.1} PPE iterations/step), {} frames in {}",
                scene.name,
                summary.steps,
                summary.time,
                summary.wall_seconds,
                summary.mean_ppe_iterations,
                summary.frames.len(),
                out.display()
            );
            Ok(())
        }
        Command::Resume { checkpoint, .. } => bail!(
            "{}: resuming from checkpoints is not available yet in this version of isph (checkpoint/restart is planned); rerun with `isph run` instead",
            checkpoint.display()
        ),
        Command::Plan { scene } => {
            let scene = Scene::load(&scene)?;
            println!("{}", Plan::new(&scene));
            Ok(())
        }
    }
}
