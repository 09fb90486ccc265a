//! Shared helpers: lattices of particles sorted into a cell list, scenes, and runs.

use isph::math::kernel::{Kernel, KernelKind};
use isph::neighbours::cell_list::CellList;
use isph::particles::{Kind, NewParticle, Particles};
use isph::run::{run, RunOptions, RunSummary};
use isph::scene::Scene;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A block of `n` fluid particles per axis at spacing `dx` around the origin, sorted by cell.
pub struct Lattice<const D: usize> {
    pub particles: Particles<D>,
    pub grid: CellList<D>,
    pub kernel: Kernel<D>,
}

impl<const D: usize> Lattice<D> {
    pub fn new(n: i64, dx: f64, h_over_dx: f64) -> Self {
        Self::part(n, dx, h_over_dx, |_| true)
    }

    /// `new` with the kernel `kind`.
    pub fn with_kernel(kind: KernelKind, n: i64, dx: f64, h_over_dx: f64) -> Self {
        Self::build(Self::block(n), dx, Kernel::new(kind, dx, h_over_dx))
    }

    /// The points of `new` whose lattice index `keep` accepts.
    pub fn part(n: i64, dx: f64, h_over_dx: f64, keep: impl Fn(&[i64; D]) -> bool) -> Self {
        let points = Self::block(n).filter(|(index, _)| keep(index));
        Self::from_indices(points, dx, h_over_dx)
    }

    /// The lattice indices of `new`, fluid.
    fn block(n: i64) -> impl Iterator<Item = ([i64; D], Kind)> {
        let half = n / 2;
        let total = (n as usize).pow(D as u32);
        (0..total).map(move |k| {
            let mut rest = k as i64;
            let index = std::array::from_fn(|_| {
                let c = rest % n;
                rest /= n;
                c - half
            });
            (index, Kind::Fluid)
        })
    }

    /// Particles at lattice indices (position = index · dx) of the given kinds.
    pub fn from_indices(
        points: impl IntoIterator<Item = ([i64; D], Kind)>,
        dx: f64,
        h_over_dx: f64,
    ) -> Self {
        Self::build(points, dx, Kernel::new(KernelKind::Quintic, dx, h_over_dx))
    }

