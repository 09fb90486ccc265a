//! `isph bench`: the 3D dam break of `scenes/dam_break_3d.toml` timed at several particle
//! counts and thread counts.
//!
//! Each (size, threads) point runs in a child process of its own (the hidden `--child` form of
//! `isph bench`, see [`crate::tools::child`]), so that the peak resident memory it reports
//! (VmHWM) is that point's alone and its thread pool has exactly the requested size. The child
//! builds the scene, takes warm-up steps, times the steps that follow and the time of each
//! stage (`Simulation::timings`), then times the apply of the PPE operator the step's own
//! stages build in one more step (`Simulation::advance_probing`), and prints a
//! [`Measurement`] as TOML on stdout; the parent collects the points, prints a table and writes
//! the CSV.

use crate::math::kernel::KernelKind;
use crate::math::reduce::in_pool;
use crate::particles::Kind;
use crate::scene::{Scene, SceneError};
use crate::simulation::{NoFluid, NumericalFailure, Simulation};
use crate::solver::krylov::LinearOperator;
use crate::solver::ppe::{PressureOperator, Role};
use crate::tools::child::{self, peak_resident_bytes, ChildError};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The tank of `scenes/dam_break_3d.toml` (x, y, z; z up) [m].
pub const TANK: [f64; 3] = [1.0, 0.4, 0.6];
/// Its water block, in the tank's corner at the origin [m].
pub const BLOCK: [f64; 3] = [0.3, 0.4, 0.5];
/// Every side of the tank and of the block is a whole multiple of this length [m]: at a spacing
/// of UNIT/m the walls and the block's faces fall on the particle lattice.
const UNIT: f64 = 0.1;
/// The block holds 3 × 4 × 5 = 60 m³ fluid particles at the spacing UNIT/m.
const BLOCK_CELLS: f64 = 60.0;
/// The smallest wanted size: the spacing UNIT/3, a block 9 × 12 × 15 particles.
pub const MIN_SIZE: f64 = 1000.0;
/// The scenes' end time [s]; the bench counts steps and never gets there.
const END_TIME: f64 = 10.0;
/// Timed applies of the PPE operator per point (the first, untimed, touches the memory).
const APPLY_REPEATS: usize = 5;

