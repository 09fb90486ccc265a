//! What a scene will run: the stages of a step in order, the particle counts, and the memory
//! the arrays of those stages take.

use crate::free_surface::Support;
use crate::lattice;
use crate::linsolve::BiCgStab;
use crate::particles::Kind;
use crate::scene::Scene;
use std::fmt;
use std::mem::size_of;

/// One stage of the time step.
#[derive(Clone, Debug, PartialEq)]
pub struct Stage {
    pub name: &'static str,
    pub what: &'static str,
    /// Per-particle bytes of the arrays this stage owns.
    pub bytes_per_particle: usize,
}

#[derive(Clone, Debug)]
pub struct Plan {
    pub scene: String,
    pub dimensions: usize,
    pub fluid_particles: usize,
    pub wall_particles: usize,
    pub smoothing_length: f64,
    pub wall_layers: usize,
    pub stages: Vec<Stage>,
}

impl Plan {
    pub fn new(scene: &Scene) -> Plan {
        let kinds = match scene.dimensions {
            2 => lattice::build::<2>(scene).kind,
            _ => lattice::build::<3>(scene).kind,
        };
        let fluid = kinds.iter().filter(|&&k| k == Kind::Fluid).count();
        let d = scene.dimensions;
        let f64s = |n: usize| 8 * n;
        let support = if d == 2 {
            size_of::<Support<2>>()
        } else {
            size_of::<Support<3>>()
        };
        let stages = vec![
            Stage {
                name: "particles",
                what: "SoA state: position, velocity, wall normal, pressure, density, mass, ρ0, ν, kind, fluid, id",
                bytes_per_particle: f64s(3 * d + 5) + 1 + 2 + 8,
            },
            Stage {
                name: "cell list",
                what: "counting sort by cell (x fastest), all arrays permuted together",
                bytes_per_particle: 4 + 4 + 8,
            },
            Stage {
                name: "density + free surface",
                what: "summation density; λ_min of the moment matrix, normal and scan region (Marrone et al. 2010) ⇒ free surface (Robin row, P = 0 half a spacing out)",
                bytes_per_particle: f64s(1) + support + 2,
            },
            Stage {
                name: "kernel correction",
                what: "L_i of Eq. (25) and L'_i of the pressure gradient (walls as Neumann ghosts) once per step, shared by every corrected operator",
                bytes_per_particle: 2 * f64s(d * d + 1),
            },
            Stage {
                name: "predictor",
                what: "Eq. (5): u* = u + Δt (∇·((ν + ν_t)∇u) (Eq. 26, Smagorinsky ν_t Eq. 3–4) + g)",
                bytes_per_particle: f64s(d + 1),
            },
            Stage {
                name: "pressure Poisson equation",
                what: "Eq. (6) source, Eq. (27) Laplacian (first-order consistent) matrix-free in BiCGSTAB + Jacobi, warm start; walls: ghosts of the fluid pressure under the Neumann condition (no unknowns); free surface: Robin row",
                bytes_per_particle: f64s(2 + d) + 1 + BiCgStab::BYTES_PER_UNKNOWN,
            },
            Stage { name: "corrector", what: "Eq. (7) with the corrected gradient (Eq. 20, 24–25); no velocity into a wall within dx of it", bytes_per_particle: f64s(d) },
            Stage {
                name: "advection + shifting",
                what: "Eq. (8): r += Δt u, then Fickian shifting δr = −D∇C with u and P Taylor-corrected (Eq. 9–10)",
                bytes_per_particle: f64s(d),
            },
            Stage {
                name: "diagnostics",
                what: "max speed, kinetic energy, density error, penetrations → stats.csv",
                bytes_per_particle: 0,
            },
        ];
        Plan {
            scene: scene.name.clone(),
            dimensions: d,
            fluid_particles: fluid,
            wall_particles: kinds.len() - fluid,
            smoothing_length: scene.smoothing_length(),
            wall_layers: lattice::wall_layers(scene),
            stages,
        }
    }

    pub fn particles(&self) -> usize {
        self.fluid_particles + self.wall_particles
    }

    pub fn bytes_per_particle(&self) -> usize {
        self.stages.iter().map(|s| s.bytes_per_particle).sum()
    }
}

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let n = self.particles();
        writeln!(f, "scene {} ({}D)", self.scene, self.dimensions)?;
        writeln!(
            f,
            "particles: {} fluid + {} wall = {n}   (h = {:.4e} m, {} wall layers)",
            self.fluid_particles, self.wall_particles, self.smoothing_length, self.wall_layers
        )?;
        writeln!(f, "stages per step:")?;
        for (k, s) in self.stages.iter().enumerate() {
            let mib = (s.bytes_per_particle * n) as f64 / (1 << 20) as f64;
            writeln!(
                f,
                "  {}. {:<26} {:>4} B/particle {:>9.2} MiB  {}",
                k + 1,
                s.name,
                s.bytes_per_particle,
                mib,
                s.what
            )?;
        }
        let total = self.bytes_per_particle();
        write!(
            f,
            "memory: {total} B/particle, {:.2} MiB for the particle arrays (plus the cell grid)",
            (total * n) as f64 / (1 << 20) as f64
        )
    }
}
