//! The state of a run and its time stepping: the particles, the simulated time and the step
//! count (what a checkpoint holds), advanced by the stages of `step`.

use crate::bodies::Bodies;
use crate::boundary::faces::Faces;
use crate::boundary::moving_frame::MovingFrame;
use crate::fill;
use crate::io::stats::StepStats;
use crate::math::kernel::Kernel;
use crate::math::memory::ArraySize;
use crate::neighbours::cell_list::CellList;
use crate::particles::Particles;
use crate::scene::{Aabb, Probe, ProbeField, Scene};
use crate::solver::krylov::{SolverError, SolverParams};
use crate::solver::ppe::PressureOperator;
use crate::sph;
use crate::sph::free_surface;
use crate::sph::interface::Interfaces;
use crate::sph::probe;
use crate::step::time_step::{self, Limit};
use crate::step::timings::Timings;
use crate::step::{Step, StepError, StepSettings};

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
#[error("{path}: the scene holds no fluid particle: every [[fluid_block]] is thinner than the spacing or lies inside obstacles and bodies")]
pub struct NoFluid {
    pub path: std::path::PathBuf,
}

pub struct Simulation<const D: usize> {
    /// The lasting state: what a checkpoint holds, with `time` and `step`.
    pub particles: Particles<D>,
    /// The rigid bodies' state (empty: none), advanced with the particles.
    pub bodies: Bodies,
    pub time: f64,
    pub step: u64,
    /// Δt of the last step (none before the first): a sliver of a step takes the divergence
    /// the particles carry into it out over it (`StepLength::carried_time`).
    pub last_dt: Option<f64>,
    /// The stages of a step and their scratch.
    stepper: Step<D>,
    /// Time spent in each stage so far.
    pub timings: Timings,
    /// The length of the box along each periodic axis (probes read across it).
    periods: [Option<f64>; D],
}

impl<const D: usize> Simulation<D> {
    pub fn new(scene: &Scene) -> Result<Self, NoFluid> {
        assert_eq!(
            scene.dimensions, D,
            "scene dimension and solver dimension differ"
        );
        let mut particles = fill::build::<D>(scene);
        if particles.fluid_count() == 0 {
            return Err(NoFluid {
                path: scene.path.clone(),
            });
        }
        let confined = fill::fills_container(scene, &particles);
        let bodies = Bodies::new(scene, &particles);
        bodies.set_particle_velocities(&mut particles);
        // Bounded axes: room for the wall layers and a spacing more; a periodic axis is one
        // period, the container's extent.
        let periodic: [bool; D] = std::array::from_fn(|d| scene.periodic[d]);
        let walls = (scene.wall_layers() as f64 + 1.0) * scene.spacing;
        let margin = |d: usize| if periodic[d] { 0.0 } else { walls };
        let lo = std::array::from_fn(|d| scene.container.min[d] - margin(d));
        let hi = std::array::from_fn(|d| scene.container.max[d] + margin(d));
        let settings = StepSettings {
            gravity: std::array::from_fn(|d| scene.gravity[d]),
            ghost_pressure: scene.walls.ghost_pressure,
            spacing: scene.spacing,
            alpha: scene.solver.alpha,
            solver: SolverParams {
                tolerance: scene.solver.tolerance,
                max_iterations: scene.solver.max_iterations,
            },
            effects: scene.effects,
            confined,
            spray_density: free_surface::spray_density::<D>(
                scene.solver.kernel,
                scene.solver.h_over_dx,
            ),
            min_correction_determinant: sph::min_correction_determinant::<D>(
                scene.solver.kernel,
                scene.solver.h_over_dx,
            ),
            cfl: scene.solver.cfl,
            max_viscosity: scene.fluids.iter().map(|f| f.viscosity).fold(0.0, f64::max),
        };
        let kernel = Kernel::new(scene.solver.kernel, scene.spacing, scene.solver.h_over_dx);
        let interfaces = scene
            .has_interfaces()
            .then(|| Interfaces::new(&kernel, scene.spacing));
        let stepper = Step::new(
            settings,
            kernel,
            Faces::new(&scene.container, &scene.periodic, &scene.obstacles),
            CellList::new(lo, hi, kernel.support(), periodic),
            interfaces,
            !bodies.is_empty(),
            scene.bodies_differ_in_density(),
            scene
                .container_motion
                .clone()
                .map(|trajectory| MovingFrame {
                    trajectory,
                    gravity: std::array::from_fn(|d| scene.gravity.get(d).copied().unwrap_or(0.0)),
                }),
        );
        let timings = Timings::new(stepper.stages().iter().map(|s| s.name()));
        let c = &scene.container;
        Ok(Self {
            particles,
            bodies,
            time: 0.0,
            step: 0,
            last_dt: None,
            stepper,
            timings,
            periods: std::array::from_fn(|d| periodic[d].then(|| c.max[d] - c.min[d])),
        })
    }

    pub fn kernel(&self) -> Kernel<D> {
        self.stepper.kernel()
    }

    /// The stages of a step and their scratch.
    pub fn stepper(&self) -> &Step<D> {
        &self.stepper
    }

    /// Largest stable Δt of the particles as they are, and the condition that sets it
    /// (`time_step::limiting`).
    pub fn time_step_limit(&self) -> Result<(f64, Limit), NumericalFailure> {
        time_step::limiting(
            &self.particles,
            self.kernel().width(),
            &self.stepper.settings,
        )
        .map_err(|e| self.failure(e))
    }

    /// Advances by one step towards the simulated time `target` (the next frame's), landing on
    /// it exactly when it is within reach (`Step::advance`).
    pub fn advance_towards(&mut self, target: f64) -> Result<StepStats, NumericalFailure> {
        self.advance(target, None)
    }

