//! One projection step, Eq. (5)–(8), as a sequence of stages over the particles sorted by
//! cell. `Step::advance` is the sequence, and the only place that orders the stages: each
//! stage is one file of this folder, owns the arrays it fills (its output), and is handed what
//! it reads from earlier stages as arguments, so the data flow is the signatures. The stages of
//! the effects a scene turns off (`scene::Effects`) are `None` and cost nothing: no call, no
//! array. `Step::stages` lists the stages that run, in order, for `isph plan` and the timings.
//! One stage fills another's array: the corrector sums the density correction's ∇P_α into it
//! (`DensityCorrection::gradient_slot`) in its walk for ∇Pⁿ⁺¹, and the density correction turns
//! it into its displacement.
//!
//! The fluid particles come first in the sorted order (`cell_list`), and every stage's array
//! but the sort's holds the fluid particles only: the walls hold no unknown and need none.
//! A rigid body's particles are sorted with the fluid and taken for fluid of the body's density
//! up to the corrector; `rigid_bodies` then moves them rigidly (`bodies`).
//! `Particles`, the lasting state, is written at named points only, each marked "Into the
//! particles" in `advance`: the order of every array (the cell sort), the summation density
//! (`free_surface`), the pressures and PPE roles (`pressure_solve`), the new velocity (`corrector`,
//! the bodies' particles' from `rigid_bodies`),
//! the walls' pressures on a frame (`wall_pressure`), the shifted velocity and pressure
//! (`shifting`, over its own displacement plus the `density_correction`'s), the positions
//! (`advection`; the bodies' particles' from their poses, `rigid_bodies`; then wrapped into a
//! periodic box). `Step` holds the
//! scene's constants and the stages' scratch: it is built again from the scene on resume and
//! never checkpointed.
//!
//! A new optional stage is its file here, its `mod` line, its field in `Step` (built in
//! `Step::new` from its scene settings), its call in `Step::advance` and its entry in
//! `Step::stages`; its settings are a section of the scene (`scene::Effects`).

mod advection;
mod body_forces;
mod body_surfaces;
mod cell_list;
mod corrector;
mod density_correction;
mod diagnostics;
mod eddy_viscosity;
mod free_surface;
mod hydrostatic_split;
mod interface_distance;
mod kernel_correction;
mod predictor;
mod pressure_solve;
mod rigid_bodies;
mod shifting;
mod surface_thickness;
pub mod time_step;
pub mod timings;
mod wall_pressure;

use crate::bodies::Bodies;
use crate::boundary::faces::Faces;
use crate::boundary::ghosts::{self, BodyForce};
use crate::boundary::moving_frame::MovingFrame;
use crate::math::kernel::Kernel;
use crate::math::memory::{ArraySize, Holds};
use crate::math::reduce::fill;
use crate::neighbours::cell_list::CellList;
use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};
use crate::scene::{Effects, GhostPressure};
use crate::solver::krylov::{SolveInfo, SolverError, SolverParams};
use crate::solver::ppe::{PressureOperator, Role};
use crate::sph::interface::Interfaces;
use crate::sph::Corrections;
use std::time::Instant;
use time_step::StepLength;
use timings::Timings;

/// The constants of a step that come from the scene.
#[derive(Clone, Copy, Debug)]
pub struct StepSettings<const D: usize> {
    pub gravity: [f64; D],
    /// How the wall ghosts' pressures continue the fluid's (`scene::GhostPressure`).
    pub ghost_pressure: GhostPressure,
    pub spacing: f64,
    /// Relaxation α of the density-invariance term of Eq. (6).
    pub alpha: f64,
    pub solver: SolverParams,
    /// The optional stages and their constants.
    pub effects: Effects,
    /// The fluid fills a closed or periodic container (`fill::fills_container`): it has no
    /// free surface, and none is looked for.
    pub confined: bool,
    /// ρ/ρ0 below which fluid is spray, for the scene's h/dx (`sph::free_surface::spray_density`).
    pub spray_density: f64,
    /// det M_i at or below which the kernel gradient correction is not applied, for the
    /// scene's h/dx (`sph::min_correction_determinant`).
    pub min_correction_determinant: f64,
    /// The CFL number of the time-step limit (`time_step`).
    pub cfl: f64,
    /// The largest kinematic viscosity of the scene's fluids [m²/s].
    pub max_viscosity: f64,
}

