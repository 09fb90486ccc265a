//! The rigid bodies' constraint, Eq. (11)–(16) (`bodies`): after the corrector, each body's
//! particles' momentum and angular momentum beyond their rigid motion advance the body, and
//! their velocities become its rigid velocities; after the advection, their positions are set
//! from its pose. Runs only in a scene with bodies.

use super::{Stage, StepSettings};
use crate::bodies::{rigid_velocity, Bodies};
use crate::math::memory::ArraySize;
use crate::math::rotation::{cross, Vec3};
use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};

pub const NAME: &str = "rigid bodies";

#[derive(Default)]
pub struct RigidBodies {
    /// The body particles' indices in the sorted order, found each step.
    members: Vec<u32>,
}

impl RigidBodies {
    /// Advances `bodies` over the step of `dt` from `time` from `velocity`, the corrector's
    /// uⁿ⁺¹ of the `nf` fluid and body particles, and puts their rigid velocities there;
    /// `force` is the body force f_i the predictor gave them and `loads` the body forces on the
    /// resting bodies' own masses (`body_forces`). The sums run over the particles in the sorted
    /// order, one thread: the same bits whatever the thread count.
    #[allow(clippy::too_many_arguments)]
    pub fn run<const D: usize>(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        bodies: &mut Bodies,
        force: &[Vec<f64>; D],
        loads: &[[Vec3; 2]],
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
            let arm: Vec3 =
                std::array::from_fn(|d| if d < D { p.pos[d][i] - centre[d] } else { 0.0 });
            let rigid = rigid_velocity(v, w, arm);
            let du: Vec3 = std::array::from_fn(|d| {
                if d < D {
                    p.mass[i] * (velocity[d][i] - rigid[d])
                } else {
                    0.0
                }
            });
            let t = cross(arm, du);
            let mf: Vec3 =
                std::array::from_fn(|d| if d < D { p.mass[i] * force[d][i] } else { 0.0 });
            let mf_t = cross(arm, mf);
            for d in 0..3 {
                impulse[b][d] += du[d];
                angular[b][d] += t[d];
                applied[b][0][d] += mf[d];
                applied[b][1][d] += mf_t[d];
            }
            touched[b] = touched[b] || touches_fluid_or_wall(nb, p, i);
        }
        for b in 0..count {
            if !touched[b] {
                // No fluid or wall in reach of its particles: in the air it feels its body
                // forces alone (gravity and its external force), whatever the pressure solve
                // left inside it (its rows are solved to the tolerance only); free fall is then
                // exact to round-off.
                impulse[b] = applied[b][0].map(|f| f * dt);
                angular[b] = applied[b][1].map(|t| t * dt);
            }
            bodies.advance(
                b, impulse[b], angular[b], applied[b], loads[b], touched[b], time, dt,
            );
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
            let mut x = std::array::from_fn(|d| if d < D { p.pos[d][i] } else { 0.0 });
            let mut u = std::array::from_fn(|d| if d < D { p.vel[d][i] } else { 0.0 });
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
        "Eq. (11)–(16): each free body's momentum and angular momentum from its particles' corrected velocities, the fluid's force and torque taken at the middle of the step (extrapolated from the last two wet steps); V, L, the centre (trapezoid) and the orientation quaternion advanced in f64; contact with the container's faces, obstacles and other bodies; a body its contacts stop rests, held still while they hold it; a fixed or prescribed body put where its motion says, the fluid's force on it measured; the particles' velocities and positions set rigidly".into()
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![ArraySize::sparse("body particles", &self.members)]
    }
}
