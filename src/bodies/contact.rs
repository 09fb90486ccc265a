//! Contact of the bodies with the container's faces, the obstacles and each other: after the
//! bodies have moved over a step, a body found closer to another surface than the lattice puts
//! neighbouring particles is pushed back out and given an impulse at the contact point.
//!
//! Two surfaces touch when a particle of one is less than half a spacing outside the other's
//! shape (the shape's surface is half a spacing beyond its outer particles, so at touching the
//! particles of the two are a spacing apart, as at t = 0). The deepest such particle gives the
//! contact: its point p, the depth δ and the normal n (the other shape's outward normal there).
//! Then, with w = 1/M the inverse mass of a body that moves freely (0 for a fixed or prescribed
//! body, a face or an obstacle) and r the arm from a body's centre to p:
//!
//! - the bodies move apart along n by δ, shared as their inverse masses;
//! - if they approach at p, v_n = (v_a − v_b)·n < 0, the normal impulse
//!   j = −(1 + e) v_n / (w_a + w_b + n·(I_a⁻¹(r_a × n) × r_a) + n·(I_b⁻¹(r_b × n) × r_b))
//!   and a Coulomb friction impulse along the sliding direction t, the one that stops the
//!   sliding, at most μ j, change both bodies' momentum and angular momentum.
//!
//! e is the larger of the two restitutions, μ the geometric mean of the two frictions (as
//! Box2D combines them); a face or an obstacle takes the body's own. The passes run over the
//! bodies, then the pairs, in index order: the same bits whatever the thread count.

use super::{outward_normal, Bodies, RigidBody};
use crate::math::rotation::{self, cross, Vec3};
use crate::math::vector::dot;
use crate::scene::BodyMotion;

/// Passes over all contacts per step: a stack of bodies on the floor needs more than one for a
/// push at the bottom to reach the top.
const PASSES: usize = 4;

/// The deepest point of a contact.
#[derive(Clone, Copy, Debug)]
struct Touch {
    point: Vec3,
    /// Unit normal, pointing towards the body that is pushed along it.
    normal: Vec3,
    depth: f64,
}

impl Bodies {
    /// Resolves the contacts of the bodies after their move over the step from `time`.
    pub fn resolve_contacts(&mut self, time: f64) {
        let (dims, gap) = (self.dims, 0.5 * self.spacing);
        for _ in 0..PASSES {
            let mut touched = false;
            for a in 0..self.bodies.len() {
                if !moves_freely(&self.bodies[a], time) {
                    continue;
                }
                let points = world_points(&self.bodies[a]);
                let faces: Vec<Touch> = self.faces_touched(&points, gap);
                let obstacles: Vec<Touch> = self
                    .obstacles
                    .iter()
                    .filter_map(|o| {
                        let distance = |x: &Vec3| o.signed_distance(&x[..dims]);
                        deepest_in(&points, &distance, gap, dims)
                    })
                    .collect();
                for touch in faces.into_iter().chain(obstacles) {
                    touched = true;
                    push_off_fixed(&mut self.bodies[a], touch, dims);
                }
            }
            for a in 0..self.bodies.len() {
                for b in a + 1..self.bodies.len() {
                    let (free_a, free_b) = (
                        moves_freely(&self.bodies[a], time),
                        moves_freely(&self.bodies[b], time),
                    );
                    if !(free_a || free_b) {
                        continue;
                    }
                    if let Some(touch) = self.pair_touch(a, b) {
                        touched = true;
                        let (head, tail) = self.bodies.split_at_mut(b);
                        push_apart(&mut head[a], free_a, &mut tail[0], free_b, touch, dims);
                    }
                }
            }
            if !touched {
                break;
            }
        }
    }