impl<const D: usize> StepSettings<D> {
    /// The body force the wall ghosts' pressures carry with hydrostatic ghosts (zero with
    /// mirror ghosts): `field` where the body force varies (`body_forces`), else gravity.
    pub fn ghost_force<'a>(&self, field: Option<&'a [Vec<f64>; D]>) -> BodyForce<'a, D> {
        match (self.ghost_pressure, field) {
            (GhostPressure::Mirror, _) => BodyForce::Uniform([0.0; D]),
            (GhostPressure::Hydrostatic, Some(f)) => BodyForce::Field(f),
            (GhostPressure::Hydrostatic, None) => BodyForce::Uniform(self.gravity),
        }
    }

    /// The body force the wall ghosts' pressures beside a particle whose body force is `f`
    /// carry (zero with mirror ghosts).
    pub fn ghost_force_of(&self, f: [f64; D]) -> BodyForce<'static, D> {
        match self.ghost_pressure {
            GhostPressure::Mirror => BodyForce::Uniform([0.0; D]),
            GhostPressure::Hydrostatic => BodyForce::Uniform(f),
        }
    }

    /// The body force the predictor adds: `field` where it varies, else gravity.
    pub fn body_force<'a>(&self, field: Option<&'a [Vec<f64>; D]>) -> BodyForce<'a, D> {
        field.map_or(BodyForce::Uniform(self.gravity), BodyForce::Field)
    }
}

/// What a step measured.
#[derive(Clone, Copy, Debug)]
pub struct StepReport {
    /// Δt and the limit it was cut from.
    pub length: StepLength,
    /// Whether the step landed on the target time it was asked to go towards.
    pub lands_on_target: bool,
    pub solve: SolveInfo,
    /// Density error, compression and disorder over the fluid particles with no free surface
    /// in reach.
    pub full_support: diagnostics::FullSupport,
    /// Fluid particles the advection put beyond a wall face, before the contact put them back.
    pub penetrations: usize,
    /// Largest fluid speed after the step.
    pub max_speed: f64,
    /// Kinetic energy of the fluid after the step.
    pub kinetic_energy: f64,
}

/// Why a step could not be taken.
#[derive(Debug)]
pub enum StepError {
    /// Particle `index` (in the particles' current order) is outside the cell grid.
    LeftDomain {
        index: usize,
    },
    /// The time step collapsed (`time_step::limiting`).
    Collapse {
        dt: f64,
        max_speed: f64,
    },
    Solver(SolverError),
    /// The velocity became non-finite in the step that ended at `time`.
    NonFinite {
        time: f64,
    },
}

/// A stage as `isph plan` and the timings see it.
pub trait Stage<const D: usize> {
    /// Its name in `isph plan`, the run summary and `isph bench`.
    fn name(&self) -> &'static str;
    /// What it computes, with the scene's constants.
    fn describe(&self, set: &StepSettings<D>) -> String;
    /// Its per-particle arrays, as they are now (allocated when it first runs).
    fn arrays(&self) -> Vec<ArraySize> {
        Vec::new()
    }
    /// Whether its arrays hold the fluid particles only (they come first in the sorted
    /// order), not every particle.
    fn fluid_only(&self) -> bool {
        true
    }
}

