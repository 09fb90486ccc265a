//! The faces of the walls: the container's box (but along its periodic axes) and the obstacles'
//! boxes, the geometry the dummy wall particles of `ghosts` stand for. From it each wall particle
//! takes its normal, and each fluid particle the kinematic wall condition: no velocity into a
//! face it touches (`no_penetration`), and at the end of a step the hard contact that puts back
//! a particle that crossed one (`contact`).

use crate::math::aabb::Aabb;
use crate::math::vector::{dot, norm, unit};

/// The container and the obstacles of a scene.
#[derive(Clone, Debug)]
pub struct Faces {
    pub container: Aabb,
    /// Per axis: the container is periodic along it (no faces there).
    pub periodic: Vec<bool>,
    pub obstacles: Vec<Aabb>,
}

/// What `Faces::contact` did to a particle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Contact {
    /// Nothing: the particle is more than `gap` inside the container and outside every obstacle.
    Clear,
    /// Put back `gap` off a face it had come closer to than `gap`, without crossing it.
    Near,
    /// Put back from beyond a face: its centre was outside the container or inside an
    /// obstacle (a penetration).
    Crossed,
}

impl Faces {
    /// The faces of `container` (none across the axes that are `periodic`) and of `obstacles`.
    pub fn new(container: &Aabb, periodic: &[bool], obstacles: &[Aabb]) -> Self {
        Self {
            container: container.clone(),
            periodic: periodic.to_vec(),
            obstacles: obstacles.to_vec(),
        }
    }

    /// Unit normal of the wall at wall particle position x, pointing into the fluid: towards
    /// the container for container walls, out of the nearest face of its obstacle for obstacle
    /// particles (of the faces the fluid can reach: a face on the container's boundary, an
    /// obstacle standing on the floor say, borders no fluid); along an edge or at a corner of
    /// an obstacle, where two or three faces are as near (up to rounding), the normalised sum
    /// of theirs, as at the container's.
    pub fn wall_normal<const D: usize>(&self, x: [f64; D]) -> [f64; D] {
        let c = &self.container;
        let to_box: [f64; D] = std::array::from_fn(|d| x[d].clamp(c.min[d], c.max[d]) - x[d]);
        if norm(to_box) > 0.0 {
            return unit(to_box);
        }
        let Some(o) = self.obstacles.iter().find(|o| o.contains(&x)) else {
            return [0.0; D];
        };
        let nearest = self
            .wet_faces(o)
            .map(|(d, _, plane)| (x[d] - plane).abs())
            .fold(f64::INFINITY, f64::min);
        let tie = nearest * (1.0 + 1e-9) + f64::MIN_POSITIVE;
        let mut n = [0.0; D];
        for (d, sign, plane) in self.wet_faces(o) {
            if (x[d] - plane).abs() <= tie {
                n[d] = sign;
            }
        }
        unit(n)
    }

    /// Per axis, the coordinate of the container's face within `reach` of x (the nearer of the
    /// two), None along a periodic axis or where neither is that near: the planes the wall
    /// particles behind them mirror the fluid across.
    pub fn container_faces_within<const D: usize>(
        &self,
        x: [f64; D],
        reach: f64,
    ) -> [Option<f64>; D] {
        let c = &self.container;
        std::array::from_fn(|d| {
            let (low, high) = (x[d] - c.min[d], c.max[d] - x[d]);
            match self.periodic[d] {
                true => None,
                false if low <= high => (low < reach).then_some(c.min[d]),
                false => (high < reach).then_some(c.max[d]),
            }
        })
    }