    /// The container faces a body whose particles are at `points` comes closer to than `gap`,
    /// each with its contact.
    fn faces_touched(&self, points: &[Vec3], gap: f64) -> Vec<Touch> {
        let mut touches = Vec::new();
        for (d, face) in self.faces.iter().enumerate() {
            let Some((lo, hi)) = *face else { continue };
            for (plane, sign) in [(lo, 1.0), (hi, -1.0)] {
                let depth = |x: &Vec3| gap - sign * (x[d] - plane);
                if let Some((point, depth)) = contact_patch(points, depth) {
                    let mut normal = [0.0; 3];
                    normal[d] = sign;
                    touches.push(Touch {
                        point,
                        normal,
                        depth,
                    });
                }
            }
        }
        touches
    }

    /// The deepest contact between bodies a and b, its normal pointing towards a.
    fn pair_touch(&self, a: usize, b: usize) -> Option<Touch> {
        let (ba, bb) = (&self.bodies[a], &self.bodies[b]);
        let gap = 0.5 * self.spacing;
        let apart = (0..3)
            .map(|d| (ba.state.centre[d] - bb.state.centre[d]).powi(2))
            .sum::<f64>()
            .sqrt();
        if apart > ba.reach + bb.reach + 2.0 * gap {
            return None;
        }
        let dims = self.dims;
        let a_in_b = deepest_in(
            &world_points(ba),
            &|x| bb.surface_distance(x, dims),
            gap,
            dims,
        );
        let b_in_a = deepest_in(
            &world_points(bb),
            &|x| ba.surface_distance(x, dims),
            gap,
            dims,
        )
        .map(|t| Touch {
            normal: t.normal.map(|n| -n),
            ..t
        });
        match (a_in_b, b_in_a) {
            (Some(x), Some(y)) => Some(if x.depth >= y.depth { x } else { y }),
            (x, y) => x.or(y),
        }
    }
}

/// Whether body b moves freely over the step from `time` (a fixed or prescribed body does not
/// yield to a contact).
fn moves_freely(body: &RigidBody, time: f64) -> bool {
    matches!(body.motion_at(time), BodyMotion::Free)
}

/// The positions of a body's particles now.
fn world_points(body: &RigidBody) -> Vec<Vec3> {
    let r = body.rotation();
    body.offsets
        .iter()
        .map(|o| {
            let arm = rotation::apply(&r, *o);
            std::array::from_fn(|d| body.state.centre[d] + arm[d])
        })
        .collect()
}

/// The contact of a body whose particles are at `points` with the surface whose signed distance
/// is `distance`: its particles closer to it than `gap` (None if none is), their depth-weighted
/// centre as the point (a body lying flat on a surface is pushed at the middle of what touches,
/// not at one corner), the largest depth, and the surface's outward normal at the point
/// (`outward_normal`).
fn deepest_in(
    points: &[Vec3],
    distance: &dyn Fn(&Vec3) -> f64,
    gap: f64,
    dims: usize,
) -> Option<Touch> {
    let (point, depth) = contact_patch(points, |x| gap - distance(x))?;
    let normal = outward_normal(distance, point, gap, dims)?;
    Some(Touch {
        point,
        normal,
        depth,
    })
}

/// The depth-weighted centre of the `points` of positive `depth`, and the largest depth.
fn contact_patch(points: &[Vec3], depth: impl Fn(&Vec3) -> f64) -> Option<(Vec3, f64)> {
    let (mut sum, mut weight, mut deepest) = ([0.0; 3], 0.0, 0.0f64);
    for x in points {
        let h = depth(x);
        if h > 0.0 {
            for d in 0..3 {
                sum[d] += h * x[d];
            }
            weight += h;
            deepest = deepest.max(h);
        }
    }
    (weight > 0.0).then(|| (sum.map(|s| s / weight), deepest))
}

/// Pushes free body `a` off a surface that does not move (a container face, an obstacle) at
/// `touch`, with the body's own restitution and friction.
fn push_off_fixed(a: &mut RigidBody, touch: Touch, dims: usize) {
    for d in 0..dims {
        a.state.centre[d] += touch.depth * touch.normal[d];
    }
    let arm = arm_to(a, touch.point);
    let relative = velocity_at(a, arm);
    let j = impulse(
        relative,
        touch.normal,
        [Some((a as &RigidBody, arm)), None],
        a.restitution,
        a.friction,
    );
    if let Some(j) = j {
        kick(a, arm, j, 1.0);
    }
}

