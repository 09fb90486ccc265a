//! What a step measured, for `stats.csv`: the density error and the particle disorder over
//! the fluid with a full kernel support, and the largest speed and the kinetic energy.

use super::{Stage, StepSettings};
use crate::math::reduce;
use crate::particles::Particles;

pub const NAME: &str = "diagnostics";

pub struct Diagnostics;

/// Two measures over the fluid particles with no free surface in reach (`full`, where the
/// summation density is not truncated), in one pass:
/// - the density error, mean |ρ/ρ0 − 1|;
/// - the particle disorder, the coefficient of variation (standard deviation over mean) of
///   the distance from each particle to its nearest neighbour (`nearest`, from the free surface's
///   walk): zero on a lattice, a few per cent when particles stay well spread, growing as they
///   cluster into lines and gaps (tensile instability, no shifting).
///
/// NaN for both where no particle has a full support (nothing measured, not a zero error).
pub fn full_support_statistics<const D: usize>(
    p: &Particles<D>,
    full: &[bool],
    nearest: &[f64],
) -> (f64, f64) {
    let [count, density, distance, square] = reduce::sums(full.len(), |i| {
        if !full[i] {
            return [0.0; 4];
        }
        let error = (p.density[i] / p.rest_density[i] - 1.0).abs();
        [1.0, error, nearest[i], nearest[i] * nearest[i]]
    });
    if count == 0.0 {
        return (f64::NAN, f64::NAN);
    }
    let mean = distance / count;
    let variance = (square / count - mean * mean).max(0.0);
    (density / count, variance.sqrt() / mean)
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
        "max speed, kinetic energy, density error, disorder, penetrations → stats.csv".into()
    }
}
