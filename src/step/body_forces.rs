//! The body force per unit mass f_i on each fluid and body particle where it is not gravity
//! alone (`ghosts::BodyForce`): in a moving container the frame's (`moving_frame`); on a free
//! body's particles that plus the body's external force over its mass, so the pressure solve
//! sees the body accelerate and its added mass is implicit, and the rigid part of the last
//! step's pressure acceleration less their own, so that the solve starts from a body that moves
//! as one (`rigidise_free_bodies`); on a fixed or prescribed body's particles the acceleration
//! that takes each to its rigid velocity at the end of the step (the solve sees them as the
//! ghosts of a wall moving so: `ppe::Role::Ghost`). A body resting on its supports
//! (`bodies::contact`) is fluid in the solve, and its particles take that acceleration plus
//! the pressure acceleration the last step's pressure gave them, ∇Pⁿ/ρ0: the corrector takes
//! the new one off, so the solve leaves the body at rest up to the change of ∇P over a step,
//! and the fluid around it sees a body that is held, not one that yields to the pressure and
//! is put back each step (which stirs still water around it). The body forces on its own
//! masses, which its supports must hold with the fluid's force, are summed apart
//! (`resting_loads`).
//! The predictor adds f_i (Eq. 5), the wall ghosts carry it (beside a body's particles the
//! water's weight instead, `ghost`), and `rigid_bodies` takes its sums over each body out of the
//! fluid's force.
//! Runs only in a scene with bodies or a moving container.

use super::corrector::pressure_gradient;
use super::free_surface::Surface;
use super::hydrostatic_split::surface_excess;
use super::{Stage, StepSettings};
use crate::bodies::{rigid_velocity, Bodies};
use crate::boundary::moving_frame::{FrameForce, MovingFrame};
use crate::math::memory::ArraySize;
use crate::math::reduce::fill_vector;
use crate::math::rotation::{apply, cross, inverse_on_span, to_3d, to_world, Mat3, Vec3};
use crate::neighbours::Neighbours;
use crate::particles::{components, Kind, Particles};
use crate::sph::interface;
use rayon::prelude::*;

pub const NAME: &str = "body forces";

pub struct BodyForces<const D: usize> {
    frame: Option<MovingFrame>,
    force: [Vec<f64>; D],
    /// The wall ghosts' body force in a scene with bodies (`ghost`), else empty.
    ghost: [Vec<f64>; D],
}

impl<const D: usize> BodyForces<D> {
    /// The stage of a scene whose container moves on `frame` (None: at rest).
    pub fn new(frame: Option<MovingFrame>) -> Self {
        Self {
            frame,
            force: components(),
            ghost: components(),
        }
    }

