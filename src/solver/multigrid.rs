//! Aggregation multigrid preconditioner for the PPE: the fine Jacobi step plus a coarse-grid
//! correction computed by a V-cycle over the blocks of the cell list.
//!
//! Level 0 is the particle operator itself, applied matrix-free. Level 1 has 1 + D unknowns per
//! block of the cell list (`CellList::blocks`, each at least one kernel support wide): the
//! particles of a block form one aggregate, and a block's unknowns are the coefficients of a
//! constant and of the D linear functions φ_d = (x_d − c_d)/H_d about its centre c (H its
//! width), so interpolation is linear within each block and discontinuous between blocks. The
//! coarse operator is the Galerkin product A₁ = Pᵀ A P, a 3^D-point stencil of (1 + D) × (1 + D)
//! blocks since a block is one support wide, smoothed by block Jacobi. A linear function per
//! block represents a smooth pressure error to second order where a constant leaves its slope:
//! BiCGSTAB takes about two thirds of the iterations of constant aggregates
//! (docs/performance.md, "The pressure solve"). Each further level merges 2^D cells of the
//! level below's constant parts, piecewise constant, which keeps the 3^D stencil. The coarsest
//! level (at most `COARSEST` cells) is relaxed by many sweeps; the others are smoothed by damped
//! Jacobi, `SMOOTHING_SWEEPS` sweeps before and after their coarse correction, which
//! piecewise-constant interpolation leaves too small on smooth errors and is scaled by
//! `OVER_CORRECTION` (Blaheta 1986; Vaněk, Mandel & Brezina 1996 for the analysis).
//!
//! A level is held over its active cells only, the cells holding unknowns, in compressed rows:
//! in a tank that is mostly air or dry wall the empty cells would otherwise cost as much as the
//! water (docs/performance.md, "The pressure solve").
//!
//! On the particles the two parts are added, not applied one after the other (an additive
//! two-level method): z = D⁻¹ r + s P V(Pᵀ r), V the V-cycle of level 1. A multiplicative
//! cycle (smooth, correct, smooth) converges in fewer iterations but applies the particle
//! operator twice per preconditioner call, four times per BiCGSTAB iteration on top of
//! BiCGSTAB's own two; the additive one applies it never. On the 3D dam break the additive
//! cycle takes more BiCGSTAB iterations but solves faster; the weight s of the coarse part
//! (`COARSE_WEIGHT`) is picked on the same runs (docs/performance.md, "The pressure solve").
//!
//! The preconditioner is a fixed linear map of the residual, as BiCGSTAB needs, and every sum
//! runs in a fixed order: the result does not depend on the thread count.

use crate::math::memory::ArraySize;
use crate::math::reduce::fill;
use crate::solver::krylov::{LinearOperator, Preconditioner, SolverError};
use rayon::prelude::*;

/// Damping of the Jacobi smoother.
const JACOBI_WEIGHT: f64 = 0.7;
/// Scaling of the coarse-grid correction within the V-cycle (piecewise-constant interpolation).
const OVER_CORRECTION: f64 = 1.6;
/// Weight s of the coarse part against the fine Jacobi part D⁻¹ r of the additive
/// preconditioner.
const COARSE_WEIGHT: f64 = 0.85;
/// A level with at most this many cells is the coarsest.
const COARSEST: usize = 64;
/// Jacobi sweeps on the coarsest level.
const COARSEST_SWEEPS: usize = 40;
/// Jacobi sweeps before and after the coarse correction on the other structured levels: on
/// the 3D dam break three take far fewer BiCGSTAB iterations than one, for a faster step, and
/// more save little (docs/performance.md, "The pressure solve").
const SMOOTHING_SWEEPS: usize = 3;
/// A diagonal at most this fraction of its row's Σ|a| is taken for zero: a cell whose unknowns
/// couple only to each other has a coarse diagonal that is zero in exact arithmetic, and its
/// rounding (~1e-16 of the row) would put a factor 1e16 into the smoother.
const NEGLIGIBLE_DIAGONAL: f64 = 1e-12;
/// A row of level 1 whose sum exceeds this fraction of its Σ|a| couples to a fixed unknown
/// (the sum of a row coupled to none is zero but for rounding, ~1e-16 of Σ|a|).
const ANCHORED_ROW_SUM: f64 = 1e-9;
/// A pivot at most this fraction of its diagonal block's Σ|a| makes the block singular
/// (`invert_block`): the linear functions of a cell with particles on one line or plane are
/// not independent, and their block's rounding would put a large factor into the smoother.
const SINGULAR_PIVOT: f64 = 1e-4;
/// A level with fewer active cells than this (over m² for m unknowns per cell) computes its
/// residual on the calling thread: a row is a few dozen flops per unknown pair, less than
/// handing the work to the pool costs.
const PARALLEL_CELLS: usize = 8192;

