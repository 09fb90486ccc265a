//! Aggregation multigrid preconditioner for the PPE: the fine Jacobi step plus a coarse-grid
//! correction computed by a V-cycle over the blocks of the cell list.
//!
//! Level 0 is the particle operator itself, applied matrix-free. Level 1 has one unknown per
//! block of the cell list (`CellList::blocks`, each at least one kernel support wide): the
//! particles of a block form one aggregate, interpolation is piecewise constant, and the coarse
//! operator is the Galerkin product A₁ = Pᵀ A P, a 3^D-point stencil since a block is one
//! support wide; along a periodic axis the stencil wraps around, the first and last cells being
//! adjacent. Each further level merges 2^D cells, which keeps the 3^D stencil. The coarsest
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
/// A level with fewer active cells than this computes its residual on the calling thread: a
/// row is a few dozen flops, less than handing the work to the pool costs.
const PARALLEL_CELLS: usize = 8192;

/// A particle operator whose unknowns are grouped into the cells of a grid of `dims` cells
/// (x fastest): the fine level of the multigrid.
pub trait Aggregated<const D: usize>: LinearOperator {
    fn dims(&self) -> [usize; D];
    /// Whether each axis of the grid is periodic: its first and last cells are adjacent, and
    /// `add_coarse_row` puts a coupling across the boundary in the slot of that adjacency.
    fn periodic(&self) -> [bool; D];
    /// The cell of unknown i, or None for an unknown held fixed (a Dirichlet row of the
    /// identity, outside every aggregate).
    fn aggregate(&self, i: usize) -> Option<usize>;
    /// Adds row i of A into the stencil row of its cell: `row[slot] += a_ij` for each entry,
    /// with `slot` the position of j's cell in the 3^D stencil around i's cell (see
    /// [`stencil_slot`]). Returns a_ii with the bits `LinearOperator::diagonal` gives it: the
    /// build takes the fine diagonal from here instead of from a pass of its own.
    fn add_coarse_row(&self, i: usize, row: &mut [f64]) -> f64;
}

/// Index in the 3^D stencil of the cell offset (o_0, …, o_{D−1}) ∈ {−1, 0, 1}^D, x fastest.
pub fn stencil_slot<const D: usize>(offset: [i64; D]) -> usize {
    (0..D)
        .rev()
        .fold(0, |s, d| 3 * s + (offset[d] + 1) as usize)
}

/// The grid of a structured level: its cells per axis (x fastest in the linear index) and
/// which axes are periodic.
#[derive(Clone, Copy, Debug)]
struct Grid<const D: usize> {
    dims: [usize; D],
    periodic: [bool; D],
}

impl<const D: usize> Grid<D> {
    fn cells(&self) -> usize {
        self.dims.iter().product()
    }

    /// The grid of 2^D cells merged (the last cell along an odd axis alone).
    fn coarser(&self) -> Self {
        Self {
            dims: self.dims.map(|n| n.div_ceil(2)),
            periodic: self.periodic,
        }
    }

    /// The cell of the coarser grid `coarse` holding cell `c`.
    fn parent(&self, coarse: &Self, c: usize) -> usize {
        let (mut rest, mut lin, mut stride) = (c, 0, 1);
        for d in 0..D {
            lin += (rest % self.dims[d]) / 2 * stride;
            rest /= self.dims[d];
            stride *= coarse.dims[d];
        }
        lin
    }

    /// The linear index of cell `c` moved by `offset`, if inside the grid: along a periodic
    /// axis the move wraps around.
    fn neighbour(&self, c: usize, offset: [i64; D]) -> Option<usize> {
        let (mut rest, mut lin, mut stride) = (c, 0usize, 1usize);
        for d in 0..D {
            let n = self.dims[d] as i64;
            let mut k = (rest % self.dims[d]) as i64 + offset[d];
            rest /= self.dims[d];
            if self.periodic[d] {
                k = k.rem_euclid(n);
            } else if k < 0 || k >= n {
                return None;
            }
            lin += k as usize * stride;
            stride *= self.dims[d];
        }
        Some(lin)
    }

    /// The offset of cell `to` from its neighbour `from`, each component −1, 0 or 1: along a
    /// periodic axis of n cells the last cell is one before the first.
    fn offset(&self, from: usize, to: usize) -> [i64; D] {
        let (mut a, mut b) = (from, to);
        std::array::from_fn(|d| {
            let n = self.dims[d] as i64;
            let mut o = (b % self.dims[d]) as i64 - (a % self.dims[d]) as i64;
            a /= self.dims[d];
            b /= self.dims[d];
            if self.periodic[d] && o.abs() > 1 {
                o -= o.signum() * n;
            }
            o
        })
    }
}

/// The 3^D-point stencils of one structured level, one row of `3^D` coefficients per cell of
/// its grid, x fastest: the form the Galerkin products are summed in.
struct Stencils<const D: usize> {
    grid: Grid<D>,
    rows: Vec<f64>,
}

