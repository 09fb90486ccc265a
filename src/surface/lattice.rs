//! The lattice the density is sampled on: points at whole multiples of the cube edge, kept only
//! in blocks of `block`ᴰ cubes that lie within a kernel radius of some particle, so memory
//! follows the fluid's surface and volume, not its bounding box.

use super::{Points, SurfaceError};
use crate::scene::CubeRule;

/// Most cubes a reconstruction may span (over the particles' box padded by the kernel radius).
pub const MAX_CUBES: f64 = 1.0e9;

/// Most lattice points a reconstruction may store (4 GB): blocks are at least a kernel's reach
/// wide, so a kernel of many cubes makes few but large blocks, more points than its box holds.
pub const MAX_POINTS: f64 = 1.0e9;

/// Cubes along a block's side: a multiple of this many (the lanes of a row of the density
/// sums), and at least a kernel radius.
const MIN_BLOCK: usize = 8;

/// A block's integer coordinates: it holds the lattice points `key × block + [0, block)ᴰ`.
pub type BlockKey<const D: usize> = [i64; D];

pub struct Lattice<const D: usize> {
    /// The cube edge [m].
    pub edge: f64,
    /// Cubes along a block's side.
    pub block: usize,
    /// The blocks that hold particles, sorted, with their particles:
    /// `order[starts[k]..starts[k + 1]]` lie in `occupied[k]`, in increasing index.
    pub occupied: Vec<BlockKey<D>>,
    pub starts: Vec<usize>,
    pub order: Vec<u32>,
    /// The blocks within a kernel radius of a particle (the occupied ones and their
    /// neighbours), sorted: the only blocks whose density is not zero.
    pub valued: Vec<BlockKey<D>>,
}

/// The cube edge of the paper's rule (§3.4): the box's volume over the most cubes allowed is
/// the volume of one cube, whose D-th root is its edge.
pub fn edge_for_max_cubes<const D: usize>(extent: [f64; D], max_cubes: u64) -> f64 {
    let volume: f64 = extent.iter().product();
    (volume / max_cubes as f64).powf(1.0 / D as f64)
}

/// Cubes along each side of a box of `extent` with cubes of `edge` (a partial cube counts).
pub fn cubes_per_axis<const D: usize>(extent: [f64; D], edge: f64) -> [f64; D] {
    extent.map(|side| (side / edge).ceil().max(1.0))
}

/// The smallest and largest coordinate of the particles along each axis.
fn bounds<const D: usize>(points: &Points) -> ([f64; D], [f64; D]) {
    let mut lo = [f64::INFINITY; D];
    let mut hi = [f64::NEG_INFINITY; D];
    for p in &points.position {
        for d in 0..D {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (lo, hi)
}

/// The cube edge a rule gives for `points`: over the particles' box padded by the kernel
/// `radius` on every side (the region where the density is not zero), refused when it spans
/// more than `MAX_CUBES`.
pub fn cube_edge<const D: usize>(
    points: &Points,
    rule: CubeRule,
    radius: f64,
) -> Result<f64, SurfaceError> {
    let (lo, hi) = bounds::<D>(points);
    let extent: [f64; D] = std::array::from_fn(|d| hi[d] - lo[d] + 2.0 * radius);
    let edge = match rule {
        CubeRule::MaxCubes(n) => edge_for_max_cubes(extent, n),
        CubeRule::Size(spacings) => spacings * points.spacing,
    };
    let cubes: f64 = cubes_per_axis(extent, edge).iter().product();
    let positive = edge > 0.0 && edge.is_finite();
    if !positive || cubes > MAX_CUBES {
        return Err(SurfaceError::TooManyCubes {
            edge,
            extent: std::array::from_fn(|d| if d < D { extent[d] } else { 0.0 }),
            cubes,
            limit: MAX_CUBES,
        });
    }
    Ok(edge)
}

impl<const D: usize> Lattice<D> {
    /// The lattice of cube `edge` for `points` and a kernel of `radius`.
    pub fn of(points: &Points, edge: f64, radius: f64) -> Self {
        let block = MIN_BLOCK * ((radius / edge) / MIN_BLOCK as f64).ceil().max(1.0) as usize;
        let side = block as f64 * edge;
        let key_of =
            |p: &[f64; 3]| -> BlockKey<D> { std::array::from_fn(|d| (p[d] / side).floor() as i64) };
        let mut keyed: Vec<(BlockKey<D>, u32)> = points
            .position
            .iter()
            .enumerate()
            .map(|(i, p)| (key_of(p), i as u32))
            .collect();
        keyed.sort_unstable();
        let (mut occupied, mut starts) = (Vec::new(), Vec::new());
        for (k, (key, _)) in keyed.iter().enumerate() {
            if occupied.last() != Some(key) {
                occupied.push(*key);
                starts.push(k);
            }
        }
        starts.push(keyed.len());
        let order = keyed.into_iter().map(|(_, i)| i).collect();
        let mut valued: Vec<BlockKey<D>> = occupied
            .iter()
            .flat_map(|key| neighbourhood(*key, -1..=1))
            .collect();
        valued.sort_unstable();
        valued.dedup();
        Self {
            edge,
            block,
            occupied,
            starts,
            order,
            valued,
        }
    }

    /// The particles of block `key` (none if it holds none).
    pub fn particles_in(&self, key: &BlockKey<D>) -> &[u32] {
        match self.occupied.binary_search(key) {
            Ok(k) => &self.order[self.starts[k]..self.starts[k + 1]],
            Err(_) => &[],
        }
    }

    /// Lattice points along a block's side, and in a block.
    pub fn points_per_block(&self) -> usize {
        self.block.pow(D as u32)
    }

    /// The global lattice coordinates of block `key`'s first point.
    pub fn first_point(&self, key: &BlockKey<D>) -> [i64; D] {
        key.map(|k| k * self.block as i64)
    }
}

/// The blocks `key + o` for every offset o in `range`ᴰ, in lexicographic order.
pub fn neighbourhood<const D: usize>(
    key: BlockKey<D>,
    range: std::ops::RangeInclusive<i64>,
) -> impl Iterator<Item = BlockKey<D>> {
    let (first, width) = (*range.start(), range.end() - range.start() + 1);
    (0..width.pow(D as u32)).map(move |n| {
        let mut rest = n;
        let mut out = key;
        for d in (0..D).rev() {
            out[d] += first + rest % width;
            rest /= width;
        }
        out
    })
}
