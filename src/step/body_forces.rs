//! The body force per unit mass f_i on each fluid and body particle where it is not gravity
//! alone (`ghosts::BodyForce`): in a moving container the frame's (`moving_frame`); on a free
//! body's particles that plus the body's external force over its mass, so the pressure solve
//! sees the body accelerate and its added mass is implicit; on a fixed or prescribed body's
//! particles the acceleration that takes each to its rigid velocity at the end of the step,
//! plus the pressure acceleration the last step's pressure gave it, ∇Pⁿ/ρ0: the corrector
//! takes the new one off, so the solve leaves the body at its rigid velocity up to the change
//! of ∇P over a step, and the fluid around it sees a body that is held, not one that yields
//! to the pressure and is put back each step (which stirs still water around a fixed body).
//! The predictor adds f_i (Eq. 5), the wall ghosts carry it, and `rigid_bodies` takes its sums
//! over each body out of the fluid's force.
//! Runs only in a scene with bodies or a moving container.

use super::corrector::pressure_gradient;
use super::free_surface::Surface;
use super::{Stage, StepSettings};
use crate::bodies::{rigid_velocity, Bodies};
use crate::boundary::moving_frame::MovingFrame;
use crate::math::memory::ArraySize;
use crate::math::reduce::fill_vector;
use crate::neighbours::Neighbours;
use crate::particles::{components, Kind, Particles};
use crate::sph::interface;

pub const NAME: &str = "body forces";

pub struct BodyForces<const D: usize> {
    frame: Option<MovingFrame>,
    force: [Vec<f64>; D],
}

impl<const D: usize> BodyForces<D> {
    /// The stage of a scene whose container moves on `frame` (None: at rest).
    pub fn new(frame: Option<MovingFrame>) -> Self {
        Self {
            frame,
            force: components(),
        }
    }

    /// f_i of the `nf` fluid and body particles over the step of `dt` from `time`; the last
    /// step's pressure gradient at a held body's particles is taken with `surface`'s roles and
    /// corrections across `interfaces`.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        bodies: &Bodies,
        set: &StepSettings<D>,
        surface: &Surface<D>,
        interfaces: Option<interface::Field<D>>,
        time: f64,
        dt: f64,
        nf: usize,
    ) -> &[Vec<f64>; D] {
        for a in &mut self.force {
            a.resize(nf, 0.0);
        }
        let frame = self.frame.as_ref().map(|f| f.at(time));
        let ghosts = set.ghost_force(None);
        let ambient = |i: usize| match &frame {
            Some(frame) => frame.at(p.position(i), p.velocity(i)),
            None => set.gravity,
        };
        let targets: Vec<_> = bodies
            .bodies
            .iter()
            .map(|b| b.target(time, dt).map(|t| (t, t.orientation.matrix())))
            .collect();
        let pushes: Vec<[f64; D]> = bodies
            .bodies
            .iter()
            .map(|b| std::array::from_fn(|d| b.external_force[d] / b.mass))
            .collect();
        fill_vector(&mut self.force, |i| {
            if p.kind[i] != Kind::Body {
                return ambient(i);
            }
            let b = p.fluid[i] as usize;
            match &targets[b] {
                Some((target, rotation)) => {
                    let arm = bodies.bodies[b].arm(rotation, p.id[i]);
                    let u = rigid_velocity(target.velocity, target.angular_velocity, arm);
                    let grad =
                        pressure_gradient(nb, p, &p.pressure, surface, ghosts, interfaces, i);
                    let rho0 = p.rest_density[i];
                    std::array::from_fn(|d| (u[d] - p.vel[d][i]) / dt + grad[d] / rho0)
                }
                None => {
                    let f = ambient(i);
                    std::array::from_fn(|d| f[d] + pushes[b][d])
                }
            }
        });
        &self.force
    }
}

impl<const D: usize> Stage<D> for BodyForces<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        let frame = if self.frame.is_some() {
            "the moving container's frame: Rᵀ(g − Ẍ) − α × r − Ω × (Ω × r) − 2 Ω × u"
        } else {
            "gravity"
        };
        format!("f on each particle for the predictor and the wall ghosts: {frame}; on a free body's particles plus its external force over its mass; on a fixed or prescribed body's the acceleration to its rigid velocity at the step's end plus the last step's ∇P/ρ0")
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![ArraySize::of_components("body force", &self.force)]
    }
}
