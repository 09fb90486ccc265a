//! Scene files: TOML in SI units, parsed with unknown keys rejected, then validated into a
//! `Scene`. Every error names the file, the key and, where it can be found, the line.

mod effects;

pub use effects::{Effects, LesSettings, ShiftingSettings};

pub use crate::math::aabb::Aabb;
use crate::math::kernel::SUPPORT_IN_H;
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("cannot read scene file {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Syntax { path: PathBuf, message: String },
    #[error("{path}{}: `{key}` {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Invalid {
        path: PathBuf,
        line: Option<usize>,
        key: String,
        message: String,
    },
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    simulation: SimulationSection,
    #[serde(default)]
    fluid: Vec<Fluid>,
    #[serde(default)]
    fluid_block: Vec<FluidBlock>,
    container: ContainerSection,
    #[serde(default)]
    obstacle: Vec<BoxSection>,
    initial_velocity: Option<InitialVelocitySection>,
    #[serde(default)]
    solver: SolverSettings,
    #[serde(default)]
    checkpoint: CheckpointSection,
    #[serde(default)]
    effects: EffectsSection,
    #[serde(default)]
    walls: WallSettings,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SimulationSection {
    name: Option<String>,
    dimensions: i64,
    spacing: f64,
    end_time: f64,
    output_interval: f64,
    gravity: Vec<f64>,
}

/// One fluid of the scene.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fluid {
    pub name: String,
    /// Rest density ρ0 [kg/m³].
    pub density: f64,
    /// Kinematic viscosity ν [m²/s].
    pub viscosity: f64,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct FluidBlock {
    fluid: String,
    min: Vec<f64>,
    max: Vec<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct BoxSection {
    min: Vec<f64>,
    max: Vec<f64>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct ContainerSection {
    min: Vec<f64>,
    max: Vec<f64>,
    periodic: Option<Vec<bool>>,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct InitialVelocitySection {
    field: String,
    amplitude: f64,
}

/// A velocity field the fluid starts with instead of rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InitialVelocity {
    /// The 2D Taylor–Green vortex of the periodic square [x0, x0 + L)²:
    /// u = U sin(kx′) cos(ky′), v = −U cos(kx′) sin(ky′), k = 2π/L, x′ = x − x0.
    TaylorGreen { amplitude: f64 },
}

impl InitialVelocity {
    /// The velocity at x inside `container`.
    pub fn at<const D: usize>(&self, container: &Aabb, x: [f64; D]) -> [f64; D] {
        match *self {
            InitialVelocity::TaylorGreen { amplitude } => {
                let k = 2.0 * std::f64::consts::PI / (container.max[0] - container.min[0]);
                let (a, b) = (k * (x[0] - container.min[0]), k * (x[1] - container.min[1]));
                let mut u = [0.0; D];
                u[0] = amplitude * a.sin() * b.cos();
                u[1] = -amplitude * a.cos() * b.sin();
                u
            }
        }
    }
}

/// The `[solver]` section: pressure solve, relaxation and time step.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSettings {
    /// Relative residual ‖b − Ax‖/‖b‖ at which BiCGSTAB stops.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Relaxation α of the density-invariance term of the PPE source, Eq. (6).
    pub alpha: f64,
    /// Courant number C of Δt ≤ C h / |u|max.
    pub cfl: f64,
    /// Smoothing length over particle spacing, h/dx.
    pub h_over_dx: f64,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            tolerance: 1.0e-6,
            max_iterations: 1000,
            alpha: 0.1,
            cfl: 0.2,
            h_over_dx: 1.2,
        }
    }
}

/// The `[walls]` section: how the dummy wall particles carry the fluid's pressure.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(deny_unknown_fields, default)]
pub struct WallSettings {
    pub ghost_pressure: GhostPressure,
}