/// The stages of a step and their arrays: scratch, rebuilt from the particles each step.
pub struct Step<const D: usize> {
    pub settings: StepSettings<D>,
    kernel: Kernel<D>,
    faces: Faces,
    cell_list: cell_list::CellSort<D>,
    interface_distance: Option<interface_distance::InterfaceDistance<D>>,
    free_surface: free_surface::FreeSurface<D>,
    kernel_correction: Option<kernel_correction::KernelCorrection<D>>,
    eddy_viscosity: Option<eddy_viscosity::EddyViscosity>,
    body_forces: Option<body_forces::BodyForces<D>>,
    body_surfaces: Option<body_surfaces::BodySurfaces>,
    predictor: predictor::Predictor<D>,
    hydrostatic_split: Option<hydrostatic_split::HydrostaticSplit<D>>,
    pressure_solve: pressure_solve::PressureSolve<D>,
    corrector: corrector::Corrector<D>,
    rigid_bodies: Option<rigid_bodies::RigidBodies>,
    density_correction: Option<density_correction::DensityCorrection<D>>,
    wall_pressure: wall_pressure::WallPressure,
    surface_thickness: Option<surface_thickness::SurfaceThickness>,
    shifting: Option<shifting::Shifting<D>>,
    advection: advection::Advection,
    diagnostics: diagnostics::Diagnostics,
}

