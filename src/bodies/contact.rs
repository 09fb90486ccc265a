//! Contact of the bodies with the container's faces, the obstacles and each other, after the
//! bodies have moved over a step: a body found closer to another surface than the lattice puts
//! neighbouring particles is pushed back out, and the velocities where they touch stop
//! approaching.
//!
//! Two surfaces touch where a particle of one is less than half a spacing outside the other's
//! shape (the shape's surface is half a spacing beyond its outer particles, so at touching the
//! particles of the two are a spacing apart, as at t = 0); its depth is how much less. The
//! deepest particle gives a contact's depth δ, and the other shape's outward normal n at the
//! depth-weighted centre p of the particles that touch its normal. With w = 1/M the inverse
//! mass of a body that moves freely (0 for a fixed or prescribed body, a face or an obstacle)
//! and r the arm from a body's centre to a point, the effective mass along a direction u at a
//! point is 1 / (w_a + w_b + u·(I_a⁻¹(r_a × u) × r_a) + u·(I_b⁻¹(r_b × u) × r_b)).
//!
//! 1. **Between bodies**, `PASSES` passes over the pairs in index order (a push at the bottom
//!    of a pile reaches its top): the two move apart along n by δ, shared as their inverse
//!    masses, and if they approach at p, v_n = (v_a − v_b)·n < 0, they exchange the impulse of
//!    a rigid-body collision at p, j = −(1 + e) v_n times the effective mass along n, and a
//!    Coulomb friction impulse along the sliding direction t that stops the sliding, at most
//!    μ j.
//! 2. **With a face or an obstacle**, a body moves out along n by δ (the same passes), and then
//!    every particle within `SLOP` spacings of touching a face, an obstacle or a body that
//!    stands still (fixed, or resting) is a contact point, with the surface's normal there. A
//!    body lying on a floor touches at many points, and one impulse at one point would spin it
//!    about that point: a circle's lattice polygon, resting on its bottom row, rocked on the
//!    floor that way. The impulses of all its points are found together by
//!    projected Gauss–Seidel with accumulated impulses (sequential impulses, as in Box2D):
//!    sweep after sweep over the points in order, each point's normal impulse λ ≥ 0 brings its
//!    normal velocity apart to −e v_n⁰ if it approached at v_n⁰ < 0 before the solve and to 0
//!    otherwise, and its friction impulse stops its sliding up to the Coulomb bound
//!    |λ_t| ≤ μ λ. Resting on a face, the solution stops the body's approach and its turn
//!    together. A point approaching slower than |g| Δt does not bounce: a body lying on a
//!    surface approaches it at up to that speed in every step, and would never come to rest.
//! 3. **Resting.** A free body whose contact points' solve stops it (all but `HELD` of its
//!    largest speed), one of them a support its weight in the water presses it onto (a heavy
//!    body's floor, a light one's lid), rests: its velocity is set to zero, and over the next
//!    step it is held where it is, as a fixed body is, so the pressure solve sees a body that
//!    does not move (`RigidBody::target`). After that solve its velocity from rest is what the
//!    fluid's force on the held body and its own body forces give it over the step
//!    (`Bodies::advance`), and the same contact solve either stops it again (it stays at rest)
//!    or not: then its supports cannot hold it (it is lifted, slides past its friction, or
//!    tips) and it moves off with what the contacts leave it. This is static friction and the floor's reaction
//!    acting within the step; without it the solve moved a body lying on the floor by its
//!    excess weight in every step and its contact stopped it after, stirring the water beside
//!    it and jittering (docs/bodies.md, "Contact").
//!
//! e is the larger of the two restitutions, μ the geometric mean of the two frictions (as
//! Box2D combines them); a face, an obstacle or a body that stands still takes the body's own
//! at its contact points. Everything runs over the bodies, the pairs and the points in index
//! order: the same bits whatever the thread count.

use super::{outward_normal, Bodies, RigidBody};
use crate::math::rotation::{self, cross, Mat3, Vec3};
use crate::math::vector::dot;
use crate::scene::BodyMotion;