/// A particle operator whose unknowns are grouped into the cells of a grid of `dims` cells
/// (x fastest): the fine level of the multigrid.
pub trait Aggregated<const D: usize>: LinearOperator {
    fn dims(&self) -> [usize; D];
    /// The cell of unknown i, or None for an unknown held fixed (a Dirichlet row of the
    /// identity, outside every aggregate).
    fn aggregate(&self, i: usize) -> Option<usize>;
    /// φ(x_i) ∈ [−½, ½]^D: unknown i's offset from the centre of its cell, in cell widths.
    /// Level 1 has 1 + D unknowns per cell, the coefficients of the constant φ_0 = 1 and of
    /// the linear functions φ_1 … φ_D.
    fn linear_basis(&self, i: usize) -> [f64; D];
    /// Adds row i of A times the basis of level 1 into the stencil row of i's cell:
    /// `row[slot (1 + D) + l] += a_ij φ_l(x_j)` for each entry and l = 0 … D, with `slot` the
    /// position of j's cell in the 3^D stencil around i's cell (see [`stencil_slot`]). Returns
    /// a_ii with the bits `LinearOperator::diagonal` gives it: the build takes the fine
    /// diagonal from here instead of from a pass of its own.
    fn add_coarse_row(&self, i: usize, row: &mut [f64]) -> f64;
}

/// Index in the 3^D stencil of the cell offset (o_0, …, o_{D−1}) ∈ {−1, 0, 1}^D, x fastest.
pub fn stencil_slot<const D: usize>(offset: [i64; D]) -> usize {
    (0..D)
        .rev()
        .fold(0, |s, d| 3 * s + (offset[d] + 1) as usize)
}

/// The offset of cell `to` from cell `from` in a grid of `dims` cells, if they are neighbours.
fn cell_offset<const D: usize>(dims: [usize; D], from: usize, to: usize) -> [i64; D] {
    let (mut a, mut b) = (from, to);
    std::array::from_fn(|d| {
        let o = (b % dims[d]) as i64 - (a % dims[d]) as i64;
        a /= dims[d];
        b /= dims[d];
        o
    })
}

/// The 3^D-point stencils of one structured level over its active cells: one row of `3^D`
/// blocks of m × m coefficients (row-major) per active cell (m unknowns per cell), the form
/// the Galerkin products are summed in.
struct Stencils<const D: usize> {
    dims: [usize; D],
    m: usize,
    /// Grid index of each active cell, ascending (x fastest).
    cells: Vec<u32>,
    rows: Vec<f64>,
}

impl<const D: usize> Stencils<D> {
    const WIDTH: usize = 3usize.pow(D as u32);
    const CENTRE: usize = (Self::WIDTH - 1) / 2;

    fn new(dims: [usize; D], m: usize, cells: Vec<u32>) -> Self {
        Self {
            dims,
            m,
            rows: vec![0.0; cells.len() * Self::WIDTH * m * m],
            cells,
        }
    }

    /// Coefficients of one cell's row.
    fn row_len(&self) -> usize {
        Self::WIDTH * self.m * self.m
    }

    /// Row of active cell k.
    fn row(&self, k: usize) -> &[f64] {
        &self.rows[k * self.row_len()..(k + 1) * self.row_len()]
    }

    /// The active index of grid cell c, if active.
    fn active_index(&self, c: usize) -> Option<usize> {
        self.cells.binary_search(&(c as u32)).ok()
    }

    /// The active index of the neighbour of active cell k in each slot of its stencil
    /// (`u32::MAX`: outside the grid or holding no unknowns), in slot order.
    fn neighbours(&self) -> Vec<u32> {
        let mut neighbours = Vec::with_capacity(self.cells.len() * Self::WIDTH);
        for &c in &self.cells {
            for_each_offset::<D>(|_, offset| {
                let n = neighbour(self.dims, c as usize, offset).and_then(|n| self.active_index(n));
                neighbours.push(n.map_or(u32::MAX, |n| n as u32));
            });
        }
        neighbours
    }
}