/// The pressure a wall particle b takes as the ghost of fluid particle i.
#[derive(Debug, Clone, Copy, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum GhostPressure {
    /// P_b = P_i + ρ0 g·N_b (r_b − r_i): the Neumann condition of the projection,
    /// ∂P/∂n = ρ0 g·n on a wall at rest (`boundary::ghosts`).
    #[default]
    Hydrostatic,
    /// P_b = P_i: ∂P/∂n = 0, the walls mirror the fluid's pressure and hold no weight of
    /// water (the simpler wall of the ablation, docs/stabilisation.md).
    Mirror,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct CheckpointSection {
    interval: Option<f64>,
    wall_interval: Option<f64>,
    keep: Option<i64>,
}

/// The `[effects]` section as written: each effect a sub-table, every key optional.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct EffectsSection {
    #[serde(default)]
    shifting: ShiftingSection,
    #[serde(default)]
    les: LesSection,
    #[serde(default)]
    kernel_correction: KernelCorrectionSection,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct ShiftingSection {
    enabled: Option<bool>,
    coefficient: Option<f64>,
    max_shift: Option<f64>,
    clustering_weight: Option<f64>,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct LesSection {
    enabled: Option<bool>,
    cs: Option<f64>,
    wall_function: Option<bool>,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct KernelCorrectionSection {
    enabled: Option<bool>,
}

/// The `[checkpoint]` section: when restart files are written to `OUT/checkpoints/`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckpointSettings {
    /// Simulated seconds between checkpoints (None: none by simulated time).
    pub interval: Option<f64>,
    /// Wall-clock seconds between checkpoints.
    pub wall_interval: f64,
    /// How many checkpoints are kept; older ones are deleted once a new one is on disk.
    pub keep: usize,
}

impl Default for CheckpointSettings {
    fn default() -> Self {
        Self {
            interval: None,
            wall_interval: 1800.0,
            keep: 2,
        }
    }
}

/// A block of fluid `fluid` (index into `Scene::fluids`).
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    pub fluid: usize,
    pub region: Aabb,
}

/// Frames a scene may ask for, at most (end_time / output_interval).
const MAX_FRAMES: f64 = 1e5;

/// Peak resident memory of a run per particle, walls included, with margin: 380–490 B measured
/// on the 3D dam break from 10⁴ to 10⁶ particles (docs/performance.md).
const PEAK_BYTES_PER_PARTICLE: f64 = 600.0;

/// A validated scene.
#[derive(Debug, Clone)]
pub struct Scene {
    pub path: PathBuf,
    pub name: String,
    pub dimensions: usize,
    pub spacing: f64,
    pub end_time: f64,
    pub output_interval: f64,
    pub gravity: Vec<f64>,
    pub fluids: Vec<Fluid>,
    pub blocks: Vec<Block>,
    pub container: Aabb,
    /// Per axis: whether the container is periodic along it (no walls on its two faces; what
    /// leaves through one comes back through the other).
    pub periodic: Vec<bool>,
    pub obstacles: Vec<Aabb>,
    /// The fluid's velocity at t = 0 (None: at rest).
    pub initial_velocity: Option<InitialVelocity>,
    pub solver: SolverSettings,
    pub checkpoint: CheckpointSettings,
    pub effects: Effects,
    pub walls: WallSettings,
}

