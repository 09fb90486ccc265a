//! The hard contact of the fluid with the bodies, the last line of the body's no-penetration
//! condition (as `Faces::contact` is the walls'): a fluid particle the step left closer than a
//! gap to a body's surface is put back off it.
//!
//! It is mirrored across the gap surface, as far beyond it as it was inside, not put on it: put
//! on it, every particle along one normal would land on one point, and the water the flow drives
//! into a body at one place would pile up there, particle on particle. Coincident particles see
//! the same neighbours and take the same steps: they never part, and carry twice the density in
//! one place. A mirror keeps any two particles' distance.
//!
//! A particle can be within the gap of two surfaces at once: in the crevice between two bodies
//! that touch, or between a body and a face of the container it lies on. Put back off each in
//! turn, it would converge to the one point at the gap from both, and every particle squeezed
//! into the crevice with it. So it is mirrored along one direction for all the surfaces in its
//! reach, the sum of their normals, across the boundary of the region the gap off all of them
//! (docs/bodies.md, "Contact").

use super::{outward_normal, rigid_velocity, Bodies};
use crate::math::rotation::Vec3;
use crate::math::vector::dot;

/// Rounds of `Bodies::keep_out` for one fluid particle: after a round's push a curved surface
/// may still be in reach.
const ROUNDS: usize = 8;

/// Below this cosine between the push and a surface's normal, the surfaces in reach face each
/// other (a slot narrower than twice the gap) and no one direction leaves all of them.
const FACING: f64 = 0.1;

/// A surface a fluid particle is within reach of.
struct Reach {
    /// Signed distance from the surface (negative inside the body or beyond the face).
    distance: f64,
    /// Outward unit normal.
    normal: Vec3,
    /// The body it belongs to (None: a face of the container).
    body: Option<usize>,
}

impl Bodies {
    /// The hard contact of a fluid particle at x with velocity u with the bodies: a particle
    /// closer than `gap` to a body's surface (or inside it) is mirrored across the gap surface,
    /// and with it across the container's faces in reach (module doc), and keeps no velocity
    /// into a body relative to the body's surface, nor into a face. Returns whether it moved,
    /// and whether it had crossed a body's surface (a penetration).
    pub fn keep_out(&self, x: &mut Vec3, u: &mut Vec3, gap: f64, dims: usize) -> (bool, bool) {
        let (mut moved, mut crossed) = (false, false);
        for _ in 0..ROUNDS {
            let reach = self.surfaces_in_reach(x, gap, dims, moved);
            let Some((direction, length)) = push_out(&reach, gap) else {
                break;
            };
            // Mirrored across the boundary of the region `gap` off every surface in reach.
            for d in 0..dims {
                x[d] += 2.0 * length * direction[d];
            }
            for r in &reach {
                let surface_velocity = match r.body {
                    Some(b) => {
                        let s = &self.bodies[b].state;
                        let arm = std::array::from_fn(|d| x[d] - s.centre[d]);
                        rigid_velocity(s.velocity, self.bodies[b].angular_velocity(), arm)
                    }
                    None => [0.0; 3],
                };
                let into: f64 = (0..dims)
                    .map(|d| (u[d] - surface_velocity[d]) * r.normal[d])
                    .sum();
                if into < 0.0 {
                    for d in 0..dims {
                        u[d] -= into * r.normal[d];
                    }
                }
                crossed = crossed || (r.body.is_some() && r.distance < 0.0);
            }
            moved = true;
        }
        if moved {
            self.put_out_of_bodies(x, gap, dims);
        }
        (moved, crossed)
    }

    /// A particle the rounds left inside a body (squeezed between it and a face or another
    /// body, off which the last round mirrored it) is mirrored across that body's surface:
    /// outside it, if within the gap, which the next step's contact takes up again. Put on
    /// the gap surface instead, the particles squeezed into one crevice would land on one
    /// point.
    fn put_out_of_bodies(&self, x: &mut Vec3, gap: f64, dims: usize) {
        for body in &self.bodies {
            let surface = body.surface_distance(dims);
            let distance = surface(x);
            if distance >= 0.0 {
                continue;
            }
            if let Some(normal) = outward_normal(&surface, *x, gap, dims) {
                for d in 0..dims {
                    x[d] -= 2.0 * distance * normal[d];
                }
            }
        }
    }

    /// The bodies' surfaces within `gap` of x, and where there is one or the particle has been
    /// mirrored off one (`pushed`), the container's faces within it too.
    fn surfaces_in_reach(&self, x: &Vec3, gap: f64, dims: usize, pushed: bool) -> Vec<Reach> {
        let mut reach = Vec::new();
        for (b, body) in self.bodies.iter().enumerate() {
            let s = &body.state;
            let arm: Vec3 = std::array::from_fn(|d| x[d] - s.centre[d]);
            if dot(arm, arm) > (body.reach + gap).powi(2) {
                continue;
            }
            let surface = body.surface_distance(dims);
            let distance = surface(x);
            if distance >= gap {
                continue;
            }
            if let Some(normal) = outward_normal(&surface, *x, gap, dims) {
                reach.push(Reach {
                    distance,
                    normal,
                    body: Some(b),
                });
            }
        }
        if reach.is_empty() && !pushed {
            return reach;
        }
        for (d, plane, inward) in self.planes() {
            let distance = inward * (x[d] - plane);
            if distance < gap {
                let mut normal = [0.0; 3];
                normal[d] = inward;
                reach.push(Reach {
                    distance,
                    normal,
                    body: None,
                });
            }
        }
        reach
    }
}

/// The direction and length of the shortest push along one direction that puts a particle
/// `gap` off every surface in `reach` (a mirror is twice it): along the one surface's normal
/// by what it lacks; for several, along the sum of their normals as far as the one that needs
/// most (module doc); for surfaces that face each other, off the nearest. None when no surface
/// is nearer than `gap`.
fn push_out(reach: &[Reach], gap: f64) -> Option<(Vec3, f64)> {
    let lack = |r: &Reach| gap - r.distance;
    if reach.is_empty() {
        return None;
    }
    if let [one] = reach {
        return Some((one.normal, lack(one)));
    }
    let sum: Vec3 = std::array::from_fn(|d| reach.iter().map(|r| r.normal[d]).sum());
    let length = dot(sum, sum).sqrt();
    let direction = sum.map(|s| s / length);
    let cosines = reach.iter().map(|r| dot(direction, r.normal));
    if length > 0.0 && cosines.clone().all(|c| c > FACING) {
        let push = reach
            .iter()
            .zip(cosines)
            .map(|(r, c)| lack(r) / c)
            .fold(0.0, f64::max);
        return Some((direction, push));
    }
    let nearest = reach
        .iter()
        .min_by(|a, b| a.distance.total_cmp(&b.distance))?;
    Some((nearest.normal, lack(nearest)))
}