/// The inverse of the m × m diagonal block `a` (row-major) of a row whose coefficients sum to
/// `size` in absolute value, into `inv`: by Gauss–Jordan elimination with partial pivoting;
/// where a pivot is negligible against the block (its unknowns' linear functions are not
/// independent: a cell with one particle, or with particles in one plane), the inverse of its
/// constant mode alone, 0 where that too is negligible against the row (`NEGLIGIBLE_DIAGONAL`).
fn invert_block(a: &[f64], m: usize, size: f64, inv: &mut [f64]) {
    inv.fill(0.0);
    let constant_only = |inv: &mut [f64]| {
        inv.fill(0.0);
        if a[0] > NEGLIGIBLE_DIAGONAL * size {
            inv[0] = 1.0 / a[0];
        }
    };
    if m == 1 {
        return constant_only(inv);
    }
    let block_size = a.iter().map(|a| a.abs()).sum::<f64>();
    let mut w = a.to_vec();
    for k in 0..m {
        inv[k * m + k] = 1.0;
    }
    for col in 0..m {
        let pivot = (col..m)
            .max_by(|&x, &y| w[x * m + col].abs().total_cmp(&w[y * m + col].abs()))
            .expect("a row");
        if w[pivot * m + col].abs() <= SINGULAR_PIVOT * block_size {
            return constant_only(inv);
        }
        for k in 0..m {
            w.swap(col * m + k, pivot * m + k);
            inv.swap(col * m + k, pivot * m + k);
        }
        let d = 1.0 / w[col * m + col];
        for k in 0..m {
            w[col * m + k] *= d;
            inv[col * m + k] *= d;
        }
        for r in (0..m).filter(|&r| r != col) {
            let f = w[r * m + col];
            for k in 0..m {
                w[r * m + k] -= f * w[col * m + k];
                inv[r * m + k] -= f * inv[col * m + k];
            }
        }
    }
}

/// One structured level, held over its active cells only: the cells holding unknowns. The
/// others (air, dry walls: most of a tank that is mostly empty) would have the identity row
/// and a zero right-hand side, solution and residual, so they are left out.
struct Level<const D: usize> {
    dims: [usize; D],
    /// Unknowns per cell: 1, or 1 + D on a first level with linear functions.
    m: usize,
    /// Grid index of each active cell, ascending.
    cells: Vec<u32>,
    /// The operator as the 3^D stencil of m × m blocks (row-major) of each active cell, in
    /// slot order: `value[(k 3^D + slot) m² ..]` couples active cell k to active cell
    /// `neighbour[k 3^D + slot]` (`u32::MAX`, and a zero block, where there is none). Held as
    /// the build sums it, so that the hierarchy is never held twice.
    neighbour: Vec<u32>,
    value: Vec<f64>,
    /// The inverse of each cell's diagonal block (m × m).
    inv_diag: Vec<f64>,
    /// The active cell of the next coarser level holding each active cell (empty on the
    /// coarsest).
    parent: Vec<u32>,
    /// Right-hand side, solution and residual of this level, m per cell.
    b: Vec<f64>,
    x: Vec<f64>,
    r: Vec<f64>,
}

impl<const D: usize> Level<D> {
    /// The level of `stencils` over its active cells `cells` (grid indices, ascending): the
    /// cells holding unknowns. A cell whose unknowns couple to nothing (every weight of their
    /// rows clipped: spray torn off at a large time step) has a zero diagonal here, or one
    /// that is zero but for rounding (`NEGLIGIBLE_DIAGONAL`), and takes no smoothing correction.
    fn of(stencils: Stencils<D>) -> Self {
        let (m, mm) = (stencils.m, stencils.m * stencils.m);
        let centre = Stencils::<D>::CENTRE;
        let cells = stencils.cells.len();
        let mut inv_diag = vec![0.0; cells * mm];
        for (k, inv) in inv_diag.chunks_exact_mut(mm).enumerate() {
            let row = stencils.row(k);
            let size = row.iter().map(|a| a.abs()).sum::<f64>();
            invert_block(&row[centre * mm..(centre + 1) * mm], m, size, inv);
        }
        Self {
            dims: stencils.dims,
            m,
            neighbour: stencils.neighbours(),
            value: stencils.rows,
            inv_diag,
            parent: Vec::new(),
            b: vec![0.0; cells * m],
            x: vec![0.0; cells * m],
            r: vec![0.0; cells * m],
            cells: stencils.cells,
        }
    }

