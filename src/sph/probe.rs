//! A field read at a point: the Shepard interpolation of the fluid particles in the kernel
//! support, f(x) = Σ_j V_j W(|x − x_j|) f_j / Σ_j V_j W(|x − x_j|), V_j = m_j/ρ0_j the volume a
//! particle holds at rest. The kernel sum is normalised, so a field that is constant over the
//! support is read exactly, also where the support is cut by a wall or the free surface (a
//! plain SPH sum there reads low by the missing part of the support). Only fluid particles
//! count: a wall particle's pressure is a ghost of its fluid neighbours' (and is computed for
//! frames only), its velocity a no-slip mirror. With one fluid and particles of one spacing
//! every V_j is dx^D, and this is PySPH's `Interpolator(method="shepard")`; DualSPHysics'
//! MeasureTool reads fluid particles only by default, as here.
//!
//! The sum runs over every particle in index order in fixed chunks (`reduce::sums`): the same
//! bits for any thread count, and a few operations per particle per probe, against hundreds
//! per particle in a step's pair loops.

use crate::math::kernel::Kernel;
use crate::math::reduce;
use crate::particles::Particles;

/// The fields at a point: pressure [Pa] and velocity [m/s]; zero where no fluid particle is
/// within the kernel support.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample<const D: usize> {
    pub pressure: f64,
    pub velocity: [f64; D],
}

/// The Shepard interpolation of the fluid's pressure and velocity at `x`. `periods[d]` is the
/// length of the box along a periodic axis d: distances along it are to the nearest image.
pub fn sample<const D: usize>(
    p: &Particles<D>,
    kernel: &Kernel<D>,
    periods: &[Option<f64>; D],
    x: [f64; D],
) -> Sample<D> {
    let support2 = kernel.support() * kernel.support();
    // [Σ V W, Σ V W P, Σ V W u_0, Σ V W u_1, Σ V W u_2]
    let sums = reduce::sums::<5>(p.len(), |j| {
        let mut term = [0.0; 5];
        if !p.is_fluid(j) {
            return term;
        }
        let mut r2 = 0.0;
        for d in 0..D {
            let mut dx = x[d] - p.pos[d][j];
            if let Some(period) = periods[d] {
                dx -= period * (dx / period).round();
            }
            r2 += dx * dx;
        }
        if r2 >= support2 {
            return term;
        }
        let weight = p.mass[j] / p.rest_density[j] * kernel.w(r2.sqrt());
        term[0] = weight;
        term[1] = weight * p.pressure[j];
        for d in 0..D {
            term[2 + d] = weight * p.vel[d][j];
        }
        term
    });
    if sums[0] == 0.0 {
        return Sample {
            pressure: 0.0,
            velocity: [0.0; D],
        };
    }
    Sample {
        pressure: sums[1] / sums[0],
        velocity: std::array::from_fn(|d| sums[2 + d] / sums[0]),
    }
}