    /// f_i of the `nf` fluid and body particles over the step of `dt` from `time` (`force`), and
    /// the body force their wall ghosts carry (`ghost`); the last step's pressure gradient at a
    /// resting or free body's particles is taken with `surface`'s roles and corrections across
    /// `interfaces`.
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
    ) {
        for a in &mut self.force {
            a.resize(nf, 0.0);
        }
        let frame = self.frame.as_ref().map(|f| f.over(time, dt));
        let ambient = |i: usize| ambient(frame.as_ref(), set, p, i);
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
                    let hold: [f64; D] = std::array::from_fn(|d| (u[d] - p.vel[d][i]) / dt);
                    if bodies.bodies[b].is_driven(time) {
                        return hold;
                    }
                    let ghosts = set.ghost_force_of(ambient(i));
                    let grad =
                        pressure_gradient(nb, p, &p.pressure, surface, ghosts, interfaces, i);
                    let rho0 = p.rest_density[i];
                    std::array::from_fn(|d| hold[d] + grad[d] / rho0)
                }
                None => {
                    let f = ambient(i);
                    std::array::from_fn(|d| f[d] + pushes[b][d])
                }
            }
        });
        if bodies.is_empty() {
            return;
        }
        self.rigidise_free_bodies(nb, p, bodies, set, surface, interfaces, time, &ambient, nf);
        for a in &mut self.ghost {
            a.resize(nf, 0.0);
        }
        let (force, water) = (&self.force, bodies.water_density());
        fill_vector(&mut self.ghost, |i| {
            if p.kind[i] == Kind::Body {
                let f = ambient(i);
                std::array::from_fn(|d| f[d] * water / p.rest_density[i])
            } else {
                std::array::from_fn(|d| force[d][i])
            }
        });
    }

    /// Adds to each free body's particles the rigid part of the pressure acceleration the last
    /// step's pressure gives them less their own, A + α × r_ic − a_i, with
    /// a_i = −(∇Pⁿ_i + E_i)/ρ0_i (E_i the hydrostatic split's part, `hydrostatic_split`), and A
    /// and α the body's linear and angular acceleration under the forces m_i a_i:
    /// M A = Σ m_i a_i, I α = Σ r_ic × m_i a_i. The sum of the added forces and of their
    /// moments is zero: the body's motion is that of the same solve. But the solve starts from
    /// a body whose particles the last pressure moves together, as one body, and the pressure
    /// that changes over the step is what moves them apart. Without it each particle of a
    /// floating body yields to the pressure as fluid of the body's density would: at rest at its
    /// draft the wet part of a box at half the water's density rises at |g| Δt in the solve and
    /// its dry part falls as fast, the water under its keel follows the keel up, and the
    /// body is put back to its rigid motion after the solve while the water keeps that kick
    /// (docs/bodies.md, "The coupling").
    #[allow(clippy::too_many_arguments)]
    fn rigidise_free_bodies(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        bodies: &Bodies,
        set: &StepSettings<D>,
        surface: &Surface<D>,
        interfaces: Option<interface::Field<D>>,
        time: f64,
        ambient: &(impl Fn(usize) -> [f64; D] + Sync),
        nf: usize,
    ) {
        let free = |i: usize| !bodies.bodies[p.fluid[i] as usize].is_held(time);
        let members: Vec<usize> = (0..nf)
            .filter(|&i| p.kind[i] == Kind::Body && free(i))
            .collect();
        if members.is_empty() {
            return;
        }
        let own = pressure_accelerations(
            nb,
            p,
            set,
            surface,
            interfaces,
            &self.force,
            ambient,
            &members,
        );
        let rotations: Vec<Mat3> = bodies.bodies.iter().map(|b| b.rotation()).collect();
        let arm = |i: usize| {
            let b = p.fluid[i] as usize;
            bodies.bodies[b].arm(&rotations[b], p.id[i])
        };
        let rigid = rigid_accelerations(p, bodies, &rotations, &members, &own, arm);
        for (&i, a) in members.iter().zip(&own) {
            let (linear, angular) = rigid[p.fluid[i] as usize];
            let turn = cross(angular, arm(i));
            for d in 0..D {
                self.force[d][i] += linear[d] + turn[d] - a[d];
            }
        }
    }

    /// f_i of the last `run`: what the predictor adds.
    pub fn force(&self) -> &[Vec<f64>; D] {
        &self.force
    }

    /// The body force the wall ghosts' pressures carry beside each particle of the last `run`
    /// (`ghosts`): f_i, but beside a body's particle the water's weight, ρ_w/ρ0_i times the
    /// body force of the water it stands for (gravity, or the frame's), not its own weight, its
    /// external force nor the force that holds it. The walls then hold up through the pressure
    /// solve what they hold of the water, and a body's weight in the water and its external
    /// force reach a wall through its contact points, whose normal impulses bound its friction.
    /// With its own weight in the ghosts, the solve carried most of a free body's weight to the
    /// floor and its contact little, and a box set sliding along a floor at μ = 0.3 slid on past
    /// where Coulomb friction stops it; with a held body's holding force there (the last step's
    /// ∇P/ρ0 and no gravity), the pressure at the floor under it only kept its last gradient,
    /// and a disc resting on the floor under a surge felt its buoyancy turned into a downward
    /// pull (docs/bodies.md, "Contact").
    pub fn ghost(&self) -> &[Vec<f64>; D] {
        if self.ghost[0].is_empty() {
            &self.force
        } else {
            &self.ghost
        }
    }

    /// The body forces of the step from `time` to `time + dt` on each resting body's particles
    /// at their own masses m_i, as on a free body's (gravity and its external force, in a moving
    /// container the frame's): Σ m_i f_i and Σ r_ic × m_i f_i, what its supports hold against
    /// with the fluid's force (`Bodies::advance`); zeros for a body that does not rest. Sums
    /// over the `nf` fluid and body particles in index order.
    pub fn resting_loads(
        &self,
        p: &Particles<D>,
        bodies: &Bodies,
        set: &StepSettings<D>,
        time: f64,
        dt: f64,
        nf: usize,
    ) -> Vec<[Vec3; 2]> {
        let mut loads = vec![[[0.0; 3]; 2]; bodies.bodies.len()];
        if bodies.bodies.iter().all(|b| !b.state.resting) {
            return loads;
        }
        let frame = self.frame.as_ref().map(|f| f.over(time, dt));
        for i in (0..nf).filter(|&i| p.kind[i] == Kind::Body) {
            let b = p.fluid[i] as usize;
            let body = &bodies.bodies[b];
            if !body.state.resting {
                continue;
            }
            let f = ambient(frame.as_ref(), set, p, i);
            let mf: Vec3 =
                to_3d::<D>(|d| body.particle_mass * (f[d] + body.external_force[d] / body.mass));
            let arm: Vec3 = to_3d::<D>(|d| p.pos[d][i] - body.state.centre[d]);
            let torque = cross(arm, mf);
            for d in 0..3 {
                loads[b][0][d] += mf[d];
                loads[b][1][d] += torque[d];
            }
        }
        loads
    }
}