#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("--sizes {value:?}: not a particle count; give whole numbers of fluid particles of at least {MIN_SIZE}, e.g. --sizes 1e4,1e5,1e6")]
    Size { value: f64 },
    #[error("--threads {value}: a thread count must be at least 1, e.g. --threads 1,2")]
    Threads { value: usize },
    #[error("--steps must be at least 1 (the steps timed at each point)")]
    Steps,
    #[error("--kernel {value:?}: not a kernel; give one of {}", KernelKind::NAMES.join(", "))]
    Kernel { value: String },
    #[error("cannot write the CSV file {}: {source}", path.display())]
    Csv {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("measuring {requested} particles on {threads} threads: {source}")]
    Point {
        requested: usize,
        threads: usize,
        source: ChildError,
    },
    #[error(transparent)]
    Process(#[from] ChildError),
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    NoFluid(#[from] NoFluid),
    #[error(transparent)]
    Numerical(#[from] NumericalFailure),
}

/// How many steps each point takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Schedule {
    /// Untimed steps first: the first steps from rest start the PPE from a zero pressure.
    pub warmup: usize,
    pub steps: usize,
}

/// The spacing for about `fluid` fluid particles: UNIT/m with m the whole number that comes
/// closest, so that tank and block stay whole numbers of spacings (60 m³ fluid particles).
pub fn spacing_for(fluid: usize) -> f64 {
    let m = (fluid as f64 / BLOCK_CELLS).cbrt().round().max(1.0);
    UNIT / m
}

/// The dam break of `scenes/dam_break_3d.toml` at `spacing` with `kernel` at its default h/dx;
/// in 2D its x–z section (tank 1.0 × 0.6 m, block 0.3 × 0.5 m).
pub fn dam_break_scene(
    dimensions: usize,
    spacing: f64,
    kernel: KernelKind,
) -> Result<Scene, SceneError> {
    let axes: &[usize] = if dimensions == 2 { &[0, 2] } else { &[0, 1, 2] };
    let list = |v: [f64; 3]| {
        let parts: Vec<String> = axes.iter().map(|&a| format!("{:?}", v[a])).collect();
        parts.join(", ")
    };
    let mut gravity = [0.0; 3];
    gravity[2] = -9.81;
    let text = format!(
        "[simulation]\n\
         name = \"bench_dam_break_{dimensions}d\"\n\
         dimensions = {dimensions}\n\
         spacing = {spacing:?}\n\
         end_time = {END_TIME:?}\n\
         output_interval = {END_TIME:?}\n\
         gravity = [{gravity}]\n\
         [[fluid]]\n\
         name = \"water\"\n\
         density = 1000.0\n\
         viscosity = 1.0e-6\n\
         [[fluid_block]]\n\
         fluid = \"water\"\n\
         min = [{zero}]\n\
         max = [{block}]\n\
         [container]\n\
         min = [{zero}]\n\
         max = [{tank}]\n\
         [solver]\n\
         kernel = \"{kernel}\"\n",
        kernel = kernel.name(),
        gravity = list(gravity),
        zero = list([0.0; 3]),
        block = list(BLOCK),
        tank = list(TANK),
    );
    Scene::parse(&text, Path::new("<isph bench dam break>"))
}

/// A wanted size from the command line, checked.
pub fn fluid_count(value: f64) -> Result<usize, BenchError> {
    if value.is_finite() && value >= MIN_SIZE && value.fract() == 0.0 {
        Ok(value as usize)
    } else {
        Err(BenchError::Size { value })
    }
}

/// What one (size, threads) point measured, in the process that ran it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Measurement {
    /// The wanted number of fluid particles.
    pub requested: usize,
    /// Threads of the pool that ran the steps.
    pub threads: usize,
    /// The kernel's name (`solver.kernel`).
    pub kernel: String,
    pub spacing: f64,
    pub fluid_particles: usize,
    /// Fluid and wall particles.
    pub particles: usize,
    pub warmup_steps: usize,
    /// Simulated time before the first and after the last timed step [s].
    pub time_start: f64,
    pub time_end: f64,
    /// Wall time of each timed step, `advance_towards` as a whole [s].
    pub step_seconds: Vec<f64>,
    /// The stages of the step, in order (`Step::stages`).
    pub stages: Vec<String>,
    /// Mean time of a timed step in each of `stages` [s].
    pub stage_seconds: Vec<f64>,
    pub ppe_iterations: Vec<usize>,
    /// `density_error` of the last timed step.
    pub density_error: f64,
    /// Neighbour pairs (j ≠ i inside the kernel support) of the interior PPE rows: the pair
    /// interactions of one apply.
    pub apply_pairs: usize,
    /// Wall time of each timed apply of the PPE operator [s].
    pub apply_seconds: Vec<f64>,
    /// VmHWM at the end of the timed steps [bytes].
    pub peak_rss_bytes: u64,
}

/// Runs one point in this process (the child's work), on the current rayon pool.
pub fn measure_point(
    requested: usize,
    schedule: Schedule,
    kernel: KernelKind,
) -> Result<Measurement, BenchError> {
    in_pool(|| measure_in_pool(requested, schedule, kernel))
}

