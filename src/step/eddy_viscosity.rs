//! The eddy viscosity ν_t: Smagorinsky's of Eq. (3)–(4), Δ = dx, and with the wall function
//! the log layer's κ u_τ y within a kernel support of a wall, where it is the larger
//! (`effects::les`).

use super::{Stage, StepSettings};
use crate::boundary::ghosts;
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

    /// ν_t of each fluid particle from its strain rates `strain_rates` ([uncorrected,
    /// corrected], the free surface's walk: `FreeSurface::strain_rates`), the corrected one
    /// where `corrections` corrects the particle's gradients; with the wall function, at least
    /// the log layer's where a wall is within the kernel support.
    pub fn run<const D: usize>(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        strain_rates: &[[f64; 2]],
        corrections: Corrections<D>,
        spacing: f64,
    ) -> &[f64] {
        self.eddy.resize(strain_rates.len(), 0.0);
        let cs = self.settings.cs;
        let wall_layer = self.settings.wall_function;
        let support = nb.kernel.support();
        fill(&mut self.eddy, |i| {
            let [plain, corrected] = strain_rates[i];
            let rate = match corrections.of(i) {
                Some(_) => corrected,
                None => plain,
            };
            let smagorinsky = les::eddy_viscosity(rate, cs, spacing);
            // Within a support of a wall, the log layer's viscosity where it is the larger.
            match wall_layer.then(|| ghosts::nearest_face(nb, p, spacing, support, i)) {
                Some(Some(face)) => smagorinsky.max(les::wall_layer_viscosity(p, face, i)),
                _ => smagorinsky,
            }
        });
        &self.eddy
    }
}

impl<const D: usize> Stage<D> for EddyViscosity {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        let wall_layer = if self.settings.wall_function {
            "; within a kernel support of a wall at least the log layer's κ u_τ y, u_τ from the particle's speed along it"
        } else {
            ""
        };
        format!(
            "Smagorinsky ν_t = (Cs Δ)² |S| (Eq. 3–4), Cs = {}, Δ = dx, walls as free-slip ghosts; the strain rate from the free surface's walk{wall_layer}",
            self.settings.cs
        )
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![ArraySize::of("ν_t", &self.eddy)]
    }
}