    /// The (slot, neighbour's active index) of active cell k's stencil entries that couple to
    /// a cell holding unknowns, in slot order; the entry's block is `block(k, slot)`.
    fn entries(&self, k: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        let width = Stencils::<D>::WIDTH;
        self.neighbour[k * width..(k + 1) * width]
            .iter()
            .enumerate()
            .filter(|&(_, &n)| n != u32::MAX)
            .map(|(slot, &n)| (slot, n as usize))
    }

    /// The m × m block of active cell k's stencil slot `slot`.
    fn block(&self, k: usize, slot: usize) -> &[f64] {
        let (mm, width) = (self.m * self.m, Stencils::<D>::WIDTH);
        &self.value[(k * width + slot) * mm..(k * width + slot + 1) * mm]
    }

    fn len(&self) -> usize {
        self.cells.len()
    }

    /// Cells of the level's grid, active or not.
    fn grid_cells(&self) -> usize {
        self.dims.iter().product()
    }

    /// The active index of grid cell c, if active.
    fn active_index(&self, c: usize) -> Option<usize> {
        self.cells.binary_search(&(c as u32)).ok()
    }

    /// r = b − A x on this level.
    fn residual(&mut self) {
        match self.m {
            1 => self.residual_of::<1>(),
            3 => self.residual_of::<3>(),
            4 => self.residual_of::<4>(),
            m => unreachable!("{m} unknowns per cell: 1, or 1 + D"),
        }
    }

    /// `residual` with M unknowns per cell, each block row an unrolled product.
    fn residual_of<const M: usize>(&mut self) {
        let mut r = std::mem::take(&mut self.r);
        let (x, b) = (&self.x, &self.b);
        let row = |k: usize| -> [f64; M] {
            let mut r: [f64; M] = std::array::from_fn(|l| b[k * M + l]);
            for (slot, n) in self.entries(k) {
                let (a, x) = (self.block(k, slot), &x[n * M..(n + 1) * M]);
                for l in 0..M {
                    for c in 0..M {
                        r[l] -= a[l * M + c] * x[c];
                    }
                }
            }
            r
        };
        if self.len() * M * M < PARALLEL_CELLS {
            for (k, r) in r.chunks_exact_mut(M).enumerate() {
                r.copy_from_slice(&row(k));
            }
        } else {
            r.par_chunks_exact_mut(M)
                .enumerate()
                .for_each(|(k, r)| r.copy_from_slice(&row(k)));
        }
        self.r = r;
    }

    /// The next coarser level: 2^D cells merged, A_c = Pᵀ A P. Sets this level's `parent`.
    /// Of a level with linear functions, the constant functions' part only (their coarse
    /// interpolation is the constant).
    fn coarsen(&mut self) -> Level<D> {
        let dims = self.dims.map(|n| n.div_ceil(2));
        let parent_of = |c: u32| parent_cell(self.dims, dims, c as usize) as u32;
        let mut parents: Vec<u32> = self.cells.iter().map(|&c| parent_of(c)).collect();
        parents.sort_unstable();
        parents.dedup();
        let mut stencils = Stencils::new(dims, 1, parents);
        self.parent = self
            .cells
            .iter()
            .map(|&c| {
                stencils
                    .active_index(parent_of(c) as usize)
                    .expect("an active cell's parent is active") as u32
            })
            .collect();
        let w = Stencils::<D>::WIDTH;
        for k in 0..self.len() {
            let parent = stencils.cells[self.parent[k] as usize] as usize;
            for (slot, n) in self.entries(k) {
                let to = parent_of(self.cells[n]) as usize;
                let s = stencil_slot(cell_offset(dims, parent, to));
                stencils.rows[self.parent[k] as usize * w + s] += self.block(k, slot)[0];
            }
        }
        Level::of(stencils)
    }
}

/// The linear index of cell `c` moved by `offset` in a grid of `dims` cells, if inside it.
fn neighbour<const D: usize>(dims: [usize; D], c: usize, offset: [i64; D]) -> Option<usize> {
    let (mut rest, mut lin, mut stride) = (c, 0usize, 1usize);
    for d in 0..D {
        let k = (rest % dims[d]) as i64 + offset[d];
        rest /= dims[d];
        if k < 0 || k >= dims[d] as i64 {
            return None;
        }
        lin += k as usize * stride;
        stride *= dims[d];
    }
    Some(lin)
}

