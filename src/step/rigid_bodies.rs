//! The rigid bodies' constraint, Eq. (11)–(16) (`bodies`): after the corrector, each body's
//! particles' momentum and angular momentum beyond their rigid motion advance the body, and
//! their velocities become its rigid velocities; after the advection, their positions are set
//! from its pose. Runs only in a scene with bodies.

use super::{Stage, StepSettings};
use crate::bodies::{rigid_velocity, Bodies, RigidBody};
use crate::math::memory::ArraySize;
use crate::math::rotation::{cross, to_3d, Vec3};
use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};
use crate::solver::ppe::Role;

pub const NAME: &str = "rigid bodies";

#[derive(Default)]
pub struct RigidBodies {
    /// The body particles' indices in the sorted order, found each step.
    members: Vec<u32>,
    /// The held bodies' particles on a dry face (`has_a_dry_face`), in the sorted order.
    dry: Vec<u32>,
}

impl RigidBodies {
    /// Advances `bodies` over the step of `dt` from `time` from `velocity`, the corrector's
    /// uⁿ⁺¹ of the `nf` fluid and body particles, and puts their rigid velocities there;
    /// `force` is the body force f_i the predictor gave them, `loads` the body forces on the
    /// resting bodies' own masses (`body_forces`) and `pressure_gradient` the corrector's
    /// ∇Pⁿ⁺¹. The sums run over the particles in the sorted order, one thread: the same bits
    /// whatever the thread count.
    ///
    /// A body's particles' momentum beyond their rigid motion and their body forces is the
    /// viscous force on them and the pressure force −Σ_i V_i ∇P_i, with the corrected gradient
    /// of Eq. (20): the integral of −∇P over the body, the surface integral of the pressures its
    /// particles hold, exact for a linear pressure field. That is the fluid's force on a free
    /// body (with its added mass) and on a body deep in the fluid. But a held body's face on a
    /// wall or in the air is dry: its particles there hold the fluid's pressure continued
    /// through the body (the ghosts, `ppe::Role::Ghost`) or what the solve's rows give a body's
    /// particles out of the fluid's reach, and the volume integral counts it. So a fixed or
    /// prescribed body's particles with a wall or a free surface in reach
    /// (`reaches_a_dry_face`) take their pressure force in the symmetric form
    /// (`symmetric_pressure_force`), whose truncated support puts the pressure on the faces
    /// the fluid touches and none on the dry ones; the particles deeper in keep the corrected
    /// gradient, which a density error of the fluid beside a moving body does not bias (the
    /// symmetric form's 2 P_i Σ_j V_j ∇W_ij, at the hydrostatic pressure of the depth, does).
    #[allow(clippy::too_many_arguments)]
    pub fn run<const D: usize>(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        bodies: &mut Bodies,
        force: &[Vec<f64>; D],
        loads: &[[Vec3; 2]],
        pressure_gradient: &[Vec<f64>; D],
        roles: &[Role],
        spacing: f64,
        velocity: &mut [Vec<f64>; D],
        time: f64,
        dt: f64,
    ) {
        let nf = velocity[0].len();
        self.members.clear();
        self.members
            .extend((0..nf as u32).filter(|&i| p.kind[i as usize] == Kind::Body));
        let count = bodies.bodies.len();
        let (mut impulse, mut angular) = (vec![[0.0; 3]; count], vec![[0.0; 3]; count]);
        // Σ m_i f_i and Σ r_ic × m_i f_i: the body forces' part of the impulses.
        let mut applied = vec![[[0.0; 3]; 2]; count];
        // Σ (F_i + V_i ∇P_i) and Σ r_ic × (F_i + V_i ∇P_i) over a held body's particles with
        // a dry face in reach, F_i their pressure force in the symmetric form.
        let mut dry_faces = vec![[[0.0; 3]; 2]; count];
        let driven: Vec<bool> = bodies.bodies.iter().map(|b| b.is_driven(time)).collect();
        self.dry.clear();
        self.dry.extend(self.members.iter().copied().filter(|&i| {
            let b = p.fluid[i as usize] as usize;
            driven[b] && has_a_dry_face(nb, p, &bodies.bodies[b], spacing, i as usize)
        }));
        let mut touched = vec![false; count];
        let rigid_now: Vec<_> = bodies
            .bodies
            .iter()
            .map(|b| (b.state.velocity, b.angular_velocity(), b.state.centre))
            .collect();
        for &i in &self.members {
            let i = i as usize;
            let b = p.fluid[i] as usize;
            let (v, w, centre) = rigid_now[b];
            let arm: Vec3 = to_3d::<D>(|d| p.pos[d][i] - centre[d]);
            let rigid = rigid_velocity(v, w, arm);
            let du: Vec3 = to_3d::<D>(|d| p.mass[i] * (velocity[d][i] - rigid[d]));
            let t = cross(arm, du);
            let mf: Vec3 = to_3d::<D>(|d| p.mass[i] * force[d][i]);
            let mf_t = cross(arm, mf);
            for d in 0..3 {
                impulse[b][d] += du[d];
                angular[b][d] += t[d];
                applied[b][0][d] += mf[d];
                applied[b][1][d] += mf_t[d];
            }
            touched[b] = touched[b] || touches_fluid_or_wall(nb, p, i);
            if driven[b] && reaches_a_dry_face(nb, p, roles, &self.dry, i) {
                let symmetric = symmetric_pressure_force(nb, p, i);
                let volume = p.mass[i] / p.rest_density[i];
                let e: Vec3 = to_3d::<D>(|d| volume.mul_add(pressure_gradient[d][i], symmetric[d]));
                let e_t = cross(arm, e);
                for d in 0..3 {
                    dry_faces[b][0][d] += e[d];
                    dry_faces[b][1][d] += e_t[d];
                }
            }
        }
        for b in 0..count {
            if !touched[b] {
                // No fluid or wall in reach of its particles: in the air it feels its body
                // forces alone (gravity and its external force), whatever the pressure solve
                // left inside it (its rows are solved to the tolerance only); free fall is then
                // exact to round-off.
                impulse[b] = applied[b][0].map(|f| f * dt);
                angular[b] = applied[b][1].map(|t| t * dt);
                dry_faces[b] = [[0.0; 3]; 2];
            }
            // The fluid's force and torque on the body over the step.
            let change = [impulse[b], angular[b]];
            let water: [Vec3; 2] = std::array::from_fn(|k| {
                std::array::from_fn(|d| change[k][d] / dt - applied[b][k][d] + dry_faces[b][k][d])
            });
            bodies.advance(b, change, water, loads[b], touched[b], time, dt);
        }
        bodies.resolve_contacts(time, dt);
        let poses: Vec<_> = bodies
            .bodies
            .iter()
            .map(|b| (b.rotation(), b.state.velocity, b.angular_velocity()))
            .collect();
        for &i in &self.members {
            let i = i as usize;
            let body = &bodies.bodies[p.fluid[i] as usize];
            let (r, v, w) = &poses[p.fluid[i] as usize];
            let u = rigid_velocity(*v, *w, body.arm(r, p.id[i]));
            for d in 0..D {
                velocity[d][i] = u[d];
            }
        }
    }