impl<const D: usize> Stencils<D> {
    const WIDTH: usize = 3usize.pow(D as u32);
    const CENTRE: usize = (Self::WIDTH - 1) / 2;

    fn new(grid: Grid<D>) -> Self {
        Self {
            grid,
            rows: vec![0.0; grid.cells() * Self::WIDTH],
        }
    }

    /// Cells of the grid.
    fn cells(&self) -> usize {
        self.rows.len() / Self::WIDTH
    }

    fn row(&self, c: usize) -> &[f64] {
        &self.rows[c * Self::WIDTH..(c + 1) * Self::WIDTH]
    }

    /// Calls `f(n, a_cn)` for the nonzero coefficients of cell c's row, in stencil-slot order,
    /// with n the neighbour cell's grid index.
    fn for_each_coefficient(&self, c: usize, mut f: impl FnMut(usize, f64)) {
        let row = self.row(c);
        for_each_offset::<D>(|slot, offset| {
            if row[slot] != 0.0 {
                if let Some(n) = self.grid.neighbour(c, offset) {
                    f(n, row[slot]);
                }
            }
        });
    }
}

/// One structured level, held over its active cells only: the cells holding unknowns. The
/// others (air, dry walls: most of a tank that is mostly empty) would have the identity row
/// and a zero right-hand side, solution and residual, so they are left out.
struct Level<const D: usize> {
    grid: Grid<D>,
    /// Grid index of each active cell, ascending.
    cells: Vec<u32>,
    /// The operator in compressed rows over the active cells: row k's coefficients are
    /// `value[start[k]..start[k + 1]]`, in stencil-slot order, coupling active cell k to
    /// active cells `column[..]`.
    start: Vec<u32>,
    column: Vec<u32>,
    value: Vec<f64>,
    inv_diag: Vec<f64>,
    /// The active cell of the next coarser level holding each active cell (empty on the
    /// coarsest).
    parent: Vec<u32>,
    /// Right-hand side, solution and residual of this level.
    b: Vec<f64>,
    x: Vec<f64>,
    r: Vec<f64>,
}

impl<const D: usize> Level<D> {
    /// The level of `stencils` over its active cells `cells` (grid indices, ascending): the
    /// cells holding unknowns. A cell whose unknowns couple to nothing (every weight of their
    /// rows clipped: spray torn off at a large time step) has a zero diagonal here, or one
    /// that is zero but for rounding (`NEGLIGIBLE_DIAGONAL`), and takes no smoothing correction.
    fn of(stencils: &Stencils<D>, cells: Vec<u32>) -> Self {
        let centre = Stencils::<D>::CENTRE;
        let mut level = Self {
            grid: stencils.grid,
            start: vec![0],
            column: Vec::new(),
            value: Vec::new(),
            inv_diag: cells
                .iter()
                .map(|&c| {
                    let row = stencils.row(c as usize);
                    let size = row.iter().map(|a| a.abs()).sum::<f64>();
                    if row[centre] > NEGLIGIBLE_DIAGONAL * size {
                        1.0 / row[centre]
                    } else {
                        0.0
                    }
                })
                .collect(),
            parent: Vec::new(),
            b: vec![0.0; cells.len()],
            x: vec![0.0; cells.len()],
            r: vec![0.0; cells.len()],
            cells,
        };
        for k in 0..level.cells.len() {
            stencils.for_each_coefficient(level.cells[k] as usize, |n, a| {
                let n = level
                    .active_index(n)
                    .expect("a coupled cell holds unknowns");
                level.column.push(n as u32);
                level.value.push(a);
            });
            level.start.push(level.column.len() as u32);
        }
        level
    }

    fn len(&self) -> usize {
        self.cells.len()
    }

    /// Cells of the level's grid, active or not.
    fn grid_cells(&self) -> usize {
        self.grid.cells()
    }

    /// The active index of grid cell c, if active.
    fn active_index(&self, c: usize) -> Option<usize> {
        self.cells.binary_search(&(c as u32)).ok()
    }

    /// r = b − A x on this level.
    fn residual(&mut self) {
        let (start, column, value, x, b) =
            (&self.start, &self.column, &self.value, &self.x, &self.b);
        let row = |k: usize| {
            let entries = start[k] as usize..start[k + 1] as usize;
            column[entries.clone()]
                .iter()
                .zip(&value[entries])
                .fold(b[k], |s, (&n, &a)| s - a * x[n as usize])
        };
        if self.r.len() < PARALLEL_CELLS {
            for (k, r) in self.r.iter_mut().enumerate() {
                *r = row(k);
            }
        } else {
            fill(&mut self.r, row);
        }
    }

