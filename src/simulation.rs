//! The state of a run and its time stepping: the cell sort, the time-step limits, the
//! projection step of `step`, and the diagnostics of each step.

use crate::boundary::faces::{Contact, Faces};
use crate::fill;
use crate::math::kernel::{Quintic, SUPPORT_IN_H};
use crate::math::memory::ArraySize;
use crate::math::reduce;
use crate::neighbours::cell_list::CellList;
use crate::particles::Particles;
use crate::scene::{GhostPressure, Scene};
use crate::solver::krylov::{SolverError, SolverParams};
use crate::sph;
use crate::sph::free_surface;
use crate::sph::interface::Interfaces;
use crate::step::timings::{Stage, Timings};
use crate::step::{speed, StepLength, StepReport, StepSettings, Workspace};
use std::time::Instant;

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
    pub disorder: f64,
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

pub struct Simulation<const D: usize> {
    pub particles: Particles<D>,
    pub time: f64,
    pub step: u64,
    kernel: Quintic<D>,
    grid: CellList<D>,
    settings: StepSettings<D>,
    faces: Faces,
    cfl: f64,
    max_viscosity: f64,
    /// Arrays of the cell sort: cell of each particle, the sorting permutation, scratch.
    cell_of: Vec<u32>,
    order: Vec<u32>,
    scratch: Vec<f64>,
    work: Workspace<D>,
    /// Time spent in each stage so far.
    pub timings: Timings,
}