    /// Puts the body particles where their bodies' poses put them, with their surface normals
    /// turned with them, then the `nf` fluid particles that came within a quarter spacing of a
    /// body back off it (`Bodies::keep_out`); returns how many had crossed a body's surface.
    pub fn place<const D: usize>(
        &self,
        p: &mut Particles<D>,
        bodies: &Bodies,
        nf: usize,
        spacing: f64,
    ) -> usize {
        let rotations: Vec<_> = bodies.bodies.iter().map(|b| b.rotation()).collect();
        for &i in &self.members {
            let i = i as usize;
            let b = p.fluid[i] as usize;
            let body = &bodies.bodies[b];
            let arm = body.arm(&rotations[b], p.id[i]);
            let normal = body.normal(&rotations[b], p.id[i]);
            for d in 0..D {
                p.pos[d][i] = body.state.centre[d] + arm[d];
                p.normal[d][i] = normal[d];
            }
        }
        let mut crossings = 0;
        for i in (0..nf).filter(|&i| p.kind[i] == Kind::Fluid) {
            let mut x = to_3d::<D>(|d| p.pos[d][i]);
            let mut u = to_3d::<D>(|d| p.vel[d][i]);
            let (moved, crossed) = bodies.keep_out(&mut x, &mut u, 0.25 * spacing, D);
            crossings += crossed as usize;
            if moved {
                for d in 0..D {
                    (p.pos[d][i], p.vel[d][i]) = (x[d], u[d]);
                }
            }
        }
        crossings
    }
}

