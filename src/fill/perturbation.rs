//! The start off the lattice: each fluid particle is moved off its lattice point by a small
//! deterministic perturbation (`simulation.perturbation`), except within a kernel support of the
//! open space above a free surface, where the lattice is kept.
//!
//! Why off the lattice: a fluid on a perfect lattice stays one under a smooth strain. The
//! lattice stretches along the flow and shrinks across it, and the shifting, which moves
//! particles down gradients of their concentration, sees none in a lattice stretched evenly.
//! When the rows come closer than the kernel resolves, the lattice breaks up at once, and the
//! burst of disorder feeds the flow energy: on a Taylor–Green vortex 5% of its kinetic energy
//! and 12% of velocity error at a fifth of L/U, at every resolution. Perturbed, the particles
//! never line up, and the shifting keeps them spread from the first step (docs/accuracy.md,
//! "The start-up error of the Taylor–Green vortex").
//!
//! Why not at the free surface: the free-surface particles carry the surface's Dirichlet
//! pressure where they are, so a perturbed top row is a rough surface, and its grid-scale
//! bumps of height a are gravity waves whose water moves at √(g k) a, k = π/dx: 0.06 m/s for
//! a = 0.1 dx at dx = 12.5 mm. The rows within a support below it move the surface particles through their
//! pressure. Kept on the lattice, the surface starts flat and the still water of
//! `scenes/hydrostatic_2d.toml` moves a hundred times slower (docs/accuracy.md).

use crate::math::lattice::for_each_lattice_point;
use crate::scene::Scene;

/// How many lattice steps from open space the fluid keeps its lattice: a kernel support.
pub fn lattice_reach(scene: &Scene) -> i64 {
    scene.solver.support_in_dx().ceil() as i64
}

/// Which lattice points of the container lie within `reach` lattice steps (along every axis)
/// of open space: a point inside the container that holds no fluid, obstacle or body.
pub struct NearOpenSpace<const D: usize> {
    cells: [i64; D],
    near: Vec<bool>,
}

impl<const D: usize> NearOpenSpace<D> {
    /// From `open`, whether each of the `cells` lattice points (x fastest) is open space, and
    /// which axes are `periodic`.
    pub fn new(cells: [i64; D], open: Vec<bool>, reach: i64, periodic: &[bool]) -> Self {
        let mut mask = Self { cells, near: open };
        for (axis, &periodic) in periodic.iter().enumerate().take(D) {
            mask.dilate(axis, reach, periodic);
        }
        mask
    }

    pub fn contains(&self, k: [i64; D]) -> bool {
        self.near[self.index(k)]
    }

    fn index(&self, k: [i64; D]) -> usize {
        (0..D)
            .rev()
            .fold(0, |index, d| index * self.cells[d] + k[d]) as usize
    }

    /// Marks every point within `reach` steps along `axis` of a marked one (across the box's
    /// faces where the axis is periodic).
    fn dilate(&mut self, axis: usize, reach: i64, periodic: bool) {
        let n = self.cells[axis];
        let mut line_start = self.cells;
        line_start[axis] = 1;
        let marked = self.near.clone();
        for_each_lattice_point([0; D], line_start, |mut k| {
            let line: Vec<bool> = (0..n)
                .map(|j| {
                    k[axis] = j;
                    marked[self.index(k)]
                })
                .collect();
            for j in 0..n {
                let reached = (j - reach..=j + reach).any(|m| match (0..n).contains(&m) {
                    true => line[m as usize],
                    false => periodic && line[m.rem_euclid(n) as usize],
                });
                k[axis] = j;
                let index = self.index(k);
                self.near[index] = reached;
            }
        });
    }
}

/// Lattice point x (of index k) moved by up to `amplitude` along each axis, by a hash of k:
/// the same displacement whatever the order of filling or the thread count.
pub fn perturbed<const D: usize>(x: [f64; D], k: [i64; D], amplitude: f64) -> [f64; D] {
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    for &k in &k {
        seed = splitmix64(seed ^ k as u64);
    }
    std::array::from_fn(|d| {
        let bits = splitmix64(seed ^ d as u64) >> 11;
        let unit = bits as f64 / (1u64 << 53) as f64;
        x[d] + amplitude * (2.0 * unit - 1.0)
    })
}

/// The SplitMix64 mixing function (Steele, Lea & Flood 2014): 64 well-mixed bits from any input.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::NearOpenSpace;

    /// One open point at x = 0 of a 6 × 3 lattice, reach 2: along a periodic x the mark wraps
    /// to x = 4 and 5, along a bounded y it stops at the edge.
    #[test]
    fn open_space_reaches_across_a_periodic_face_only() {
        let mut mask = NearOpenSpace::<2> {
            cells: [6, 3],
            near: vec![false; 18],
        };
        let i = mask.index([0, 0]);
        mask.near[i] = true;
        mask.dilate(0, 2, true);
        mask.dilate(1, 2, false);
        for y in 0..3 {
            let row: Vec<bool> = (0..6).map(|x| mask.contains([x, y])).collect();
            assert_eq!(row, [true, true, true, false, true, true], "row y = {y}");
        }
        let mut bounded = NearOpenSpace::<2> {
            cells: [6, 3],
            near: vec![false; 18],
        };
        let i = bounded.index([0, 0]);
        bounded.near[i] = true;
        bounded.dilate(0, 2, false);
        let row: Vec<bool> = (0..6).map(|x| bounded.contains([x, 0])).collect();
        assert_eq!(row, [true, true, true, false, false, false]);
    }
}