fn measure_in_pool(
    requested: usize,
    schedule: Schedule,
    kernel: KernelKind,
) -> Result<Measurement, BenchError> {
    let scene = dam_break_scene(3, spacing_for(requested), kernel)?;
    let mut sim = Simulation::<3>::new(&scene)?;
    for _ in 0..schedule.warmup {
        sim.advance_towards(END_TIME)?;
    }
    let before = sim.timings.clone();
    let time_start = sim.time;
    let (mut step_seconds, mut ppe_iterations, mut density_error) = (Vec::new(), Vec::new(), 0.0);
    for _ in 0..schedule.steps {
        let clock = Instant::now();
        let stats = sim.advance_towards(END_TIME)?;
        step_seconds.push(clock.elapsed().as_secs_f64());
        ppe_iterations.push(stats.ppe_iterations);
        density_error = stats.density_error;
    }
    let stages: Vec<String> = sim.timings.names().map(String::from).collect();
    let stage_seconds = sim
        .timings
        .names()
        .map(|s| (sim.timings.get(s) - before.get(s)).as_secs_f64() / schedule.steps as f64)
        .collect();
    // Read before the apply probe below allocates its own arrays.
    let peak_rss_bytes = peak_resident_bytes()?;
    let (fluid_particles, particles) = (sim.particles.fluid_count(), sim.particles.len());
    let (apply_pairs, apply_seconds) = time_ppe_apply(&mut sim)?;
    Ok(Measurement {
        requested,
        threads: rayon::current_num_threads(),
        kernel: kernel.name().into(),
        spacing: scene.spacing,
        fluid_particles,
        particles,
        warmup_steps: schedule.warmup,
        time_start,
        time_end: sim.time,
        step_seconds,
        stages,
        stage_seconds,
        ppe_iterations,
        density_error,
        apply_pairs,
        apply_seconds,
        peak_rss_bytes,
    })
}

impl Measurement {
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a Measurement is plain numbers and lists")
    }
}

/// Times the apply of the PPE operator of one more step, the operator its own stages build
/// (`Simulation::advance_probing`): (pairs per apply, seconds of each timed apply).
fn time_ppe_apply<const D: usize>(
    sim: &mut Simulation<D>,
) -> Result<(usize, Vec<f64>), NumericalFailure> {
    let probed = sim.advance_probing(END_TIME, |op| {
        let x = op.p.pressure[..op.len()].to_vec();
        let mut y = vec![0.0; op.len()];
        op.apply(&x, &mut y);
        let seconds = (0..APPLY_REPEATS)
            .map(|_| {
                let clock = Instant::now();
                op.apply(&x, &mut y);
                clock.elapsed().as_secs_f64()
            })
            .collect();
        (apply_pairs(op), seconds)
    });
    probed.map(|(_, timed)| timed)
}

/// Fluid neighbour pairs of the interior rows of `op`, the only rows that visit their
/// neighbours (the others are identity rows) and the only pairs they visit (the walls' are
/// known numbers, in the right-hand side): the pair interactions of one apply.
pub fn apply_pairs<const D: usize>(op: &PressureOperator<D>) -> usize {
    (0..op.roles.len())
        .into_par_iter()
        .filter(|&i| op.roles[i] == Role::Interior)
        .map(|i| {
            let mut n = 0;
            op.nb.for_each_of(i, &[Kind::Fluid], |_, _, _| n += 1);
            n
        })
        .sum()
}

/// What `isph bench` runs.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Wanted fluid-particle counts, ascending.
    pub sizes: Vec<usize>,
    /// Thread counts, ascending.
    pub threads: Vec<usize>,
    pub schedule: Schedule,
    pub kernel: KernelKind,
    pub csv: Option<PathBuf>,
}