/// Whether body particle i, of `body`, lies in its outer layer (within a `spacing` of its
/// surface) on a face with no fluid in front of it within reach: on a wall, on another body, or
/// in the air.
fn has_a_dry_face<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    body: &RigidBody,
    spacing: f64,
    i: usize,
) -> bool {
    if body.surface_point(p.id[i]).depth > spacing {
        return false;
    }
    let normal = p.wall_normal(i);
    let mut wet = false;
    nb.for_each_of(i, &[Kind::Fluid], |j, rij, _| {
        // r_ji·n_i > 0: j lies in front of the face.
        let ahead = (0..D).fold(0.0, |s, d| normal[d].mul_add(-rij[d], s));
        wet = wet || (p.kind[j] == Kind::Fluid && ahead > 0.0);
    });
    !wet
}

/// Whether a wall, a free surface of the fluid or a body particle on a dry face (`dry`, in
/// increasing order: `has_a_dry_face`) lies in reach of body particle i, or i is on one.
fn reaches_a_dry_face<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    roles: &[Role],
    dry: &[u32],
    i: usize,
) -> bool {
    let on_dry = |j: usize| dry.binary_search(&(j as u32)).is_ok();
    let mut reaches = on_dry(i);
    nb.for_each(i, |j, _, _| {
        reaches = reaches
            || p.kind[j] == Kind::Wall
            || roles[j].is_free()
            || (p.kind[j] == Kind::Body && on_dry(j))
    });
    reaches
}

/// −V_i Σ_j V_j (P_i + P_j) ∇_i W_ij over the fluid and body particles in reach of body particle
/// i: its pressure force in the symmetric form of the momentum equation, whose pairs within a
/// body cancel; where the support is cut by a face on a wall or in the air, its sum over the
/// body's particles there holds that face's surface term, and the force of the pressure on the
/// face the fluid touches only.
fn symmetric_pressure_force<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    i: usize,
) -> [f64; D] {
    let (pressure, volume) = (p.pressure[i], p.mass[i] / p.rest_density[i]);
    let mut force = [0.0; D];
    nb.for_each_of(i, &[Kind::Fluid], |j, rij, r| {
        let c = -volume * p.mass[j] / p.rest_density[j]
            * (pressure + p.pressure[j])
            * nb.kernel.grad_factor(r);
        for d in 0..D {
            force[d] = c.mul_add(rij[d], force[d]);
        }
    });
    force
}

/// Whether a particle of the fluid or of a wall is in reach of body particle i. Another body's
/// particles do not count: two bodies that meet in the air touch through their contact
/// (`Bodies::resolve_contacts`), not through the pressure the solve puts between them.
fn touches_fluid_or_wall<const D: usize>(nb: &Neighbours<D>, p: &Particles<D>, i: usize) -> bool {
    let mut touches = false;
    nb.for_each(i, |j, _, _| {
        touches = touches || p.kind[j] != Kind::Body;
    });
    touches
}

impl<const D: usize> Stage<D> for RigidBodies {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        "Eq. (11)–(16): each free body's momentum and angular momentum from its particles' corrected velocities, the fluid's force and torque taken at the middle of the step (extrapolated from the last two wet steps); V, L, the centre (trapezoid) and the orientation quaternion advanced in f64; contact with the container's faces, obstacles and other bodies; a body its contacts stop rests, held still while they hold it; a fixed or prescribed body put where its motion says, the fluid's force on it measured on its wet faces (the symmetric form beside a dry face); the particles' velocities and positions set rigidly".into()
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![
            ArraySize::sparse("body particles", &self.members),
            ArraySize::sparse("held bodies' particles on a dry face", &self.dry),
        ]
    }
}
