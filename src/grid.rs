//! Cell list: a uniform grid of cells finer than the kernel support, particles counting-sorted
//! by kind, then by linear cell index (x fastest): the fluid first, the walls after it, each
//! sorted by cell. A row of cells along x is then one contiguous index range per kind.
//!
//! The cells are a quarter of the support R along x and half of it across (`SUBDIVISION`). The
//! neighbours of a particle at x lie in the rows of cells across x whose slab comes within R of
//! it, and in each row in the cells within √(R² − d²) of x along the row, d the distance from x
//! to the row's slab: about 2.2 candidates per neighbour in 3D, against 6.4 for the 27 cells one
//! support wide around x. Every 4 × 2 × 2 cells (4 × 2 in 2D) form one block at least one
//! support wide: the aggregates of the PPE's multigrid (`blocks`), whose stencil then reaches
//! the adjacent blocks only.

use crate::memory::ArraySize;
use crate::particles::Kind;
use rayon::prelude::*;
use std::ops::Range;

/// Cells per kernel support along axis d (x: 4, the others: 2).
pub const fn subdivision(d: usize) -> usize {
    if d == 0 {
        4
    } else {
        2
    }
}

/// Rows of cells across x within reach, at most (reach ≤ 2 along axes subdivided in two).
const MAX_SPAN: usize = 5;

/// Distances are widened by this fraction of a cell's width in the neighbour search.
const SLACK: f64 = 1e-9;

/// A slab of cells across axis d as seen from a point: `index` its contribution to the linear
/// cell index (None outside a bounded axis), `gap2` the squared distance from the point to it,
/// `image` the point's coordinate along d next to it (moved by a period across a periodic
/// boundary).
#[derive(Clone, Copy, Debug)]
struct Slab {
    index: Option<usize>,
    gap2: f64,
    image: f64,
}

impl Slab {
    const OUTSIDE: Self = Self {
        index: None,
        gap2: f64::INFINITY,
        image: 0.0,
    };
}

/// The kinds of particle the sort groups, in index order: every kind's particles follow those
/// of the kinds before it.
pub const KINDS: [Kind; 2] = [Kind::Fluid, Kind::Wall];

#[derive(Clone, Debug)]
pub struct CellList<const D: usize> {
    /// Lower corner of cell (0, 0, …).
    origin: [f64; D],
    width: [f64; D],
    inv_width: [f64; D],
    dims: [usize; D],
    /// Cells within the support of a point along each axis, at most.
    reach: [i64; D],
    support2: f64,
    /// Per axis: the lower bound and length of the period of a periodic axis.
    period: [Option<(f64, f64)>; D],
    /// Particles of kind k in cell c are `cell_start[k n + c]..cell_start[k n + c + 1]` (n
    /// cells; after `sort`).
    cell_start: Vec<u32>,
    /// Cell of each particle in the sorted order.
    sorted_cell: Vec<u32>,
}

/// A particle outside the grid's box (it has left the domain).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutsideGrid {
    pub index: usize,
}

impl<const D: usize> CellList<D> {
    /// Grid over the box [lo, hi] for a kernel of support radius `support`. Along a periodic
    /// axis [lo, hi) is one period, split into whole cells; it must span at least three
    /// supports (a particle then never meets two images of another), and a neighbour search
    /// near one end continues at the other.
    pub fn new(lo: [f64; D], hi: [f64; D], support: f64, periodic: [bool; D]) -> Self {
        let period: [Option<(f64, f64)>; D] =
            std::array::from_fn(|d| periodic[d].then_some((lo[d], hi[d] - lo[d])));
        let cells: [(usize, f64); D] = std::array::from_fn(|d| {
            let target = support / subdivision(d) as f64;
            match period[d] {
                Some((_, length)) => {
                    let count = (length / target).floor();
                    assert!(
                        count >= (3 * subdivision(d)) as f64,
                        "a periodic axis spans at least three supports"
                    );
                    (count as usize, length / count)
                }
                None => (((hi[d] - lo[d]) / target).floor() as usize + 1, target),
            }
        });
        let (dims, width) = (cells.map(|(n, _)| n), cells.map(|(_, w)| w));
        let ncells: usize = dims.iter().product();
        Self {
            origin: lo,
            width,
            inv_width: width.map(|w| 1.0 / w),
            dims,
            reach: std::array::from_fn(|d| {
                let reach = (support / width[d]).ceil() as i64;
                assert!(d == 0 || reach as usize <= MAX_SPAN / 2);
                reach
            }),
            support2: support * support,
            period,
            cell_start: vec![0; KINDS.len() * ncells + 1],
            sorted_cell: Vec::new(),
        }
    }

    /// Moves every position along a periodic axis back into its period [lo, lo + L).
    pub fn wrap(&self, pos: &mut [Vec<f64>; D]) {
        for (axis, period) in pos.iter_mut().zip(self.period) {
            if let Some((lo, length)) = period {
                axis.par_iter_mut().for_each(|x| {
                    if *x < lo || *x >= lo + length {
                        let r = (*x - lo).rem_euclid(length);
                        // rem_euclid of a tiny negative number rounds up to the length itself.
                        *x = lo + if r < length { r } else { 0.0 };
                    }
                });
            }
        }
    }

