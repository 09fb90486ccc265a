//! The state of a run and one projection step, Eq. (5)–(8):
//! cell list → density and free surface → predictor → PPE → corrector → advection → diagnostics.

use crate::free_surface::Support;
use crate::grid::CellList;
use crate::kernel::{Quintic, SUPPORT_IN_H};
use crate::lattice;
use crate::linsolve::{BiCgStab, SolverError, SolverParams};
use crate::particles::{components, Kind, Particles};
use crate::ppe::{self, PressureOperator, Role};
use crate::reduce::{self, fill, fill_vector};
use crate::scene::{Aabb, Scene};
use crate::shifting::Shifting;
use crate::sph::{self, Correction, Neighbours};
use crate::turbulence;
use crate::wall;
use rayon::prelude::*;

/// Viscous time-step limit Δt ≤ C_ν h²/ν.
const VISCOUS_NUMBER: f64 = 0.125;
/// Body-force time-step limit Δt ≤ C_g √(h/|g|).
const BODY_FORCE_NUMBER: f64 = 0.25;

/// A CFL time step below this fraction of the body-force step is a blow-up.
const COLLAPSE_FRACTION: f64 = 1.0e-3;

/// What one step measured: a row of `stats.csv` (without the wall time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepStats {
    pub step: u64,
    pub time: f64,
    pub dt: f64,
    pub ppe_iterations: usize,
    pub ppe_residual: f64,
    pub max_speed: f64,
    pub kinetic_energy: f64,
    pub density_error: f64,
    pub penetrations: usize,
}

#[derive(Debug, thiserror::Error)]
pub enum NumericalFailure {
    #[error("particle {id} left the domain at step {step} (t = {time} s), at {position:?}")]
    LeftDomain {
        id: u64,
        step: u64,
        time: f64,
        position: Vec<f64>,
    },
    #[error("the pressure solve failed at step {step} (t = {time} s): {source}")]
    Solver {
        step: u64,
        time: f64,
        source: SolverError,
    },
    #[error("the velocity became non-finite at step {step} (t = {time} s)")]
    NonFinite { step: u64, time: f64 },
    #[error("the time step collapsed to {dt:e} s at step {step} (t = {time} s): the flow has blown up (max speed {max_speed:e} m/s)")]
    TimeStepCollapse {
        step: u64,
        time: f64,
        dt: f64,
        max_speed: f64,
    },
}

#[derive(Debug, thiserror::Error)]
#[error("{path}: the scene holds no fluid particle: every [[fluid_block]] is thinner than the spacing or lies inside obstacles")]
pub struct NoFluid {
    pub path: std::path::PathBuf,
}

/// Per-step scratch arrays, allocated once and reused.
struct Workspace<const D: usize> {
    cell_of: Vec<u32>,
    order: Vec<u32>,
    scratch: Vec<f64>,
    /// Summation density of the step (swapped with the particles' density).
    density: Vec<f64>,
    /// How the neighbours fill each kernel support (free surface, shifting).
    supports: Vec<Support<D>>,
    roles: Vec<Role>,
    full_support: Vec<bool>,
    u_star: [Vec<f64>; D],
    /// Kernel gradient correction L_i of each particle, Eq. (25).
    corrections: Vec<Correction<D>>,
    /// The correction L'_i of the pressure gradient, whose wall ghosts carry the normal part
    /// of the gradient only (see `sph::Moments`).
    pressure_corrections: Vec<Correction<D>>,
    /// Smagorinsky eddy viscosity ν_t.
    eddy: Vec<f64>,
    /// The per-row vectors of the PPE operator (`ppe::row_vectors`).
    row_vectors: [Vec<f64>; D],
    /// Normal of the wall each fluid particle touches (zero: none).
    contact: [Vec<f64>; D],
    /// Shifting displacement δr of each particle.
    shift: [Vec<f64>; D],
    rhs: Vec<f64>,
    pressure: Vec<f64>,
    bicgstab: BiCgStab,
}

