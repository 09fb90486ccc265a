//! What a scene will run: the stages of a step in order (only those of the effects the scene
//! asks for), the particle counts, and the memory the arrays of each stage take. The byte
//! counts come from the arrays themselves (`Simulation::arrays`, `Particles::arrays_mut`), so
//! the plan and the step cannot disagree.

use crate::math::kernel::KernelKind;
use crate::scene::{BodyMotion, Effects, Scene, BYTES_PER_CONTAINER_POINT};
use crate::scene::{CubeRule, Probe, ProbeField, SurfaceSettings};
use crate::simulation::{NoFluid, Simulation};
use std::fmt;

/// One stage of the time step.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedStage {
    /// The stage's name (its line in `isph plan`, its timing).
    pub stage: &'static str,
    /// What it computes, with the scene's constants.
    pub what: String,
    /// Bytes of the arrays this stage allocates for the scene's particles (each array holds
    /// every particle or the fluid particles only; the lists of some particles are not
    /// counted).
    pub bytes: usize,
}

#[derive(Clone, Debug)]
pub struct Plan {
    pub scene: String,
    pub dimensions: usize,
    pub fluid_particles: usize,
    pub wall_particles: usize,
    pub smoothing_length: f64,
    pub kernel: KernelKind,
    /// The kernel support radius, in spacings.
    pub support_in_dx: f64,
    pub wall_layers: usize,
    /// `simulation.perturbation` [dx], and the lattice steps from open space within which the
    /// fluid keeps its lattice (`fill::lattice_reach`).
    pub perturbation: (f64, i64),
    pub effects: Effects,
    /// The container's prescribed motion, described (None: at rest).
    pub container_motion: Option<String>,
    /// `[output.surface]`, built at every frame (None: particles only).
    pub surface: Option<SurfaceSettings>,
    /// `[[probe]]`, read after every step into probes.csv.
    pub probes: Vec<Probe>,
    /// Per-particle bytes of the particle state (position, velocity, …).
    pub state_bytes_per_particle: usize,
    pub stages: Vec<PlannedStage>,
    /// `[[body]]`, each with its particles and the fluid lattice points it displaced.
    pub bodies: Vec<PlannedBody>,
    /// Lattice points of the container and its walls (`Scene::container_points`): the extent
    /// of the per-cell arrays.
    pub container_points: f64,
}

/// One rigid body as the plan lists it.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedBody {
    pub name: String,
    pub motion: BodyMotion,
    /// The time a fixed or prescribed body is let go (None: never).
    pub release: Option<f64>,
    pub particles: usize,
    /// Its mass [kg] (per metre of depth in 2D) and density [kg/m³].
    pub mass: f64,
    pub density: f64,
    /// The diagonal of its inertia tensor about its centre of mass [kg m²] (2D: zz only).
    pub inertia: [f64; 3],
    /// Fluid lattice points it keeps clear of fluid at t = 0.
    pub displaced: usize,
}

impl Plan {
    /// The plan of `scene`; an error where it holds no fluid particle (it cannot run).
    pub fn new(scene: &Scene) -> Result<Plan, NoFluid> {
        match scene.dimensions {
            2 => Self::in_dimension::<2>(scene),
            _ => Self::in_dimension::<3>(scene),
        }
    }

    fn in_dimension<const D: usize>(scene: &Scene) -> Result<Plan, NoFluid> {
        let mut sim = Simulation::<D>::new(scene)?;
        let arrays = sim.arrays();
        let fluid = sim.particles.fluid_count();
        let total = sim.particles.len();
        let step = sim.stepper();
        let stages = step
            .stages()
            .into_iter()
            .map(|s| (s.name(), s.describe(&step.settings)))
            .map(|(stage, what)| PlannedStage {
                stage,
                what,
                bytes: arrays
                    .iter()
                    .filter(|(s, _)| *s == stage)
                    .map(|(_, a)| a.bytes_per_element * a.elements(total, fluid))
                    .sum(),
            })
            .collect();
        let displaced = crate::fill::displaced_by_bodies::<D>(scene);
        let volume = scene.spacing.powi(D as i32);
        let bodies = sim
            .bodies
            .bodies
            .iter()
            .zip(displaced)
            .map(|(b, displaced)| PlannedBody {
                name: b.name.clone(),
                motion: b.motion.clone(),
                release: b.release,
                particles: b.offsets.len(),
                mass: b.mass,
                density: b.mass / (b.offsets.len() as f64 * volume),
                inertia: std::array::from_fn(|d| b.inertia[d][d]),
                displaced,
            })
            .collect();
        let state = sim.particles.arrays_mut();
        Ok(Plan {
            scene: scene.name.clone(),
            dimensions: D,
            fluid_particles: fluid,
            wall_particles: total - fluid,
            smoothing_length: scene.smoothing_length(),
            kernel: scene.solver.kernel,
            support_in_dx: scene.solver.support_in_dx(),
            wall_layers: scene.wall_layers(),
            perturbation: (scene.perturbation, crate::fill::lattice_reach(scene)),
            effects: scene.effects,
            container_motion: scene.container_motion.as_ref().map(|t| t.describe()),
            surface: scene.surface,
            probes: scene.probes.clone(),
            state_bytes_per_particle: state.iter().map(|(_, a)| a.element_bytes()).sum(),
            stages,
            bodies,
            container_points: scene.container_points(),
        })
    }

    pub fn particles(&self) -> usize {
        self.fluid_particles + self.wall_particles
    }

    /// Bytes of the particle state and the arrays of every stage.
    pub fn bytes(&self) -> usize {
        self.state_bytes_per_particle * self.particles()
            + self.stages.iter().map(|s| s.bytes).sum::<usize>()
    }

