//! Scene files: TOML in SI units, parsed with unknown keys rejected, then validated into a
//! `Scene`. Every error names the file, the key and, where it can be found, the line.

mod bodies;
mod effects;
mod file;
mod mesh_file;
pub mod overrides;
mod probes;
mod surface;
pub mod trajectory;
mod validate;

pub use bodies::{Body, BodyMass, BodyMotion, Shape};
pub use effects::{Effects, LesSettings, ShiftingSettings};
pub use probes::{Probe, ProbeField};
pub use surface::{CubeRule, SurfaceKernel, SurfaceRequest, SurfaceSettings};

pub use crate::math::aabb::Aabb;
use crate::math::kernel::KernelKind;
use crate::math::mesh::TriangleMesh;
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

/// The `[solver]` section: pressure solve, relaxation, time step and kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Relative residual ‖b − Ax‖/‖b‖ at which BiCGSTAB stops.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Relaxation α of the density-invariance term of the PPE source, Eq. (6).
    pub alpha: f64,
    /// Courant number C of Δt ≤ C dx / |u|max, on the particle spacing as the peers define it.
    pub cfl: f64,
    /// The smoothing kernel.
    pub kernel: KernelKind,
    /// Smoothing length over particle spacing, h/dx (the kernel's default unless the scene sets
    /// it).
    pub h_over_dx: f64,
}

impl SolverSettings {
    /// The kernel support radius, in spacings.
    pub fn support_in_dx(&self) -> f64 {
        self.kernel.support_in_h() * self.h_over_dx
    }
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            tolerance: 1.0e-4,
            max_iterations: 1000,
            alpha: 0.3,
            cfl: 0.4,
            kernel: KernelKind::Quintic,
            h_over_dx: KernelKind::Quintic.default_h_over_dx(),
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
    /// The box it fills; a mesh block's the box around its mesh.
    pub region: Aabb,
    /// The closed mesh it fills instead of the whole box (3D), if any.
    pub mesh: Option<TriangleMesh>,
}

impl Block {
    /// Whether x lies strictly inside its box and, for a mesh block, inside the mesh.
    pub fn contains(&self, x: &[f64]) -> bool {
        self.region.contains(x) && self.mesh.as_ref().is_none_or(|m| m.contains(x))
    }
}

/// Bytes a run holds per lattice point of the container (walls included) whether water fills
/// it or not: the fill's map of what each point holds, the cell list's starts and the
/// multigrid's first level span the whole container. 10 B in 2D and about 14 B in 3D measured
/// (peak RSS of mostly empty containers at 1.6e7 and 8e6 points, 2026-12-06).
pub const BYTES_PER_CONTAINER_POINT: f64 = 24.0;

/// A validated scene.
#[derive(Debug, Clone)]
pub struct Scene {
    pub path: PathBuf,
    /// The text the scene was parsed from: a stop time beyond `end_time` is validated on it
    /// (`check_stop_time`).
    pub text: String,
    pub name: String,
    pub dimensions: usize,
    pub spacing: f64,
    /// Largest initial displacement of a fluid particle from its lattice point, per axis, in
    /// spacings (`fill`).
    pub perturbation: f64,
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
    /// `[container.trajectory]`: the container's prescribed motion, with its walls and obstacles
    /// (None: at rest). The particles move in its frame (`boundary::moving_frame`).
    pub container_motion: Option<trajectory::Trajectory>,
    /// The fluid's velocity at t = 0 (None: at rest).
    pub initial_velocity: Option<InitialVelocity>,
    pub solver: SolverSettings,
    pub checkpoint: CheckpointSettings,
    pub effects: Effects,
    /// `[output.surface]`: the surface reconstructed at every frame (None: particles only).
    pub surface: Option<SurfaceSettings>,
    /// `[[probe]]`: points whose field is written to `probes.csv` every step (empty: none).
    pub probes: Vec<Probe>,
    pub walls: WallSettings,
    /// `[[body]]`: rigid bodies in the fluid (empty: none).
    pub bodies: Vec<Body>,
}

/// A TOML error of `text` in one line: where it is and what is wrong, without the source
/// line and caret that `toml` draws under it (a long line would be echoed whole).
pub fn syntax_message(text: &str, e: &toml::de::Error) -> String {
    let what = e
        .message()
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(": ");
    match e.span() {
        Some(span) => {
            let before = text.get(..span.start).unwrap_or(text);
            let line = before.matches('\n').count() + 1;
            let column = before[before.rfind('\n').map_or(0, |k| k + 1)..]
                .chars()
                .count()
                + 1;
            // A missing key is reported at the header of the section that lacks it.
            let header = text.get(span.start..).and_then(|t| t.lines().next());
            let header = header.unwrap_or("").trim();
            let section = if header.starts_with('[') && what.starts_with("missing field") {
                format!(" in the section `{header}` that starts there")
            } else {
                String::new()
            };
            format!("TOML parse error at line {line}, column {column}: {what}{section}")
        }
        None => format!("TOML parse error: {what}"),
    }
}