/// Calls `f(slot, offset)` for each of the 3^D stencil offsets.
fn for_each_offset<const D: usize>(mut f: impl FnMut(usize, [i64; D])) {
    for slot in 0..3usize.pow(D as u32) {
        let mut rest = slot;
        let offset = std::array::from_fn(|_| {
            let o = (rest % 3) as i64 - 1;
            rest /= 3;
            o
        });
        f(slot, offset);
    }
}

/// The cell of the coarser grid `coarse` holding cell `c` of the grid `fine`.
fn parent_cell<const D: usize>(fine: [usize; D], coarse: [usize; D], c: usize) -> usize {
    let (mut rest, mut lin, mut stride) = (c, 0, 1);
    for d in 0..D {
        lin += (rest % fine[d]) / 2 * stride;
        rest /= fine[d];
        stride *= coarse[d];
    }
    lin
}

/// The set of union–find element k (path halving).
fn find(root: &mut [usize], mut k: usize) -> usize {
    while root[k] != k {
        root[k] = root[root[k]];
        k = root[k];
    }
    k
}

/// The multigrid hierarchy of one PPE and the work vectors of its V-cycle.
#[derive(Default)]
pub struct Multigrid<const D: usize> {
    fine_inv_diag: Vec<f64>,
    /// Cell of each fine unknown (`u32::MAX`: outside every aggregate).
    fine_cell: Vec<u32>,
    /// φ(x_i) of each fine unknown where the first level has linear functions (else empty).
    fine_basis: Vec<[f64; D]>,
    levels: Vec<Level<D>>,
}

/// The unknowns of each cell of level 1, in index order: a counting sort of the unknowns by
/// cell (no list per cell).
struct Members {
    /// The unknowns of cell c are `unknowns[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    unknowns: Vec<u32>,
}

impl Members {
    /// The members of the `cells` cells, with `cell_of[i]` the cell of unknown i (`u32::MAX`:
    /// none).
    fn of(cell_of: &[u32], cells: usize) -> Self {
        let mut start = vec![0u32; cells + 1];
        for &c in cell_of.iter().filter(|&&c| c != u32::MAX) {
            start[c as usize + 1] += 1;
        }
        for c in 0..cells {
            start[c + 1] += start[c];
        }
        let mut next = start[..cells].to_vec();
        let mut unknowns = vec![0u32; start[cells] as usize];
        for (i, &c) in cell_of.iter().enumerate().filter(|&(_, &c)| c != u32::MAX) {
            unknowns[next[c as usize] as usize] = i as u32;
            next[c as usize] += 1;
        }
        Self { start, unknowns }
    }

    /// The cells holding unknowns, ascending.
    fn occupied(&self) -> Vec<u32> {
        (0..self.start.len() - 1)
            .filter(|&c| self.start[c + 1] > self.start[c])
            .map(|c| c as u32)
            .collect()
    }

    /// The unknowns of cell c.
    fn of_cell(&self, c: usize) -> &[u32] {
        &self.unknowns[self.start[c] as usize..self.start[c + 1] as usize]
    }
}

impl<const D: usize> Multigrid<D> {
    /// The fine unknowns of each region of the first level that no row couples to a fixed
    /// unknown: cells joined by nonzero couplings, none of whose rows sums above zero (a row of
    /// level 1 sums to the weight its particles give to the fixed unknowns, the Dirichlet rows).
    /// Such a region's part of A is singular: water sealed off from the free surface. Unknowns
    /// in index order, regions by their first unknown; none when every region is anchored.
    pub fn unanchored_regions(&self) -> Vec<Vec<usize>> {
        let Some(first) = self.levels.first() else {
            return Vec::new();
        };
        // Union–find over the active cells, each set named by its smallest cell.
        let mut root: Vec<usize> = (0..first.len()).collect();
        for k in 0..first.len() {
            for (slot, n) in first.entries(k) {
                if first.block(k, slot).iter().all(|&a| a == 0.0) {
                    continue;
                }
                let (a, b) = (find(&mut root, k), find(&mut root, n));
                root[a.max(b)] = a.min(b);
            }
        }
        let mut anchored = vec![false; first.len()];
        for k in 0..first.len() {
            let row: Vec<f64> = first
                .entries(k)
                .map(|(slot, _)| first.block(k, slot)[0])
                .collect();
            let size: f64 = row.iter().map(|a| a.abs()).sum();
            if row.iter().sum::<f64>() > ANCHORED_ROW_SUM * size {
                anchored[find(&mut root, k)] = true;
            }
        }
        let (mut regions, mut slot) = (Vec::<Vec<usize>>::new(), vec![usize::MAX; first.len()]);
        for (i, &c) in self.fine_cell.iter().enumerate() {
            if c == u32::MAX {
                continue;
            }
            let r = find(&mut root, c as usize);
            if anchored[r] {
                continue;
            }
            if slot[r] == usize::MAX {
                slot[r] = regions.len();
                regions.push(Vec::new());
            }
            regions[slot[r]].push(i);
        }
        regions
    }

