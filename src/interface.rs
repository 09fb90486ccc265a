//! Interfaces between fluids of different rest density: how far each fluid particle lies from
//! the nearest interface, and the density a pair of particles sees between them.
//!
//! Across an interface the PPE's Laplacian and the pressure gradient divide each pair's
//! pressure difference by a density between the pair's two (`pair_weight`). In a stable
//! layering at rest the difference is g·(r_j − r_i) times the density along the segment from
//! i to j: ρ̄_ij = f ρ0_i + (1 − f) ρ0_j, with f the fraction of the segment on i's side of the
//! interface. The harmonic mean 2/(ρ0_i + ρ0_j) of 1/ρ (Cummins & Rudman 1999) is the case
//! f = ½, exact only where the interface lies halfway between the two; the kernel's support
//! (3.6 spacings at h/dx = 1.2) holds pairs crossing it anywhere along their length. With
//! f = ½ a stable layering of a fluid at half the water's density over water reached 0.19 m/s
//! in 0.6 s where this one stays at 0.03 (`tests/hydrostatic.rs`; `ppe::laplacian_correction`
//! and `PressureOperator::interior_weights` for the other half of that fix). The fraction comes from each
//! particle's distance to the interface along the normal, d_i (`Interfaces::distance`):
//! f = d_i/(d_i + d_j), whatever the pair's direction.

use crate::kernel::Quintic;
use crate::lanes::F64s;
use crate::neighbours::{Lanes, Neighbours};
use crate::particles::{Kind, Particles};
use crate::vector::norm;

/// Intervals of the table of `Interfaces` over [0, 3h].
const TABLE_INTERVALS: usize = 600;
/// Quadrature intervals per table interval.
const QUADRATURE_STEPS: usize = 20;

/// The fraction of the kernel's mass beyond a plane, against the plane's distance from the
/// kernel's centre: inverted, it turns the mass of the other fluid a particle's kernel holds
/// into its distance from a flat interface.
#[derive(Clone, Debug)]
pub struct Interfaces {
    /// Fraction of ∫W beyond a plane at distance s_k = 3h k/TABLE_INTERVALS: ½ at k = 0,
    /// falling to 0 at the support radius.
    beyond: Vec<f64>,
    /// 3h/TABLE_INTERVALS.
    step: f64,
}

impl Interfaces {
    pub fn new<const D: usize>(kernel: &Quintic<D>) -> Self {
        let support = kernel.support();
        let step = support / TABLE_INTERVALS as f64;
        // The kernel's mass per unit distance along one axis, at distance t from the centre:
        // W integrated over the plane (line, in 2D) at t.
        let slice = |t: f64| -> f64 {
            match D {
                1 => kernel.w(t),
                2 => {
                    // 2 ∫_0^√(R²−t²) W(√(t² + y²)) dy.
                    let end = (support * support - t * t).max(0.0).sqrt();
                    2.0 * simpson(|y| kernel.w((t * t + y * y).sqrt()), end)
                }
                _ => {
                    // 2π ∫_t^R W(r) r dr (r² = t² + ρ² over the plane's disc).
                    2.0 * std::f64::consts::PI * simpson(|u| kernel.w(t + u) * (t + u), support - t)
                }
            }
        };
        let mut beyond = vec![0.0; TABLE_INTERVALS + 1];
        for k in (0..TABLE_INTERVALS).rev() {
            let t0 = k as f64 * step;
            beyond[k] = beyond[k + 1] + simpson(|u| slice(t0 + u), step);
        }
        Self { beyond, step }
    }

    /// Distance from a particle to a flat interface whose far side holds the fraction
    /// `other` of the particle's kernel mass (`other_fluid_fraction`): 0 where it holds half
    /// or more, the support radius where it holds none.
    pub fn distance(&self, other: f64) -> f64 {
        let b = &self.beyond;
        if other >= b[0] {
            return 0.0;
        }
        // The first table point whose fraction is at most `other` (the table falls with k).
        let k = b.partition_point(|&f| f > other);
        if k > TABLE_INTERVALS {
            return TABLE_INTERVALS as f64 * self.step;
        }
        let (hi, lo) = (b[k - 1], b[k]);
        let s = if hi > lo {
            (hi - other) / (hi - lo)
        } else {
            0.0
        };
        ((k - 1) as f64 + s) * self.step
    }
}

