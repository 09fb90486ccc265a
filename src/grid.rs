//! Cell list: a uniform grid of cells at least one kernel support wide, particles
//! counting-sorted by linear cell index (x fastest), so that the 3^D neighbour cells of a
//! particle are 3^(D−1) contiguous index ranges of the particle arrays.

use crate::memory::ArraySize;
use rayon::prelude::*;
use std::ops::Range;

#[derive(Clone, Debug)]
pub struct CellList<const D: usize> {
    /// Lower corner of cell (0, 0, …); the grid has one empty guard cell on each side.
    origin: [f64; D],
    inv_cell: [f64; D],
    dims: [usize; D],
    /// Per axis: the lower bound and length of the period of a periodic axis.
    period: [Option<(f64, f64)>; D],
    /// Particles of cell c are `cell_start[c]..cell_start[c + 1]` (after `sort`).
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
    /// Grid over the box [lo, hi] with cells of edge ≥ `cell` (the kernel support). Along a
    /// periodic axis [lo, hi) is one period, split into whole cells (at least three: a
    /// particle then never meets two images of another), and a neighbour search near one end
    /// continues at the other.
    pub fn new(lo: [f64; D], hi: [f64; D], cell: f64, periodic: [bool; D]) -> Self {
        let period: [Option<(f64, f64)>; D] =
            std::array::from_fn(|d| periodic[d].then_some((lo[d], hi[d] - lo[d])));
        // Interior cells and cell width per axis.
        let cells: [(usize, f64); D] = std::array::from_fn(|d| match period[d] {
            Some((_, length)) => {
                let count = (length / cell).floor();
                assert!(count >= 3.0, "a periodic axis spans at least three cells");
                (count as usize, length / count)
            }
            None => (((hi[d] - lo[d]) / cell).ceil().max(1.0) as usize, cell),
        });
        let (dims, width) = (cells.map(|(n, _)| n + 2), cells.map(|(_, w)| w));
        let origin = std::array::from_fn(|d| lo[d] - width[d]);
        let ncells: usize = dims.iter().product();
        Self {
            origin,
            inv_cell: width.map(|w| 1.0 / w),
            dims,
            period,
            cell_start: vec![0; ncells + 1],
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

    /// Cells per axis, guard cells included (x fastest in the linear index).
    pub fn dims(&self) -> [usize; D] {
        self.dims
    }

    /// The cell of particle k of the sorted order (after `sort`).
    #[inline]
    pub fn cell_of_sorted(&self, k: usize) -> usize {
        self.sorted_cell[k] as usize
    }

    /// The per-particle array of the grid: the cell of each particle in the sorted order.
    pub fn sorted_cells(&self) -> ArraySize {
        ArraySize::of("cell of sorted particle", &self.sorted_cell)
    }

    pub fn cell_count(&self) -> usize {
        self.cell_start.len() - 1
    }

    /// Linear index of the cell holding `x`, or None outside the interior cells.
    #[inline]
    pub fn cell_of(&self, x: [f64; D]) -> Option<usize> {
        let mut lin = 0;
        for d in (0..D).rev() {
            let c = ((x[d] - self.origin[d]) * self.inv_cell[d]).floor();
            if !(c >= 1.0 && c <= (self.dims[d] - 2) as f64) {
                return None;
            }
            lin = lin * self.dims[d] + c as usize;
        }
        Some(lin)
    }

    /// Counting sort by cell. Fills `cell_of` (per particle, input order) and `order`
    /// (new position → old index, stable within a cell) and the cell ranges.
    pub fn sort(
        &mut self,
        pos: &[Vec<f64>; D],
        cell_of: &mut Vec<u32>,
        order: &mut Vec<u32>,
    ) -> Result<(), OutsideGrid> {
        let n = pos[0].len();
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
        self.cell_start.fill(0);
        for &c in cell_of.iter() {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..self.cell_count() {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        order.resize(n, 0);
        self.sorted_cell.resize(n, 0);
        let mut next = self.cell_start.clone();
        for (i, &c) in cell_of.iter().enumerate() {
            let k = next[c as usize] as usize;
            order[k] = i as u32;
            self.sorted_cell[k] = c;
            next[c as usize] += 1;
        }
        Ok(())
    }

    /// Calls `f(range, x′)` with the contiguous particle ranges covering the 3^D cells around
    /// `x`'s cell (after `sort`; `x` must lie in an interior cell), with x′ the image of `x`
    /// next to the range's particles: `x` itself, or shifted by a period where the cells around
    /// it continue across a periodic boundary. Each row of three cells along x is one range,
    /// or two where it wraps around a periodic x axis.
    #[inline]
    pub fn for_each_neighbour_range(&self, x: [f64; D], mut f: impl FnMut(Range<usize>, [f64; D])) {
        let c: [usize; D] =
            std::array::from_fn(|d| ((x[d] - self.origin[d]) * self.inv_cell[d]).floor() as usize);
        let rows = 3usize.pow(D as u32 - 1);
        for row in 0..rows {
            // Row (c0 − 1 ..= c0 + 1, c1 + o1, c2 + o2) with o in {−1, 0, 1}.
            let mut image = x;
            let (mut lin, mut code, mut stride) = (0, row, self.dims[0]);
            for d in 1..D {
                let o = code % 3;
                code /= 3;
                lin += self.wrapped(d, c[d] + o - 1, &mut image) * stride;
                stride *= self.dims[d];
            }
            let (first, last) = (c[0] - 1, c[0] + 1);
            let mut emit = |from: usize, to: usize, image: [f64; D]| {
                let start = self.cell_start[lin + from] as usize;
                let end = self.cell_start[lin + to + 1] as usize;
                if start < end {
                    f(start..end, image);
                }
            };
            let interior = self.dims[0] - 2;
            match self.period[0] {
                Some(_) if first == 0 => {
                    emit(interior, interior, self.shifted(0, 1.0, image));
                    emit(1, last, image);
                }
                Some(_) if last == interior + 1 => {
                    emit(first, interior, image);
                    emit(1, 1, self.shifted(0, -1.0, image));
                }
                _ => emit(first, last, image),
            }
        }
    }

    /// Cell index `k` along axis `d`, wrapped into the interior cells along a periodic axis
    /// (with `image` moved by the period accordingly).
    #[inline]
    fn wrapped(&self, d: usize, k: usize, image: &mut [f64; D]) -> usize {
        let interior = self.dims[d] - 2;
        match self.period[d] {
            Some(_) if k == 0 => {
                *image = self.shifted(d, 1.0, *image);
                interior
            }
            Some(_) if k == interior + 1 => {
                *image = self.shifted(d, -1.0, *image);
                1
            }
            _ => k,
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