impl BenchOptions {
    /// Checks the command line's values; sizes and thread counts are sorted and deduplicated.
    pub fn new(
        sizes: &[f64],
        threads: &[usize],
        schedule: Schedule,
        kernel: &str,
        csv: Option<PathBuf>,
    ) -> Result<Self, BenchError> {
        let kernel = KernelKind::from_name(kernel).ok_or_else(|| BenchError::Kernel {
            value: kernel.into(),
        })?;
        let mut sizes = sizes
            .iter()
            .map(|&s| fluid_count(s))
            .collect::<Result<Vec<_>, _>>()?;
        if let Some(&value) = threads.iter().find(|&&t| t == 0) {
            return Err(BenchError::Threads { value });
        }
        if schedule.steps == 0 {
            return Err(BenchError::Steps);
        }
        let mut threads = threads.to_vec();
        for v in [&mut sizes, &mut threads] {
            v.sort_unstable();
            v.dedup();
        }
        Ok(Self {
            sizes,
            threads,
            schedule,
            kernel,
            csv,
        })
    }
}

/// 1 up to the number of cores.
pub fn default_threads() -> Vec<usize> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    (1..=cores).collect()
}

/// A measured point with what the parent derives from the others.
#[derive(Clone, Debug)]
pub struct Row {
    pub m: Measurement,
    /// t_b·T_b / (t·T), with t the median step time on T threads and b the point of the same
    /// size with the fewest threads (1 when 1 is measured): 1 is perfect scaling.
    pub parallel_efficiency: f64,
}

impl Row {
    pub fn step_median(&self) -> f64 {
        median(&self.m.step_seconds)
    }

    /// Median step time per fluid particle [µs].
    pub fn us_per_fluid_particle_step(&self) -> f64 {
        1e6 * self.step_median() / self.m.fluid_particles as f64
    }

    pub fn mean_ppe_iterations(&self) -> f64 {
        mean(
            &self
                .m
                .ppe_iterations
                .iter()
                .map(|&n| n as f64)
                .collect::<Vec<_>>(),
        )
    }

    pub fn pairs_per_fluid_particle(&self) -> f64 {
        self.m.apply_pairs as f64 / self.m.fluid_particles as f64
    }

    /// Pair interactions per second of the PPE apply (median apply time).
    pub fn apply_pairs_per_second(&self) -> f64 {
        self.m.apply_pairs as f64 / median(&self.m.apply_seconds)
    }

    pub fn peak_bytes_per_particle(&self) -> f64 {
        self.m.peak_rss_bytes as f64 / self.m.particles as f64
    }

    /// Mean step time not in any stage of `Timings` (time-step limit, diagnostics).
    pub fn other_seconds(&self) -> f64 {
        mean(&self.m.step_seconds) - self.m.stage_seconds.iter().sum::<f64>()
    }

