//! The pressures of the wall particles, for the frames only (they enter no equation): the
//! ghost pressures their fluid neighbours give them (`ghosts::Ghosts::wall_pressure`), zero
//! where no fluid is in reach. A wall particle visits only its fluid neighbours (the fluid and
//! the walls are sorted apart): in a large tank most walls are dry, and cost no more than
//! finding their fluid cells empty.

use super::{Stage, StepSettings};
use crate::boundary::ghosts;
use crate::math::reduce::fill;
use crate::neighbours::Neighbours;

pub const NAME: &str = "wall pressure";

pub struct WallPressure;

impl WallPressure {
    /// The pressures of the wall particles, from index `nf` of `pressure` on, from those of
    /// the fluid before it.
    pub fn run<const D: usize>(
        &self,
        nb: &Neighbours<D>,
        ghosts: &ghosts::Ghosts<D>,
        pressure: &mut [f64],
        nf: usize,
    ) {
        let (fluid, walls) = pressure.split_at_mut(nf);
        fill(walls, |k| ghosts.wall_pressure(nb, fluid, nf + k));
    }
}

impl<const D: usize> Stage<D> for WallPressure {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        "pressure of the wall particles, on the steps that end on a frame: kernel mean of the ghost pressures of their fluid neighbours".into()
    }
}
