//! What a vertex carries besides its position: the outward normal (the area-weighted mean of
//! its cells' normals) and the fluid's velocity there (the kernel-weighted mean of the
//! particles' velocities, Shepard's interpolation with the surface's own kernel).

use super::kernels::Kernel;
use super::lattice::{neighbourhood, BlockKey, Lattice};
use super::mesh::{cross, norm, sub};
use super::Points;
use rayon::prelude::*;

/// The outward unit normal at each vertex: in 3D the sum of its triangles' normals weighted by
/// their areas (the unnormalised cross products), in 2D the sum of its segments' normals
/// weighted by their lengths (each turned right of the segment, away from the fluid on its
/// left). Summed in cell order.
pub fn normals(positions: &[[f64; 3]], cells: &[u32], dimensions: usize) -> Vec<[f32; 3]> {
    let mut sum = vec![[0.0f64; 3]; positions.len()];
    for cell in cells.chunks_exact(dimensions) {
        let p: Vec<[f64; 3]> = cell.iter().map(|&v| positions[v as usize]).collect();
        let n = if dimensions == 3 {
            cross(sub(p[1], p[0]), sub(p[2], p[0]))
        } else {
            let t = sub(p[1], p[0]);
            [t[1], -t[0], 0.0]
        };
        for &v in cell {
            for d in 0..3 {
                sum[v as usize][d] += n[d];
            }
        }
    }
    sum.into_iter()
        .map(|n| {
            let length = norm(n);
            if length > 0.0 {
                n.map(|c| (c / length) as f32)
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

/// The fluid's velocity at each vertex. The vertices of a block lie within its closed box, so
/// the particles within a kernel radius of them are in the blocks around it; those are binned
/// in cells one radius wide, and each vertex reads the 3ᴰ cells around its own.
pub fn velocities<const D: usize>(
    lattice: &Lattice<D>,
    points: &Points,
    kernel: &Kernel,
    positions: &[[f64; 3]],
    blocks: &[BlockKey<D>],
    vertex_starts: &[usize],
) -> Vec<[f32; 3]> {
    blocks
        .par_iter()
        .enumerate()
        .flat_map_iter(|(k, key)| {
            let range = vertex_starts[k]..vertex_starts[k + 1];
            if range.is_empty() {
                return Vec::new();
            }
            let bins = Bins::of(lattice, points, kernel.support, key);
            positions[range]
                .iter()
                .map(|x| bins.velocity_at(x, points, kernel))
                .collect()
        })
        .collect()
}

/// The particles near one block, binned in cells of one kernel radius.
struct Bins<const D: usize> {
    /// The first cell's corner.
    origin: [f64; 3],
    cell: f64,
    size: [usize; 3],
    /// Particles of cell c: `particles[starts[c]..starts[c + 1]]`, in increasing index.
    starts: Vec<usize>,
    particles: Vec<u32>,
}

impl<const D: usize> Bins<D> {
    fn of(lattice: &Lattice<D>, points: &Points, radius: f64, key: &BlockKey<D>) -> Self {
        let side = lattice.block as f64 * lattice.edge;
        let origin: [f64; 3] = std::array::from_fn(|d| if d < D { key[d] as f64 * side - radius } else { 0.0 });
        let size: [usize; 3] =
            std::array::from_fn(|d| if d < D { ((side + 2.0 * radius) / radius).ceil() as usize } else { 1 });
        let cell_of = |x: &[f64; 3]| -> Option<usize> {
            let mut c = 0;
            for d in (0..3).rev() {
                let k = if d < D { ((x[d] - origin[d]) / radius).floor() } else { 0.0 };
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
        Self {
            origin,
            cell: radius,
            size,
            starts,
            particles: near.into_iter().map(|(_, i)| i).collect(),
        }
    }

    fn velocity_at(&self, x: &[f64; 3], points: &Points, kernel: &Kernel) -> [f32; 3] {
        let centre: [i64; 3] = std::array::from_fn(|d| {
            if d < D {
                ((x[d] - self.origin[d]) / self.cell).floor() as i64
            } else {
                0
            }
        });
        let (mut weight, mut sum) = (0.0, [0.0; 3]);
        let reach: [i64; 3] = std::array::from_fn(|d| (d < D) as i64);
        for cz in centre[2] - reach[2]..=centre[2] + reach[2] {
            for cy in centre[1] - reach[1]..=centre[1] + reach[1] {
                for cx in centre[0] - reach[0]..=centre[0] + reach[0] {
                    let c = [cx, cy, cz];
                    if (0..3).any(|d| c[d] < 0 || c[d] >= self.size[d] as i64) {
                        continue;
                    }
                    let index = (c[0] + self.size[0] as i64 * (c[1] + self.size[1] as i64 * c[2])) as usize;
                    for &i in &self.particles[self.starts[index]..self.starts[index + 1]] {
                        let p = &points.position[i as usize];
                        let r2: f64 = (0..D).map(|d| (p[d] - x[d]) * (p[d] - x[d])).sum();
                        let w = kernel.value(r2);
                        if w > 0.0 {
                            weight += w;
                            let u = &points.velocity[i as usize];
                            for d in 0..3 {
                                sum[d] += w * u[d];
                            }
                        }
                    }
                }
            }
        }
        if weight > 0.0 {
            sum.map(|s| (s / weight) as f32)
        } else {
            [0.0; 3]
        }
    }
}