/// Pushes bodies a and b apart at `touch` (its normal towards a); `free_a`, `free_b` whether
/// each yields.
fn push_apart(
    a: &mut RigidBody,
    free_a: bool,
    b: &mut RigidBody,
    free_b: bool,
    touch: Touch,
    dims: usize,
) {
    let (wa, wb) = (
        if free_a { 1.0 / a.mass } else { 0.0 },
        if free_b { 1.0 / b.mass } else { 0.0 },
    );
    for d in 0..dims {
        a.state.centre[d] += touch.depth * wa / (wa + wb) * touch.normal[d];
        b.state.centre[d] -= touch.depth * wb / (wa + wb) * touch.normal[d];
    }
    let (arm_a, arm_b) = (arm_to(a, touch.point), arm_to(b, touch.point));
    let (va, vb) = (velocity_at(a, arm_a), velocity_at(b, arm_b));
    let relative = std::array::from_fn(|d| va[d] - vb[d]);
    let restitution = a.restitution.max(b.restitution);
    let friction = (a.friction * b.friction).sqrt();
    let sides = [
        free_a.then_some((&*a, arm_a)),
        free_b.then_some((&*b, arm_b)),
    ];
    if let Some(j) = impulse(relative, touch.normal, sides, restitution, friction) {
        if free_a {
            kick(a, arm_a, j, 1.0);
        }
        if free_b {
            kick(b, arm_b, j, -1.0);
        }
    }
}

fn arm_to(body: &RigidBody, point: Vec3) -> Vec3 {
    std::array::from_fn(|d| point[d] - body.state.centre[d])
}

fn velocity_at(body: &RigidBody, arm: Vec3) -> Vec3 {
    super::rigid_velocity(body.state.velocity, body.angular_velocity(), arm)
}

/// The impulse on the first side of a contact with relative velocity `relative` (first less
/// second) at the point, normal `n` towards the first: the normal impulse with restitution e
/// and the Coulomb friction impulse, at most μ times it. `sides` are the bodies that yield with
/// their arms to the point. None if they do not approach.
fn impulse(
    relative: Vec3,
    n: Vec3,
    sides: [Option<(&RigidBody, Vec3)>; 2],
    restitution: f64,
    friction: f64,
) -> Option<Vec3> {
    let vn = dot(relative, n);
    if vn >= 0.0 {
        return None;
    }
    let j = -(1.0 + restitution) * vn / resistance(&sides, n);
    let sliding: Vec3 = std::array::from_fn(|d| relative[d] - vn * n[d]);
    let speed = dot(sliding, sliding).sqrt();
    let mut p = n.map(|c| j * c);
    if speed > 0.0 && friction > 0.0 {
        let t = sliding.map(|c| c / speed);
        let jt = (speed / resistance(&sides, t)).min(friction * j);
        for d in 0..3 {
            p[d] -= jt * t[d];
        }
    }
    Some(p)
}

/// 1/m_eff along direction `u` at the contact: Σ w + u·(I⁻¹(r × u) × r) over the yielding sides.
fn resistance(sides: &[Option<(&RigidBody, Vec3)>; 2], u: Vec3) -> f64 {
    sides
        .iter()
        .flatten()
        .map(|(body, arm)| {
            let r = body.rotation();
            let inverse = rotation::to_world(&r, &rotation::inverse_on_span(&body.inertia));
            let turn = cross(rotation::apply(&inverse, cross(*arm, u)), *arm);
            1.0 / body.mass + dot(u, turn)
        })
        .sum()
}

/// Adds `sign` times the impulse `p` at `arm` to a body's momentum and angular momentum.
fn kick(body: &mut RigidBody, arm: Vec3, p: Vec3, sign: f64) {
    let turn = cross(arm, p);
    for d in 0..3 {
        body.state.velocity[d] += sign * p[d] / body.mass;
        body.state.angular_momentum[d] += sign * turn[d];
    }
}