impl Scene {
    /// Reads, parses and validates a scene file.
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Read {
            path: path.to_owned(),
            source,
        })?;
        Scene::parse(&text, path)
    }

    /// Parses and validates scene text; `path` is used in messages and for the default name.
    pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
        let file: SceneFile = toml::from_str(text).map_err(|e| SceneError::Syntax {
            path: path.to_owned(),
            message: e.to_string().trim_end().to_owned(),
        })?;
        Validator { text, path }.scene(file)
    }

    /// Number of dummy wall layers that fill the kernel support 3h.
    pub fn wall_layers(&self) -> usize {
        (SUPPORT_IN_H * self.solver.h_over_dx - 1e-9).ceil() as usize
    }

    /// At least as many particles as `fill::build` makes, fluid and wall, counted without making them
    /// (blocks and obstacles as if none overlapped another): a scene too large for the machine is
    /// refused before its particles fill the memory.
    pub fn particle_bound(&self) -> f64 {
        let scene = self;
        // Lattice points along axis d of box b, at most; with `grow` more on each side.
        let along = |b: &Aabb, d: usize, grow: f64| {
            ((b.max[d] - b.min[d]) / scene.spacing).ceil() + 1.0 + 2.0 * grow
        };
        let points =
            |b: &Aabb| -> f64 { (0..scene.dimensions).map(|d| along(b, d, 0.0)).product() };
        let layers = scene.wall_layers() as f64;
        let c = &scene.container;
        let inside = points(c);
        let with_walls: f64 = (0..scene.dimensions)
            .map(|d| along(c, d, if scene.periodic[d] { 0.0 } else { layers }))
            .product();
        let fluid: f64 = scene.blocks.iter().map(|b| points(&b.region)).sum();
        let obstacles: f64 = scene.obstacles.iter().map(points).sum();
        fluid.min(inside) + (with_walls - inside) + obstacles.min(inside)
    }

    /// Smoothing length h.
    pub fn smoothing_length(&self) -> f64 {
        self.solver.h_over_dx * self.spacing
    }

    /// Whether the fluids differ in rest density: the scene has interfaces whose pairs are
    /// weighted (`interface`).
    pub fn has_interfaces(&self) -> bool {
        self.fluids
            .iter()
            .any(|f| f.density != self.fluids[0].density)
    }

    /// A hash of everything in the validated scene that shapes the trajectory: xxh3-64 of its
    /// Debug rendering (which prints every f64 so that it reads back to the same bits), with the
    /// fields that cannot change a step blanked: the file's path, the run's name, `end_time`
    /// (`--until` overrides it anyway) and the checkpoint cadence. So comments, formatting and
    /// defaults written out do not count, and a run can be extended or checkpointed differently
    /// and still resume without `--force`.
    pub fn content_hash(&self) -> u64 {
        let trajectory = Scene {
            path: PathBuf::new(),
            name: String::new(),
            end_time: 0.0,
            checkpoint: CheckpointSettings::default(),
            ..self.clone()
        };
        xxhash_rust::xxh3::xxh3_64(format!("{trajectory:?}").as_bytes())
    }
}

/// Checks a parsed file and turns it into a `Scene`, locating bad keys in the source text.
struct Validator<'a> {
    text: &'a str,
    path: &'a Path,
}