/// The body force on particle i where it is not a held body's: gravity, or in a moving
/// container the frame's at its position and velocity.
fn ambient<const D: usize>(
    frame: Option<&FrameForce>,
    set: &StepSettings<D>,
    p: &Particles<D>,
    i: usize,
) -> [f64; D] {
    match frame {
        Some(frame) => frame.at(p.position(i), p.velocity(i)),
        None => set.gravity,
    }
}

/// a_i = −(∇Pⁿ_i + E_i)/ρ0_i of the body particles `members`: the acceleration the last
/// step's pressure gives each, with the hydrostatic split's part E_i where the scene has
/// `interfaces` (`hydrostatic_split`; `force` the fluid particles' body force).
#[allow(clippy::too_many_arguments)]
fn pressure_accelerations<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    set: &StepSettings<D>,
    surface: &Surface<D>,
    interfaces: Option<interface::Field<D>>,
    force: &[Vec<f64>; D],
    ambient: &(impl Fn(usize) -> [f64; D] + Sync),
    members: &[usize],
) -> Vec<[f64; D]> {
    let body: Vec<f64> = match interfaces {
        Some(_) => (0..force[0].len())
            .map(|i| f64::from(p.kind[i] == Kind::Body))
            .collect(),
        None => Vec::new(),
    };
    members
        .par_iter()
        .map(|&i| {
            let ghosts = set.ghost_force_of(ambient(i));
            let mut grad = pressure_gradient(nb, p, &p.pressure, surface, ghosts, interfaces, i);
            if let Some(field) = interfaces {
                let e = surface_excess(nb, p, surface, field, &body, force, i);
                for d in 0..D {
                    grad[d] += e[d];
                }
            }
            grad.map(|g| -g / p.rest_density[i])
        })
        .collect()
}

/// Each body's (A, α) under the forces m_i a_i on its particles `members` (`accelerations`,
/// in the same order), with `arm` a particle's offset from its body's centre of mass:
/// M A = Σ m_i a_i, I α = Σ r_ic × m_i a_i, I the inertia turned by `rotations`. Summed in
/// index order on one thread: the same bits whatever the thread count.
fn rigid_accelerations<const D: usize>(
    p: &Particles<D>,
    bodies: &Bodies,
    rotations: &[Mat3],
    members: &[usize],
    accelerations: &[[f64; D]],
    arm: impl Fn(usize) -> Vec3,
) -> Vec<(Vec3, Vec3)> {
    let count = bodies.bodies.len();
    let (mut sum, mut moment) = (vec![[0.0; 3]; count], vec![[0.0; 3]; count]);
    for (&i, a) in members.iter().zip(accelerations) {
        let b = p.fluid[i] as usize;
        let ma: Vec3 = to_3d::<D>(|d| p.mass[i] * a[d]);
        let t = cross(arm(i), ma);
        for d in 0..3 {
            sum[b][d] += ma[d];
            moment[b][d] += t[d];
        }
    }
    bodies
        .bodies
        .iter()
        .enumerate()
        .map(|(b, body)| {
            let inverse = inverse_on_span(&to_world(&rotations[b], &body.inertia));
            (sum[b].map(|s| s / body.mass), apply(&inverse, moment[b]))
        })
        .collect()
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
        format!("f on each particle for the predictor and the wall ghosts: {frame}; on a free body's particles plus its external force over its mass and the rigid part of the last step's pressure acceleration less their own (A + α × r − a_i, zero net force and moment); on a fixed or prescribed body's the acceleration to its rigid velocity at the step's end (the solve's ghosts of a moving wall); on a resting body's that plus the last step's ∇P/ρ0, and its own weight and external force for its supports; beside a body's particles the wall ghosts carry the water's weight, ρ_w f, not the body's")
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![
            ArraySize::of_components("body force", &self.force),
            ArraySize::of_components(
                "wall ghosts' body force (the water's beside bodies)",
                &self.ghost,
            ),
        ]
    }
}