    /// The kinematic wall condition v·n ≥ 0 for a velocity or displacement v of a fluid
    /// particle at x, for every face within `reach` of it, n the face's normal into the fluid:
    /// v ← v − min(v·n, 0) n. Near an obstacle n points from its nearest point to x (out of a
    /// face, or away from an edge or corner). The pressure keeps fluid with neighbours off the
    /// walls; this catches what it cannot hold (a drop of spray with no fluid around it, a
    /// particle driven at a face faster than its ghosts' pressure can stop it), which meets the
    /// wall inelastically.
    pub fn no_penetration<const D: usize>(
        &self,
        x: [f64; D],
        mut v: [f64; D],
        reach: f64,
    ) -> [f64; D] {
        let c = &self.container;
        for d in (0..D).filter(|&d| !self.periodic[d]) {
            if x[d] - c.min[d] < reach {
                v[d] = v[d].max(0.0);
            }
            if c.max[d] - x[d] < reach {
                v[d] = v[d].min(0.0);
            }
        }
        for o in &self.obstacles {
            let away: [f64; D] = std::array::from_fn(|d| x[d] - x[d].clamp(o.min[d], o.max[d]));
            let distance = norm(away);
            if distance > 0.0 && distance < reach {
                let n = unit(away);
                let v_n = dot(v, n).min(0.0);
                v = std::array::from_fn(|d| v[d] - v_n * n[d]);
            }
        }
        v
    }

    /// Hard contact with the faces, the last line of the wall condition: a fluid particle
    /// whose step ended within `gap` of a face of the container or inside an obstacle (a fast
    /// particle at a large CFL number can cross the half spacing between the fluid and a face
    /// in one step, where the ghost pressure has had no time to stop it) is put back `gap`
    /// inside the fluid's side of that face, and its velocity loses the part into the face (an
    /// inelastic contact, as `no_penetration`).
    pub fn contact<const D: usize>(&self, gap: f64, x: &mut [f64; D], u: &mut [f64; D]) -> Contact {
        let c = &self.container;
        let mut contact = Contact::Clear;
        for d in (0..D).filter(|&d| !self.periodic[d]) {
            let (lo, hi) = (c.min[d] + gap, c.max[d] - gap);
            if x[d] < c.min[d] || x[d] > c.max[d] {
                contact = Contact::Crossed;
            } else if contact == Contact::Clear && (x[d] < lo || x[d] > hi) {
                contact = Contact::Near;
            }
            if x[d] < lo {
                (x[d], u[d]) = (lo, u[d].max(0.0));
            } else if x[d] > hi {
                (x[d], u[d]) = (hi, u[d].min(0.0));
            }
        }
        for o in &self.obstacles {
            if !o.contains(x.as_slice()) {
                continue;
            }
            // Out through the nearest face the fluid can reach.
            let (mut depth, mut d, mut sign) = (f64::INFINITY, 0, 0.0);
            for (axis, s, plane) in self.wet_faces(o) {
                let inside = (x[axis] - plane).abs();
                if inside < depth {
                    (depth, d, sign) = (inside, axis, s);
                }
            }
            x[d] = if sign < 0.0 {
                o.min[d] - gap
            } else {
                o.max[d] + gap
            };
            if u[d] * sign < 0.0 {
                u[d] = 0.0;
            }
            contact = Contact::Crossed;
        }
        contact
    }

    /// The faces of obstacle `o` inside the container, where fluid can meet them: (axis, the
    /// sign of the outward normal along it, the face's coordinate).
    fn wet_faces<'a>(&'a self, o: &'a Aabb) -> impl Iterator<Item = (usize, f64, f64)> + 'a {
        let c = &self.container;
        (0..o.min.len()).flat_map(move |d| {
            let low = (o.min[d] > c.min[d]).then_some((d, -1.0, o.min[d]));
            let high = (o.max[d] < c.max[d]).then_some((d, 1.0, o.max[d]));
            low.into_iter().chain(high)
        })
    }
}

/// Distance from a wall face within which a fluid particle touches it (the kinematic condition
/// of `Faces::no_penetration`): half a spacing, the distance at which the fluid's first layer
/// rests, and a hair more so that the resting layer is included (the still tank and the
/// violent impact at other distances: docs/stabilisation.md, "The kinematic wall condition and
/// wall crossings").
pub fn touching_distance(spacing: f64) -> f64 {
    0.5001 * spacing
}
