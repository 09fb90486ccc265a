//! The fluid's velocity at the surface's vertices: the kernel-weighted mean of the particles'
//! velocities (Shepard's interpolation with the surface's own kernel).

use super::kernels::{Kernel, Profile, ProfileVisitor};
use super::lattice::{neighbourhood, BlockKey, Lattice};
use super::Points;
use rayon::prelude::*;

/// The fluid's velocity at each vertex. The vertices of a block lie within its closed box, so
/// the particles within the kernel's support of them are in the blocks around it; those are
/// binned in cells one support wide, and each vertex reads the 3ᴰ cells around its own, a row
/// of cells (contiguous in memory) at a time.
pub fn velocities<const D: usize>(
    lattice: &Lattice<D>,
    points: &Points,
    kernel: &Kernel,
    positions: &[[f64; 3]],
    blocks: &[BlockKey<D>],
    vertex_starts: &[usize],
) -> Vec<[f32; 3]> {
    kernel.with_profile(
        1.0,
        Interpolation {
            lattice,
            points,
            support: kernel.support,
            positions,
            blocks,
            vertex_starts,
        },
    )
}

struct Interpolation<'a, const D: usize> {
    lattice: &'a Lattice<D>,
    points: &'a Points,
    support: f64,
    positions: &'a [[f64; 3]],
    blocks: &'a [BlockKey<D>],
    vertex_starts: &'a [usize],
}

impl<const D: usize> ProfileVisitor for Interpolation<'_, D> {
    type Output = Vec<[f32; 3]>;

    fn visit<P: Profile>(self, profile: P) -> Vec<[f32; 3]> {
        let Self {
            lattice,
            points,
            support,
            positions,
            blocks,
            vertex_starts,
        } = self;
        blocks
            .par_iter()
            .enumerate()
            .flat_map_iter(|(k, key)| {
                let range = vertex_starts[k]..vertex_starts[k + 1];
                if range.is_empty() {
                    return Vec::new();
                }
                let bins = Bins::of(lattice, points, support, key);
                positions[range]
                    .iter()
                    .map(|x| bins.velocity_at(x, &profile))
                    .collect()
            })
            .collect()
    }
}

/// The particles near one block, binned in cells one support wide: positions relative to the
/// first cell's corner and velocities, in single precision, cell after cell (x fastest).
struct Bins<const D: usize> {
    origin: [f64; 3],
    cell: f64,
    size: [usize; 3],
    /// Particles of cell c: `starts[c]..starts[c + 1]`, in increasing index.
    starts: Vec<usize>,
    position: [Vec<f32>; 3],
    velocity: [Vec<f32>; 3],
}

impl<const D: usize> Bins<D> {
    fn of(lattice: &Lattice<D>, points: &Points, support: f64, key: &BlockKey<D>) -> Self {
        let side = lattice.block as f64 * lattice.edge;
        // Cells one support wide, or wider when the block is many supports wide (large cubes,
        // a small kernel): at most 64 along a side. A vertex reads the cells next to its own,
        // which hold every particle within one support of it for any cell at least that wide.
        let cell = support.max((side + 2.0 * support) / 64.0);
        let origin: [f64; 3] = std::array::from_fn(|d| {
            if d < D {
                key[d] as f64 * side - support
            } else {
                0.0
            }
        });
        let size: [usize; 3] = std::array::from_fn(|d| {
            if d < D {
                ((side + 2.0 * support) / cell).ceil() as usize
            } else {
                1
            }
        });
        let cell_of = |x: &[f64; 3]| -> Option<usize> {
            let mut c = 0;
            for d in (0..3).rev() {
                let k = if d < D {
                    ((x[d] - origin[d]) / cell).floor()
                } else {
                    0.0
                };
                if k < 0.0 || k >= size[d] as f64 {
                    return None;
                }
                c = c * size[d] + k as usize;
            }
            Some(c)
        };
        let mut near: Vec<(usize, u32)> = neighbourhood(*key, -1..=1)
            .flat_map(|b| lattice.particles_in(&b).iter().copied())
            .filter_map(|i| cell_of(&points.position[i as usize]).map(|c| (c, i)))
            .collect();
        near.sort_unstable();
        let cells: usize = size.iter().product();
        let mut starts = vec![0; cells + 1];
        for &(c, _) in &near {
            starts[c + 1] += 1;
        }
        for c in 0..cells {
            starts[c + 1] += starts[c];
        }
        let column = |f: &dyn Fn(usize) -> f32| -> Vec<f32> {
            near.iter().map(|&(_, i)| f(i as usize)).collect()
        };
        Self {
            origin,
            cell,
            size,
            starts,
            position: std::array::from_fn(|d| {
                column(&|i| (points.position[i][d] - origin[d]) as f32)
            }),
            velocity: std::array::from_fn(|d| column(&|i| points.velocity[i][d] as f32)),
        }
    }

    fn velocity_at<P: Profile>(&self, x: &[f64; 3], profile: &P) -> [f32; 3] {
        let local: [f64; 3] = std::array::from_fn(|d| x[d] - self.origin[d]);
        let centre: [i64; 3] = std::array::from_fn(|d| {
            if d < D {
                (local[d] / self.cell).floor() as i64
            } else {
                0
            }
        });
        let x32 = local.map(|c| c as f32);
        let (mut weight, mut sum) = (0.0f32, [0.0f32; 3]);
        let reach: [i64; 3] = std::array::from_fn(|d| (d < D) as i64);
        let clamp = |d: usize, c: i64| c.clamp(0, self.size[d] as i64 - 1) as usize;
        for cz in
            (centre[2] - reach[2]).max(0)..=(centre[2] + reach[2]).min(self.size[2] as i64 - 1)
        {
            for cy in
                (centre[1] - reach[1]).max(0)..=(centre[1] + reach[1]).min(self.size[1] as i64 - 1)
            {
                // The row of cells along x around the vertex: one run of particles.
                let row = (cz as usize * self.size[1] + cy as usize) * self.size[0];
                let first = self.starts[row + clamp(0, centre[0] - 1)];
                let end = self.starts[row + clamp(0, centre[0] + 1) + 1];
                for j in first..end {
                    let r: [f32; 3] = std::array::from_fn(|d| self.position[d][j] - x32[d]);
                    let w = profile.at(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
                    weight += w;
                    for d in 0..3 {
                        sum[d] += w * self.velocity[d][j];
                    }
                }
            }
        }
        if weight > 0.0 {
            sum.map(|s| s / weight)
        } else {
            [0.0; 3]
        }
    }
}
