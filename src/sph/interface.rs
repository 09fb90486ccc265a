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
//! f = ½ a stable layering of a fluid at half the water's density over water is set in motion,
//! with this f it stays at rest (`tests/hydrostatic.rs`,
//! `a_fluid_at_half_the_density_of_water_keeps_its_hydrostatic_pressure`; docs/scene-format.md,
//! "`[[fluid]]`"; `ppe::LaplacianTruncation` and `PressureOperator::interior_weights` for the
//! other half of the weighting). f comes from each particle's distance to the interface d_i
//! (`Interfaces::distance`) and its normal across it (`other_fluid_share`): `pair_weight`.

use crate::math::kernel::Kernel;
use crate::math::lanes::F64s;
use crate::math::lattice::for_each_lattice_point;
use crate::math::vector::norm;
use crate::neighbours::{Lanes, Neighbours};
use crate::particles::{Kind, Particles};

/// Intervals of the table of `Interfaces` over the kernel support.
const TABLE_INTERVALS: usize = 600;

/// The fraction of a particle's kernel mass that a lattice of the particle spacing beyond a
/// plane holds, against the plane's distance from the particle: inverted, it turns the mass of
/// the other fluid a particle's kernel holds into its distance from a flat interface. The
/// lattice is the particles' own: its first layer a spacing beyond the particle's where the
/// plane runs halfway between the two (each particle fills its spacing), so that the layers
/// beside an interface at rest read a half spacing, and the next ones 1.5, 2.5, … exactly
/// (a continuum's half space read 0.53, 1.60, 2.73 spacings in 2D).
#[derive(Clone, Debug)]
pub struct Interfaces {
    /// Fraction of the kernel's mass beyond a plane at distance s_k = support × k/TABLE_INTERVALS,
    /// about ½ at k = 0, falling to 0 half a spacing short of the support radius.
    beyond: Vec<f64>,
    /// The support over TABLE_INTERVALS.
    step: f64,
}

impl Interfaces {
    pub fn new<const D: usize>(kernel: &Kernel<D>, spacing: f64) -> Self {
        let support = kernel.support();
        let step = support / TABLE_INTERVALS as f64;
        let reach = (support / spacing).ceil() as i64;
        // Squared distances from the particle's foot of the lattice points of one layer (the
        // lattice points with no offset along the last axis).
        let (mut lo, mut hi) = ([-reach; D], [reach + 1; D]);
        (lo[D - 1], hi[D - 1]) = (0, 1);
        let mut across = Vec::new();
        for_each_lattice_point(lo, hi, |k| {
            across.push(k.iter().map(|&o| (o as f64 * spacing).powi(2)).sum::<f64>());
        });
        let volume = spacing.powi(D as i32);
        let beyond = (0..=TABLE_INTERVALS)
            .map(|k| {
                let plane = k as f64 * step;
                (0..)
                    .map(|m| plane + (m as f64 + 0.5) * spacing)
                    .take_while(|&layer| layer < support)
                    .map(|layer| {
                        across
                            .iter()
                            .map(|a| volume * kernel.w((a + layer * layer).sqrt()))
                            .sum::<f64>()
                    })
                    .sum()
            })
            .collect();
        Self { beyond, step }
    }

