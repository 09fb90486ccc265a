//! The Smagorinsky eddy viscosity ν_t of Eq. (3)–(4), Δ = dx (`effects::les`).

use super::{Stage, StepSettings};
use crate::effects::les;
use crate::math::memory::ArraySize;
use crate::math::reduce::fill;
use crate::neighbours::Neighbours;
use crate::particles::Particles;
use crate::scene::LesSettings;
use crate::sph::Corrections;

pub const NAME: &str = "eddy viscosity";

pub struct EddyViscosity {
    settings: LesSettings,
    /// ν_t of each fluid particle.
    eddy: Vec<f64>,
}

impl EddyViscosity {
    pub fn new(settings: LesSettings) -> Self {
        Self {
            settings,
            eddy: Vec::new(),
        }
    }

    /// ν_t of the `nf` fluid particles, from the velocity gradient corrected by `corrections`.
    pub fn run<const D: usize>(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        corrections: Corrections<D>,
        spacing: f64,
        nf: usize,
    ) -> &[f64] {
        self.eddy.resize(nf, 0.0);
        let cs = self.settings.cs;
        fill(&mut self.eddy, |i| {
            les::eddy_viscosity(nb, p, corrections.of(i), cs, spacing, i)
        });
        &self.eddy
    }
}

impl<const D: usize> Stage<D> for EddyViscosity {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        format!(
            "Smagorinsky ν_t = (Cs Δ)² |S| (Eq. 3–4), Cs = {}, Δ = dx, walls as free-slip ghosts",
            self.settings.cs
        )
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![ArraySize::of("ν_t", &self.eddy)]
    }
}
