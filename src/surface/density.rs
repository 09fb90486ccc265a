//! The density lattice c(x) = Σ_i V_i D(|x − x_i|) (the paper's §3.3) at the points of every
//! block within reach of a particle. Each block is summed on its own from the particles of the
//! blocks around it, in a fixed order, so the values do not depend on the thread count.

use super::kernels::Kernel;
use super::lattice::{neighbourhood, Lattice};
use super::Points;
use rayon::prelude::*;

/// c at the points of each of `lattice.valued`, x fastest (`Lattice::points_per_block` each).
///
/// V_i is the particle's rest volume dx^D: the summation density written with a frame falls
/// at the free surface because the kernel there is cut off, not because the fluid expands, and
/// dividing by it would swell every surface particle.
pub fn sample<const D: usize>(lattice: &Lattice<D>, points: &Points, kernel: &Kernel) -> Vec<Vec<f32>> {
    let volume = points.spacing.powi(D as i32);
    lattice
        .valued
        .par_iter()
        .map(|key| {
            let mut values = vec![0.0f32; lattice.points_per_block()];
            let first = lattice.first_point(key);
            for near in neighbourhood(*key, -1..=1) {
                for &i in lattice.particles_in(&near) {
                    let x = &points.position[i as usize];
                    scatter(lattice, &first, x, volume, kernel, &mut values);
                }
            }
            values
        })
        .collect()
}

/// Adds V D(|x_p − x|) to each point p of the block starting at lattice point `first` within
/// the kernel's radius of `x`.
fn scatter<const D: usize>(
    lattice: &Lattice<D>,
    first: &[i64; D],
    x: &[f64; 3],
    volume: f64,
    kernel: &Kernel,
    values: &mut [f32],
) {
    let (b, h, n) = (kernel.support, lattice.edge, lattice.block as i64);
    // The block's points within the radius along each axis, as offsets from `first`; the
    // axes beyond D hold the one point 0.
    let mut range = [(0i64, 0i64); 3];
    for d in 0..D {
        let lo = ((x[d] - b) / h).ceil() as i64 - first[d];
        let hi = ((x[d] + b) / h).floor() as i64 - first[d];
        range[d] = (lo.max(0), hi.min(n - 1));
        if range[d].0 > range[d].1 {
            return;
        }
    }
    let squared = |d: usize, l: i64| -> f64 {
        if d < D {
            let r = (first[d] + l) as f64 * h - x[d];
            r * r
        } else {
            0.0
        }
    };
    let b2 = b * b;
    for lz in range[2].0..=range[2].1 {
        let dz2 = squared(2, lz);
        for ly in range[1].0..=range[1].1 {
            let dyz2 = squared(1, ly) + dz2;
            if dyz2 >= b2 {
                continue;
            }
            let row = ((lz * n + ly) * n) as usize;
            for lx in range[0].0..=range[0].1 {
                let r2 = squared(0, lx) + dyz2;
                if r2 < b2 {
                    values[row + lx as usize] += (volume * kernel.value(r2)) as f32;
                }
            }
        }
    }
}