    /// Distance from a particle to a flat interface whose far side holds the fraction
    /// `other` of the particle's kernel mass (`other_fluid_share`): 0 where it holds half
    /// or more, the support radius where it holds none.
    pub fn distance(&self, other: f64) -> f64 {
        let b = &self.beyond;
        if other >= b[0] {
            return 0.0;
        }
        if other <= 0.0 {
            return TABLE_INTERVALS as f64 * self.step;
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

/// The fraction of fluid particle i's kernel mass, Σ_j V_j W_ij, held by fluid particles of
/// another rest density, and its gradient Σ_j V_j ∇_i W_ij, which points across the interface
/// into the other fluid. The wall particles behind the container's faces within reach of i
/// (`faces`, `Faces::container_faces_within`) stand for the mirror image of the fluid, as
/// their ghost pressures do: each fluid neighbour j of the other density counts once more at
/// each of its images, across every set of those faces (across one face beside a wall, two at
/// an edge, three in a corner). Without the images a particle beside a side wall misses the
/// part of the other fluid's share that lies behind the wall, takes itself for 37% farther
/// from an interface at its height than it is (`tests/interface.rs`, on a lattice), and the
/// pairs across it for the wrong density: the layerings of `tests/hydrostatic.rs` then drift
/// along their side walls (docs/scene-format.md, "`[[fluid]]`").
/// The obstacles' faces are not mirrored.
pub fn other_fluid_share<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    faces: [Option<f64>; D],
    i: usize,
) -> (f64, [f64; D]) {
    // Per mirrored axis, twice i's signed distance from the face: the image of j across it is
    // at 2 δ − (r_ij)_d from i along that axis.
    let twice: [Option<f64>; D] =
        std::array::from_fn(|d| faces[d].map(|face| 2.0 * (p.pos[d][i] - face)));
    let mirrored = (0..D).fold(0, |set, d| set | (twice[d].is_some() as usize) << d);
    let (mut share, mut gradient) = (0.0, [0.0; D]);
    let rest_density = p.rest_density[i];
    nb.for_each_of(i, &[Kind::Fluid], |j, rij, _| {
        if p.rest_density[j] == rest_density {
            return;
        }
        let volume = p.mass[j] / p.rest_density[j];
        // j itself (the empty set) and its images: the subsets of the mirrored axes, as bits.
        for set in (0..1 << D).filter(|set| set & !mirrored == 0) {
            let image: [f64; D] = std::array::from_fn(|d| match twice[d] {
                Some(twice) if set >> d & 1 == 1 => twice - rij[d],
                _ => rij[d],
            });
            let r = norm(image);
            share += volume * nb.kernel.w(r);
            let factor = volume * nb.kernel.grad_factor(r);
            for d in 0..D {
                gradient[d] += factor * image[d];
            }
        }
    });
    (share, gradient)
}

/// The interfaces between fluids of different rest density as the pair loops see them: each
/// fluid particle's distance to the nearest one (`Interfaces::distance`) and the unit normal
/// pointing across it into the other fluid (zero far from any).
#[derive(Clone, Copy, Debug)]
pub struct Field<'a, const D: usize> {
    pub distance: &'a [f64],
    pub normal: &'a [Vec<f64>; D],
}

/// ρ0_i/ρ̄_ij in lanes, with ρ̄_ij = f ρ0_i + (1 − f) ρ0_j the density along the segment from
/// i to j, f the part of it on i's side of the interface; exactly 1 where ρ0_j = ρ0_i. With
/// L the segment's length across the interface (`Side::across`), each particle's distance
/// places the interface: d_i from i, L − d_j from j. Where the two disagree the interface is
/// taken halfway between the places, f = ½ + (d_i − d_j)/(2L) (½ where L is not positive).
/// The disagreement is that of particles that moved: a distance read off the other fluid's
/// mass moves with that fluid's particles as much as with i, so when the two layers beside an
/// interface close in by 2ε each reads itself 2ε nearer to it, against ε in truth. The ratio
/// f = d_i/(d_i + d_j), which ignores L, turns that error into a pressure gradient pulling the
/// two layers further together: a layering at half the water's density pairs its layers near
/// the interface in a growing mode (`tests/hydrostatic.rs`,
/// `a_deep_layering_beside_side_walls_stays_at_rest`; docs/scene-format.md, "`[[fluid]]`").
#[inline(always)]
pub fn pair_weight(
    rest_density_i: F64s,
    rest_density_j: F64s,
    distance_i: F64s,
    distance_j: F64s,
    length: F64s,
) -> F64s {
    let half = F64s::splat(0.5);
    let f = length.simd_gt(F64s::ZERO).select(
        ((distance_i - distance_j) / (length + length) + half)
            .fast_max(F64s::ZERO)
            .fast_min(F64s::ONE),
        half,
    );
    rest_density_i / f.mul_add(rest_density_i - rest_density_j, rest_density_j)
}

/// Particle i's side of its pairs across interfaces, in lanes: ρ0_i, i's distance to the
/// nearest interface and its normal (zero where the fluids share one rest density).
#[derive(Clone, Copy, Debug)]
pub struct Side<const D: usize> {
    pub rest_density: F64s,
    distance: F64s,
    normal: [F64s; D],
}

impl<const D: usize> Side<D> {
    /// Particle i's side, with `field` the interfaces where the fluids differ in rest density.
    pub fn of(p: &Particles<D>, field: Option<Field<D>>, i: usize) -> Self {
        Self {
            rest_density: F64s::splat(p.rest_density[i]),
            distance: F64s::splat(field.map_or(0.0, |f| f.distance[i])),
            normal: std::array::from_fn(|d| F64s::splat(field.map_or(0.0, |f| f.normal[d][i]))),
        }
    }

    /// `value`, a term of the pairs of i with the lanes `l`, weighted by ρ0_i/ρ̄_ij
    /// (`weight`).
    #[inline(always)]
    pub fn across(
        &self,
        p: &Particles<D>,
        field: Option<Field<D>>,
        l: &Lanes<D>,
        value: F64s,
    ) -> F64s {
        match self.weight(p, field, l) {
            Some(weight) => value * weight,
            None => value,
        }
    }

    /// The weight ρ0_i/ρ̄_ij (`pair_weight`) of the pairs of i with the lanes `l` where the
    /// fluids differ in rest density (`field`); None, a weight of exactly 1, where they share
    /// one and for wall lanes (a wall ghost is one of i's own fluid). The length across the
    /// interface is L = ½ (n_j − n_i)·r_ij, the segment projected on the two normals.
    #[inline(always)]
    pub fn weight(&self, p: &Particles<D>, field: Option<Field<D>>, l: &Lanes<D>) -> Option<F64s> {
        let (Some(field), Kind::Fluid) = (field, l.kind) else {
            return None;
        };
        let rest_density = l.load(&p.rest_density);
        if rest_density.simd_eq(self.rest_density).all() {
            return None;
        }
        let distance_j = l.load(field.distance);
        let length = (0..D).fold(F64s::ZERO, |s, d| {
            (l.load(&field.normal[d]) - self.normal[d]).mul_add(l.rij[d], s)
        }) * F64s::splat(0.5);
        Some(pair_weight(
            self.rest_density,
            rest_density,
            self.distance,
            distance_j,
            length,
        ))
    }
}
