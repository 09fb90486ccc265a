//! Iso-surface extraction over the block lattice, marching squares and cubes alike: each lattice
//! edge the surface crosses gets one vertex, computed once by the block holding the edge's
//! first point and shared by every cell around it (the paper's "4 new corners, 8 new edges" of
//! each cube), linearly interpolated between the edge's two densities.
//!
//! Two passes, each over the blocks in parallel: the crossed edges each block owns (its
//! vertices, numbered block after block), then each cube's cells from the case table, their
//! vertices found in the owning block. Blocks, vertices and cells come out in one order
//! whatever the thread count.

use super::lattice::{neighbourhood, BlockKey, Lattice};
use super::table::Table;
use rayon::prelude::*;

/// The surface as extracted: vertices in block order, and the vertex numbers of its cells.
pub struct Extracted<const D: usize> {
    pub positions: Vec<[f64; 3]>,
    /// The outward unit normal at each vertex: against the density's gradient.
    pub normals: Vec<[f32; 3]>,
    pub cells: Vec<u32>,
    /// The blocks that own vertices, with their first vertex (`vertex_starts` has one more
    /// entry, the vertex count).
    pub blocks: Vec<BlockKey<D>>,
    pub vertex_starts: Vec<usize>,
}

/// The crossed edges a block owns, as `point × D + axis` in its own numbering, increasing, with
/// their vertices; and whether its cubes hold any surface at all.
struct Owned {
    edges: Vec<u32>,
    positions: Vec<[f64; 3]>,
    normals: Vec<[f32; 3]>,
    crossed: bool,
}

/// The densities of a block's points and of the points around it: the corners of all its cubes
/// (points 0 to n along each axis) and one more point on each side, for the gradient at every
/// corner. Axes beyond D hold one point.
struct Corners {
    values: Vec<f32>,
    /// Points along each axis (n + 3 for the first D, 1 beyond).
    size: [usize; 3],
    /// The first D axes start at point −1.
    halo: [usize; 3],
}

impl Corners {
    fn of<const D: usize>(lattice: &Lattice<D>, values: &[Vec<f32>], key: &BlockKey<D>) -> Self {
        let n = lattice.block as i64;
        let size: [usize; 3] = std::array::from_fn(|d| if d < D { n as usize + 3 } else { 1 });
        let halo: [usize; 3] = std::array::from_fn(|d| (d < D) as usize);
        // The blocks around this one, −1, 0 or +1 along each axis (digit d + 1 in base 3).
        let sources: Vec<Option<&[f32]>> = neighbourhood(*key, -1..=1)
            .map(|near| {
                lattice
                    .valued
                    .binary_search(&near)
                    .ok()
                    .map(|k| values[k].as_slice())
            })
            .collect();
        let mut out = vec![0.0f32; size.iter().product()];
        let mut k = 0;
        for z in 0..size[2] {
            for y in 0..size[1] {
                for x in 0..size[0] {
                    let l = [x, y, z];
                    let (mut source, mut local) = (0, 0);
                    for d in 0..D {
                        let p = l[d] as i64 - 1;
                        let o = if p < 0 {
                            -1
                        } else if p >= n {
                            1
                        } else {
                            0
                        };
                        source = source * 3 + (o + 1) as usize;
                    }
                    for d in (0..D).rev() {
                        let p = l[d] as i64 - 1;
                        local = local * n + p.rem_euclid(n);
                    }
                    out[k] = sources[source].map_or(0.0, |v| v[local as usize]);
                    k += 1;
                }
            }
        }
        Self {
            values: out,
            size,
            halo,
        }
    }

    /// Where the point `i` (a block point shifted by `halo`) is stored.
    fn index(&self, i: [usize; 3]) -> usize {
        i[0] + self.size[0] * (i[1] + self.size[1] * i[2])
    }

    /// The density at block point `l` (0 to n along each axis).
    fn at(&self, l: [usize; 3]) -> f32 {
        self.values[self.index(std::array::from_fn(|d| l[d] + self.halo[d]))]
    }

    /// The gradient of the density at block point `l` by central differences, per cube edge.
    fn gradient<const D: usize>(&self, l: [usize; 3]) -> [f64; 3] {
        std::array::from_fn(|d| {
            if d >= D {
                return 0.0;
            }
            let i: [usize; 3] = std::array::from_fn(|e| l[e] + self.halo[e]);
            let (mut below, mut above) = (i, i);
            below[d] -= 1;
            above[d] += 1;
            (self.values[self.index(above)] - self.values[self.index(below)]) as f64 / 2.0
        })
    }
}

/// The blocks whose cubes may touch a point of density: the valued blocks and those just
/// before them along any set of axes (their last cubes reach into a valued block).
fn marching_blocks<const D: usize>(lattice: &Lattice<D>) -> Vec<BlockKey<D>> {
    let mut keys: Vec<BlockKey<D>> = lattice
        .valued
        .iter()
        .flat_map(|key| {
            (0..1usize << D)
                .map(move |bits| std::array::from_fn(|d| key[d] - (bits >> d & 1) as i64))
        })
        .collect();
    keys.sort_unstable();
    keys.dedup();
    keys
}

/// The block-local number of point `l` (each coordinate below the block size `n`).
fn local_index<const D: usize>(l: [usize; 3], n: usize) -> usize {
    (0..D).rev().fold(0, |acc, d| acc * n + l[d])
}

/// Every point of a block (or its cubes' first corners), x fastest.
fn block_points<const D: usize>(n: usize) -> impl Iterator<Item = [usize; 3]> {
    let size: [usize; 3] = std::array::from_fn(|d| if d < D { n } else { 1 });
    (0..size[2])
        .flat_map(move |z| (0..size[1]).flat_map(move |y| (0..size[0]).map(move |x| [x, y, z])))
}