impl Validator<'_> {
    fn error(&self, key: &str, message: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            path: self.path.to_owned(),
            line: line_of_key(self.text, key),
            key: key.to_owned(),
            message: message.into(),
        }
    }

    fn check(&self, ok: bool, key: &str, message: impl Into<String>) -> Result<(), SceneError> {
        if ok {
            Ok(())
        } else {
            Err(self.error(key, message))
        }
    }

    fn positive(&self, value: f64, key: &str, unit: &str) -> Result<(), SceneError> {
        self.check(
            value.is_finite() && value > 0.0,
            key,
            format!("= {value:?} must be a positive number [{unit}]"),
        )
    }

    fn vector(&self, v: &[f64], dims: usize, key: &str) -> Result<(), SceneError> {
        self.check(
            v.len() == dims,
            key,
            format!(
                "has {} components but the scene has `simulation.dimensions = {dims}`",
                v.len()
            ),
        )?;
        self.check(
            v.iter().all(|x| x.is_finite()),
            key,
            "must hold finite numbers",
        )
    }

    fn aabb(
        &self,
        b: &BoxSection,
        dims: usize,
        key: &str,
        spacing: f64,
    ) -> Result<Aabb, SceneError> {
        self.vector(&b.min, dims, &format!("{key}.min"))?;
        self.vector(&b.max, dims, &format!("{key}.max"))?;
        for d in 0..dims {
            self.check(
                // (0.21 − 0.2 = 0.00999… is one spacing of 0.01)
                b.max[d] - b.min[d] >= spacing * (1.0 - 1e-9),
                &format!("{key}.max"),
                format!(
                    "must exceed `{key}.min` by at least one particle spacing ({spacing:?} m) in every axis; axis {d} has {:?} .. {:?}",
                    b.min[d], b.max[d]
                ),
            )?;
        }
        Ok(Aabb {
            min: b.min.clone(),
            max: b.max.clone(),
        })
    }

    /// A box section that must lie inside the container.
    fn region_inside(
        &self,
        b: &BoxSection,
        container: &Aabb,
        dims: usize,
        key: &str,
        spacing: f64,
        what: &str,
    ) -> Result<Aabb, SceneError> {
        let region = self.aabb(b, dims, key, spacing)?;
        self.check(
            region.within(container),
            &format!("{key}.min"),
            format!(
                "the {what} {:?} .. {:?} is not inside the container {:?} .. {:?}",
                region.min, region.max, container.min, container.max
            ),
        )?;
        Ok(region)
    }

    fn scene(&self, f: SceneFile) -> Result<Scene, SceneError> {
        let s = &f.simulation;
        self.check(
            s.dimensions == 2 || s.dimensions == 3,
            "simulation.dimensions",
            format!("= {} is not supported: use 2 or 3", s.dimensions),
        )?;
        let dims = s.dimensions as usize;
        self.positive(s.spacing, "simulation.spacing", "m")?;
        self.positive(s.end_time, "simulation.end_time", "s")?;
        self.positive(s.output_interval, "simulation.output_interval", "s")?;
        let frames = s.end_time / s.output_interval;
        self.check(
            frames <= MAX_FRAMES,
            "simulation.output_interval",
            format!(
                "= {:?} makes {frames:.3e} frames to end_time = {:?} s; at most {MAX_FRAMES} (each frame holds every particle)",
                s.output_interval, s.end_time
            ),
        )?;
        self.vector(&s.gravity, dims, "simulation.gravity")?;

        self.check(
            !f.fluid.is_empty(),
            "fluid",
            "is missing: define at least one [[fluid]]",
        )?;
        for (k, fl) in f.fluid.iter().enumerate() {
            let key = format!("fluid[{k}]");
            self.positive(fl.density, &format!("{key}.density"), "kg/m^3")?;
            self.check(
                fl.viscosity.is_finite() && fl.viscosity >= 0.0,
                &format!("{key}.viscosity"),
                format!("= {:?} must be a non-negative number [m^2/s]", fl.viscosity),
            )?;
            self.check(
                f.fluid[..k].iter().all(|o| o.name != fl.name),
                &format!("{key}.name"),
                format!("= \"{}\" is defined twice", fl.name),
            )?;
        }

        let container_box = BoxSection {
            min: f.container.min.clone(),
            max: f.container.max.clone(),
        };
        let container = self.aabb(&container_box, dims, "container", s.spacing)?;
        let periodic = self.periodic(
            f.container.periodic.as_deref(),
            &container,
            s.spacing,
            &f.solver,
        )?;
        self.check(
            !f.fluid_block.is_empty(),
            "fluid_block",
            "is missing: define at least one [[fluid_block]]",
        )?;
        let mut blocks = Vec::new();
        for (k, b) in f.fluid_block.iter().enumerate() {
            let key = format!("fluid_block[{k}]");
            let fluid = f
                .fluid
                .iter()
                .position(|fl| fl.name == b.fluid)
                .ok_or_else(|| {
                    let names: Vec<_> = f
                        .fluid
                        .iter()
                        .map(|fl| format!("\"{}\"", fl.name))
                        .collect();
                    self.error(
                        &format!("{key}.fluid"),
                        format!(
                            "= \"{}\" names no [[fluid]]; defined fluids: {}",
                            b.fluid,
                            names.join(", ")
                        ),
                    )
                })?;
            let section = BoxSection {
                min: b.min.clone(),
                max: b.max.clone(),
            };
            let region =
                self.region_inside(&section, &container, dims, &key, s.spacing, "block")?;
            blocks.push(Block { fluid, region });
        }
        let mut obstacles = Vec::new();
        for (k, o) in f.obstacle.iter().enumerate() {
            let key = format!("obstacle[{k}]");
            let region = self.region_inside(o, &container, dims, &key, s.spacing, "obstacle")?;
            obstacles.push(region);
        }

        let sv = &f.solver;
        self.check(
            sv.tolerance > 0.0 && sv.tolerance < 1.0,
            "solver.tolerance",
            format!("= {:?} must lie in (0, 1)", sv.tolerance),
        )?;
        self.check(
            sv.max_iterations >= 1,
            "solver.max_iterations",
            "must be at least 1",
        )?;
        self.check(
            (0.0..=1.0).contains(&sv.alpha),
            "solver.alpha",
            format!(
                "= {:?} must lie in [0, 1] (0: divergence-free only, 1: density-invariant only)",
                sv.alpha
            ),
        )?;
        self.check(
            sv.cfl > 0.0 && sv.cfl <= 1.0,
            "solver.cfl",
            format!("= {:?} must lie in (0, 1]", sv.cfl),
        )?;
        self.check(
            (1.0..=2.0).contains(&sv.h_over_dx),
            "solver.h_over_dx",
            format!("= {:?} must lie in [1, 2]", sv.h_over_dx),
        )?;

        let initial_velocity = f
            .initial_velocity
            .as_ref()
            .map(|v| self.initial_velocity(v, &container, &periodic))
            .transpose()?;
        let checkpoint = self.checkpoint(&f.checkpoint)?;
        let effects = self.effects(&f.effects)?;

        let name = match &s.name {
            Some(n) => {
                // The run goes to out/<name>: one plain directory name, not a path.
                let plain = !n.is_empty()
                    && n != "."
                    && n != ".."
                    && !n.contains(['/', '\\'])
                    && n.trim() == n;
                self.check(
                    plain,
                    "simulation.name",
                    format!("= \"{n}\" must be a plain directory name (the run goes to out/<name>): not empty, no '/', not \".\" or \"..\", no surrounding spaces"),
                )?;
                n.clone()
            }
            None => self
                .path
                .file_stem()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scene".into()),
        };
        let scene = Scene {
            path: self.path.to_owned(),
            name,
            dimensions: dims,
            spacing: s.spacing,
            end_time: s.end_time,
            output_interval: s.output_interval,
            gravity: s.gravity.clone(),
            fluids: f.fluid,
            blocks,
            container,
            periodic,
            obstacles,
            initial_velocity,
            solver: f.solver,
            checkpoint,
            effects,
            walls: f.walls,
        };
        self.fits_in_memory(&scene)?;
        Ok(scene)
    }

    /// Refuses a scene whose particles could not be held: more than the u32 indices of the
    /// cell sort reach, or more memory at the peak of a run (`PEAK_BYTES_PER_PARTICLE`) than
    /// the machine has in all (not what is free now: a study measures its finished points while
    /// others run).
    fn fits_in_memory(&self, scene: &Scene) -> Result<(), SceneError> {
        let particles = scene.particle_bound();
        let key = "simulation.spacing";
        let what = format!(
            "= {:?} puts up to {particles:.3e} particles in the container and its walls",
            scene.spacing
        );
        self.check(
            particles < u32::MAX as f64,
            key,
            format!("{what}, more than the {} isph can index", u32::MAX),
        )?;
        let needed = particles * PEAK_BYTES_PER_PARTICLE;
        // The machine's memory in all (MemTotal); no check where /proc/meminfo cannot be read.
        if let Ok(memory) = crate::math::memory::proc_bytes("/proc/meminfo", "MemTotal") {
            let memory = memory as f64;
            const GIB: f64 = (1u64 << 30) as f64;
            self.check(
                needed <= memory,
                key,
                format!(
                    "{what}: about {:.1} GiB at {PEAK_BYTES_PER_PARTICLE} B/particle, more than the {:.1} GiB of memory this machine has",
                    needed / GIB,
                    memory / GIB
                ),
            )?;
        }
        Ok(())
    }

    /// `container.periodic`: one flag per axis. A periodic axis must hold a whole number of
    /// particle spacings (the lattice must close on itself) and at least three kernel supports
    /// (so that a particle never meets two images of another).
    fn periodic(
        &self,
        flags: Option<&[bool]>,
        container: &Aabb,
        spacing: f64,
        solver: &SolverSettings,
    ) -> Result<Vec<bool>, SceneError> {
        let dims = container.min.len();
        let Some(flags) = flags else {
            return Ok(vec![false; dims]);
        };
        let key = "container.periodic";
        self.check(
            flags.len() == dims,
            key,
            format!(
                "has {} flags but the scene has `simulation.dimensions = {dims}`",
                flags.len()
            ),
        )?;
        let support = SUPPORT_IN_H * solver.h_over_dx * spacing;
        for d in (0..dims).filter(|&d| flags[d]) {
            let length = container.max[d] - container.min[d];
            let spacings = length / spacing;
            self.check(
                (spacings - spacings.round()).abs() < 1e-6 * spacings,
                key,
                format!("axis {d} is periodic, so its length {length:?} m must be a whole number of spacings ({spacing:?} m); it is {spacings:.4} spacings"),
            )?;
            self.check(
                length >= 3.0 * support,
                key,
                format!("axis {d} is periodic, so its length {length:?} m must be at least three kernel supports (3 × 3h = {:.4} m)", 3.0 * support),
            )?;
        }
        Ok(flags.to_vec())
    }

    /// `[initial_velocity]`: a named analytic field and its amplitude.
    fn initial_velocity(
        &self,
        v: &InitialVelocitySection,
        container: &Aabb,
        periodic: &[bool],
    ) -> Result<InitialVelocity, SceneError> {
        self.check(
            v.field == "taylor_green",
            "initial_velocity.field",
            format!(
                "= \"{}\" is not a known field; known: \"taylor_green\"",
                v.field
            ),
        )?;
        let lengths: Vec<f64> = (0..container.min.len())
            .map(|d| container.max[d] - container.min[d])
            .collect();
        self.check(
            lengths.len() == 2
                && periodic.iter().all(|&p| p)
                && (lengths[0] - lengths[1]).abs() <= 1e-9 * lengths[0],
            "initial_velocity.field",
            "= \"taylor_green\" needs a 2D container periodic in both axes (`container.periodic = [true, true]`) and square",
        )?;
        self.check(
            v.amplitude.is_finite(),
            "initial_velocity.amplitude",
            format!("= {:?} must be a finite number [m/s]", v.amplitude),
        )?;
        Ok(InitialVelocity::TaylorGreen {
            amplitude: v.amplitude,
        })
    }

    fn effects(&self, e: &EffectsSection) -> Result<Effects, SceneError> {
        Ok(Effects {
            shifting: self.shifting(&e.shifting)?,
            les: self.les(&e.les)?,
            kernel_correction: e.kernel_correction.enabled.unwrap_or(true),
        })
    }

    /// Whether effect `name` is on (`enabled`, default true); an effect turned off must not be
    /// given parameters, which it would silently ignore: `given` lists them (key, present).
    fn enabled(
        &self,
        name: &str,
        enabled: Option<bool>,
        given: &[(&str, bool)],
    ) -> Result<bool, SceneError> {
        let on = enabled.unwrap_or(true);
        if !on {
            if let Some((key, _)) = given.iter().find(|(_, present)| *present) {
                return Err(self.error(
                    &format!("effects.{name}.{key}"),
                    format!("is given but `effects.{name}.enabled = false` turns the effect off: remove the key or the `enabled = false`"),
                ));
            }
        }
        Ok(on)
    }

    fn shifting(&self, s: &ShiftingSection) -> Result<Option<ShiftingSettings>, SceneError> {
        let given = [
            ("coefficient", s.coefficient.is_some()),
            ("max_shift", s.max_shift.is_some()),
            ("clustering_weight", s.clustering_weight.is_some()),
        ];
        if !self.enabled("shifting", s.enabled, &given)? {
            return Ok(None);
        }
        let default = ShiftingSettings::default();
        let settings = ShiftingSettings {
            coefficient: s.coefficient.unwrap_or(default.coefficient),
            max_shift: s.max_shift.unwrap_or(default.max_shift),
            clustering_weight: s.clustering_weight.unwrap_or(default.clustering_weight),
        };
        self.check(
            settings.coefficient.is_finite() && settings.coefficient > 0.0,
            "effects.shifting.coefficient",
            format!(
                "= {:?} must be a positive number (A of D = A h U Δt)",
                settings.coefficient
            ),
        )?;
        self.check(
            settings.max_shift > 0.0 && settings.max_shift <= 1.0,
            "effects.shifting.max_shift",
            format!(
                "= {:?} must lie in (0, 1] [particle spacings]",
                settings.max_shift
            ),
        )?;
        self.check(
            settings.clustering_weight.is_finite() && settings.clustering_weight >= 0.0,
            "effects.shifting.clustering_weight",
            format!(
                "= {:?} must be a non-negative number",
                settings.clustering_weight
            ),
        )?;
        Ok(Some(settings))
    }

    fn les(&self, l: &LesSection) -> Result<Option<LesSettings>, SceneError> {
        let given = [
            ("cs", l.cs.is_some()),
            ("wall_function", l.wall_function.is_some()),
        ];
        if !self.enabled("les", l.enabled, &given)? {
            return Ok(None);
        }
        let default = LesSettings::default();
        let settings = LesSettings {
            cs: l.cs.unwrap_or(default.cs),
            wall_function: l.wall_function.unwrap_or(default.wall_function),
        };
        self.check(
            settings.cs > 0.0 && settings.cs <= 1.0,
            "effects.les.cs",
            format!(
                "= {:?} must lie in (0, 1] (to turn LES off, set `effects.les.enabled = false`)",
                settings.cs
            ),
        )?;
        Ok(Some(settings))
    }

    fn checkpoint(&self, c: &CheckpointSection) -> Result<CheckpointSettings, SceneError> {
        let default = CheckpointSettings::default();
        if let Some(interval) = c.interval {
            self.positive(interval, "checkpoint.interval", "s")?;
        }
        let wall_interval = c.wall_interval.unwrap_or(default.wall_interval);
        self.positive(wall_interval, "checkpoint.wall_interval", "s")?;
        let keep = c.keep.unwrap_or(default.keep as i64);
        self.check(
            keep >= 1,
            "checkpoint.keep",
            format!("= {keep} must be at least 1 (the newest checkpoint is always kept)"),
        )?;
        Ok(CheckpointSettings {
            interval: c.interval,
            wall_interval,
            keep: keep as usize,
        })
    }
}

/// 1-based line of a dotted key such as `fluid_block[1].fluid` in TOML source, if present.
fn line_of_key(text: &str, key: &str) -> Option<usize> {
    let doc = toml_edit::ImDocument::parse(text).ok()?;
    let mut item = doc.as_item();
    for part in key.split('.') {
        let (name, index) = match part.split_once('[') {
            Some((n, rest)) => (n, rest.trim_end_matches(']').parse::<usize>().ok()),
            None => (part, None),
        };
        item = item.get(name)?;
        if let Some(k) = index {
            item = item.get(k)?;
        }
    }
    let span = item.span()?;
    Some(text[..span.start].matches('\n').count() + 1)
}