impl Scene {
    /// Refuses a stop time `end` (`--until`) beyond `end_time` that the scene's validation
    /// would refuse as its `end_time`: more frames than a run writes, a motion table that ends
    /// before it (after its last row a table holds its last pose, at rest, and a run past it
    /// would stop the motion dead), a prescribed body's path that leaves the container or runs
    /// into an obstacle before it. The scene's text is validated again with `end_time = end`.
    pub fn check_stop_time(&self, end: f64) -> Result<(), SceneError> {
        if end <= self.end_time {
            return Ok(());
        }
        let setting = ("simulation.end_time".to_string(), toml::Value::Float(end));
        let text = overrides::apply(&self.text, &[setting]).map_err(|e| SceneError::Syntax {
            path: self.path.clone(),
            message: e.to_string(),
        })?;
        match Scene::parse(&text, &self.path) {
            Ok(_) => Ok(()),
            Err(SceneError::Invalid {
                path,
                line,
                key,
                message,
            }) => Err(SceneError::Invalid {
                path,
                line,
                key,
                message: format!("{message} (with the stop time {end:?} s of `--until`)"),
            }),
            Err(e) => Err(e),
        }
    }

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
        let file: file::SceneFile = toml::from_str(text).map_err(|e| SceneError::Syntax {
            path: path.to_owned(),
            message: syntax_message(text, &e),
        })?;
        validate::Validator { text, path }.scene(file)
    }

    /// Number of dummy wall layers that fill the kernel support.
    pub fn wall_layers(&self) -> usize {
        (self.solver.support_in_dx() - 1e-9).ceil() as usize
    }

    /// Lattice points of the container and its wall layers: the points `fill::build` visits,
    /// and the extent of the cell list and the multigrid's first level.
    pub fn container_points(&self) -> f64 {
        let layers = self.wall_layers() as f64;
        self.container.lattice_points_bound(self.spacing, |d| {
            if self.periodic[d] {
                0.0
            } else {
                layers
            }
        })
    }

    /// At least as many particles as `fill::build` makes, fluid and wall, counted without making
    /// them (blocks and obstacles as if none overlapped another): a scene too large for the machine
    /// is refused before its particles fill the memory.
    pub fn particle_bound(&self) -> f64 {
        let points = |b: &Aabb| b.lattice_points_bound(self.spacing, |_| 0.0);
        let inside = points(&self.container);
        let with_walls = self.container_points();
        let fluid: f64 = self.blocks.iter().map(|b| points(&b.region)).sum();
        let obstacles: f64 = self.obstacles.iter().map(points).sum();
        let bodies: f64 = self.bodies.iter().map(|b| points(&b.shape.bounds())).sum();
        fluid.min(inside) + (with_walls - inside) + obstacles.min(inside) + bodies.min(inside)
    }

    /// Smoothing length h.
    pub fn smoothing_length(&self) -> f64 {
        self.solver.h_over_dx * self.spacing
    }

    /// Whether the fluids differ in rest density: the scene has interfaces whose pairs are
    /// weighted (`interface`).
    pub fn has_interfaces(&self) -> bool {
        let water = self.fluids[0].density;
        self.fluids.iter().any(|f| f.density != water) || self.bodies_differ_in_density()
    }

    /// Whether a body that moves freely at some time differs in rest density from a fluid:
    /// its surface is then an interface of the pressure solve (`step::hydrostatic_split`). A
    /// held body takes the water's density in the solve (`Bodies::set_solve_densities`).
    pub fn bodies_differ_in_density(&self) -> bool {
        self.bodies
            .iter()
            .filter(|b| b.motion == BodyMotion::Free || b.release.is_some())
            .any(|b| {
                self.fluids
                    .iter()
                    .any(|f| b.mass != BodyMass::Density(f.density))
            })
    }

    /// A hash of everything in the validated scene that shapes the trajectory: xxh3-64 of its
    /// Debug rendering (which prints every f64 so that it reads back to the same bits), with the
    /// fields that cannot change a step blanked: the file's path and text, the run's name, `end_time`
    /// (`--until` overrides it anyway), the checkpoint cadence, the surface output and the
    /// probes (what a run records, read off the particles after each step, never fed back into
    /// them). So comments, formatting and defaults written out do not count, and a run can be
    /// extended, checkpointed differently or given other probes and still resume without
    /// `--force`.
    pub fn content_hash(&self) -> u64 {
        let trajectory = Scene {
            path: PathBuf::new(),
            text: String::new(),
            name: String::new(),
            end_time: 0.0,
            checkpoint: CheckpointSettings::default(),
            surface: None,
            probes: Vec::new(),
            ..self.clone()
        };
        xxhash_rust::xxh3::xxh3_64(format!("{trajectory:?}").as_bytes())
    }
}