impl<const D: usize> Default for Workspace<D> {
    fn default() -> Self {
        Self {
            cell_of: Vec::new(),
            order: Vec::new(),
            scratch: Vec::new(),
            density: Vec::new(),
            supports: Vec::new(),
            roles: Vec::new(),
            full_support: Vec::new(),
            u_star: components(),
            shift: components(),
            contact: components(),
            row_vectors: components(),
            eddy: Vec::new(),
            corrections: Vec::new(),
            pressure_corrections: Vec::new(),
            rhs: Vec::new(),
            pressure: Vec::new(),
            bicgstab: BiCgStab::default(),
        }
    }
}

pub struct Simulation<const D: usize> {
    pub particles: Particles<D>,
    pub time: f64,
    pub step: u64,
    kernel: Quintic<D>,
    grid: CellList<D>,
    gravity: [f64; D],
    container: Aabb,
    obstacles: Vec<Aabb>,
    spacing: f64,
    cfl: f64,
    alpha: f64,
    solver: SolverParams,
    max_viscosity: f64,
    work: Workspace<D>,
}

impl<const D: usize> Simulation<D> {
    pub fn new(scene: &Scene) -> Result<Self, NoFluid> {
        assert_eq!(
            scene.dimensions, D,
            "scene dimension and solver dimension differ"
        );
        let particles = lattice::build::<D>(scene);
        if particles.fluid_count() == 0 {
            return Err(NoFluid {
                path: scene.path.clone(),
            });
        }
        let h = scene.smoothing_length();
        let margin = (lattice::wall_layers(scene) as f64 + 1.0) * scene.spacing;
        let lo = std::array::from_fn(|d| scene.container.min[d] - margin);
        let hi = std::array::from_fn(|d| scene.container.max[d] + margin);
        Ok(Self {
            particles,
            time: 0.0,
            step: 0,
            kernel: Quintic::new(h),
            grid: CellList::new(lo, hi, SUPPORT_IN_H * h),
            gravity: std::array::from_fn(|d| scene.gravity[d]),
            container: scene.container.clone(),
            obstacles: scene.obstacles.clone(),
            spacing: scene.spacing,
            cfl: scene.solver.cfl,
            alpha: scene.solver.alpha,
            solver: SolverParams {
                tolerance: scene.solver.tolerance,
                max_iterations: scene.solver.max_iterations,
            },
            max_viscosity: scene.fluids.iter().map(|f| f.viscosity).fold(0.0, f64::max),
            work: Workspace::default(),
        })
    }

    pub fn kernel(&self) -> Quintic<D> {
        self.kernel
    }

    /// Largest stable Δt: CFL, viscous and body-force limits. A CFL step far below the
    /// body-force step means the flow has blown up: that is reported, not integrated (without
    /// gravity there is no such reference, and only a non-finite velocity stops the run).
    pub fn time_step_limit(&self) -> Result<f64, NumericalFailure> {
        let p = &self.particles;
        let h = self.kernel.h();
        let max_speed = reduce::max(p.len(), |i| if p.is_fluid(i) { speed(p, i) } else { 0.0 });
        let g = self.gravity.iter().map(|g| g * g).sum::<f64>().sqrt();
        let (cfl, body_force) = (self.cfl * h / max_speed, BODY_FORCE_NUMBER * (h / g).sqrt());
        let dt = cfl
            .min(body_force)
            .min(VISCOUS_NUMBER * h * h / self.max_viscosity);
        if body_force.is_finite() && cfl < COLLAPSE_FRACTION * body_force {
            return Err(NumericalFailure::TimeStepCollapse {
                step: self.step,
                time: self.time,
                dt,
                max_speed,
            });
        }
        Ok(dt)
    }

    /// Re-sorts the particles by cell, permuting every array together.
    fn sort_by_cell(&mut self) -> Result<(), NumericalFailure> {
        let w = &mut self.work;
        if let Err(out) = self
            .grid
            .sort(&self.particles.pos, &mut w.cell_of, &mut w.order)
        {
            let p = &self.particles;
            return Err(NumericalFailure::LeftDomain {
                id: p.id[out.index],
                step: self.step,
                time: self.time,
                position: p.position(out.index).to_vec(),
            });
        }
        self.particles.permute(&w.order, &mut w.scratch);
        Ok(())
    }