    /// The arrays of the fine level, one entry per unknown each (the coarser levels hold one
    /// entry per cell).
    pub fn fine_arrays(&self) -> Vec<ArraySize> {
        let Multigrid {
            fine_inv_diag,
            fine_cell,
            fine_basis,
            levels: _,
        } = self;
        vec![
            ArraySize::of("multigrid D⁻¹", fine_inv_diag),
            ArraySize::of("multigrid aggregate", fine_cell),
            ArraySize::of("multigrid linear basis", fine_basis),
        ]
    }

    /// Builds the hierarchy for operator `a`.
    pub fn build(&mut self, a: &impl Aggregated<D>) -> Result<(), SolverError> {
        // The last hierarchy goes before the new one is summed: the two are not held at once.
        self.levels.clear();
        let n = a.len();
        self.fine_cell.resize(n, 0);
        fill(&mut self.fine_cell, |i| {
            a.aggregate(i).map_or(u32::MAX, |c| c as u32)
        });

        let m = 1 + D;
        self.fine_basis.resize(n, [0.0; D]);
        fill(&mut self.fine_basis, |i| a.linear_basis(i));
        let dims = a.dims();
        let members = Members::of(&self.fine_cell, dims.iter().product());
        let mut first = Stencils::new(dims, m, members.occupied());
        // Each cell's stencil row is the sum of its unknowns' rows, in index order; each row
        // gives its own a_ii on the way.
        let mut diagonal = vec![0.0; members.unknowns.len()];
        let mut tasks = Vec::with_capacity(first.cells.len());
        let mut diagonals = &mut diagonal[..];
        let row_len = first.row_len();
        for (row, &c) in first.rows.chunks_mut(row_len).zip(&first.cells) {
            let unknowns = members.of_cell(c as usize);
            let (these, rest) = std::mem::take(&mut diagonals).split_at_mut(unknowns.len());
            tasks.push((row, unknowns, these));
            diagonals = rest;
        }
        let basis = &self.fine_basis;
        tasks.into_par_iter().for_each(|(row, unknowns, diagonal)| {
            // Block (k, l) of slot L of row K of P₁ᵀ A P₁: Σ_i∈K φ_k(x_i) Σ_j∈L a_ij φ_l(x_j).
            let mut times_basis = vec![0.0; Stencils::<D>::WIDTH * m];
            for (&i, d) in unknowns.iter().zip(diagonal) {
                times_basis.fill(0.0);
                *d = a.add_coarse_row(i as usize, &mut times_basis);
                let phi = basis[i as usize];
                for (slot, from) in times_basis.chunks_exact(m).enumerate() {
                    if from.iter().all(|&f| f == 0.0) {
                        continue;
                    }
                    for k in 0..m {
                        let phi_k = if k == 0 { 1.0 } else { phi[k - 1] };
                        let to = &mut row[(slot * m + k) * m..(slot * m + k + 1) * m];
                        for (t, f) in to.iter_mut().zip(from) {
                            *t += phi_k * f;
                        }
                    }
                }
            }
        });
        // The unknowns outside every aggregate are rows of the identity.
        self.fine_inv_diag.clear();
        self.fine_inv_diag.resize(n, 1.0);
        for (&i, &d) in members.unknowns.iter().zip(&diagonal) {
            if d == 0.0 {
                return Err(SolverError::ZeroDiagonal { row: i as usize });
            }
            self.fine_inv_diag[i as usize] = 1.0 / d;
        }
        let first = Level::of(first);
        // From here on an aggregated unknown names its cell by its active index in level 1.
        for c in self.fine_cell.iter_mut().filter(|c| **c != u32::MAX) {
            *c = first
                .active_index(*c as usize)
                .expect("a cell with unknowns is active") as u32;
        }
        self.levels.push(first);
        while self.levels.last().expect("a level").grid_cells() > COARSEST {
            let next = self.levels.last_mut().expect("a level").coarsen();
            self.levels.push(next);
        }
        Ok(())
    }