impl<const D: usize> Step<D> {
    /// The step of a scene with `settings`, on `grid`; `interfaces` is the kernel's table of
    /// distances to an interface where the fluids differ in rest density (None: one density);
    /// `bodies` whether the scene has rigid bodies, `body_interfaces` whether some differ in
    /// rest density from a fluid; `frame` the container's motion (None: at rest).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        settings: StepSettings<D>,
        kernel: Kernel<D>,
        faces: Faces,
        grid: CellList<D>,
        interfaces: Option<Interfaces>,
        bodies: bool,
        body_interfaces: bool,
        frame: Option<MovingFrame>,
    ) -> Self {
        let effects = &settings.effects;
        Self {
            kernel,
            faces,
            cell_list: cell_list::CellSort::new(grid),
            interface_distance: interfaces.map(interface_distance::InterfaceDistance::new),
            free_surface: free_surface::FreeSurface::new(effects),
            kernel_correction: effects
                .kernel_correction
                .then(kernel_correction::KernelCorrection::default),
            eddy_viscosity: effects.les.map(eddy_viscosity::EddyViscosity::new),
            body_forces: (bodies || frame.is_some()).then(|| body_forces::BodyForces::new(frame)),
            body_surfaces: bodies.then(body_surfaces::BodySurfaces::default),
            predictor: predictor::Predictor::new(&settings),
            hydrostatic_split: body_interfaces.then(hydrostatic_split::HydrostaticSplit::default),
            pressure_solve: pressure_solve::PressureSolve::new(settings.alpha > 0.0),
            corrector: corrector::Corrector::default(),
            rigid_bodies: bodies.then(rigid_bodies::RigidBodies::default),
            density_correction: (settings.alpha > 0.0)
                .then(density_correction::DensityCorrection::default),
            wall_pressure: wall_pressure::WallPressure,
            surface_thickness: (!settings.confined)
                .then(surface_thickness::SurfaceThickness::default),
            shifting: effects.shifting.map(shifting::Shifting::new),
            advection: advection::Advection,
            diagnostics: diagnostics::Diagnostics,
            settings,
        }
    }

    pub fn kernel(&self) -> Kernel<D> {
        self.kernel
    }

    pub fn grid(&self) -> &CellList<D> {
        self.cell_list.grid()
    }

    /// The stages that run, in the order `advance` runs them.
    pub fn stages(&self) -> Vec<&dyn Stage<D>> {
        let mut stages: Vec<&dyn Stage<D>> = vec![&self.cell_list];
        if let Some(s) = &self.interface_distance {
            stages.push(s);
        }
        stages.push(&self.free_surface);
        if let Some(s) = &self.kernel_correction {
            stages.push(s);
        }
        if let Some(s) = &self.eddy_viscosity {
            stages.push(s);
        }
        if let Some(s) = &self.body_forces {
            stages.push(s);
        }
        if let Some(s) = &self.body_surfaces {
            stages.push(s);
        }
        stages.push(&self.predictor);
        if let Some(s) = &self.hydrostatic_split {
            stages.push(s);
        }
        stages.extend([&self.pressure_solve as &dyn Stage<D>, &self.corrector]);
        if let Some(s) = &self.rigid_bodies {
            stages.push(s);
        }
        stages.push(&self.wall_pressure);
        if let Some(s) = &self.density_correction {
            stages.push(s);
        }
        if let Some(s) = &self.surface_thickness {
            stages.push(s);
        }
        if let Some(s) = &self.shifting {
            stages.push(s);
        }
        stages.extend([&self.advection as &dyn Stage<D>, &self.diagnostics]);
        stages
    }

    /// Every per-particle array of the stages with the name of the stage that holds it, as it
    /// is now. The cell list's hold every particle; every other stage's the fluid particles
    /// only (see the module doc).
    pub fn arrays(&self) -> Vec<(&'static str, ArraySize)> {
        let mut arrays = Vec::new();
        for stage in self.stages() {
            let fluid_only = stage.fluid_only();
            arrays.extend(stage.arrays().into_iter().map(|a| {
                let a = if fluid_only && a.holds == Holds::EveryParticle {
                    a.fluid()
                } else {
                    a
                };
                (stage.name(), a)
            }));
        }
        arrays
    }

    /// Sorts the particles by cell, then advances them by one step towards the simulated time
    /// `target` from `time` (`time_step::length`; `last_dt` the last step's Δt, none on a
    /// run's first). The step that lands on the target also
    /// computes the wall particles' pressure for the frame: in a large tank most wall
    /// particles are dry, and visiting them at every step costs a large part of a step
    /// (docs/performance.md, "Walls no fluid touches").
    /// `probe`, if any, is handed the PPE's operator before the solve (`isph bench` times its
    /// apply); the step goes on as without it. `bodies` are the rigid bodies the particles of
    /// kind `Body` belong to, advanced with them.
    #[allow(clippy::too_many_arguments)]
    pub fn advance(
        &mut self,
        p: &mut Particles<D>,
        bodies: &mut Bodies,
        time: f64,
        target: f64,
        last_dt: Option<f64>,
        timings: &mut Timings,
        probe: Option<&mut dyn FnMut(&PressureOperator<D>)>,
    ) -> Result<StepReport, StepError> {
        let mut laps = Laps::new(timings);
        self.cell_list.run(p)?;
        if self.rigid_bodies.is_some() {
            // Into the particles: the bodies' particles' mass and rest density for the step.
            bodies.set_solve_densities(p, time);
        }
        laps.lap(cell_list::NAME);
        let (limit, _) = time_step::limiting(p, self.kernel.width(), &self.settings)?;
        let (length, lands_on_target) = time_step::length(limit, target - time, last_dt);
        let set = &self.settings;
        let dt = length.dt;
        let fluid = self.grid().range_of(Kind::Fluid);
        debug_assert_eq!(fluid.start, 0, "the fluid comes first in the sorted order");
        let nf = fluid.end;
        let (solve, measured, shift) = {
            let nb = Neighbours::new(self.cell_list.grid(), &p.pos, self.kernel);
            // The time-step limit is in no stage (`isph bench`'s "other").
            laps.skip();
            if let Some(stage) = &mut self.interface_distance {
                stage.run(&nb, p, &self.faces, nf);
                laps.lap(interface_distance::NAME);
            }
            let interfaces = self.interface_distance.as_ref().map(|s| s.field());
            let driven = |b: usize| bodies.bodies[b].is_driven(time);
            self.free_surface
                .run(&nb, p, set, interfaces.is_some(), driven, nf);
            // Into the particles: ρ.
            p.density[..nf].copy_from_slice(self.free_surface.density());
            laps.lap(free_surface::NAME);
            let full_support = self.free_surface.full_support();
            let corrections = match &mut self.kernel_correction {
                Some(stage) => {
                    let c = stage.run(&nb, p, full_support, set.min_correction_determinant);
                    laps.lap(kernel_correction::NAME);
                    c
                }
                None => Corrections::sparse(false, &[], &[]),
            };
            let eddy = self.eddy_viscosity.as_mut().map(|stage| {
                let strain_rates = self
                    .free_surface
                    .strain_rates()
                    .expect("with LES the free surface's walk finds the strain rates");
                let eddy = stage.run(&nb, p, strain_rates, corrections, set.spacing);
                laps.lap(eddy_viscosity::NAME);
                eddy
            });
            let loads = match &self.body_forces {
                Some(stage) => stage.resting_loads(p, bodies, set, time, dt, nf),
                None => Vec::new(),
            };
            if let Some(stage) = &mut self.body_forces {
                let surface = self.free_surface.output();
                stage.run(&nb, p, bodies, set, &surface, interfaces, time, dt, nf);
                laps.lap(body_forces::NAME);
            }
            let body_surfaces = self.body_surfaces.as_mut().map(|stage| {
                stage.run(&nb, p, bodies, set.spacing, nf);
                laps.lap(body_surfaces::NAME);
                stage.distances()
            });
            let force = self.body_forces.as_ref().map(|stage| stage.force());
            let ghost = self.body_forces.as_ref().map(|stage| stage.ghost());
            let u_star = self.predictor.run(
                &nb,
                p,
                set,
                eddy,
                set.body_force(force),
                body_surfaces,
                full_support,
                dt,
                nf,
            );
            laps.lap(predictor::NAME);
            if let (Some(stage), Some(field), Some(force)) =
                (&mut self.hydrostatic_split, interfaces, force)
            {
                let surface = self.free_surface.output();
                stage.run(&nb, p, &surface, field, force, nf);
                stage.apply(u_star, dt);
                laps.lap(hydrostatic_split::NAME);
            }
            let surface = &mut self.free_surface;
            let solve = self
                .pressure_solve
                .run(
                    &nb,
                    p,
                    set,
                    surface,
                    corrections,
                    interfaces,
                    ghost,
                    set.body_force(force),
                    u_star,
                    length,
                    probe,
                )
                .map_err(StepError::Solver)?;
            let surface = self.free_surface.output();
            let clip = surface.reference.is_none();
            let solved = self.pressure_solve.pressure();
            // Into the particles: P (without tension where the fluid has a free surface), roles.
            fill(&mut p.pressure[..nf], |i| {
                cavitation(clip, surface.roles[i], solved[i])
            });
            fill(&mut p.free_surface[..nf], |i| surface.roles[i].code());
            laps.lap(pressure_solve::NAME);
            let density = self.density_correction.as_mut().map(|stage| {
                let density_pressure = self.pressure_solve.density_pressure();
                (density_pressure, stage.gradient_slot())
            });
            self.corrector.run(
                &nb,
                p,
                set,
                &self.faces,
                &surface,
                interfaces,
                ghost,
                u_star,
                density,
                dt,
            );
            let grad_p = &*u_star;
            laps.lap(corrector::NAME);
            let velocity = self.corrector.velocity_scratch();
            if let (Some(stage), Some(force)) = (&mut self.rigid_bodies, force) {
                stage.run(
                    &nb,
                    p,
                    bodies,
                    force,
                    &loads,
                    grad_p,
                    surface.roles,
                    set.spacing,
                    velocity,
                    time,
                    dt,
                );
                laps.lap(rigid_bodies::NAME);
            }
            // Into the particles: uⁿ⁺¹ (the bodies' rigid).
            copy_vector(velocity, &mut p.vel);
            let measured = diagnostics::full_support_statistics(
                p,
                surface.full_support,
                self.free_surface.nearest(),
            );
            laps.part(diagnostics::NAME);
            if lands_on_target {
                let ghosts = ghosts::Ghosts {
                    rest_density: &p.rest_density,
                    normal: &p.normal,
                    force: set.ghost_force(ghost),
                };
                // Into the particles: the walls' P, for the frame.
                self.wall_pressure.run(&nb, &ghosts, &mut p.pressure, nf);
                laps.lap(wall_pressure::NAME);
            }
            let density_shift = match &mut self.density_correction {
                Some(stage) => {
                    let shift = stage.run(p, set, &self.faces, &surface, dt);
                    laps.lap(density_correction::NAME);
                    Some(&*shift)
                }
                None => None,
            };
            if let Some(stage) = &self.surface_thickness {
                // τ for the next step's surface rows, updated in the particles' own array.
                let mut thickness = std::mem::take(&mut p.surface_thickness);
                stage.run(
                    &nb,
                    p,
                    &surface,
                    set.body_force(force),
                    dt,
                    &mut thickness[..nf],
                );
                p.surface_thickness = thickness;
                laps.lap(surface_thickness::NAME);
            }
            let shift = match &mut self.shifting {
                Some(stage) => {
                    let velocity = self.corrector.velocity_scratch();
                    let shift = stage.run(
                        &nb,
                        p,
                        set,
                        &self.faces,
                        &surface,
                        corrections,
                        velocity,
                        density_shift,
                        dt,
                    );
                    // Into the particles: u and P at the shifted positions.
                    copy_vector(velocity, &mut p.vel);
                    shifting::carry_pressure(
                        &mut p.pressure[..nf],
                        grad_p,
                        shift,
                        clip,
                        surface.roles,
                    );
                    laps.lap(shifting::NAME);
                    Some(shift)
                }
                None => density_shift,
            };
            (solve, measured, shift)
        };
        // Into the particles: r (and u where the contact puts a particle back).
        let penetrations = self
            .advection
            .run(p, nf, dt, shift, &self.faces, set.spacing);
        let penetrations = penetrations
            + match &self.rigid_bodies {
                // Into the particles: the bodies' particles' r, from their poses, and the
                // fluid's put back off the bodies.
                Some(stage) => stage.place(p, bodies, nf, set.spacing),
                None => 0,
            };
        laps.lap(advection::NAME);
        // Along a periodic axis a particle leaves the period only in the advection: wrapped
        // back here, the frames and checkpoints hold every position inside the box.
        self.cell_list.grid().wrap(&mut p.pos);
        laps.skip();
        let (max_speed, kinetic_energy) = diagnostics::motion(p);
        laps.lap(diagnostics::NAME);
        if !max_speed.is_finite() {
            let time = if lands_on_target { target } else { time + dt };
            return Err(StepError::NonFinite { time });
        }
        Ok(StepReport {
            length,
            lands_on_target,
            solve,
            full_support: measured,
            penetrations,
            max_speed,
            kinetic_energy,
        })
    }
}

