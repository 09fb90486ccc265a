//! The kernel gradient correction L_i = M_i⁻¹ of Eq. (24)–(25) for the divergence and velocity
//! gradients.
//!
//! Inside the fluid (no free surface in reach) the moment matrix measures the disorder of the
//! particles, not a truncated support: corrected there, the divergence of the PPE source
//! amplifies that disorder into the pressure (a collision of two blocks then gains energy
//! instead of losing it: docs/stabilisation.md, "Near the free surface only: the divergence
//! correction and the Taylor step"). So L_i is kept only where the free surface is in reach,
//! and stored for those particles only (a few per cent of a large run): their slots
//! are given out in index order, then L_i is inverted from the moments of each. The pressure
//! gradient keeps its correction L'_i everywhere (`free_surface`), which inside the fluid
//! corrects the wall ghosts' missing tangential gradient.

use super::{Stage, StepSettings};
use crate::math::memory::ArraySize;
use crate::neighbours::Neighbours;
use crate::particles::Particles;
use crate::sph::{self, Correction, Corrections, NO_SLOT};
use rayon::prelude::*;

pub const NAME: &str = "kernel correction";

#[derive(Default)]
pub struct KernelCorrection<const D: usize> {
    /// L_i of each slot.
    corrections: Vec<Correction<D>>,
    /// Each particle's slot in `corrections` (`sph::NO_SLOT`: none, the particle has no free
    /// surface in reach) and the particle of each slot.
    slot: Vec<u32>,
    corrected: Vec<u32>,
}

impl<const D: usize> KernelCorrection<D> {
    /// L_i of the fluid particles whose support is not full (`full_support`).
    pub fn run(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        full_support: &[bool],
        min_determinant: f64,
    ) -> Corrections<'_, D> {
        self.slot.resize(full_support.len(), NO_SLOT);
        self.corrected.clear();
        for (i, slot) in self.slot.iter_mut().enumerate() {
            *slot = if !full_support[i] {
                self.corrected.push(i as u32);
                (self.corrected.len() - 1) as u32
            } else {
                NO_SLOT
            };
        }
        self.corrections.resize(self.corrected.len(), None);
        self.corrections
            .par_iter_mut()
            .zip(&self.corrected)
            .for_each(|(l, &i)| {
                // The free surface's walk inverts the same moments for the eddy viscosity's
                // strain rate (`free_surface::particle_support`): keep the two alike.
                let moments = sph::support_moments(nb, p, i as usize);
                *l = sph::gradient_correction(moments.m, min_determinant);
            });
        Corrections::sparse(true, &self.slot, &self.corrections)
    }
}

impl<const D: usize> Stage<D> for KernelCorrection<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        format!("L_i = M_i⁻¹ (Eq. 24–25) for the divergence and velocity gradients, only where the free surface is in reach and stored for those particles only ({} B each, not in the figure)", std::mem::size_of::<Correction<D>>() + std::mem::size_of::<u32>())
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![
            ArraySize::sparse("L", &self.corrections),
            ArraySize::of("slot of L", &self.slot),
            ArraySize::sparse("particle of L", &self.corrected),
        ]
    }
}