    /// Restricts the fine residual `r` into level 1's right-hand side (sum over each
    /// aggregate).
    fn restrict_fine(&mut self, r: &[f64]) {
        let first = &mut self.levels[0];
        let m = first.m;
        first.b.fill(0.0);
        for (i, (&r, &c)) in r.iter().zip(&self.fine_cell).enumerate() {
            if c != u32::MAX {
                let c = c as usize * m;
                first.b[c] += r;
                for k in 1..m {
                    first.b[c + k] += self.fine_basis[i][k - 1] * r;
                }
            }
        }
    }

    /// V-cycle on structured level `k` for its right-hand side `b`, solution left in `x`.
    fn cycle(&mut self, k: usize) {
        let last = k + 1 == self.levels.len();
        let (head, tail) = self.levels.split_at_mut(k + 1);
        let level = &mut head[k];
        let sweeps = if last {
            COARSEST_SWEEPS
        } else {
            SMOOTHING_SWEEPS
        };
        level.x.fill(0.0);
        for _ in 0..sweeps {
            smooth(level);
        }
        if last {
            return;
        }
        level.residual();
        let coarse = &mut tail[0];
        coarse.b.fill(0.0);
        let m = level.m;
        for (&p, r) in level.parent.iter().zip(level.r.chunks_exact(m)) {
            coarse.b[p as usize] += r[0];
        }
        self.cycle(k + 1);
        let (head, tail) = self.levels.split_at_mut(k + 1);
        let (level, coarse) = (&mut head[k], &tail[0]);
        for (x, &p) in level.x.chunks_exact_mut(m).zip(&level.parent) {
            x[0] += OVER_CORRECTION * coarse.x[p as usize];
        }
        for _ in 0..SMOOTHING_SWEEPS {
            smooth(level);
        }
    }
}

/// One damped Jacobi sweep x ← x + ω D⁻¹ (b − A x) on a structured level.
fn smooth<const D: usize>(level: &mut Level<D>) {
    level.residual();
    let (x, r, d, m) = (&mut level.x, &level.r, &level.inv_diag, level.m);
    if m == 1 {
        for c in 0..x.len() {
            x[c] += JACOBI_WEIGHT * d[c] * r[c];
        }
        return;
    }
    for (c, (x, r)) in x.chunks_exact_mut(m).zip(r.chunks_exact(m)).enumerate() {
        let d = &d[c * m * m..(c + 1) * m * m];
        for k in 0..m {
            let dr: f64 = (0..m).map(|l| d[k * m + l] * r[l]).sum();
            x[k] += JACOBI_WEIGHT * dr;
        }
    }
}

impl<const D: usize, A: Aggregated<D>> Preconditioner<A> for Multigrid<D> {
    fn setup(&mut self, a: &A) -> Result<(), SolverError> {
        self.build(a)
    }

    /// z ≈ A⁻¹ r: z = D⁻¹ r + s P V(Pᵀ r) (see the module doc).
    fn precondition(&mut self, _: &A, r: &[f64], z: &mut [f64]) {
        self.restrict_fine(r);
        self.cycle(0);
        let (cells, first, inv) = (&self.fine_cell, &self.levels[0], &self.fine_inv_diag);
        let (m, basis) = (first.m, &self.fine_basis);
        fill(z, |i| {
            let coarse = match cells[i] {
                u32::MAX => 0.0,
                c if m == 1 => COARSE_WEIGHT * first.x[c as usize],
                c => {
                    let x = &first.x[c as usize * m..(c as usize + 1) * m];
                    let linear: f64 = (1..m).map(|k| basis[i][k - 1] * x[k]).sum();
                    COARSE_WEIGHT * (x[0] + linear)
                }
            };
            inv[i] * r[i] + coarse
        });
    }
}
