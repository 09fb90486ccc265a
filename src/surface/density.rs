//! The density lattice c(x) = Σ_i V_i D(|x − x_i|) (the paper's §3.3) at the points of every
//! block within reach of a particle. Each block is summed on its own from the particles of the
//! blocks around it, in a fixed order, so the values do not depend on the thread count.

use super::kernels::{Kernel, Profile, ProfileVisitor};
use super::lattice::{neighbourhood, Lattice};
use super::Points;
use rayon::prelude::*;

/// c at the points of each of `lattice.valued`, x fastest (`Lattice::points_per_block` each).
///
/// V_i is the particle's rest volume dx^D: the summation density written with a frame falls
/// at the free surface because the kernel there is cut off, not because the fluid expands, and
/// dividing by it would swell every surface particle.
pub fn sample<const D: usize>(
    lattice: &Lattice<D>,
    points: &Points,
    kernel: &Kernel,
) -> Vec<Vec<f32>> {
    let volume = points.spacing.powi(D as i32);
    kernel.with_profile(
        volume,
        Sampler {
            lattice,
            points,
            support: kernel.support,
        },
    )
}

struct Sampler<'a, const D: usize> {
    lattice: &'a Lattice<D>,
    points: &'a Points,
    support: f64,
}

impl<const D: usize> ProfileVisitor for Sampler<'_, D> {
    type Output = Vec<Vec<f32>>;

    fn visit<P: Profile>(self, profile: P) -> Vec<Vec<f32>> {
        let Self {
            lattice,
            points,
            support,
        } = self;
        // Positions and support in cube edges, computed once: a particle is visited by the
        // 3ᴰ blocks around its own.
        let scaled: Vec<[f64; 3]> = points
            .position
            .iter()
            .map(|x| x.map(|c| c / lattice.edge))
            .collect();
        let reach = support / lattice.edge;
        lattice
            .valued
            .par_iter()
            .map(|key| {
                let mut values = vec![0.0f32; lattice.points_per_block()];
                let mut squared = vec![0.0f32; 3 * lattice.block];
                let first = lattice.first_point(key);
                for near in neighbourhood(*key, -1..=1) {
                    for &i in lattice.particles_in(&near) {
                        let x = &scaled[i as usize];
                        scatter(
                            lattice,
                            &first,
                            x,
                            reach,
                            &profile,
                            &mut squared,
                            &mut values,
                        );
                    }
                }
                values
            })
            .collect()
    }
}

/// Adds V D(|x_p − x|) to each point p of the block starting at lattice point `first` within
/// the kernel's support (`reach` cube edges) of `x` (in cube edges), a row of points at a time;
/// `squared` is room for a distance per point along each axis.
fn scatter<const D: usize, P: Profile>(
    lattice: &Lattice<D>,
    first: &[i64; D],
    x: &[f64; 3],
    reach: f64,
    profile: &P,
    squared: &mut [f32],
    values: &mut [f32],
) {
    let (h, n) = (lattice.edge, lattice.block as i64);
    // The block's points within the support along y and z, as offsets from `first`, and the
    // squared distances from x along each axis of every point of the block's side (rows along
    // x are summed whole, the profile being zero beyond its support: full SIMD lanes); the
    // axes beyond D hold the one point 0.
    let mut range = [(0usize, 0usize); 3];
    let (along_x, rest) = squared.split_at_mut(n as usize);
    let (along_y, along_z) = rest.split_at_mut(n as usize);
    let squared = [along_x, along_y, along_z];
    squared[2][0] = 0.0;
    for d in 0..D {
        let lo = ((x[d] - reach).ceil() as i64 - first[d]).max(0);
        let hi = ((x[d] + reach).floor() as i64 - first[d]).min(n - 1);
        if lo > hi {
            return;
        }
        range[d] = (lo as usize, hi as usize);
        // Relative to the block's first point, so single precision keeps the offsets exact
        // to its last bits.
        let offset = (x[d] - first[d] as f64) as f32;
        let h = h as f32;
        let (from, to) = if d == 0 {
            (0, n as usize - 1)
        } else {
            range[d]
        };
        for l in from..=to {
            let r = (l as f32 - offset) * h;
            squared[d][l] = r * r;
        }
    }
    let support2 = profile.support2();
    let n = n as usize;
    for lz in range[2].0..=range[2].1 {
        let dz2 = squared[2][lz];
        for ly in range[1].0..=range[1].1 {
            let dyz2 = squared[1][ly] + dz2;
            if dyz2 >= support2 {
                continue;
            }
            let row = (lz * n + ly) * n;
            for (v, &dx2) in values[row..row + n].iter_mut().zip(squared[0].iter()) {
                *v += profile.at(dx2 + dyz2);
            }
        }
    }
}
