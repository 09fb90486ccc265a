//! The Smagorinsky eddy viscosity ν_t of Eq. (3)–(4), Δ = dx (`effects::les`).

use super::{Stage, StepSettings};
use crate::effects::les;
use crate::math::memory::ArraySize;
use crate::math::reduce::fill;
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

    /// ν_t of each fluid particle from its strain rates `strain_rates` ([uncorrected,
    /// corrected], the free surface's walk: `FreeSurface::strain_rates`), the corrected one
    /// where `corrections` corrects the particle's gradients.
    pub fn run<const D: usize>(
        &mut self,
        strain_rates: &[[f64; 2]],
        corrections: Corrections<D>,
        spacing: f64,
    ) -> &[f64] {
        self.eddy.resize(strain_rates.len(), 0.0);
        let cs = self.settings.cs;
        fill(&mut self.eddy, |i| {
            let [plain, corrected] = strain_rates[i];
            let rate = match corrections.of(i) {
                Some(_) => corrected,
                None => plain,
            };
            les::eddy_viscosity(rate, cs, spacing)
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
            "Smagorinsky ν_t = (Cs Δ)² |S| (Eq. 3–4), Cs = {}, Δ = dx, walls as free-slip ghosts; the strain rate from the free surface's walk",
            self.settings.cs
        )
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![ArraySize::of("ν_t", &self.eddy)]
    }
}
