//! The distance from each fluid particle to the surface of the body nearest it, for the
//! no-slip of the viscous term at a body, Eq. (26): as at a wall (`ghosts::no_slip_difference`),
//! the body's particles take the velocity of Morris, Fox & Zhu (1997) that puts the body's own
//! velocity on its surface, not half a spacing inside it (`sph::viscous_acceleration`). Runs
//! only in a scene with bodies.

use super::{Stage, StepSettings};
use crate::bodies::Bodies;
use crate::boundary::ghosts;
use crate::math::memory::ArraySize;
use crate::math::reduce::fill;
use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};

pub const NAME: &str = "body surfaces";

#[derive(Default)]
pub struct BodySurfaces {
    /// Distance to the nearest body's surface of each fluid particle (infinite where no body's
    /// particle is in reach, and for the bodies' particles).
    distances: Vec<f64>,
}

impl BodySurfaces {
    /// The distance from each of the `nf` fluid and body particles to the surface of the body
    /// nearest it: for a fluid particle with a body's particle b within the kernel support,
    /// from the nearest such b along its outward normal, n_b·r_ib − depth_b, at least a quarter
    /// spacing (as `ghosts::Face::distance` from a wall's); infinite elsewhere, and for the
    /// bodies' own particles.
    pub fn run<const D: usize>(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        bodies: &Bodies,
        spacing: f64,
        nf: usize,
    ) {
        self.distances.resize(nf, f64::INFINITY);
        let support = nb.kernel.support();
        fill(&mut self.distances, |i| {
            if p.kind[i] != Kind::Fluid || !bodies.near(p.position(i), support) {
                return f64::INFINITY;
            }
            // A body's particles are sorted with the fluid's.
            let is_body = |j: usize| p.kind[j] == Kind::Body;
            ghosts::nearest_boundary(nb, support, i, &[Kind::Fluid], is_body).map_or(
                f64::INFINITY,
                |(b, r_ib, _)| {
                    let depth = bodies.depth(p.fluid[b] as usize, p.id[b]);
                    ghosts::face_distance(p.wall_normal(b), r_ib, depth, spacing)
                },
            )
        });
    }

    pub fn distances(&self) -> &[f64] {
        &self.distances
    }
}

impl<const D: usize> Stage<D> for BodySurfaces {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        "distance of each fluid particle near a body to the body's surface, from the nearest body particle's depth and outward normal, for the no-slip body velocity of Morris et al. (1997) in the viscous term (Eq. 26), as at the walls".into()
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![ArraySize::of("distance to a body", &self.distances)]
    }
}