    /// `bytes` per particle, walls included (rounded).
    pub fn bytes_per_particle(&self) -> usize {
        (self.bytes() as f64 / self.particles() as f64).round() as usize
    }
}

/// The effects of a scene in one line.
fn effects_line(e: &Effects) -> String {
    let shifting = match e.shifting {
        Some(s) => format!(
            "shifting (A = {}, max {} dx, R = {})",
            s.coefficient, s.max_shift, s.clustering_weight
        ),
        None => "shifting off".into(),
    };
    let les = match e.les {
        Some(l) if l.wall_function => format!("LES (Cs = {}, log-law wall function)", l.cs),
        Some(l) => format!("LES (Cs = {}, no wall function)", l.cs),
        None => "LES off".into(),
    };
    let correction = if e.kernel_correction {
        "kernel correction"
    } else {
        "kernel correction off"
    };
    format!("{shifting}, {les}, {correction}")
}

/// What `[output.surface]` builds, as the plan says it.
fn surface_line(s: &SurfaceSettings, dimensions: usize) -> String {
    let cubes = match s.cubes {
        CubeRule::Size(size) => format!("cubes of {size} dx"),
        CubeRule::MaxCubes(n) => format!("at most {n} cubes over the fluid's box"),
    };
    let method = if dimensions == 3 {
        "marching cubes"
    } else {
        "marching squares"
    };
    format!(
        "surface by {method} at c = {} of the {} kernel's density (b = {} dx), {cubes}; surface.h5 + surface.xdmf, a PLY{} per frame in surface/ (a sparse lattice near the fluid, freed after each frame)",
        s.iso,
        s.kernel.name(),
        s.radius,
        if s.obj { " and an OBJ" } else { "" }
    )
}

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let n = self.particles();
        let mib = |bytes: usize| bytes as f64 / (1 << 20) as f64;
        let per_particle = |bytes: usize| (bytes as f64 / n as f64).round() as usize;
        writeln!(f, "scene {} ({}D)", self.scene, self.dimensions)?;
        writeln!(
            f,
            "particles: {} fluid + {} wall and body = {n}   ({} kernel, h = {:.4e} m, support {:.2} dx, {} wall layers)",
            self.fluid_particles,
            self.wall_particles,
            self.kernel.name(),
            self.smoothing_length,
            self.support_in_dx,
            self.wall_layers
        )?;
        writeln!(f, "start: {}", start_line(self.perturbation))?;
        writeln!(f, "effects: {}", effects_line(&self.effects))?;
        if let Some(motion) = &self.container_motion {
            writeln!(f, "container moves, solved in its frame: {motion}")?;
        }
        for b in &self.bodies {
            writeln!(
                f,
                "body {}: {} with {} particles, mass {:.4e} kg, density {:.1} kg/m³, inertia diag {} kg m²; displaces {} fluid lattice points",
                b.name,
                match &b.motion {
                    BodyMotion::Prescribed(t) => format!("prescribed ({})", t.describe()),
                    m => m.name().to_string(),
                } + &b
                    .release
                    .map(|t| format!(", released at {t} s"))
                    .unwrap_or_default(),
                b.particles,
                b.mass,
                b.density,
                b.inertia.iter().map(|i| format!("{i:.3e}")).collect::<Vec<_>>().join(" "),
                b.displaced
            )?;
        }
        writeln!(
            f,
            "      {:<25} {:>4} B/particle {:>9.2} MiB  position, velocity, wall normal, pressure, density, mass, ρ0, ν, kind, free surface, fluid, id",
            "particle state",
            self.state_bytes_per_particle,
            mib(self.state_bytes_per_particle * n),
        )?;
        writeln!(f, "stages per step:")?;
        for (k, s) in self.stages.iter().enumerate() {
            writeln!(
                f,
                "  {:>2}. {:<25} {:>4} B/particle {:>9.2} MiB  {}",
                k + 1,
                s.stage,
                per_particle(s.bytes),
                mib(s.bytes),
                s.what
            )?;
        }
        if let Some(s) = &self.surface {
            writeln!(f, "at every frame: {}", surface_line(s, self.dimensions))?;
        }
        if !self.probes.is_empty() {
            writeln!(f, "after every step, into probes.csv (the Shepard sum of the fluid particles within the kernel support where the water covers the point; a gauge, the height where the fluid fraction falls through half its full value on the vertical line; no array):")?;
            for p in &self.probes {
                let place = match p.field {
                    ProbeField::Elevation => "on the vertical line through",
                    ProbeField::Pressure | ProbeField::Velocity => "at",
                };
                writeln!(
                    f,
                    "      {:<25} {} {place} {:?} m  columns {}",
                    p.name,
                    p.field.name(),
                    p.point,
                    p.columns().join(",")
                )?;
            }
        }
        write!(
            f,
            "memory: {} B/particle, {:.2} MiB for the particle arrays, plus the per-cell arrays over the container's {:.3e} lattice points (the fill's map, the cell list, the multigrid levels: at most {BYTES_PER_CONTAINER_POINT} B each, {:.2} MiB); the workspace of a step holds the fluid particles only",
            self.bytes_per_particle(),
            mib(self.bytes()),
            self.container_points,
            self.container_points * BYTES_PER_CONTAINER_POINT / (1u64 << 20) as f64
        )
    }
}

/// Where the fluid particles start: on the lattice, or off it by up to `amplitude` spacings
/// but within `reach` lattice steps of open space.
fn start_line((amplitude, reach): (f64, i64)) -> String {
    if amplitude == 0.0 {
        return "fluid on the lattice (simulation.perturbation = 0)".into();
    }
    format!("fluid off its lattice points by up to {amplitude} dx per axis (simulation.perturbation), on them within {reach} spacings of open space (a flat free surface)")
}