/// Passes over the separations and the contacts between bodies per step: a stack of bodies on
/// the floor needs more than one for a push at the bottom to reach the top.
const PASSES: usize = 4;

/// How near to touching a face or an obstacle, in spacings, a particle counts as a contact
/// point: the points of a body's side lying on a face differ in depth by its tilt (0.05
/// spacing is a tilt of 3° across a side a spacing wide), and all of them hold it.
const SLOP: f64 = 0.05;

/// A body whose contact points' solve takes all but this fraction of its largest speed is held
/// by them, and rests (module doc, 3.): the solve stops to `TOLERANCE` of its impulses, and a
/// body that slides, turns or lifts off keeps far more than this.
const HELD: f64 = 1e-6;

/// Most sweeps of the contact points' solve; it stops earlier when a sweep changes no impulse
/// by more than `TOLERANCE` of the largest.
const SWEEPS: usize = 200;
const TOLERANCE: f64 = 1e-12;

/// The deepest point of a contact.
#[derive(Clone, Copy, Debug)]
struct Touch {
    point: Vec3,
    /// Unit normal, pointing towards the body that is pushed along it.
    normal: Vec3,
    depth: f64,
}

/// A point where a body touches a face or an obstacle.
#[derive(Clone, Copy, Debug)]
struct ContactPoint {
    /// From the body's centre to the point.
    arm: Vec3,
    /// The surface's unit normal, towards the body.
    normal: Vec3,
    /// The least normal velocity apart the solve leaves at the point.
    target: f64,
    normal_impulse: f64,
    tangent_impulse: Vec3,
}

/// A body's motion during the solve of its contacts.
#[derive(Clone, Copy, Debug)]
struct Motion {
    velocity: Vec3,
    angular_momentum: Vec3,
    angular_velocity: Vec3,
    /// 1/M and I⁻¹ in the world frame of a body that yields to its contacts; zero for one that
    /// does not (a fixed or prescribed body).
    inverse_mass: f64,
    inverse_inertia: Mat3,
}

impl Motion {
    fn of(body: &RigidBody, yields: bool) -> Self {
        let (inverse_mass, inverse_inertia) = if yields {
            let inverse = rotation::inverse_on_span(&body.inertia);
            (
                1.0 / body.mass,
                rotation::to_world(&body.rotation(), &inverse),
            )
        } else {
            (0.0, [[0.0; 3]; 3])
        };
        Motion {
            velocity: body.state.velocity,
            angular_momentum: body.state.angular_momentum,
            angular_velocity: body.angular_velocity(),
            inverse_mass,
            inverse_inertia,
        }
    }

    fn velocity_at(&self, arm: Vec3) -> Vec3 {
        super::rigid_velocity(self.velocity, self.angular_velocity, arm)
    }

    /// 1/M + u·(I⁻¹(r × u) × r): the inverse effective mass along u at arm r.
    fn resistance(&self, arm: Vec3, u: Vec3) -> f64 {
        let turn = cross(rotation::apply(&self.inverse_inertia, cross(arm, u)), arm);
        self.inverse_mass + dot(u, turn)
    }

    /// Adds the impulse p at arm r to the momentum and the angular momentum of a body that
    /// yields.
    fn kick(&mut self, arm: Vec3, p: Vec3) {
        if self.inverse_mass == 0.0 {
            return;
        }
        let turn = cross(arm, p);
        for d in 0..3 {
            self.velocity[d] += p[d] * self.inverse_mass;
            self.angular_momentum[d] += turn[d];
        }
        self.angular_velocity = rotation::apply(&self.inverse_inertia, self.angular_momentum);
    }
}