    /// The next coarser level: 2^D cells merged, A_c = Pᵀ A P. Sets this level's `parent`.
    fn coarsen(&mut self) -> Level<D> {
        let (fine, coarse) = (self.grid, self.grid.coarser());
        let mut stencils = Stencils::new(coarse);
        let w = Stencils::<D>::WIDTH;
        for k in 0..self.len() {
            let parent = fine.parent(&coarse, self.cells[k] as usize);
            for e in self.start[k] as usize..self.start[k + 1] as usize {
                let n = self.cells[self.column[e] as usize] as usize;
                let to = fine.parent(&coarse, n);
                let s = stencil_slot(coarse.offset(parent, to));
                stencils.rows[parent * w + s] += self.value[e];
            }
        }
        let mut parents: Vec<u32> = self
            .cells
            .iter()
            .map(|&c| fine.parent(&coarse, c as usize) as u32)
            .collect();
        parents.sort_unstable();
        parents.dedup();
        let coarse = Level::of(&stencils, parents);
        self.parent = self
            .cells
            .iter()
            .map(|&c| {
                let p = fine.parent(&coarse.grid, c as usize);
                coarse
                    .active_index(p)
                    .expect("an active cell's parent is active") as u32
            })
            .collect();
        coarse
    }
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

    /// The unknowns of each cell in turn.
    fn cells(&self) -> impl Iterator<Item = &[u32]> {
        self.start
            .windows(2)
            .map(|w| &self.unknowns[w[0] as usize..w[1] as usize])
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
        let entries = |k: usize| first.start[k] as usize..first.start[k + 1] as usize;
        // Union–find over the active cells, each set named by its smallest cell.
        let mut root: Vec<usize> = (0..first.len()).collect();
        for k in 0..first.len() {
            for e in entries(k) {
                let (a, b) = (
                    find(&mut root, k),
                    find(&mut root, first.column[e] as usize),
                );
                root[a.max(b)] = a.min(b);
            }
        }
        let mut anchored = vec![false; first.len()];
        for k in 0..first.len() {
            let row = &first.value[entries(k)];
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
            levels: _,
        } = self;
        vec![
            ArraySize::of("multigrid D⁻¹", fine_inv_diag),
            ArraySize::of("multigrid aggregate", fine_cell),
        ]
    }

    /// Builds the hierarchy for operator `a`.
    pub fn build(&mut self, a: &impl Aggregated<D>) -> Result<(), SolverError> {
        let n = a.len();
        self.fine_cell.resize(n, 0);
        fill(&mut self.fine_cell, |i| {
            a.aggregate(i).map_or(u32::MAX, |c| c as u32)
        });

        let mut first = Stencils::new(Grid {
            dims: a.dims(),
            periodic: a.periodic(),
        });
        let members = Members::of(&self.fine_cell, first.cells());
        // Each cell's stencil row is the sum of its unknowns' rows, in index order; each row
        // gives its own a_ii on the way.
        let mut diagonal = vec![0.0; members.unknowns.len()];
        let mut tasks = Vec::with_capacity(members.start.len());
        let mut diagonals = &mut diagonal[..];
        for (row, unknowns) in first
            .rows
            .chunks_mut(Stencils::<D>::WIDTH)
            .zip(members.cells())
        {
            let (these, rest) = std::mem::take(&mut diagonals).split_at_mut(unknowns.len());
            tasks.push((row, unknowns, these));
            diagonals = rest;
        }
        tasks.into_par_iter().for_each(|(row, unknowns, diagonal)| {
            for (&i, d) in unknowns.iter().zip(diagonal) {
                *d = a.add_coarse_row(i as usize, row);
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
        let first = Level::of(&first, members.occupied());
        // From here on an aggregated unknown names its cell by its active index in level 1.
        for c in self.fine_cell.iter_mut().filter(|c| **c != u32::MAX) {
            *c = first
                .active_index(*c as usize)
                .expect("a cell with unknowns is active") as u32;
        }
        self.levels.clear();
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
        first.b.fill(0.0);
        for (&r, &c) in r.iter().zip(&self.fine_cell) {
            if c != u32::MAX {
                first.b[c as usize] += r;
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
        for (&p, &r) in level.parent.iter().zip(&level.r) {
            coarse.b[p as usize] += r;
        }
        self.cycle(k + 1);
        let (head, tail) = self.levels.split_at_mut(k + 1);
        let (level, coarse) = (&mut head[k], &tail[0]);
        for (x, &p) in level.x.iter_mut().zip(&level.parent) {
            *x += OVER_CORRECTION * coarse.x[p as usize];
        }
        for _ in 0..SMOOTHING_SWEEPS {
            smooth(level);
        }
    }
}

/// One damped Jacobi sweep x ← x + ω D⁻¹ (b − A x) on a structured level.
fn smooth<const D: usize>(level: &mut Level<D>) {
    level.residual();
    let (x, r, d) = (&mut level.x, &level.r, &level.inv_diag);
    for c in 0..x.len() {
        x[c] += JACOBI_WEIGHT * d[c] * r[c];
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
        fill(z, |i| {
            let coarse = match cells[i] {
                u32::MAX => 0.0,
                c => COARSE_WEIGHT * first.x[c as usize],
            };
            inv[i] * r[i] + coarse
        });
    }
}