    /// Particles at lattice indices of the given kinds, with `kernel`.
    fn build(
        points: impl IntoIterator<Item = ([i64; D], Kind)>,
        dx: f64,
        kernel: Kernel<D>,
    ) -> Self {
        let mut particles = Particles::<D>::default();
        let mut extent = 0.0_f64;
        for (index, kind) in points {
            let pos = index.map(|c| c as f64 * dx);
            extent = pos.iter().fold(extent, |e, x| e.max(x.abs()));
            particles.push(NewParticle {
                pos,
                kind,
                normal: [0.0; D],
                fluid: 0,
                mass: 1000.0 * dx.powi(D as i32),
                rest_density: 1000.0,
                viscosity: 0.0,
            });
        }
        let extent = extent + 2.0 * dx;
        let mut grid = CellList::new([-extent; D], [extent; D], kernel.support(), [false; D]);
        let (mut cells, mut order, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
        grid.sort(&particles.pos, &particles.kind, &mut cells, &mut order)
            .expect("lattice inside grid");
        particles.permute(&order, &mut scratch);
        Self {
            particles,
            grid,
            kernel,
        }
    }

    /// Index of the particle nearest the origin.
    pub fn centre(&self) -> usize {
        let p = &self.particles;
        (0..p.len())
            .min_by(|&a, &b| {
                let r = |i: usize| (0..D).map(|d| p.pos[d][i].powi(2)).sum::<f64>();
                r(a).total_cmp(&r(b))
            })
            .unwrap()
    }
}

/// A temporary directory removed when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("isph-test-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A small 2D scene: a 10 × 10 block of water (dx = 0.02 m) in a 20 × 15 box, run to `end_time`
/// with frames every 0.02 s (at most).
pub fn water_block_scene(end_time: f64) -> String {
    format!(
        r#"[simulation]
dimensions = 2
spacing = 0.02
end_time = {end_time}
output_interval = {interval}
gravity = [0.0, -9.81]

[[fluid]]
name = "water"
density = 1000.0
viscosity = 1.0e-6

[[fluid_block]]
fluid = "water"
min = [0.0, 0.0]
max = [0.2, 0.2]

[container]
min = [0.0, 0.0]
max = [0.4, 0.3]
"#,
        interval = end_time.min(0.02)
    )
}

/// A scene from TOML text (errors name the file `scene.toml`).
pub fn scene_from_text(text: &str) -> Scene {
    Scene::parse(text, Path::new("scene.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// Loads a scene shipped in `scenes/`.
pub fn shipped_scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs `scene` quietly into `out` until `until`.
pub fn run_scene(scene: &Scene, out: &Path, until: f64) -> RunSummary {
    let opts = RunOptions {
        out: out.to_owned(),
        until: Some(until),
        overwrite: true,
        quiet: true,
        stop: Default::default(),
    };
    run(scene, &opts).unwrap_or_else(|e| panic!("{e}"))
}

/// Reads one frame's dataset from a run's particles.h5.
pub fn read_frame<T: hdf5::H5Type>(out: &Path, frame: usize, name: &str) -> Vec<T> {
    let file = hdf5::File::open(out.join("particles.h5")).unwrap();
    file.dataset(&format!("frame_{frame:06}/{name}"))
        .unwrap()
        .read_raw::<T>()
        .unwrap()
}

/// Column `name` of a run's stats.csv.
pub fn stats_column(out: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(out.join("stats.csv")).unwrap();
    let mut lines = text.lines();
    let col = lines
        .next()
        .unwrap()
        .split(',')
        .position(|c| c == name)
        .expect("column");
    lines
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect()
}

/// A command whose process inherits no file descriptor but stdin, stdout and stderr. HDF5 opens
/// files without O_CLOEXEC and holds a lock on them, so a child spawned while another test is
/// writing a run would otherwise keep that run's particles.h5 locked until it exits.
pub fn command(program: &str) -> Command {
    let mut c = Command::new(program);
    // SAFETY: close(2) is async-signal-safe, and nothing else runs between fork and exec.
    unsafe {
        c.pre_exec(|| {
            for fd in 3..1024 {
                libc::close(fd);
            }
            Ok(())
        });
    }
    c
}

/// The isph binary under test, as a `command`.
pub fn isph_command() -> Command {
    command(env!("CARGO_BIN_EXE_isph"))
}

/// A 3D block of water `block` m from the origin in a closed tank `tank` m (dx = 0.02 m), run
/// to `end_time` with frames every `interval` s, with `extra` appended to the scene.
pub fn water_block_scene_3d(
    block: [f64; 3],
    tank: [f64; 3],
    end_time: f64,
    interval: f64,
    extra: &str,
) -> String {
    format!(
        r#"[simulation]
dimensions = 3
spacing = 0.02
end_time = {end_time}
output_interval = {interval}
gravity = [0.0, 0.0, -9.81]

[[fluid]]
name = "water"
density = 1000.0
viscosity = 1.0e-6

[[fluid_block]]
fluid = "water"
min = [0.0, 0.0, 0.0]
max = {block:?}

[container]
min = [0.0, 0.0, 0.0]
max = {tank:?}
{extra}"#
    )
}

/// A tank `width` × `height` with water `depth` deep (dx = `spacing`), gravity along −y (−z in
/// 3D), frames every `interval` s, and the sections `body` after it (bodies, a trajectory).
pub fn tank(
    dims: usize,
    spacing: f64,
    size: [f64; 3],
    depth: f64,
    interval: f64,
    body: &str,
) -> String {
    let v = |x: &[f64]| {
        format!(
            "[{}]",
            x[..dims]
                .iter()
                .map(|x| format!("{x:?}"))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let mut gravity = [0.0; 3];
    gravity[dims - 1] = -9.81;
    let mut block = size;
    block[dims - 1] = depth;
    format!(
        r#"[simulation]
dimensions = {dims}
spacing = {spacing:?}
end_time = 10.0
output_interval = {interval:?}
gravity = {g}

[[fluid]]
name = "water"
density = 1000.0
viscosity = 1.0e-6

[[fluid_block]]
fluid = "water"
min = {zero}
max = {block}

[container]
min = {zero}
max = {size}

{body}
"#,
        g = v(&gravity),
        zero = v(&[0.0; 3]),
        block = v(&block),
        size = v(&size),
    )
}

/// Frames every 0.02, 0.025 and 0.03 s: three draws of a chaotic run (`over_draws`).
pub const THREE_DRAWS: [f64; 3] = [0.02, 0.025, 0.03];

/// Six draws of a chaotic run (`over_draws`), frames every 0.015 to 0.04 s.
pub const SIX_DRAWS: [f64; 6] = [0.015, 0.02, 0.025, 0.03, 0.035, 0.04];

/// `run` over draws of a chaotic run of `scene`: frames every `intervals` s land other steps on
/// them (a step is cut short to land on a frame), and after a plunge or a pile-up each lands
/// elsewhere. For tests that judge a chaotic outcome over draws, not on one.
pub fn over_draws<T>(scene: &Scene, intervals: &[f64], run: impl Fn(&Scene) -> T) -> Vec<T> {
    intervals
        .iter()
        .map(|&interval| {
            run(&Scene {
                output_interval: interval,
                ..scene.clone()
            })
        })
        .collect()
}
