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
//! The fluid fraction c(x) = s Σ_j V_j W(|x − x_j|), s the kernel's lattice-sum scale
//! (`Kernel::density_scale`), is 1 in water at rest and falls from 1 to 0 across a flat surface
//! symmetrically about the surface itself, half a spacing above the top row's centres, where it
//! is 1/2. So a point reads only where water covers it: where c is at least half the fraction
//! water filling the container would give there (`full_fraction`: 1 inside, 1/2 on a face).
//! Elsewhere it reads as dry, a zero pressure and velocity, as where no fluid is in reach.
//! Without that rule the normalised sum reads the pressure of the first particle that enters
//! the support, 3h away, at full weight: a thin film running up a wall gave a sensor 80 mm up
//! its first reading before water reached it (docs/accuracy.md, "Wall pressures against
//! Lobovsky et al. 2014"). DualSPHysics' MeasureTool keeps a reading only where Σ_j V_j W ≥ 0.5
//! (`-kclimit`), the same rule away from walls. A wave gauge (`surface_height`) reads the height
//! at which c falls through half its full value on a vertical line.
//!
//! The sum runs over every particle in index order in fixed chunks (`reduce::sums`): the same
//! bits for any thread count, and a few operations per particle per probe, against hundreds
//! per particle in a step's pair loops.

use crate::math::aabb::Aabb;
use crate::math::kernel::Kernel;
use crate::math::lattice::for_each_lattice_point;
use crate::math::reduce;
use crate::particles::Particles;

/// The fields at a point: pressure [Pa] and velocity [m/s]; zero where the water does not
/// cover it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample<const D: usize> {
    pub pressure: f64,
    pub velocity: [f64; D],
}

/// The Shepard interpolation of the fluid's pressure and velocity at `x`, where its fluid
/// fraction is at least `wet` (zero elsewhere), the particles of `p` standing at `pos`.
/// `periods[d]` is the length of the box along a periodic axis d: distances along it are to
/// the nearest image.
pub fn sample<const D: usize>(
    p: &Particles<D>,
    pos: &[Vec<f64>; D],
    kernel: &Kernel<D>,
    periods: &[Option<f64>; D],
    x: [f64; D],
    wet: f64,
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
            let mut dx = x[d] - pos[d][j];
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
    if sums[0] == 0.0 || kernel.density_scale() * sums[0] < wet {
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

/// The fluid fraction c must fall through this share of its full value on the way up for a
/// surface to be there.
pub const SURFACE_FRACTION: f64 = 0.5;

/// The fluid fraction at `x` of water at rest filling `container`: s Σ_k dx^D W(|x − y_k|) over
/// the container's lattice points y_k = min + (k + 1/2) dx (the fill's), 1 inside, 1/2 on a
/// face, 1/4 on an edge of two faces. A periodic axis has no face. Obstacles and bodies are
/// not taken out: a point on an obstacle's face takes the fraction of open water.
pub fn full_fraction<const D: usize>(
    kernel: &Kernel<D>,
    spacing: f64,
    container: &Aabb,
    periods: &[Option<f64>; D],
    x: [f64; D],
) -> f64 {
    let support = kernel.support();
    let index = |d: usize, y: f64| (y - container.min[d]) / spacing - 0.5;
    let reach = |d: usize, sign: f64| index(d, x[d] + sign * support);
    let lo: [i64; D] = std::array::from_fn(|d| reach(d, -1.0).ceil() as i64);
    let hi: [i64; D] = std::array::from_fn(|d| reach(d, 1.0).floor() as i64 + 1);
    let mut sum = 0.0;
    for_each_lattice_point(lo, hi, |k| {
        let y: [f64; D] = std::array::from_fn(|d| container.min[d] + (k[d] as f64 + 0.5) * spacing);
        let inside = (0..D)
            .all(|d| periods[d].is_some() || (container.min[d]..container.max[d]).contains(&y[d]));
        if inside {
            let r2: f64 = (0..D).map(|d| (x[d] - y[d]).powi(2)).sum();
            sum += kernel.w(r2.sqrt());
        }
    });
    sum * spacing.powi(D as i32) * kernel.density_scale()
}

/// Sample spacing of a gauge's line, in particle spacings, before the crossing is bisected.
const GAUGE_SAMPLE: f64 = 0.25;

/// The height of the free surface on the vertical line through `x` (its last coordinate is
/// not read) across `container`: the highest point where the fluid fraction c falls through
/// half its full value (`full_fraction`) going up (the crest of a wave that overturns above
/// water, not the water under it), the container's top where c stays above it up to there,
/// none where c stays below it on the whole line (no water under the gauge). c is sampled every
/// quarter `spacing` down from the top, and the first interval that crosses is bisected to
/// round-off. `pos` and `periods` as for `sample`.
pub fn surface_height<const D: usize>(
    p: &Particles<D>,
    pos: &[Vec<f64>; D],
    kernel: &Kernel<D>,
    periods: &[Option<f64>; D],
    x: [f64; D],
    container: &Aabb,
    spacing: f64,
) -> Option<f64> {
    let up = D - 1;
    let support = kernel.support();
    // The fluid particles within the support of the line: (horizontal r², height, s V_j).
    let near: Vec<(f64, f64, f64)> = (0..p.len())
        .filter(|&j| p.is_fluid(j))
        .filter_map(|j| {
            let mut r2 = 0.0;
            for d in 0..up {
                let mut dx = x[d] - pos[d][j];
                if let Some(period) = periods[d] {
                    dx -= period * (dx / period).round();
                }
                r2 += dx * dx;
            }
            let volume = p.mass[j] / p.rest_density[j] * kernel.density_scale();
            (r2 < support * support).then_some((r2, pos[up][j], volume))
        })
        .collect();
    let fraction = |z: f64| -> f64 {
        near.iter()
            .map(|&(r2, zj, v)| {
                let dz = z - zj;
                let r2 = r2 + dz * dz;
                if r2 < support * support {
                    v * kernel.w(r2.sqrt())
                } else {
                    0.0
                }
            })
            .sum()
    };
    let (bottom, top) = (container.min[up], container.max[up]);
    let wet = |z: f64| {
        let mut point = x;
        point[up] = z;
        let full = full_fraction(kernel, spacing, container, periods, point);
        fraction(z) >= SURFACE_FRACTION * full
    };
    if wet(top) {
        return Some(top);
    }
    let step = GAUGE_SAMPLE * spacing;
    let samples = ((top - bottom) / step).ceil() as usize;
    let (mut dry, mut under) = (top, None);
    for k in 1..=samples {
        let z = (top - k as f64 * step).max(bottom);
        if wet(z) {
            under = Some(z);
            break;
        }
        dry = z;
    }
    let mut wet_z = under?;
    // Bisection: c(wet_z) ≥ 1/2 > c(dry).
    while dry - wet_z > 1e-12 * spacing.max(dry.abs()) {
        let mid = 0.5 * (wet_z + dry);
        if mid <= wet_z || mid >= dry {
            break;
        }
        if wet(mid) {
            wet_z = mid;
        } else {
            dry = mid;
        }
    }
    Some(0.5 * (wet_z + dry))
}
