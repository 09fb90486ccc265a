//! The cell sort: the particles re-sorted by kind and cell, every particle array permuted
//! together, so that the neighbours of a particle lie in a few contiguous index ranges
//! (`neighbours`); particles that left through a periodic boundary come back through the
//! opposite one first.

use super::{Stage, StepError, StepSettings};
use crate::math::memory::ArraySize;
use crate::neighbours::cell_list::CellList;
use crate::particles::Particles;

pub const NAME: &str = "cell list";

/// The grid and the arrays of the sort: cell of each particle, the sorting permutation, and
/// the scratch the permutation goes through.
pub struct CellSort<const D: usize> {
    grid: CellList<D>,
    cell_of: Vec<u32>,
    order: Vec<u32>,
    scratch: Vec<f64>,
}

impl<const D: usize> CellSort<D> {
    pub fn new(grid: CellList<D>) -> Self {
        Self {
            grid,
            cell_of: Vec::new(),
            order: Vec::new(),
            scratch: Vec::new(),
        }
    }

    pub fn grid(&self) -> &CellList<D> {
        &self.grid
    }

    /// Sorts `p` by cell; a particle outside the grid is an error.
    pub fn run(&mut self, p: &mut Particles<D>) -> Result<(), StepError> {
        // (A no-op after a step, which wraps the positions it moves; a checkpoint may still hold
        // positions past the period.)
        self.grid.wrap(&mut p.pos);
        self.grid
            .sort(&p.pos, &p.kind, &mut self.cell_of, &mut self.order)
            .map_err(|out| StepError::LeftDomain { index: out.index })?;
        p.permute(&self.order, &mut self.scratch);
        Ok(())
    }
}

impl<const D: usize> Stage<D> for CellSort<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        "counting sort by cell (x fastest), every particle array permuted together; the runs of cells around each fluid particle, which every pair loop of the step reads instead of searching the grid (about 20 runs of 6 B per fluid particle in 3D, not in the figure)".into()
    }

    fn fluid_only(&self) -> bool {
        false
    }

    fn arrays(&self) -> Vec<ArraySize> {
        let sort = [
            ArraySize::of("cell of particle", &self.cell_of),
            ArraySize::of("sort order", &self.order),
            ArraySize::of("sort scratch", &self.scratch),
            self.grid.sorted_cells(),
        ];
        sort.into_iter().chain(self.grid.runs_arrays()).collect()
    }
}