    /// Advances by one step towards the simulated time `target`, landing on it exactly when it
    /// is within reach (two steps to go are split evenly, so no step is tiny).
    pub fn advance_towards(&mut self, target: f64) -> Result<StepStats, NumericalFailure> {
        self.sort_by_cell()?;
        let limit = self.time_step_limit()?;
        let remaining = target - self.time;
        let dt = if remaining <= limit {
            remaining
        } else if remaining < 2.0 * limit {
            0.5 * remaining
        } else {
            limit
        };
        let stats = self.project(dt)?;
        self.time = if dt == remaining {
            target
        } else {
            self.time + dt
        };
        self.finish_step(dt, stats)
    }

    /// The projection step of size `dt` on particles sorted by cell; returns
    /// (PPE iterations, PPE residual, density error).
    fn project(&mut self, dt: f64) -> Result<(usize, f64, f64), NumericalFailure> {
        let (step, time) = (self.step, self.time);
        let Self {
            particles: p,
            work: w,
            grid,
            kernel,
            gravity,
            ..
        } = self;
        let gravity = *gravity;
        let nb = Neighbours::new(grid, &p.pos, *kernel);

        for a in w
            .u_star
            .iter_mut()
            .chain(&mut w.shift)
            .chain(&mut w.row_vectors)
            .chain(&mut w.contact)
        {
            a.resize(p.len(), 0.0);
        }
        // Summation density; walls keep their rest density.
        w.density.resize(p.len(), 0.0);
        fill(&mut w.density, |i| match p.kind[i] {
            Kind::Fluid => sph::density(&nb, p, i),
            Kind::Wall => p.rest_density[i],
        });
        std::mem::swap(&mut p.density, &mut w.density);

        // Kernel gradient corrections, Eq. (25), once per step for every operator below, and
        // how each support is filled, for the free-surface detection.
        w.corrections.resize(p.len(), None);
        w.pressure_corrections.resize(p.len(), None);
        w.supports.resize(p.len(), Support::FULL);
        w.corrections
            .par_iter_mut()
            .zip(&mut w.pressure_corrections)
            .zip(&mut w.supports)
            .enumerate()
            .for_each(|(i, ((l, lp), support))| {
                (*l, *lp, *support) = match p.kind[i] {
                    Kind::Fluid => {
                        let mo = sph::support_moments(&nb, p, i);
                        (
                            sph::gradient_correction(mo.m),
                            sph::gradient_correction(mo.m_neumann),
                            Support::new(&mo.m, mo.grad_c),
                        )
                    }
                    Kind::Wall => (None, None, Support::FULL),
                }
            });
        ppe::assign_roles(
            &nb,
            p,
            &w.supports,
            &w.pressure_corrections,
            gravity,
            &mut w.roles,
        );
        ppe::full_support(&nb, &w.roles, &mut w.full_support);
        fill(&mut p.free_surface, |i| match w.roles[i] {
            Role::Surface => 1,
            Role::Splash => 2,
            Role::Interior | Role::Wall => 0,
        });
        // Inside the fluid (no free surface in reach) the moment matrix measures the disorder of
        // the particles, not a truncated support: corrected there, the divergence of the PPE
        // source amplifies that disorder into the pressure (measured: a collision of two blocks
        // gains energy instead of losing it). The pressure gradient keeps its correction, which
        // there corrects the wall ghosts' missing tangential gradient.
        w.corrections
            .par_iter_mut()
            .zip(&w.full_support)
            .for_each(|(l, &full)| {
                if full {
                    *l = None;
                }
            });
        let (corrections, pressure_corrections) = (&w.corrections, &w.pressure_corrections);

        // Smagorinsky eddy viscosity, Eq. (3)–(4).
        w.eddy.resize(p.len(), 0.0);
        let spacing = self.spacing;
        fill(&mut w.eddy, |i| match p.kind[i] {
            Kind::Fluid => turbulence::eddy_viscosity(&nb, p, &corrections[i], spacing, i),
            Kind::Wall => 0.0,
        });

        // Predictor, Eq. (5): u* = uⁿ + Δt (∇·((ν + ν_t)∇uⁿ) + τ_w + g), with τ_w the turbulent
        // wall shear; walls stay at rest.
        fill_vector(&mut w.u_star, |i| match p.kind[i] {
            Kind::Fluid => {
                let visc = sph::viscous_acceleration(&nb, p, &w.eddy, i);
                let wall = turbulence::wall_shear(&nb, p, spacing, i);
                std::array::from_fn(|d| p.vel[d][i] + dt * (visc[d] + wall[d] + gravity[d]))
            }
            Kind::Wall => [0.0; D],
        });

        // PPE, Eq. (6), solved from the last pressure (warm start; walls hold no unknown).
        ppe::row_vectors(
            &nb,
            p,
            &w.roles,
            pressure_corrections,
            &w.supports,
            self.spacing,
            &mut w.row_vectors,
        );
        let op = PressureOperator {
            nb: &nb,
            p,
            roles: &w.roles,
            row_vectors: &w.row_vectors,
            gravity,
        };
        ppe::source(
            &op,
            &w.full_support,
            corrections,
            &w.u_star,
            dt,
            self.alpha,
            &mut w.rhs,
        );
        w.pressure.resize(p.len(), 0.0);
        fill(&mut w.pressure, |i| match w.roles[i] {
            Role::Interior | Role::Surface => p.pressure[i],
            Role::Splash | Role::Wall => 0.0,
        });
        let info = w
            .bicgstab
            .solve(&op, &w.rhs, &mut w.pressure, self.solver)
            .map_err(|source| NumericalFailure::Solver { step, time, source })?;
        // The fluid cannot sustain tension, which would pull particles into clumps: negative
        // pressures are clipped, as SPlisHSPlasH's implicit solvers do.
        fill(&mut p.pressure, |i| w.pressure[i].max(0.0));

        // The wall each fluid particle touches, for the kinematic condition on its velocity and
        // its shift.
        fill_vector(&mut w.contact, |i| match p.kind[i] {
            Kind::Fluid => wall::contact_normal(&nb, p, self.spacing, i),
            Kind::Wall => [0.0; D],
        });
        let contact = &w.contact;
        let contact_of = |i: usize| -> [f64; D] { std::array::from_fn(|d| contact[d][i]) };

        // Corrector, Eq. (7): uⁿ⁺¹ = u* − (Δt/ρ0)∇Pⁿ⁺¹ with the corrected gradient and the
        // walls as ghosts; particles touching a wall then keep no velocity into it.
        let full = &w.full_support;
        let mut vel = std::mem::replace(&mut p.vel, components());
        fill_vector(&mut vel, |i| match p.kind[i] {
            Kind::Fluid => {
                let grad = pressure_gradient(&nb, p, gravity, &pressure_corrections[i], i);
                let rho0 = p.rest_density[i];
                let u = std::array::from_fn(|d| w.u_star[d][i] - dt * grad[d] / rho0);
                wall::no_penetration(u, contact_of(i))
            }
            Kind::Wall => [0.0; D],
        });
        p.vel = vel;

        // Density error where the summation density is not truncated by the free surface.
        let n_full = full.iter().filter(|&&f| f).count();
        let density_error = if n_full == 0 {
            0.0
        } else {
            reduce::sum(p.len(), |i| {
                if full[i] {
                    (p.density[i] / p.rest_density[i] - 1.0).abs()
                } else {
                    0.0
                }
            }) / n_full as f64
        };

        // Particle shifting δr = −D ∇C (Eq. 10) at rⁿ, then velocity and pressure carried to
        // the shifted position by Eq. (9).
        let max_speed = reduce::max(p.len(), |i| if p.is_fluid(i) { speed(p, i) } else { 0.0 });
        let shifting = Shifting::new(&nb, self.spacing, max_speed, dt);
        fill_vector(&mut w.shift, |i| match w.roles[i] {
            // Splashes are left in place: neither ∇C nor the Taylor correction means anything
            // there.
            Role::Interior | Role::Surface => {
                let dr = shifting.displacement(&nb, p, &w.supports[i], full[i], i);
                wall::no_penetration(dr, contact_of(i))
            }
            Role::Splash | Role::Wall => [0.0; D],
        });
        let shift = &w.shift;
        let shift_of = |i: usize| -> [f64; D] { std::array::from_fn(|d| shift[d][i]) };
        fill_vector(&mut w.u_star, |i| match p.kind[i] {
            Kind::Fluid => {
                let g = sph::velocity_gradient(
                    &nb,
                    p,
                    &corrections[i],
                    |j| sph::fluid_velocity(p, i, j),
                    i,
                );
                // Where the free surface is in reach the velocity gradient is no longer that of
                // a filled support, and shifting moves particles into the thinning, faster parts
                // of a stretching flow: the Taylor step there feeds the flow energy (measured).
                let dr = if full[i] { shift_of(i) } else { [0.0; D] };
                std::array::from_fn(|a| p.vel[a][i] + (0..D).map(|b| dr[b] * g[b][a]).sum::<f64>())
            }
            Kind::Wall => [0.0; D],
        });
        std::mem::swap(&mut p.vel, &mut w.u_star);
        fill(&mut w.pressure, |i| match p.kind[i] {
            Kind::Fluid => {
                let g = pressure_gradient(&nb, p, gravity, &pressure_corrections[i], i);
                let dr = shift_of(i);
                (p.pressure[i] + (0..D).map(|d| g[d] * dr[d]).sum::<f64>()).max(0.0)
            }
            Kind::Wall => wall::wall_pressure(&nb, p, gravity, i),
        });
        std::mem::swap(&mut p.pressure, &mut w.pressure);

        // Advection, Eq. (8), plus the shift.
        for d in 0..D {
            let (kind, shift) = (&p.kind, &w.shift[d]);
            p.pos[d]
                .par_iter_mut()
                .zip(&p.vel[d])
                .zip(kind)
                .zip(shift)
                .for_each(|(((x, v), k), s)| {
                    if *k == Kind::Fluid {
                        *x += dt * v + s;
                    }
                });
        }
        Ok((info.iterations, info.relative_residual, density_error))
    }