/// ∫_0^length f by Simpson's rule over `QUADRATURE_STEPS` intervals.
fn simpson(f: impl Fn(f64) -> f64, length: f64) -> f64 {
    let n = QUADRATURE_STEPS;
    let h = length / n as f64;
    let inner: f64 = (1..n)
        .map(|k| f(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(0.0) + inner + f(length)) * h / 3.0
}

/// The fraction of fluid particle i's kernel mass, Σ_j V_j W_ij, held by fluid particles of
/// another rest density. The wall particles behind the container's faces within reach of i
/// (`faces`, `Faces::container_faces_within`) stand for the mirror image of the fluid, as
/// their ghost pressures do: each fluid neighbour j of the other density counts once more at
/// each of its images, across every set of those faces (across one face beside a wall, two at
/// an edge, three in a corner). Without the images a particle beside a side wall missed the
/// part of the other fluid's share that lies behind the wall, took itself for 37% farther from
/// an interface at its height than it is (`tests/interface.rs`), and the pairs across it for
/// the wrong density: the layerings of `tests/hydrostatic.rs` drifted along their side walls at
/// 0.010, 0.029 and 0.069 m/s within 0.6 s (upper fluid at 800, 500 and 100 kg/m³ over water),
/// 1.4e-4, 6.5e-4 and 7.5e-3 m/s with the images. The obstacles' faces are not mirrored.
pub fn other_fluid_fraction<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    faces: [Option<f64>; D],
    i: usize,
) -> f64 {
    // Per mirrored axis, twice i's signed distance from the face: the image of j across it is
    // at 2 δ − (r_ij)_d from i along that axis.
    let twice: [Option<f64>; D] =
        std::array::from_fn(|d| faces[d].map(|face| 2.0 * (p.pos[d][i] - face)));
    let mirrored = (0..D).fold(0, |set, d| set | (twice[d].is_some() as usize) << d);
    let mut sum = 0.0;
    let rest_density = p.rest_density[i];
    nb.for_each_of(i, &[Kind::Fluid], |j, rij, r| {
        if p.rest_density[j] != rest_density {
            let volume = p.mass[j] / p.rest_density[j];
            sum += volume * nb.kernel.w(r);
            // Every non-empty set of the mirrored axes, as bits.
            for set in (1..1 << D).filter(|set| set & !mirrored == 0) {
                let image: [f64; D] = std::array::from_fn(|d| match twice[d] {
                    Some(twice) if set >> d & 1 == 1 => twice - rij[d],
                    _ => rij[d],
                });
                sum += volume * nb.kernel.w(norm(image));
            }
        }
    });
    sum
}

/// ρ0_i/ρ̄_ij in lanes, with ρ̄_ij = f ρ0_i + (1 − f) ρ0_j the density along the segment from
/// i to j, f = d_i/(d_i + d_j) the part of it on i's side of the interface (½ where both
/// distances are zero); exactly 1 where ρ0_j = ρ0_i.
#[inline(always)]
pub fn pair_weight(
    rest_density_i: F64s,
    rest_density_j: F64s,
    distance_i: F64s,
    distance_j: F64s,
) -> F64s {
    let sum = distance_i + distance_j;
    let f = sum
        .simd_gt(F64s::ZERO)
        .select(distance_i / sum, F64s::splat(0.5));
    rest_density_i / f.mul_add(rest_density_i - rest_density_j, rest_density_j)
}

/// Particle i's side of its pairs across interfaces, in lanes: ρ0_i and i's distance to the
/// nearest interface (0 where the fluids share one rest density).
#[derive(Clone, Copy, Debug)]
pub struct Side {
    pub rest_density: F64s,
    distance: F64s,
}

impl Side {
    /// Particle i's side, with `distances` each fluid particle's distance to the nearest
    /// interface where the fluids differ in rest density (`Interfaces::distance`).
    pub fn of<const D: usize>(p: &Particles<D>, distances: Option<&[f64]>, i: usize) -> Self {
        Self {
            rest_density: F64s::splat(p.rest_density[i]),
            distance: F64s::splat(distances.map_or(0.0, |d| d[i])),
        }
    }

    /// `value`, a term of the pairs of i with the lanes `l`, weighted by ρ0_i/ρ̄_ij
    /// (`pair_weight`) where the fluids differ in rest density (`distances`); unchanged where
    /// they share one and for wall lanes (a wall ghost is one of i's own fluid).
    #[inline(always)]
    pub fn across<const D: usize>(
        &self,
        p: &Particles<D>,
        distances: Option<&[f64]>,
        l: &Lanes<D>,
        value: F64s,
    ) -> F64s {
        match (distances, l.kind) {
            (Some(distance), Kind::Fluid) => {
                let rest_density = l.load(&p.rest_density);
                let distance_j = l.load(distance);
                value * pair_weight(self.rest_density, rest_density, self.distance, distance_j)
            }
            _ => value,
        }
    }
}