    /// `advance_towards`, handing `probe` the PPE operator of the step before its solve: the
    /// operator the step's own stages build (`isph bench` times its apply).
    pub fn advance_probing<R>(
        &mut self,
        target: f64,
        probe: impl FnOnce(&PressureOperator<D>) -> R,
    ) -> Result<(StepStats, R), NumericalFailure> {
        let mut probe = Some(probe);
        let mut probed = None;
        let mut hook = |op: &PressureOperator<D>| {
            if let Some(probe) = probe.take() {
                probed = Some(probe(op));
            }
        };
        let stats = self.advance(target, Some(&mut hook))?;
        Ok((stats, probed.expect("every step solves the PPE")))
    }

    fn advance(
        &mut self,
        target: f64,
        probe: Option<&mut dyn FnMut(&PressureOperator<D>)>,
    ) -> Result<StepStats, NumericalFailure> {
        let report = self.stepper.advance(
            &mut self.particles,
            &mut self.bodies,
            self.time,
            target,
            self.last_dt,
            &mut self.timings,
            probe,
        );
        let report = report.map_err(|e| self.failure(e))?;
        self.time = if report.lands_on_target {
            target
        } else {
            self.time + report.length.dt
        };
        self.step += 1;
        self.last_dt = Some(report.length.dt);
        Ok(StepStats {
            step: self.step,
            time: self.time,
            dt: report.length.dt,
            ppe_iterations: report.solve.iterations,
            ppe_residual: report.solve.relative_residual,
            max_speed: report.max_speed,
            kinetic_energy: report.kinetic_energy,
            density_error: report.full_support.density_error,
            penetrations: report.penetrations,
            disorder: report.full_support.disorder,
            compression: report.full_support.compression,
        })
    }

    /// The failure of a step, at this step and time.
    fn failure(&self, e: StepError) -> NumericalFailure {
        let (step, time) = (self.step, self.time);
        match e {
            StepError::LeftDomain { index } => NumericalFailure::LeftDomain {
                id: self.particles.id[index],
                step,
                time,
                position: self.particles.position(index).to_vec(),
            },
            StepError::Collapse { dt, max_speed } => NumericalFailure::TimeStepCollapse {
                step,
                time,
                dt,
                max_speed,
            },
            StepError::Solver(source) => NumericalFailure::Solver { step, time, source },
            StepError::NonFinite { time } => NumericalFailure::NonFinite {
                step: step + 1,
                time,
            },
        }
    }

    /// Where the particles stand at `time`, what a frame, a probe and a surface built during a
    /// run read. The advection moves the fluid over the whole step with the step's velocity,
    /// rⁿ⁺¹ = rⁿ + Δt uⁿ⁺¹ + δr (Eq. 8), while uⁿ⁺¹ is the velocity of the step's end time (in
    /// free fall from rest uⁿ = g tⁿ exactly) and the projection made it divergence-free at the
    /// midpoint of that drift (`ppe::divergence_source`): the positions lead the velocities by
    /// half a drift (in free fall at a constant step rⁿ = g tⁿ²/2 + (Δt/2) uⁿ), and the fluid
    /// stands at rⁿ⁺¹ − (Δt/2) uⁿ⁺¹, the midpoint of the last drift (docs/accuracy.md, "Where a
    /// frame's particles stand"). The walls stand where the container is, and a body's
    /// particles where its pose puts them, whose centre drifts by the trapezoid, exact in free
    /// fall. Before the first step the particles stand where they are. The checkpoint keeps
    /// the advection's positions, from which the next step starts.
    pub fn present_positions(&self) -> [Vec<f64>; D] {
        let p = &self.particles;
        let half_drift = 0.5 * self.last_dt.unwrap_or(0.0);
        let mut pos: [Vec<f64>; D] = std::array::from_fn(|d| {
            (0..p.len())
                .map(|i| {
                    let back = if p.is_fluid(i) {
                        half_drift * p.vel[d][i]
                    } else {
                        0.0
                    };
                    p.pos[d][i] - back
                })
                .collect()
        });
        self.stepper.grid().wrap(&mut pos);
        pos
    }

    /// The values of `probes` where the particles stand at `time` (`present_positions`), in the
    /// order of their columns in `probes.csv` (`Probe::columns`): the Shepard interpolation of
    /// the fluid, or a gauge's surface height on its vertical line across `container`
    /// (`sph::probe`; NaN where no water is under it).
    pub fn probe_values(&self, probes: &[Probe], container: &Aabb) -> Vec<f64> {
        let pos = self.present_positions();
        let kernel = self.kernel();
        let spacing = self.stepper.settings.spacing;
        let periods = &self.periods;
        let sample = |point| {
            let full = probe::full_fraction(&kernel, spacing, container, periods, point);
            let wet = probe::SURFACE_FRACTION * full;
            probe::sample(&self.particles, &pos, &kernel, periods, point, wet)
        };
        let gauge = |point| {
            let p = &self.particles;
            probe::surface_height(p, &pos, &kernel, periods, point, container, spacing)
                .unwrap_or(f64::NAN)
        };
        let mut values = Vec::new();
        for p in probes {
            let point: [f64; D] = std::array::from_fn(|d| p.point[d]);
            match p.field {
                ProbeField::Pressure => values.push(sample(point).pressure),
                ProbeField::Velocity => values.extend(sample(point).velocity),
                ProbeField::Elevation => values.push(gauge(point)),
            }
        }
        values
    }

    /// Every per-particle array of the step with the stage that holds it, as it is now
    /// (`Step::arrays`). The particles' own arrays are `Particles::arrays_mut`.
    pub fn arrays(&self) -> Vec<(&'static str, ArraySize)> {
        self.stepper.arrays()
    }
}