    /// Cells per axis (x fastest in the linear index).
    pub fn dims(&self) -> [usize; D] {
        self.dims
    }

    /// Blocks of `subdivision(d)` cells per axis, each at least one support wide: the
    /// aggregates of the multigrid.
    pub fn blocks(&self) -> [usize; D] {
        std::array::from_fn(|d| self.dims[d].div_ceil(subdivision(d)))
    }

    /// The block (linear index, x fastest, in a grid of `blocks()`) of particle k of the sorted
    /// order.
    #[inline]
    pub fn block_of_sorted(&self, k: usize) -> usize {
        let blocks = self.blocks();
        let (mut rest, mut lin, mut stride) = (self.sorted_cell[k] as usize, 0, 1);
        for d in 0..D {
            lin += (rest % self.dims[d]) / subdivision(d) * stride;
            rest /= self.dims[d];
            stride *= blocks[d];
        }
        lin
    }

    /// The block along axis d of coordinate x (of a point inside the grid), as
    /// `block_of_sorted` counts them.
    #[inline]
    pub fn block_along(&self, d: usize, x: f64) -> i64 {
        self.cell_along(d, x) / subdivision(d) as i64
    }

    /// The per-particle array of the grid: the cell of each particle in the sorted order.
    pub fn sorted_cells(&self) -> ArraySize {
        ArraySize::of("cell of sorted particle", &self.sorted_cell)
    }

    pub fn cell_count(&self) -> usize {
        self.dims.iter().product()
    }

    /// The index range of the particles of `kind` (after `sort`).
    pub fn range_of(&self, kind: Kind) -> Range<usize> {
        let (n, k) = (self.cell_count(), kind as usize);
        self.cell_start[k * n] as usize..self.cell_start[(k + 1) * n] as usize
    }

    /// Linear index of the cell holding `x`, or None outside the grid.
    #[inline]
    pub fn cell_of(&self, x: [f64; D]) -> Option<usize> {
        let mut lin = 0;
        for d in (0..D).rev() {
            let mut c = ((x[d] - self.origin[d]) * self.inv_width[d]).floor();
            if self.period[d].is_some() {
                // A wrapped position just below the period's end can round onto it.
                c = c.min((self.dims[d] - 1) as f64);
            }
            if !(c >= 0.0 && c < self.dims[d] as f64) {
                return None;
            }
            lin = lin * self.dims[d] + c as usize;
        }
        Some(lin)
    }