    /// The CSV columns of this row, (name, value) in order.
    fn fields(&self) -> Vec<(String, String)> {
        let m = &self.m;
        let (min, max) = min_max(&m.step_seconds);
        let mut f: Vec<(String, String)> = vec![
            ("requested_fluid".into(), m.requested.to_string()),
            ("threads".into(), m.threads.to_string()),
            ("kernel".into(), m.kernel.clone()),
            ("spacing_m".into(), m.spacing.to_string()),
            ("fluid_particles".into(), m.fluid_particles.to_string()),
            ("particles".into(), m.particles.to_string()),
            ("warmup_steps".into(), m.warmup_steps.to_string()),
            ("timed_steps".into(), m.step_seconds.len().to_string()),
            ("time_start_s".into(), m.time_start.to_string()),
            ("time_end_s".into(), m.time_end.to_string()),
            ("step_median_s".into(), self.step_median().to_string()),
            ("step_min_s".into(), min.to_string()),
            ("step_max_s".into(), max.to_string()),
            (
                "us_per_fluid_particle_step".into(),
                self.us_per_fluid_particle_step().to_string(),
            ),
        ];
        for (stage, seconds) in m.stages.iter().zip(&m.stage_seconds) {
            f.push((
                format!("{}_s", stage.replace(' ', "_")),
                seconds.to_string(),
            ));
        }
        f.extend([
            ("other_s".into(), self.other_seconds().to_string()),
            (
                "ppe_iterations_mean".into(),
                self.mean_ppe_iterations().to_string(),
            ),
            ("density_error".into(), m.density_error.to_string()),
            ("apply_pairs".into(), m.apply_pairs.to_string()),
            (
                "pairs_per_fluid_particle".into(),
                self.pairs_per_fluid_particle().to_string(),
            ),
            (
                "apply_median_s".into(),
                median(&m.apply_seconds).to_string(),
            ),
            (
                "apply_pairs_per_s".into(),
                self.apply_pairs_per_second().to_string(),
            ),
            ("peak_rss_bytes".into(), m.peak_rss_bytes.to_string()),
            (
                "peak_bytes_per_particle".into(),
                self.peak_bytes_per_particle().to_string(),
            ),
            (
                "parallel_efficiency".into(),
                self.parallel_efficiency.to_string(),
            ),
        ]);
        f
    }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

fn min_max(v: &[f64]) -> (f64, f64) {
    let min = v.iter().copied().fold(f64::INFINITY, f64::min);
    let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (min, max)
}

/// The CSV file, one row written (and flushed) per point as it comes into `FILE.partial`,
/// which takes the name FILE once every point is measured: the points measured before a
/// failure are kept there, and a FILE already on disk is replaced only by a finished bench.
struct CsvOut {
    path: PathBuf,
    partial: PathBuf,
    out: BufWriter<File>,
    header_written: bool,
}

impl CsvOut {
    /// Creates `FILE.partial` at once, so an unwritable path fails before any measurement.
    fn create(path: &Path) -> Result<Self, BenchError> {
        let mut partial = path.as_os_str().to_owned();
        partial.push(".partial");
        let partial = PathBuf::from(partial);
        let file = File::create(&partial).map_err(|source| BenchError::Csv {
            path: partial.clone(),
            source,
        })?;
        Ok(Self {
            path: path.to_owned(),
            partial,
            out: BufWriter::new(file),
            header_written: false,
        })
    }

    /// Gives the finished file its name.
    fn finish(self) -> Result<(), BenchError> {
        drop(self.out);
        std::fs::rename(&self.partial, &self.path).map_err(|source| BenchError::Csv {
            path: self.path,
            source,
        })
    }

