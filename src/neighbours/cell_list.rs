//! Cell list: a uniform grid of cells finer than the kernel support, particles counting-sorted
//! by kind, then by linear cell index (x fastest): the fluid first, the walls after it, each
//! sorted by cell. A row of cells along x is then one contiguous index range per kind.
//!
//! The cells are a quarter of the support R along x and half of it across (`SUBDIVISION`). The
//! neighbours of a particle at x lie in the rows of cells across x whose slab comes within R of
//! it, and in each row in the cells within √(R² − d²) of x along the row, d the distance from x
//! to the row's slab: far fewer candidates per neighbour than the 27 cells one support wide
//! around x hold (docs/performance.md, "The PPE apply"). Every 4 × 2 × 2 cells (4 × 2 in 2D)
//! form one block at least one support wide: the aggregates of the PPE's multigrid
//! (`blocks`), whose stencil then reaches the adjacent blocks only.

use crate::math::lanes::F64s;
use crate::math::memory::ArraySize;
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
/// Runs of cells around a point at most: one row along x per cell within reach across it
/// (MAX_SPAN² in 3D), two runs where a row wraps around a periodic x axis.
const MAX_RUNS: usize = 2 * MAX_SPAN * MAX_SPAN;

/// Distances are widened by this fraction of a cell's width in the neighbour search.
const SLACK: f64 = 1e-9;

/// A slab of cells across axis d as seen from a point: `index` its contribution to the linear
/// cell index (None outside a bounded axis), `gap2` the squared distance from the point to it,
/// `shift` the periods the point's image next to it is moved by along d (−1, 0 or 1: across
/// a periodic boundary).
#[derive(Clone, Copy, Debug)]
struct Slab {
    index: Option<usize>,
    gap2: f64,
    shift: i8,
}

impl Slab {
    const OUTSIDE: Self = Self {
        index: None,
        gap2: f64::INFINITY,
        shift: 0,
    };
}

