//! What a scene will run: the stages of a step in order (only those of the effects the scene
//! asks for), the particle counts, and the memory the arrays of each stage take. The byte
//! counts come from the arrays themselves (`Simulation::arrays`, `Particles::arrays_mut`), so
//! the plan and the step cannot disagree.

use crate::scene::{Effects, GhostPressure, Scene};
use crate::simulation::{NoFluid, Simulation};
use crate::sph::Correction;
use crate::step;
use crate::step::timings::Stage;
use std::fmt;

/// One stage of the time step.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedStage {
    pub stage: Stage,
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
    pub wall_layers: usize,
    pub effects: Effects,
    /// Per-particle bytes of the particle state (position, velocity, …).
    pub state_bytes_per_particle: usize,
    pub stages: Vec<PlannedStage>,
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
        let stages = step::stages(&scene.effects)
            .into_iter()
            .map(|stage| PlannedStage {
                stage,
                what: describe(stage, scene),
                bytes: arrays
                    .iter()
                    .filter(|(s, _)| *s == stage)
                    .map(|(_, a)| a.bytes_per_element * a.elements(total, fluid))
                    .sum(),
            })
            .collect();
        let state = sim.particles.arrays_mut();
        Ok(Plan {
            scene: scene.name.clone(),
            dimensions: D,
            fluid_particles: fluid,
            wall_particles: total - fluid,
            smoothing_length: scene.smoothing_length(),
            wall_layers: scene.wall_layers(),
            effects: scene.effects,
            state_bytes_per_particle: state.iter().map(|(_, a)| a.element_bytes()).sum(),
            stages,
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

/// What `stage` computes in `scene`, after the method of `step`, `ppe`, `wall`, `turbulence`,
/// `shifting` and `multigrid`.
fn describe(stage: Stage, scene: &Scene) -> String {
    let effects = &scene.effects;
    match stage {
        Stage::CellList => {
            "counting sort by cell (x fastest), every particle array permuted together; the runs of cells around each fluid particle, which every pair loop of the step reads instead of searching the grid (about 20 runs of 6 B per fluid particle in 3D, not in the figure)".into()
        }
        Stage::Density if scene.has_interfaces() => {
            "summation density ρ_i = ρ0_i Σ_j V_j W_ij (fluids of different density); each fluid particle's distance to the nearest interface and normal across it, from the other fluid's share of its kernel (the walls mirroring the fluid), for the pairs across it".into()
        }
        Stage::Density => "summation density ρ_i = Σ_j m_j W_ij; walls keep ρ0".into(),
        Stage::FreeSurface => "moment matrix M_i of each kernel support; its smallest eigenvalue and the scan region (Marrone et al. 2010) find the free surface; PPE roles: interior, free surface (P = ρ0|g|dx/2), splash (P = 0: the moment matrix of its pressure gradient is near-singular)".into(),
        Stage::KernelCorrection => format!("L_i = M_i⁻¹ (Eq. 24–25) for the divergence and velocity gradients, only where the free surface is in reach and stored for those particles only ({} B each, not in the figure); L'_i for the pressure gradient and the PPE rows (wall ghosts carry the normal gradient only), inverted in the free-surface pass from its moments", sparse_correction_bytes(scene.dimensions)),
        Stage::EddyViscosity => format!(
            "Smagorinsky ν_t = (Cs Δ)² |S| (Eq. 3–4), Cs = {}, Δ = dx, walls as free-slip ghosts",
            effects.les.map_or(0.0, |les| les.cs)
        ),
        Stage::Predictor => match effects.les {
            Some(les) if les.wall_function => "Eq. (5): u* = u + Δt (∇·((ν + ν_t)∇u) (Eq. 26) + τ_w + g), no-slip laminar wall pairs, τ_w the log-law wall shear on the particles touching a wall".into(),
            Some(_) => "Eq. (5): u* = u + Δt (∇·((ν + ν_t)∇u) (Eq. 26) + g), no-slip laminar wall pairs".into(),
            None => "Eq. (5): u* = u + Δt (∇·(ν∇u) (Eq. 26) + g), no-slip wall pairs".into(),
        },
        Stage::PressureSolve => format!(
            "Eq. (6): source −(ρ0/Δt)∇·u*{} − α(ρ0 − ρ)/Δt², α = {}; Eq. (27) Laplacian made first-order consistent near walls and the free surface, matrix-free; walls: {} (no unknowns); free surface: P = ρ0|g|dx/2, the water above the particle's centre; BiCGSTAB preconditioned by additive two-level aggregation multigrid (Jacobi + a coarse V-cycle over the cell blocks), warm start",
            if effects.kernel_correction { " (corrected by L_i)" } else { "" },
            scene.solver.alpha,
            match scene.walls.ghost_pressure {
                GhostPressure::Hydrostatic => "Neumann ghosts of the fluid pressure, P_b = P_i + ρ0 g·N_b r_bi",
                GhostPressure::Mirror => "mirror ghosts of the fluid pressure, P_b = P_i (∂P/∂n = 0)",
            }
        ),
        Stage::Corrector => format!(
            "Eq. (7): u = u* − (Δt/ρ0)∇P, ∇P {} with the walls as ghosts; no velocity into a wall face within half a spacing of it",
            if effects.kernel_correction { "corrected by L'_i (Eq. 20, 24–25)" } else { "of Eq. (20)" }
        ),
        Stage::WallPressure => "pressure of the wall particles, on the steps that end on a frame: kernel mean of the ghost pressures of their fluid neighbours".into(),
        Stage::Shifting => {
            let s = effects.shifting.unwrap_or_default();
            format!(
                "Fickian shifting δr = −D∇C (Eq. 10), D = {} h U Δt, anti-clustering weight R = {}, each component at most {} dx, tangential at the free surface; u and P Taylor-corrected to the new position (Eq. 9)",
                s.coefficient, s.clustering_weight, s.max_shift
            )
        }
        Stage::Advection => format!(
            "Eq. (8): r += Δt u{}; a particle that crossed a wall face is put back a quarter spacing inside (counted in penetrations)",
            if effects.shifting.is_some() { " + δr" } else { "" }
        ),
        Stage::Diagnostics => "max speed, kinetic energy, density error, disorder, penetrations → stats.csv".into(),
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

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let n = self.particles();
        let mib = |bytes: usize| bytes as f64 / (1 << 20) as f64;
        let per_particle = |bytes: usize| (bytes as f64 / n as f64).round() as usize;
        writeln!(f, "scene {} ({}D)", self.scene, self.dimensions)?;
        writeln!(
            f,
            "particles: {} fluid + {} wall = {n}   (h = {:.4e} m, {} wall layers)",
            self.fluid_particles, self.wall_particles, self.smoothing_length, self.wall_layers
        )?;
        writeln!(f, "effects: {}", effects_line(&self.effects))?;
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
                s.stage.name(),
                per_particle(s.bytes),
                mib(s.bytes),
                s.what
            )?;
        }
        write!(
            f,
            "memory: {} B/particle, {:.2} MiB for the particle arrays (plus per-cell arrays: the cell list and the multigrid levels); the workspace of a step holds the fluid particles only",
            self.bytes_per_particle(),
            mib(self.bytes())
        )
    }
}

/// Bytes of one particle's entry in the sparse list of L_i: the matrix and the particle index.
fn sparse_correction_bytes(dimensions: usize) -> usize {
    let matrix = match dimensions {
        2 => std::mem::size_of::<Correction<2>>(),
        _ => std::mem::size_of::<Correction<3>>(),
    };
    matrix + std::mem::size_of::<u32>()
}