    fn finish_step(
        &mut self,
        dt: f64,
        (ppe_iterations, ppe_residual, density_error): (usize, f64, f64),
    ) -> Result<StepStats, NumericalFailure> {
        self.step += 1;
        let p = &self.particles;
        let fluid = |i: usize| p.is_fluid(i);
        let max_speed = reduce::max(p.len(), |i| if fluid(i) { speed(p, i) } else { 0.0 });
        if !max_speed.is_finite() {
            return Err(NumericalFailure::NonFinite {
                step: self.step,
                time: self.time,
            });
        }
        let kinetic_energy = reduce::sum(p.len(), |i| {
            if fluid(i) {
                0.5 * p.mass[i] * speed(p, i).powi(2)
            } else {
                0.0
            }
        });
        Ok(StepStats {
            step: self.step,
            time: self.time,
            dt,
            ppe_iterations,
            ppe_residual,
            max_speed,
            kinetic_energy,
            density_error,
            penetrations: self.penetrations(),
        })
    }

    /// Fluid particles whose centre lies inside a wall: outside the container or in an obstacle.
    pub fn penetrations(&self) -> usize {
        let p = &self.particles;
        reduce::count(p.len(), |i| {
            if !p.is_fluid(i) {
                return false;
            }
            let x = p.position(i);
            let c = &self.container;
            let outside = (0..D).any(|d| x[d] < c.min[d] || x[d] > c.max[d]);
            outside || self.obstacles.iter().any(|o| o.contains(&x))
        })
    }
}

/// ∇P_i of fluid particle i with the corrected gradient (Eq. 20, 24–25) and the walls as
/// ghosts of its pressure (see `wall`).
fn pressure_gradient<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    gravity: [f64; D],
    l: &Correction<D>,
    i: usize,
) -> [f64; D] {
    sph::gradient(nb, p, l, i, |j, rij| match p.kind[j] {
        Kind::Fluid => p.pressure[j] - p.pressure[i],
        Kind::Wall => wall::ghost_pressure_difference(p, gravity, i, j, rij),
    })
}

fn speed<const D: usize>(p: &Particles<D>, i: usize) -> f64 {
    (0..D)
        .map(|d| p.vel[d][i] * p.vel[d][i])
        .sum::<f64>()
        .sqrt()
}