    fn row(&mut self, row: &Row) -> Result<(), BenchError> {
        let fields = row.fields();
        let names: Vec<&str> = fields.iter().map(|(name, _)| name.as_str()).collect();
        let values: Vec<&str> = fields.iter().map(|(_, value)| value.as_str()).collect();
        let mut text = String::new();
        if !self.header_written {
            text = names.join(",") + "\n";
            self.header_written = true;
        }
        text += &(values.join(",") + "\n");
        self.out
            .write_all(text.as_bytes())
            .and_then(|_| self.out.flush())
            .map_err(|source| BenchError::Csv {
                path: self.partial.clone(),
                source,
            })
    }
}

/// Runs every point in a child process of `exe` (this program), sizes outer, threads inner;
/// `log` receives a line before and after each point.
pub fn run(
    opts: &BenchOptions,
    exe: &Path,
    mut log: impl FnMut(String),
) -> Result<Vec<Row>, BenchError> {
    let mut csv = opts.csv.as_deref().map(CsvOut::create).transpose()?;
    let mut rows: Vec<Row> = Vec::new();
    let total = opts.sizes.len() * opts.threads.len();
    for &requested in &opts.sizes {
        for &threads in &opts.threads {
            log(format!(
                "[{}/{total}] {requested} fluid particles (spacing {:.5} m) on {threads} thread(s) …",
                rows.len() + 1,
                spacing_for(requested)
            ));
            let m = run_child(exe, requested, threads, opts.schedule, opts.kernel)?;
            let baseline = rows.iter().find(|r| r.m.requested == requested);
            let parallel_efficiency = match baseline {
                Some(b) => {
                    (b.step_median() * b.m.threads as f64)
                        / (median(&m.step_seconds) * m.threads as f64)
                }
                None => 1.0,
            };
            let row = Row {
                m,
                parallel_efficiency,
            };
            log(format!(
                "      {} fluid + {} wall particles: {:.3} s/step, {:.1} PPE iterations/step",
                row.m.fluid_particles,
                row.m.particles - row.m.fluid_particles,
                row.step_median(),
                row.mean_ppe_iterations()
            ));
            if let Some(csv) = csv.as_mut() {
                csv.row(&row)?;
            }
            rows.push(row);
        }
    }
    if let Some(csv) = csv {
        csv.finish()?;
    }
    Ok(rows)
}

/// Measures one point in a child process: `exe bench --child …` (see main.rs).
fn run_child(
    exe: &Path,
    requested: usize,
    threads: usize,
    schedule: Schedule,
    kernel: KernelKind,
) -> Result<Measurement, BenchError> {
    child::run(
        Command::new(exe)
            .args(["bench", "--child"])
            .args(["--sizes", &requested.to_string()])
            .args(["--threads", &threads.to_string()])
            .args(["--steps", &schedule.steps.to_string()])
            .args(["--warmup", &schedule.warmup.to_string()])
            .args(["--kernel", kernel.name()]),
    )
    .map_err(|source| BenchError::Point {
        requested,
        threads,
        source,
    })
}

/// The human table of the rows: one line per point, then the time per stage.
pub fn table(rows: &[Row], schedule: Schedule, kernel: KernelKind) -> String {
    let mut t = String::new();
    let (tank, block) = (TANK.map(|x| x.to_string()), BLOCK.map(|x| x.to_string()));
    let _ = writeln!(
        t,
        "3D dam break, tank {} m, block {} m, {} kernel at h/dx {}; {} warm-up + {} timed steps per point; times are medians over the timed steps [min, max]",
        tank.join(" × "),
        block.join(" × "),
        kernel.name(),
        kernel.default_h_over_dx(),
        schedule.warmup,
        schedule.steps
    );
    let _ = writeln!(
        t,
        "{:>9} {:>9} {:>3} {:>9} {:>26} {:>12} {:>7} {:>10} {:>12} {:>10} {:>6}",
        "fluid",
        "total",
        "thr",
        "dx [m]",
        "step [s]",
        "µs/fluid/st",
        "PPE it",
        "pairs/fl",
        "apply pair/s",
        "peak B/p",
        "eff"
    );
    for r in rows {
        let m = &r.m;
        let (min, max) = min_max(&m.step_seconds);
        let _ = writeln!(
            t,
            "{:>9} {:>9} {:>3} {:>9.5} {:>26} {:>12.2} {:>7.1} {:>10.1} {:>12.3e} {:>10.0} {:>6.2}",
            m.fluid_particles,
            m.particles,
            m.threads,
            m.spacing,
            format!("{:.3} [{:.3}, {:.3}]", r.step_median(), min, max),
            r.us_per_fluid_particle_step(),
            r.mean_ppe_iterations(),
            r.pairs_per_fluid_particle(),
            r.apply_pairs_per_second(),
            r.peak_bytes_per_particle(),
            r.parallel_efficiency
        );
    }
    let _ = writeln!(t, "time per step by stage [ms], mean over the timed steps:");
    let mut header = format!("{:>9} {:>3}", "fluid", "thr");
    for s in rows.first().map_or(&[][..], |r| &r.m.stages[..]) {
        let _ = write!(header, " {:>14}", s);
    }
    let _ = writeln!(t, "{header} {:>8}", "other");
    for r in rows {
        let _ = write!(t, "{:>9} {:>3}", r.m.fluid_particles, r.m.threads);
        for s in &r.m.stage_seconds {
            let _ = write!(t, " {:>14.1}", 1e3 * s);
        }
        let _ = writeln!(t, " {:>8.1}", 1e3 * r.other_seconds());
    }
    t
}