impl<const D: usize> Simulation<D> {
    pub fn new(scene: &Scene) -> Result<Self, NoFluid> {
        assert_eq!(
            scene.dimensions, D,
            "scene dimension and solver dimension differ"
        );
        let particles = fill::build::<D>(scene);
        if particles.fluid_count() == 0 {
            return Err(NoFluid {
                path: scene.path.clone(),
            });
        }
        let confined = fill::fills_container(scene, &particles);
        let h = scene.smoothing_length();
        // Bounded axes: room for the wall layers and a spacing more; a periodic axis is one
        // period, the container's extent.
        let periodic: [bool; D] = std::array::from_fn(|d| scene.periodic[d]);
        let walls = (scene.wall_layers() as f64 + 1.0) * scene.spacing;
        let margin = |d: usize| if periodic[d] { 0.0 } else { walls };
        let lo = std::array::from_fn(|d| scene.container.min[d] - margin(d));
        let hi = std::array::from_fn(|d| scene.container.max[d] + margin(d));
        Ok(Self {
            particles,
            time: 0.0,
            step: 0,
            kernel: Quintic::new(h),
            grid: CellList::new(lo, hi, SUPPORT_IN_H * h, periodic),
            settings: StepSettings {
                gravity: std::array::from_fn(|d| scene.gravity[d]),
                ghost_gravity: match scene.walls.ghost_pressure {
                    GhostPressure::Hydrostatic => std::array::from_fn(|d| scene.gravity[d]),
                    GhostPressure::Mirror => [0.0; D],
                },
                spacing: scene.spacing,
                alpha: scene.solver.alpha,
                solver: SolverParams {
                    tolerance: scene.solver.tolerance,
                    max_iterations: scene.solver.max_iterations,
                },
                effects: scene.effects,
                confined,
                spray_density: free_surface::spray_density::<D>(scene.solver.h_over_dx),
                min_correction_determinant: sph::min_correction_determinant::<D>(
                    scene.solver.h_over_dx,
                ),
            },
            faces: Faces::new(scene),
            cfl: scene.solver.cfl,
            max_viscosity: scene.fluids.iter().map(|f| f.viscosity).fold(0.0, f64::max),
            cell_of: Vec::new(),
            order: Vec::new(),
            scratch: Vec::new(),
            work: Workspace::new(
                scene
                    .has_interfaces()
                    .then(|| Interfaces::new(&Quintic::<D>::new(h), scene.spacing)),
            ),
            timings: Timings::default(),
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
        let g = self
            .settings
            .gravity
            .iter()
            .map(|g| g * g)
            .sum::<f64>()
            .sqrt();
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

    /// Re-sorts the particles by cell, permuting every array together; particles that left
    /// through a periodic boundary come back through the opposite one first.
    fn sort_by_cell(&mut self) -> Result<(), NumericalFailure> {
        let clock = Instant::now();
        // (A no-op after a step; a checkpoint written before steps wrapped may hold positions
        // past the period.)
        self.grid.wrap(&mut self.particles.pos);
        if let Err(out) = self.grid.sort(
            &self.particles.pos,
            &self.particles.kind,
            &mut self.cell_of,
            &mut self.order,
        ) {
            let p = &self.particles;
            return Err(NumericalFailure::LeftDomain {
                id: p.id[out.index],
                step: self.step,
                time: self.time,
                position: p.position(out.index).to_vec(),
            });
        }
        self.particles.permute(&self.order, &mut self.scratch);
        self.timings.add(Stage::CellList, clock.elapsed());
        Ok(())
    }

    /// Advances by one step towards the simulated time `target` (the next frame's), landing on
    /// it exactly when it is within reach (two steps to go are split evenly, so no step is
    /// tiny). The step that lands on it also computes the wall particles' pressure for the
    /// frame.
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
        let lands_on_target = dt == remaining;
        let (step, time) = (self.step, self.time);
        let report = self
            .work
            .project(
                &mut self.particles,
                &self.grid,
                self.kernel,
                &self.settings,
                &self.faces,
                StepLength { dt, limit },
                lands_on_target,
                &mut self.timings,
            )
            .map_err(|source| NumericalFailure::Solver { step, time, source })?;
        self.time = if lands_on_target {
            target
        } else {
            self.time + dt
        };
        let penetrations = self.keep_off_the_faces();
        // Along a periodic axis a particle leaves the period only in the advection: wrapped
        // back here, the frames and checkpoints hold every position inside the box.
        self.grid.wrap(&mut self.particles.pos);
        self.finish_step(dt, report, penetrations)
    }

    fn finish_step(
        &mut self,
        dt: f64,
        report: StepReport,
        penetrations: usize,
    ) -> Result<StepStats, NumericalFailure> {
        let clock = Instant::now();
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
        let stats = StepStats {
            step: self.step,
            time: self.time,
            dt,
            ppe_iterations: report.solve.iterations,
            ppe_residual: report.solve.relative_residual,
            max_speed,
            kinetic_energy,
            density_error: report.density_error,
            penetrations,
            disorder: report.disorder,
        };
        self.timings.add(Stage::Diagnostics, clock.elapsed());
        Ok(stats)
    }

    /// Every per-particle array of the step with the stage that allocates it, as it is now:
    /// the cell sort's and the workspace's (`Workspace::arrays`). The particles' own arrays are
    /// `Particles::arrays_mut`.
    pub fn arrays(&self) -> Vec<(Stage, ArraySize)> {
        let sort = [
            ArraySize::of("cell of particle", &self.cell_of),
            ArraySize::of("sort order", &self.order),
            ArraySize::of("sort scratch", &self.scratch),
            self.grid.sorted_cells(),
        ];
        let runs = self.grid.runs_arrays();
        let mut arrays: Vec<_> = sort
            .into_iter()
            .chain(runs)
            .map(|a| (Stage::CellList, a))
            .collect();
        arrays.extend(self.work.arrays());
        arrays
    }

    /// `Faces::contact` for every fluid particle, a quarter spacing off the faces (at rest
    /// the fluid sits half a spacing off them). Returns the penetrations the step's advection
    /// made, counted before the contact puts them back: the particles the walls' pressure did
    /// not stop. Timed as part of the advection.
    fn keep_off_the_faces(&mut self) -> usize {
        let clock = Instant::now();
        let gap = 0.25 * self.settings.spacing;
        let p = &mut self.particles;
        let mut penetrations = 0;
        for i in 0..p.len() {
            if !p.is_fluid(i) {
                continue;
            }
            let (mut x, mut u) = (p.position(i), p.velocity(i));
            match self.faces.contact(gap, &mut x, &mut u) {
                Contact::Clear => continue,
                Contact::Near => {}
                Contact::Crossed => penetrations += 1,
            }
            for d in 0..D {
                (p.pos[d][i], p.vel[d][i]) = (x[d], u[d]);
            }
        }
        self.timings.add_part(Stage::Advection, clock.elapsed());
        penetrations
    }
}