    /// Counting sort by kind (in the order of `KINDS`), then by cell. Fills `cell_of` (per
    /// particle, input order) and `order` (new position → old index, stable within a cell)
    /// and the cell ranges.
    pub fn sort(
        &mut self,
        pos: &[Vec<f64>; D],
        kind: &[Kind],
        cell_of: &mut Vec<u32>,
        order: &mut Vec<u32>,
    ) -> Result<(), OutsideGrid> {
        let (n, ncells) = (pos[0].len(), self.cell_count());
        cell_of.resize(n, 0);
        crate::reduce::fill(cell_of, |i| {
            match self.cell_of(std::array::from_fn(|d| pos[d][i])) {
                Some(c) => c as u32,
                None => u32::MAX,
            }
        });
        if let Some(index) = cell_of.iter().position(|&c| c == u32::MAX) {
            return Err(OutsideGrid { index });
        }
        let key = |i: usize| kind[i] as usize * ncells + cell_of[i] as usize;
        self.cell_start.fill(0);
        for i in 0..n {
            self.cell_start[key(i) + 1] += 1;
        }
        for c in 0..self.cell_start.len() - 1 {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        order.resize(n, 0);
        self.sorted_cell.resize(n, 0);
        let mut next = self.cell_start.clone();
        for i in 0..n {
            let k = next[key(i)] as usize;
            order[k] = i as u32;
            self.sorted_cell[k] = cell_of[i];
            next[key(i)] += 1;
        }
        Ok(())
    }

    /// Calls `f(range, x′, kind)` with contiguous ranges of the particles of each of `kinds`
    /// that hold every such particle within the support of `x` (after `sort`; `x` inside the
    /// grid), with x′ the image of `x` next to the range's particles: `x` itself, or shifted by
    /// a period where the cells around it continue across a periodic boundary. Each row of
    /// cells along x within reach is one range per kind, or two where it wraps around a
    /// periodic x axis.
    #[inline(always)]
    pub fn for_each_neighbour_range(
        &self,
        x: [f64; D],
        kinds: &[Kind],
        mut f: impl FnMut(Range<usize>, [f64; D], Kind),
    ) {
        // Per axis across x, the rows of cells within reach: the linear index each adds, the
        // squared distance from x to its slab and x's image next to it.
        let mut across = [[Slab::OUTSIDE; MAX_SPAN]; D];
        for (d, slabs) in across.iter_mut().enumerate().skip(1) {
            let cell = self.cell_along(d, x[d]);
            let stride: usize = self.dims[..d].iter().product();
            for (o, slab) in slabs.iter_mut().enumerate().take(self.span(d)) {
                *slab = self.slab(d, cell + o as i64 - self.reach[d], x[d], stride);
            }
        }
        let ncells = self.cell_count();
        let n = self.dims[0] as i64;
        // The rows, as an odometer over the offsets across x (axis 1 fastest).
        let mut offset = [0usize; D];
        loop {
            let (mut lin, mut d2, mut image, mut inside) = (0, 0.0, x, true);
            for d in 1..D {
                let slab = across[d][offset[d]];
                inside &= slab.index.is_some();
                lin += slab.index.unwrap_or(0);
                d2 += slab.gap2;
                image[d] = slab.image;
            }
            if inside && d2 < self.support2 {
                // The cells of the row within √(R² − d²) of x along it: one run of cells, or
                // two where the row wraps around a periodic x axis.
                let along = (self.support2 - d2).sqrt() + SLACK * self.width[0];
                let from = ((x[0] - along - self.origin[0]) * self.inv_width[0]).floor() as i64;
                let to = ((x[0] + along - self.origin[0]) * self.inv_width[0]).floor() as i64;
                let runs = match self.period[0] {
                    None => [(from.max(0), to.min(n - 1), image), (0, -1, image)],
                    Some(_) if from < 0 => [
                        (from + n, n - 1, self.shifted(0, 1.0, image)),
                        (0, to, image),
                    ],
                    Some(_) if to >= n => [
                        (from, n - 1, image),
                        (0, to - n, self.shifted(0, -1.0, image)),
                    ],
                    Some(_) => [(from, to, image), (0, -1, image)],
                };
                for (from, to, image) in runs {
                    if from > to {
                        continue;
                    }
                    for &kind in kinds {
                        let base = kind as usize * ncells + lin;
                        let start = self.cell_start[base + from as usize] as usize;
                        let end = self.cell_start[base + to as usize + 1] as usize;
                        if start < end {
                            f(start..end, image, kind);
                        }
                    }
                }
            }
            // Next row.
            let mut d = 1;
            loop {
                if d == D {
                    return;
                }
                offset[d] += 1;
                if offset[d] < self.span(d) {
                    break;
                }
                offset[d] = 0;
                d += 1;
            }
        }
    }

    /// The cell along axis d of coordinate x (of a point inside the grid).
    #[inline(always)]
    fn cell_along(&self, d: usize, x: f64) -> i64 {
        let c = ((x - self.origin[d]) * self.inv_width[d]).floor() as i64;
        c.min(self.dims[d] as i64 - 1)
    }

    /// Rows of cells within reach of a point along axis d (d ≥ 1).
    #[inline(always)]
    fn span(&self, d: usize) -> usize {
        2 * self.reach[d] as usize + 1
    }

    /// Slab `k` of cells along axis d seen from coordinate x (`stride`: the linear index
    /// step of the axis).
    #[inline(always)]
    fn slab(&self, d: usize, k: i64, x: f64, stride: usize) -> Slab {
        let lo = self.origin[d] + k as f64 * self.width[d];
        // A margin, so that rounding in the cell of a particle on a cell's boundary never drops
        // it: candidates too far are masked by the pair test anyway.
        let gap = ((lo - x).max(x - lo - self.width[d]) - SLACK * self.width[d]).max(0.0);
        let mut image = [x; D];
        let index = self.wrapped(d, k, &mut image);
        Slab {
            index: index.map(|k| k * stride),
            gap2: gap * gap,
            image: image[d],
        }
    }

    /// Cell index `k` along axis `d`, wrapped into the grid along a periodic axis (with `image`
    /// moved by the period accordingly); None outside the grid along a bounded one.
    #[inline]
    fn wrapped(&self, d: usize, k: i64, image: &mut [f64; D]) -> Option<usize> {
        let n = self.dims[d] as i64;
        match self.period[d] {
            Some(_) if k < 0 => {
                *image = self.shifted(d, 1.0, *image);
                Some((k + n) as usize)
            }
            Some(_) if k >= n => {
                *image = self.shifted(d, -1.0, *image);
                Some((k - n) as usize)
            }
            _ if k < 0 || k >= n => None,
            _ => Some(k as usize),
        }
    }

    /// `x` moved by `sign` periods along axis `d`: +1 when the cells it looks at wrapped to
    /// the far end of the axis (their particles' images lie one period below them), −1 when
    /// they wrapped to the first cell.
    #[inline]
    fn shifted(&self, d: usize, sign: f64, mut x: [f64; D]) -> [f64; D] {
        let (_, length) = self.period[d].expect("a periodic axis");
        x[d] += sign * length;
        x
    }
}