/// Times the stages of one step: each `lap` charges the time since the last to a stage and
/// counts a run of it; `part` charges it without counting a run (a stage done in two places).
struct Laps<'a> {
    timings: &'a mut Timings,
    clock: Instant,
}

impl<'a> Laps<'a> {
    fn new(timings: &'a mut Timings) -> Self {
        Self {
            timings,
            clock: Instant::now(),
        }
    }

    fn lap(&mut self, stage: &'static str) {
        let now = Instant::now();
        self.timings.add(stage, now - self.clock);
        self.clock = now;
    }

    /// Starts the next lap here: the time since the last is charged to no stage.
    fn skip(&mut self) {
        self.clock = Instant::now();
    }

    fn part(&mut self, stage: &'static str) {
        let now = Instant::now();
        self.timings.add_part(stage, now - self.clock);
        self.clock = now;
    }
}

/// The pressure a particle of `role` takes: with a free surface the pressure is absolute (zero
/// at the surface) and the water cannot hold a tension, so negative pressures are cut to zero; in
/// a closed box (`clip` false) only differences count and P is kept as solved. A held body's
/// ghost (`Role::Ghost`) is not water: it continues the water's pressure into the body, negative
/// above the waterline, and keeps it. Clipped there, the ghosts beside the water's surface held
/// more than the water's pressure continued, and pushed the water at the contact line off the
/// body every step: a box held through the surface of still water stirred it to 0.12 m/s within
/// 1 s and ever more after (docs/bodies.md, "Fixed and prescribed bodies").
#[inline]
fn cavitation(clip: bool, role: Role, pressure: f64) -> f64 {
    if clip && role != Role::Ghost {
        pressure.max(0.0)
    } else {
        pressure
    }
}

/// `to[d][..n] = from[d]` for each component, n the length of `from`.
fn copy_vector<const D: usize>(from: &[Vec<f64>; D], to: &mut [Vec<f64>; D]) {
    for (f, t) in from.iter().zip(to) {
        t[..f.len()].copy_from_slice(f);
    }
}