impl Bodies {
    /// Resolves the contacts of the bodies after their move over the step of `dt` from `time`,
    /// and finds which rest on their contact points (module doc, 3.).
    pub fn resolve_contacts(&mut self, time: f64, dt: f64) {
        let free: Vec<bool> = self.bodies.iter().map(|b| moves_freely(b, time)).collect();
        self.separate(&free);
        let bounce_above = dot(self.gravity, self.gravity).sqrt() * dt;
        for a in (0..self.bodies.len()).filter(|&a| free[a]) {
            let mut points = self.contact_points(a, time);
            let body = &mut self.bodies[a];
            let before = body.largest_speed();
            if !points.is_empty() {
                let mut motion = Motion::of(body, true);
                let bounce = Bounce {
                    restitution: body.restitution,
                    above: bounce_above,
                };
                solve_contact_points(&mut points, &mut motion, bounce, body.friction);
                body.state.velocity = motion.velocity;
                body.state.angular_momentum = motion.angular_momentum;
            }
            let weight = body.weight_in_water(self.gravity, self.water_density);
            let supported = points.iter().any(|c| dot(weight, c.normal) < 0.0);
            let held = supported && body.largest_speed() <= HELD * before;
            if held {
                body.state.velocity = [0.0; 3];
                body.state.angular_momentum = [0.0; 3];
            } else if body.state.resting {
                // Let go: it moves over this step from rest.
                body.drift([0.0; 3], [0.0; 3], dt);
            }
            body.state.resting = held;
        }
    }

