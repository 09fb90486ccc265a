//! Cell list: a uniform grid of cells at least one kernel support wide, particles
//! counting-sorted by linear cell index (x fastest), so that the 3^D neighbour cells of a
//! particle are 3^(D−1) contiguous index ranges of the particle arrays.

use crate::memory::ArraySize;
use std::ops::Range;

#[derive(Clone, Debug)]
pub struct CellList<const D: usize> {
    /// Lower corner of cell (0, 0, …); the grid has one empty guard cell on each side.
    origin: [f64; D],
    inv_cell: f64,
    dims: [usize; D],
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
    /// Grid over the box [lo, hi] with cells of edge ≥ `cell` (the kernel support).
    pub fn new(lo: [f64; D], hi: [f64; D], cell: f64) -> Self {
        let dims = std::array::from_fn(|d| ((hi[d] - lo[d]) / cell).ceil().max(1.0) as usize + 2);
        let origin = std::array::from_fn(|d| lo[d] - cell);
        let ncells: usize = dims.iter().product();
        Self {
            origin,
            inv_cell: 1.0 / cell,
            dims,
            cell_start: vec![0; ncells + 1],
            sorted_cell: Vec::new(),
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
            let c = ((x[d] - self.origin[d]) * self.inv_cell).floor();
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

    /// Calls `f` with the 3^(D−1) contiguous particle ranges covering the cells around `x`'s
    /// cell (after `sort`; `x` must lie in an interior cell).
    #[inline]
    pub fn for_each_neighbour_range(&self, x: [f64; D], mut f: impl FnMut(Range<usize>)) {
        let c: [usize; D] =
            std::array::from_fn(|d| ((x[d] - self.origin[d]) * self.inv_cell).floor() as usize);
        let rows = 3usize.pow(D as u32 - 1);
        for row in 0..rows {
            // Cell (c0 − 1, c1 + o1, c2 + o2) with o in {−1, 0, 1}.
            let mut lin = 0;
            let mut code = row;
            let mut stride = 1;
            for d in 0..D {
                let cd = if d == 0 {
                    c[0] - 1
                } else {
                    let o = code % 3;
                    code /= 3;
                    c[d] + o - 1
                };
                lin += cd * stride;
                stride *= self.dims[d];
            }
            let start = self.cell_start[lin] as usize;
            let end = self.cell_start[lin + 3] as usize;
            if start < end {
                f(start..end);
            }
        }
    }
}