fn owned_edges<const D: usize>(
    lattice: &Lattice<D>,
    corners: &Corners,
    key: &BlockKey<D>,
    iso: f32,
) -> Owned {
    let (n, h) = (lattice.block, lattice.edge);
    let first = lattice.first_point(key);
    let (mut edges, mut positions, mut normals) = (Vec::new(), Vec::new(), Vec::new());
    let inside0 = corners.values[0] > iso;
    let crossed = corners.values.iter().any(|&v| (v > iso) != inside0);
    if !crossed {
        return Owned {
            edges,
            positions,
            normals,
            crossed,
        };
    }
    for l in block_points::<D>(n) {
        let v0 = corners.at(l);
        for axis in 0..D {
            let mut m = l;
            m[axis] += 1;
            let v1 = corners.at(m);
            if (v0 > iso) != (v1 > iso) {
                let t = (iso - v0) as f64 / (v1 - v0) as f64;
                let mut x = [0.0; 3];
                for d in 0..D {
                    x[d] = (first[d] + l[d] as i64) as f64 * h;
                }
                x[axis] += t * h;
                edges.push((local_index::<D>(l, n) * D + axis) as u32);
                positions.push(x);
                normals.push(outward(
                    corners.gradient::<D>(l),
                    corners.gradient::<D>(m),
                    t,
                ));
            }
        }
    }
    Owned {
        edges,
        positions,
        normals,
        crossed,
    }
}

/// The outward unit normal where an edge from a point of density gradient `g0` to one of `g1`
/// is crossed at fraction `t`: against the interpolated gradient (the density falls outward).
fn outward(g0: [f64; 3], g1: [f64; 3], t: f64) -> [f32; 3] {
    let g: [f64; 3] = std::array::from_fn(|d| -(g0[d] + t * (g1[d] - g0[d])));
    let length = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if length > 0.0 {
        g.map(|c| (c / length) as f32)
    } else {
        [0.0; 3]
    }
}

/// Where each block's vertices are: the marching blocks, the edges each owns, and the number
/// of its first vertex.
struct Owners<'a, const D: usize> {
    blocks: &'a [BlockKey<D>],
    owned: &'a [Owned],
    vertex_starts: &'a [usize],
}

impl<const D: usize> Owners<'_, D> {
    /// The vertex on edge `id` (`point × D + axis`) of block `key`.
    fn vertex(&self, key: &BlockKey<D>, id: u32) -> u32 {
        // The owner holds this edge: one of its ends is inside, so the owner is a valued
        // block or one just before a valued block, a marching block either way.
        let b = self
            .blocks
            .binary_search(key)
            .expect("the owner of a crossed edge is a marching block");
        let k = self.owned[b]
            .edges
            .binary_search(&id)
            .expect("a crossed edge has a vertex");
        (self.vertex_starts[b] + k) as u32
    }
}

/// The cells of block `key`'s cubes, as global vertex numbers.
fn block_cells<const D: usize>(
    lattice: &Lattice<D>,
    corners: &Corners,
    key: &BlockKey<D>,
    table: &Table<D>,
    iso: f32,
    owners: &Owners<D>,
) -> Vec<u32> {
    let n = lattice.block;
    let mut cells = Vec::new();
    let vertex = |l: [usize; 3], corner: usize, axis: usize| -> u32 {
        let mut q = l;
        let mut near = *key;
        for d in 0..D {
            q[d] += corner >> d & 1;
            if q[d] == n {
                q[d] = 0;
                near[d] += 1;
            }
        }
        owners.vertex(&near, (local_index::<D>(q, n) * D + axis) as u32)
    };
    for l in block_points::<D>(n) {
        let mut case = 0;
        for c in 0..1usize << D {
            let corner: [usize; 3] = std::array::from_fn(|d| l[d] + (c >> d & 1));
            if corners.at(corner) > iso {
                case |= 1 << c;
            }
        }
        for cell in &table.cases[case] {
            for &e in cell {
                let (corner, axis) = table.edges[e as usize];
                cells.push(vertex(l, corner, axis));
            }
        }
    }
    cells
}

/// The iso-surface c = `iso` of the density `values` (one per `lattice.valued` block).
pub fn extract<const D: usize>(
    lattice: &Lattice<D>,
    values: &[Vec<f32>],
    table: &Table<D>,
    iso: f64,
) -> Extracted<D> {
    let iso = iso as f32;
    let blocks = marching_blocks(lattice);
    let owned: Vec<Owned> = blocks
        .par_iter()
        .map(|key| owned_edges(lattice, &Corners::of(lattice, values, key), key, iso))
        .collect();
    let mut vertex_starts = Vec::with_capacity(blocks.len() + 1);
    let mut total = 0;
    for o in &owned {
        vertex_starts.push(total);
        total += o.edges.len();
    }
    vertex_starts.push(total);
    let owners = Owners {
        blocks: &blocks,
        owned: &owned,
        vertex_starts: &vertex_starts,
    };
    let cells: Vec<Vec<u32>> = blocks
        .par_iter()
        .zip(&owned)
        .map(|(key, o)| {
            if !o.crossed {
                return Vec::new();
            }
            let corners = Corners::of(lattice, values, key);
            block_cells(lattice, &corners, key, table, iso, &owners)
        })
        .collect();
    let positions = owned
        .iter()
        .flat_map(|o| o.positions.iter().copied())
        .collect();
    let normals = owned
        .iter()
        .flat_map(|o| o.normals.iter().copied())
        .collect();
    Extracted {
        positions,
        normals,
        cells: cells.concat(),
        blocks,
        vertex_starts,
    }
}