/// The kinds of particle the sort groups, in index order: every kind's particles follow those
/// of the kinds before it. Body particles are grouped with the fluid (`Kind::sorted_as`).
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
    /// The runs of cells around each fluid particle (after `sort`).
    runs: Runs,
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
                // A cell is at least support / subdivision(d) wide (a period holds a whole
                // number of cells no narrower than that), so the quotient exceeds the
                // subdivision only by the rounding of the width: not a cell more of reach.
                let reach = ((support / width[d]) * (1.0 - 4.0 * f64::EPSILON)).ceil() as i64;
                assert!(d == 0 || reach as usize <= MAX_SPAN / 2);
                reach
            }),
            support2: support * support,
            period,
            cell_start: vec![0; KINDS.len() * ncells + 1],
            sorted_cell: Vec::new(),
            runs: Runs::default(),
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
    /// aggregates of the multigrid. Along a periodic axis the last cells of the period, fewer
    /// than a block, join the block before them: a block one support wide or more then meets
    /// only the adjacent blocks, across the boundary too.
    pub fn blocks(&self) -> [usize; D] {
        std::array::from_fn(|d| self.blocks_along(d))
    }

    /// `blocks` along axis d alone.
    #[inline]
    fn blocks_along(&self, d: usize) -> usize {
        match self.period[d] {
            Some(_) => self.dims[d] / subdivision(d),
            None => self.dims[d].div_ceil(subdivision(d)),
        }
    }

    /// Whether each axis is periodic.
    pub fn periodic(&self) -> [bool; D] {
        self.period.map(|p| p.is_some())
    }

    /// The block along axis d of cell `k` along it (`blocks`).
    #[inline]
    fn block_of_cell(&self, d: usize, k: usize) -> usize {
        (k / subdivision(d)).min(self.blocks_along(d) - 1)
    }

    /// The block (linear index, x fastest, in a grid of `blocks()`) of particle k of the sorted
    /// order.
    #[inline]
    pub fn block_of_sorted(&self, k: usize) -> usize {
        let blocks = self.blocks();
        let (mut rest, mut lin, mut stride) = (self.sorted_cell[k] as usize, 0, 1);
        for d in 0..D {
            lin += self.block_of_cell(d, rest % self.dims[d]) * stride;
            rest /= self.dims[d];
            stride *= blocks[d];
        }
        lin
    }

    /// The block along axis d of coordinate x (of a point inside the grid), as
    /// `block_of_sorted` counts them.
    #[inline]
    pub fn block_along(&self, d: usize, x: f64) -> i64 {
        self.block_of_cell(d, self.cell_along(d, x) as usize) as i64
    }

    /// `block_along` of the coordinates `x` of a chunk's lanes, as whole numbers: the same
    /// subtraction, product, floor and clamps, and the division by the subdivision (4 or 2) is
    /// exact as a product; the two agree for every point at or above the grid's origin, as
    /// every particle is (`sort` refuses one outside, `wrap` keeps periodic ones inside).
    #[inline(always)]
    pub fn block_along_lanes(&self, d: usize, x: F64s) -> F64s {
        let cell = ((x - F64s::splat(self.origin[d])) * F64s::splat(self.inv_width[d])).floor();
        let cell = cell.fast_min(F64s::splat((self.dims[d] - 1) as f64));
        let block = (cell * F64s::splat(1.0 / subdivision(d) as f64)).floor();
        block.fast_min(F64s::splat((self.blocks_along(d) - 1) as f64))
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
        let (n, k) = (self.cell_count(), kind.sorted_as() as usize);
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
        crate::math::reduce::fill(cell_of, |i| {
            match self.cell_of(std::array::from_fn(|d| pos[d][i])) {
                Some(c) => c as u32,
                None => u32::MAX,
            }
        });
        if let Some(index) = cell_of.iter().position(|&c| c == u32::MAX) {
            return Err(OutsideGrid { index });
        }
        let key = |i: usize| kind[i].sorted_as() as usize * ncells + cell_of[i] as usize;
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
        self.find_runs(pos, order);
        Ok(())
    }

    /// The runs of cells around every fluid particle that hold particles (`Runs`), in sorted
    /// order: `order` maps a sorted index to the index of `pos`. Two passes, each parallel
    /// over the particles: count the runs, then write them, each block of particles into its
    /// own slices.
    fn find_runs(&mut self, pos: &[Vec<f64>; D], order: &[u32]) {
        let nf = self.cell_start[self.cell_count()] as usize;
        let at = |k: usize| -> [f64; D] { std::array::from_fn(|d| pos[d][order[k] as usize]) };
        let mut runs = std::mem::take(&mut self.runs);
        runs.end.resize(nf, 0);
        crate::math::reduce::fill(&mut runs.end, |k| {
            let mut n = 0;
            self.for_each_run(at(k), |first, cells, _| {
                n += self.holds_particles(first, cells) as u32
            });
            n
        });
        for k in 1..nf {
            runs.end[k] = (runs.end[k].checked_add(runs.end[k - 1]))
                .expect("fewer than 2^32 runs of cells around the fluid particles");
        }
        let start = |k: usize| if k == 0 { 0 } else { runs.end[k - 1] as usize };
        let total = start(nf);
        runs.first.resize(total, 0);
        runs.code.resize(total, 0);
        let mut blocks = Vec::with_capacity(nf.div_ceil(RUN_BLOCK));
        let (mut first, mut code) = (&mut runs.first[..], &mut runs.code[..]);
        for lo in (0..nf).step_by(RUN_BLOCK) {
            let hi = (lo + RUN_BLOCK).min(nf);
            let len = start(hi) - start(lo);
            let (block_first, rest) = std::mem::take(&mut first).split_at_mut(len);
            first = rest;
            let (block_code, rest) = std::mem::take(&mut code).split_at_mut(len);
            code = rest;
            blocks.push((lo..hi, block_first, block_code));
        }
        blocks.into_par_iter().for_each(|(particles, first, code)| {
            let mut slot = 0;
            for k in particles {
                self.for_each_run(at(k), |cell, cells, shift| {
                    if self.holds_particles(cell, cells) {
                        first[slot] = cell as u32;
                        code[slot] = Runs::encode(cells, shift);
                        slot += 1;
                    }
                });
            }
        });
        self.runs = runs;
    }

    /// Whether the `cells` cells from linear index `first` on hold particles of some kind.
    fn holds_particles(&self, first: usize, cells: usize) -> bool {
        let ncells = self.cell_count();
        KINDS.iter().any(|&kind| {
            let base = kind as usize * ncells + first;
            self.cell_start[base] < self.cell_start[base + cells]
        })
    }

    /// The runs of cells around the fluid particles, found by `sort`.
    pub fn runs_arrays(&self) -> [ArraySize; 3] {
        [
            ArraySize::of("end of a fluid particle's runs", &self.runs.end).fluid(),
            ArraySize::sparse("first cell of a run", &self.runs.first),
            ArraySize::sparse("cells and shift of a run", &self.runs.code),
        ]
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
        self.for_each_run(x, |first, cells, shift| {
            self.ranges_of_run(first, cells, self.image(x, shift), kinds, &mut f)
        });
    }

    /// `for_each_neighbour_range` around sorted particle i at `x`: a fluid particle's ranges
    /// come from the runs `sort` found for it (the same ranges in the same order), any other
    /// particle's from a search of the grid into a buffer on the stack. Either way `f` is
    /// called from one place, so that it is inlined into the loop over the runs and the pair
    /// loops keep their sums in registers across the ranges (called from two places, the
    /// compiler kept `f` out of line: a call, and the sums through memory, for every range).
    #[inline(always)]
    pub fn for_each_range_around(
        &self,
        i: usize,
        x: [f64; D],
        kinds: &[Kind],
        mut f: impl FnMut(Range<usize>, [f64; D], Kind),
    ) {
        // The runs hold for the positions of the last sort.
        debug_assert!(
            self.runs.of(i).is_none() || self.cell_of(x) == Some(self.sorted_cell[i] as usize)
        );
        let (mut found_first, mut found_code) = ([0u32; MAX_RUNS], [0u16; MAX_RUNS]);
        let (first, code) = match self.runs.of(i) {
            Some(runs) => runs,
            None => {
                let mut n = 0;
                self.for_each_run(x, |cell, cells, shift| {
                    found_first[n] = cell as u32;
                    found_code[n] = Runs::encode(cells, shift);
                    n += 1;
                });
                (&found_first[..n], &found_code[..n])
            }
        };
        for (&cell, &code) in first.iter().zip(code) {
            let (cells, shift) = Runs::decode::<D>(code);
            self.ranges_of_run(cell as usize, cells, self.image(x, shift), kinds, &mut f);
        }
    }

    /// The range of each of `kinds` in the `cells` cells from linear index `first` on, where
    /// it holds particles.
    #[inline(always)]
    fn ranges_of_run(
        &self,
        first: usize,
        cells: usize,
        image: [f64; D],
        kinds: &[Kind],
        f: &mut impl FnMut(Range<usize>, [f64; D], Kind),
    ) {
        let ncells = self.cell_count();
        for &kind in kinds {
            let base = kind as usize * ncells + first;
            let start = self.cell_start[base] as usize;
            let end = self.cell_start[base + cells] as usize;
            if start < end {
                f(start..end, image, kind);
            }
        }
    }

    /// Calls `f(first, cells, shift)` for every run of cells within reach of `x`: `cells`
    /// cells from linear index `first` on, one row of cells
    /// along x cut to the cells within √(R² − d²) of x (d the distance from x to the row), or
    /// two runs where the row wraps around a periodic x axis; `shift[d]` is the number of
    /// periods x's image next to the run is moved by along axis d (`image`).
    #[inline(always)]
    fn for_each_run(&self, x: [f64; D], mut f: impl FnMut(usize, usize, [i8; D])) {
        // Per axis across x, the rows of cells within reach: the linear index each adds, the
        // squared distance from x to its slab and the periods x's image is shifted by.
        let mut across = [[Slab::OUTSIDE; MAX_SPAN]; D];
        for (d, slabs) in across.iter_mut().enumerate().skip(1) {
            let cell = self.cell_along(d, x[d]);
            let stride: usize = self.dims[..d].iter().product();
            for (o, slab) in slabs.iter_mut().enumerate().take(self.span(d)) {
                *slab = self.slab(d, cell + o as i64 - self.reach[d], x[d], stride);
            }
        }
        let n = self.dims[0] as i64;
        // The rows, as an odometer over the offsets across x (axis 1 fastest).
        let mut offset = [0usize; D];
        loop {
            let (mut lin, mut d2, mut shift, mut inside) = (0, 0.0, [0i8; D], true);
            for d in 1..D {
                let slab = across[d][offset[d]];
                inside &= slab.index.is_some();
                lin += slab.index.unwrap_or(0);
                d2 += slab.gap2;
                shift[d] = slab.shift;
            }
            if inside && d2 < self.support2 {
                // The cells of the row within √(R² − d²) of x along it: one run of cells, or
                // two where the row wraps around a periodic x axis.
                let along = (self.support2 - d2).sqrt() + SLACK * self.width[0];
                let from = ((x[0] - along - self.origin[0]) * self.inv_width[0]).floor() as i64;
                let to = ((x[0] + along - self.origin[0]) * self.inv_width[0]).floor() as i64;
                let wrapped = |s: i8| {
                    let mut w = shift;
                    w[0] = s;
                    w
                };
                let runs = match self.period[0] {
                    None => [(from.max(0), to.min(n - 1), shift), (0, -1, shift)],
                    Some(_) if from < 0 => [(from + n, n - 1, wrapped(1)), (0, to, shift)],
                    Some(_) if to >= n => [(from, n - 1, shift), (0, to - n, wrapped(-1))],
                    Some(_) => [(from, to, shift), (0, -1, shift)],
                };
                for (from, to, shift) in runs {
                    if from > to {
                        continue;
                    }
                    f(lin + from as usize, (to - from + 1) as usize, shift);
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

    /// `x` moved by `shift[d]` periods along each axis d (`for_each_run`).
    #[inline(always)]
    fn image(&self, x: [f64; D], shift: [i8; D]) -> [f64; D] {
        let mut image = x;
        for (d, &s) in shift.iter().enumerate() {
            if s != 0 {
                image = self.shifted(d, s as f64, image);
            }
        }
        image
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
        let (index, shift) = match self.wrapped(d, k) {
            Some((k, shift)) => (Some(k * stride), shift),
            None => (None, 0),
        };
        Slab {
            index,
            gap2: gap * gap,
            shift,
        }
    }

    /// Cell index `k` along axis `d`, wrapped into the grid along a periodic axis, with the
    /// periods a point's image is shifted by accordingly (`shifted`); None outside the grid
    /// along a bounded one.
    #[inline]
    fn wrapped(&self, d: usize, k: i64) -> Option<(usize, i8)> {
        let n = self.dims[d] as i64;
        match self.period[d] {
            Some(_) if k < 0 => Some(((k + n) as usize, 1)),
            Some(_) if k >= n => Some(((k - n) as usize, -1)),
            _ if k < 0 || k >= n => None,
            _ => Some((k as usize, 0)),
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

/// Fluid particles per block of `CellList::find_runs`'s parallel pass.
const RUN_BLOCK: usize = 1024;

/// Bits of a run's code that hold its number of cells; two bits per axis above them hold the
/// periods the image is shifted by (0: none, 1: +1, 2: −1).
const RUN_CELLS_BITS: u32 = 10;

/// The runs of cells around every fluid particle, found once per `CellList::sort`: a step's
/// pair loops visit a fluid particle's neighbours many times (the PPE apply alone thirty times
/// and more), and finding the runs once makes the apply faster than searching the grid in
/// every pair loop (docs/performance.md, "The PPE apply"). A run takes 6 bytes (the runs per
/// fluid particle: docs/performance.md, "Memory per particle"); the pairs themselves are never
/// stored.
#[derive(Clone, Debug, Default)]
struct Runs {
    /// The runs of sorted fluid particle k are `end[k − 1]..end[k]` (from 0 for k = 0).
    end: Vec<u32>,
    /// Linear index of a run's first cell.
    first: Vec<u32>,
    /// A run's cells and image shift (`encode`).
    code: Vec<u16>,
}

impl Runs {
    /// The runs of sorted particle i, if it is a fluid particle.
    #[inline(always)]
    fn of(&self, i: usize) -> Option<(&[u32], &[u16])> {
        let hi = *self.end.get(i)? as usize;
        let lo = if i == 0 { 0 } else { self.end[i - 1] as usize };
        let run = lo..hi;
        Some((&self.first[run.clone()], &self.code[run]))
    }

    #[inline(always)]
    fn encode<const D: usize>(cells: usize, shift: [i8; D]) -> u16 {
        assert!(cells < 1 << RUN_CELLS_BITS, "a run of {cells} cells");
        let shifts = shift.iter().enumerate().fold(0, |code, (d, &s)| {
            let bits = match s {
                0 => 0,
                1 => 1,
                _ => 2,
            };
            code | bits << (RUN_CELLS_BITS as usize + 2 * d)
        });
        cells as u16 | shifts
    }

    #[inline(always)]
    fn decode<const D: usize>(code: u16) -> (usize, [i8; D]) {
        let cells = (code & ((1 << RUN_CELLS_BITS) - 1)) as usize;
        let shift =
            std::array::from_fn(|d| match (code >> (RUN_CELLS_BITS as usize + 2 * d)) & 3 {
                0 => 0,
                1 => 1,
                _ => -1,
            });
        (cells, shift)
    }
}