    /// Moves the free bodies (`free`) out of the faces and the obstacles, and the bodies out of
    /// each other with their collisions' impulses (module doc, 1. and 2.).
    fn separate(&mut self, free: &[bool]) {
        let (dims, gap) = (self.dims, 0.5 * self.spacing);
        for _ in 0..PASSES {
            let mut touched = false;
            for a in (0..self.bodies.len()).filter(|&a| free[a]) {
                let points = world_points(&self.bodies[a]);
                let mut touches = self.faces_touched(&points, gap);
                touches.extend(self.obstacles.iter().filter_map(|o| {
                    let distance = |x: &Vec3| o.signed_distance(&x[..dims]);
                    deepest_in(&points, &distance, gap, dims)
                }));
                for touch in touches {
                    touched = true;
                    for d in 0..dims {
                        self.bodies[a].state.centre[d] += touch.depth * touch.normal[d];
                    }
                }
            }
            for a in 0..self.bodies.len() {
                for b in (a + 1..self.bodies.len()).filter(|&b| free[a] || free[b]) {
                    if let Some(touch) = self.pair_touch(a, b) {
                        touched = true;
                        let (head, tail) = self.bodies.split_at_mut(b);
                        push_apart(&mut head[a], free[a], &mut tail[0], free[b], touch, dims);
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
        self.planes()
            .filter_map(|(d, plane, sign)| {
                let depth = |x: &Vec3| gap - sign * (x[d] - plane);
                let (point, depth) = contact_patch(points, depth)?;
                Some(Touch {
                    point,
                    normal: axis(d, sign),
                    depth,
                })
            })
            .collect()
    }

    /// The container's faces a body can touch: the axis d, the plane's coordinate along it
    /// and the sign of its inward normal (+1 at the low face, −1 at the high one).
    pub(super) fn planes(&self) -> impl Iterator<Item = (usize, f64, f64)> + '_ {
        self.faces.iter().enumerate().flat_map(|(d, face)| {
            face.iter()
                .flat_map(move |&(lo, hi)| [(d, lo, 1.0), (d, hi, -1.0)])
        })
    }

    /// The deepest contact between bodies a and b, its normal pointing towards a.
    fn pair_touch(&self, a: usize, b: usize) -> Option<Touch> {
        let (ba, bb) = (&self.bodies[a], &self.bodies[b]);
        let gap = 0.5 * self.spacing;
        if !within_reach(ba, bb, gap) {
            return None;
        }
        let dims = self.dims;
        let a_in_b = deepest_in(&world_points(ba), &bb.surface_distance(dims), gap, dims);
        let b_in_a =
            deepest_in(&world_points(bb), &ba.surface_distance(dims), gap, dims).map(|t| Touch {
                normal: t.normal.map(|n| -n),
                ..t
            });
        match (a_in_b, b_in_a) {
            (Some(x), Some(y)) => Some(if x.depth >= y.depth { x } else { y }),
            (x, y) => x.or(y),
        }
    }

    /// The contact points of body a with the faces, the obstacles and the bodies that stand
    /// still over the step from `time` (fixed, or resting): its particles within `SLOP`
    /// spacings of touching, with the surface's normal there.
    fn contact_points(&self, a: usize, time: f64) -> Vec<ContactPoint> {
        let (dims, gap) = (self.dims, 0.5 * self.spacing);
        let near = gap + SLOP * self.spacing;
        let body = &self.bodies[a];
        let points = world_points(body);
        let mut found = Vec::new();
        for (d, plane, sign) in self.planes() {
            for x in points.iter().filter(|x| sign * (x[d] - plane) < near) {
                found.push(ContactPoint::new(body, *x, axis(d, sign)));
            }
        }
        let mut touching = |distance: &dyn Fn(&Vec3) -> f64| {
            for x in points.iter().filter(|x| distance(x) < near) {
                if let Some(n) = outward_normal(distance, *x, gap, dims) {
                    found.push(ContactPoint::new(body, *x, n));
                }
            }
        };
        for o in &self.obstacles {
            touching(&|x: &Vec3| o.signed_distance(&x[..dims]));
        }
        for (b, support) in self.bodies.iter().enumerate() {
            let still = support.state.resting || support.motion_at(time) == &BodyMotion::Fixed;
            if b != a && still && within_reach(body, support, near) {
                touching(&support.surface_distance(dims));
            }
        }
        found
    }
}

impl ContactPoint {
    fn new(body: &RigidBody, x: Vec3, normal: Vec3) -> Self {
        ContactPoint {
            arm: arm_to(body, x),
            normal,
            target: 0.0,
            normal_impulse: 0.0,
            tangent_impulse: [0.0; 3],
        }
    }
}

/// How a contact point bounces: by the body's `restitution`, where it approaches faster than
/// `above`.
#[derive(Clone, Copy, Debug)]
struct Bounce {
    restitution: f64,
    above: f64,
}

/// The impulses of all of a body's contact points (`Bodies::contact_points`) together,
/// by projected Gauss–Seidel (module doc, 2.), with its `bounce` and `friction`.
fn solve_contact_points(
    points: &mut [ContactPoint],
    motion: &mut Motion,
    bounce: Bounce,
    friction: f64,
) {
    for c in points.iter_mut() {
        let approach = dot(motion.velocity_at(c.arm), c.normal);
        c.target = if approach < -bounce.above {
            -bounce.restitution * approach
        } else {
            0.0
        };
    }
    for _ in 0..SWEEPS {
        let (mut change, mut largest) = (0.0f64, 0.0f64);
        for c in points.iter_mut() {
            change = change.max(solve_point(c, motion, friction));
            largest = largest.max(c.normal_impulse);
        }
        if change <= TOLERANCE * largest {
            break;
        }
    }
}

/// One sweep's update of contact point c: its normal impulse, then its friction impulse, each
/// accumulated and clamped (λ ≥ 0, |λ_t| ≤ μ λ) and the change applied to the body; returns
/// the larger change.
fn solve_point(c: &mut ContactPoint, motion: &mut Motion, friction: f64) -> f64 {
    let n = c.normal;
    let vn = dot(motion.velocity_at(c.arm), n);
    let total = (c.normal_impulse + (c.target - vn) / motion.resistance(c.arm, n)).max(0.0);
    let normal_change = total - c.normal_impulse;
    c.normal_impulse = total;
    motion.kick(c.arm, n.map(|x| normal_change * x));
    if friction == 0.0 {
        return normal_change.abs();
    }
    let mut tangent = c.tangent_impulse;
    if let Some((t, speed)) = sliding(motion.velocity_at(c.arm), n) {
        let stop = speed / motion.resistance(c.arm, t);
        for d in 0..3 {
            tangent[d] -= stop * t[d];
        }
    }
    let size = dot(tangent, tangent).sqrt();
    let bound = friction * c.normal_impulse;
    if size > bound {
        tangent = tangent.map(|x| x * bound / size);
    }
    let tangent_change: Vec3 = std::array::from_fn(|d| tangent[d] - c.tangent_impulse[d]);
    c.tangent_impulse = tangent;
    motion.kick(c.arm, tangent_change);
    normal_change
        .abs()
        .max(dot(tangent_change, tangent_change).sqrt())
}

/// Pushes bodies a and b apart at `touch` (its normal towards a), with the impulse of their
/// collision there if they approach (module doc, 1.); `free_a`, `free_b` whether each yields.
fn push_apart(
    a: &mut RigidBody,
    free_a: bool,
    b: &mut RigidBody,
    free_b: bool,
    touch: Touch,
    dims: usize,
) {
    let (mut ma, mut mb) = (Motion::of(a, free_a), Motion::of(b, free_b));
    let (wa, wb) = (ma.inverse_mass, mb.inverse_mass);
    for d in 0..dims {
        a.state.centre[d] += touch.depth * wa / (wa + wb) * touch.normal[d];
        b.state.centre[d] -= touch.depth * wb / (wa + wb) * touch.normal[d];
    }
    let (arm_a, arm_b) = (arm_to(a, touch.point), arm_to(b, touch.point));
    let (va, vb) = (ma.velocity_at(arm_a), mb.velocity_at(arm_b));
    let relative: Vec3 = std::array::from_fn(|d| va[d] - vb[d]);
    let n = touch.normal;
    let vn = dot(relative, n);
    if vn >= 0.0 {
        return;
    }
    let resistance = |u| ma.resistance(arm_a, u) + mb.resistance(arm_b, u);
    let j = -(1.0 + a.restitution.max(b.restitution)) * vn / resistance(n);
    let friction = (a.friction * b.friction).sqrt();
    let mut p = n.map(|c| j * c);
    if let Some((t, speed)) = sliding(relative, n).filter(|_| friction > 0.0) {
        let jt = (speed / resistance(t)).min(friction * j);
        for d in 0..3 {
            p[d] -= jt * t[d];
        }
    }
    ma.kick(arm_a, p);
    mb.kick(arm_b, p.map(|c| -c));
    for (body, motion, yields) in [(a, ma, free_a), (b, mb, free_b)] {
        if yields {
            body.state.velocity = motion.velocity;
            body.state.angular_momentum = motion.angular_momentum;
        }
    }
}

/// The direction and the speed of the part of `relative` across the normal `n`: how the two
/// sides of a contact slide on each other; None where they do not.
fn sliding(relative: Vec3, n: Vec3) -> Option<(Vec3, f64)> {
    let vn = dot(relative, n);
    let across: Vec3 = std::array::from_fn(|d| relative[d] - vn * n[d]);
    let speed = dot(across, across).sqrt();
    (speed > 0.0).then(|| (across.map(|c| c / speed), speed))
}

/// Whether body b moves freely over the step from `time` (a fixed or prescribed body does not
/// yield to a contact).
fn moves_freely(body: &RigidBody, time: f64) -> bool {
    matches!(body.motion_at(time), BodyMotion::Free)
}

/// Whether bodies a and b may be nearer than `gap`: their centres closer than their reaches
/// and twice the gap.
fn within_reach(a: &RigidBody, b: &RigidBody, gap: f64) -> bool {
    let apart = (0..3)
        .map(|d| (a.state.centre[d] - b.state.centre[d]).powi(2))
        .sum::<f64>()
        .sqrt();
    apart <= a.reach + b.reach + 2.0 * gap
}

/// The unit vector along axis d with `sign`.
fn axis(d: usize, sign: f64) -> Vec3 {
    let mut n = [0.0; 3];
    n[d] = sign;
    n
}

fn arm_to(body: &RigidBody, point: Vec3) -> Vec3 {
    std::array::from_fn(|d| point[d] - body.state.centre[d])
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
