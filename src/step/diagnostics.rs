//! What a step measured, for `stats.csv`: the density error, the compression and the particle
//! disorder over the fluid with a full kernel support, and the largest speed and the kinetic
//! energy.

use super::{Stage, StepSettings};
use crate::math::reduce;
use crate::particles::Particles;

pub const NAME: &str = "diagnostics";

pub struct Diagnostics;

/// What the fluid particles with no free surface in reach (where the summation density is
/// not truncated) measure.
#[derive(Clone, Copy, Debug)]
pub struct FullSupport {
    /// The density error, mean |ρ/ρ0 − 1|: compression and the summation density's scatter
    /// about its mean together.
    pub density_error: f64,
    /// The compression, mean (ρ/ρ0 − 1), signed: positive where the water is compressed
    /// (its volume below the rest volume), negative where it has expanded; the scatter
    /// averages out (docs/accuracy.md, "Smoothing length").
    pub compression: f64,
    /// The particle disorder, the coefficient of variation (standard deviation over mean) of
    /// the distance from each particle to its nearest neighbour: zero on a lattice, a few per
    /// cent when particles stay well spread, growing as they cluster into lines and gaps
    /// (tensile instability, no shifting).
    pub disorder: f64,
}

/// `FullSupport` over the fluid particles flagged `full`, in one pass, with `nearest` the
/// distance from each to its nearest neighbour (from the free surface's walk). NaN throughout
/// where no particle has a full support (nothing measured, not a zero error).
pub fn full_support_statistics<const D: usize>(
    p: &Particles<D>,
    full: &[bool],
    nearest: &[f64],
) -> FullSupport {
    let [count, error, excess, distance, square] = reduce::sums(full.len(), |i| {
        if !full[i] {
            return [0.0; 5];
        }
        let excess = p.density[i] / p.rest_density[i] - 1.0;
        [
            1.0,
            excess.abs(),
            excess,
            nearest[i],
            nearest[i] * nearest[i],
        ]
    });
    if count == 0.0 {
        return FullSupport {
            density_error: f64::NAN,
            compression: f64::NAN,
            disorder: f64::NAN,
        };
    }
    let mean = distance / count;
    let variance = (square / count - mean * mean).max(0.0);
    FullSupport {
        density_error: error / count,
        compression: excess / count,
        disorder: variance.sqrt() / mean,
    }
}

/// The largest fluid speed and the fluid's kinetic energy.
pub fn motion<const D: usize>(p: &Particles<D>) -> (f64, f64) {
    let max_speed = p.max_fluid_speed();
    let kinetic_energy = reduce::sum(p.len(), |i| {
        if p.is_fluid(i) {
            0.5 * p.mass[i] * p.speed(i).powi(2)
        } else {
            0.0
        }
    });
    (max_speed, kinetic_energy)
}

impl<const D: usize> Stage<D> for Diagnostics {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        "max speed, kinetic energy, density error, compression, disorder, penetrations → stats.csv"
            .into()
    }
}
