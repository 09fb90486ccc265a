//! The pair loop every operator is built on. The particles are sorted by kind and cell
//! (`cell_list`), so the neighbours of particle i lie in a few contiguous index ranges, one per row
//! of cells within reach and kind (operators that need one kind only visit its ranges); the loop
//! walks each range `LANES` particles at a time in SIMD lanes (`lanes::F64s`): positions are loaded
//! contiguously, the distance test and the kernel are evaluated for `LANES` pairs at once, and each
//! operator accumulates in lanes, summed at the end in a fixed order. Lanes past the end of a range
//! (and past the end of the arrays, which read far-away sentinels) are masked off.
//!
//! `for_each` offers the same walk one neighbour at a time, for the operators that run once per
//! step; the hot loops (the PPE apply, density, …) work on the lanes directly.

use crate::math::kernel::Kernel;
use crate::math::lanes::{F64s, LANES};
use crate::neighbours::cell_list::{CellList, KINDS};
use crate::particles::Kind;
use std::ops::Range;

/// η² = 0.0001 h² of Eq. (26)–(27), in units of h².
const ETA2_IN_H2: f64 = 1.0e-4;
/// Coordinate of the lanes past the end of the arrays: farther than any support.
const SENTINEL: f64 = 1.0e30;
/// 0, 1, … LANES − 1: each lane's offset from the chunk's first candidate.
const LANE_INDEX: [f64; LANES] = {
    let mut k = [0.0; LANES];
    let mut l = 0;
    while l < LANES {
        k[l] = l as f64;
        l += 1;
    }
    k
};

/// `LANES` consecutive candidate neighbours j0 … j0 + LANES − 1 of particle i.
#[derive(Clone, Copy, Debug)]
pub struct Lanes<const D: usize> {
    /// Index of the first lane.
    pub j0: usize,
    /// r_ij = r_i − r_j per lane.
    pub rij: [F64s; D],
    /// |r_ij| per lane (0 where masked).
    pub r: F64s,
    /// All bits set in the lanes that are neighbours (inside the support, j ≠ i), zero elsewhere.
    pub mask: F64s,
    /// The kind of the candidates (a range holds particles of one kind), as the sort groups
    /// them (`Kind::sorted_as`): `Fluid` for fluid and body particles, or `Wall`.
    pub kind: Kind,
}

impl<const D: usize> Lanes<D> {
    /// `a[j0 .. j0 + LANES]`, zero past the end of `a`.
    #[inline(always)]
    pub fn load(&self, a: &[f64]) -> F64s {
        load(a, self.j0, 0.0)
    }

    /// Whether lane k is a neighbour.
    #[inline(always)]
    pub fn active(&self, k: usize) -> bool {
        self.mask.to_array()[k] != 0.0
    }

    /// The neighbours among the lanes.
    #[inline(always)]
    pub fn count(&self) -> usize {
        self.mask.to_bitmask().count_ones() as usize
    }
}

/// a[j0 .. j0 + LANES] with `fill` past the end of `a`.
#[inline(always)]
fn load(a: &[f64], j0: usize, fill: f64) -> F64s {
    match a.get(j0..j0 + LANES) {
        Some(s) => F64s::from(<[f64; LANES]>::try_from(s).expect("LANES lanes")),
        None => F64s::from(std::array::from_fn(|k| {
            a.get(j0 + k).copied().unwrap_or(fill)
        })),
    }
}

/// The neighbourhood of every particle: positions sorted by cell plus the kernel.
pub struct Neighbours<'a, const D: usize> {
    grid: &'a CellList<D>,
    pos: &'a [Vec<f64>; D],
    pub kernel: Kernel<D>,
    support2: f64,
    eta2: f64,
    /// F(0) = W''(0).
    f_at_zero: f64,
}

impl<'a, const D: usize> Neighbours<'a, D> {
    pub fn new(grid: &'a CellList<D>, pos: &'a [Vec<f64>; D], kernel: Kernel<D>) -> Self {
        let support2 = kernel.support() * kernel.support();
        let eta2 = ETA2_IN_H2 * kernel.h() * kernel.h();
        Self {
            grid,
            pos,
            kernel,
            support2,
            eta2,
            f_at_zero: kernel.grad_factor(0.0),
        }
    }

    /// The cell list the particles are sorted by.
    pub fn grid(&self) -> &CellList<D> {
        self.grid
    }

    /// The pair loop in lanes: calls `f` with every chunk of `LANES` candidates around particle
    /// i that holds at least one neighbour, over the particles of every kind.
    #[inline(always)]
    pub fn for_each_lanes(&self, i: usize, f: impl FnMut(&Lanes<D>)) {
        self.for_each_lanes_of(i, &KINDS, f);
    }

    /// The pair loop in lanes over the neighbours of `kinds` only.
    #[inline(always)]
    pub fn for_each_lanes_of(&self, i: usize, kinds: &[Kind], mut f: impl FnMut(&Lanes<D>)) {
        // `xi` is i's image next to the range (itself but across a periodic boundary).
        self.grid
            .for_each_range_around(i, self.position(i), kinds, |range, xi, kind| {
                self.for_each_lanes_in(i, xi, range, kind, &mut f)
            });
    }

    /// Position of particle i.
    #[inline(always)]
    fn position(&self, i: usize) -> [f64; D] {
        std::array::from_fn(|d| self.pos[d][i])
    }

    /// The pair loop in lanes over one range of candidates of one kind, with `xi` the image of
    /// particle i next to them.
    #[inline(always)]
    fn for_each_lanes_in(
        &self,
        i: usize,
        xi: [f64; D],
        range: Range<usize>,
        kind: Kind,
        f: &mut impl FnMut(&Lanes<D>),
    ) {
        let support2 = F64s::splat(self.support2);
        let mut j0 = range.start;
        while j0 < range.end {
            let rij: [F64s; D] =
                std::array::from_fn(|d| F64s::splat(xi[d]) - load(&self.pos[d], j0, SENTINEL));
            let r2 = rij.iter().fold(F64s::ZERO, |s, x| x.mul_add(*x, s));
            let mut mask = r2.simd_lt(support2);
            if i.wrapping_sub(j0) < LANES || j0 + LANES > range.end {
                // Lane k holds j0 + k: off where it is i or past the range's end.
                let k = F64s::from(LANE_INDEX);
                let past_end = F64s::splat((range.end - j0) as f64);
                let own = F64s::splat(i as f64 - j0 as f64);
                mask = mask & k.simd_lt(past_end) & k.simd_ne(own);
            }
            if mask.any() {
                let r = (r2 & mask).sqrt();
                f(&Lanes {
                    j0,
                    rij,
                    r,
                    mask,
                    kind,
                });
            }
            j0 += LANES;
        }
    }

    /// The pair loop one neighbour at a time: calls `f(j, r_ij, |r_ij|)` for every particle
    /// j ≠ i inside the kernel support of i.
    #[inline(always)]
    pub fn for_each(&self, i: usize, f: impl FnMut(usize, [f64; D], f64)) {
        self.for_each_of(i, &KINDS, f);
    }

    /// `for_each` over the neighbours of `kinds` only.
    #[inline(always)]
    pub fn for_each_of(&self, i: usize, kinds: &[Kind], mut f: impl FnMut(usize, [f64; D], f64)) {
        self.for_each_lanes_of(i, kinds, |l| {
            let r = l.r.to_array();
            let rij = l.rij.map(|x| x.to_array());
            for k in 0..LANES {
                if l.active(k) {
                    f(l.j0 + k, std::array::from_fn(|d| rij[d][k]), r[k]);
                }
            }
        });
    }

    /// r_ij·∇W_ij / (r_ij² + η²), the radial factor shared by Eq. (26) and Eq. (27).
    #[inline]
    pub fn laplacian_factor(&self, r: f64) -> f64 {
        r * r * self.kernel.grad_factor(r) / (r * r + self.eta2)
    }

    /// F(r) = W'(r)/r and r² F/(r² + η²) (`laplacian_factor`) in lanes, with one division.
    #[inline(always)]
    pub fn gradient_and_laplacian_factors_lanes(&self, r: F64s) -> (F64s, F64s) {
        let radial = self.radial_terms_lanes(r);
        let f = r
            .simd_eq(F64s::ZERO)
            .select(F64s::splat(self.f_at_zero), radial.k * radial.r2_eta2);
        (f, radial.k * radial.r2)
    }

    /// The radial terms of Eq. (27)'s pair weights in lanes (`RadialTerms`), with one division.
    #[inline(always)]
    pub fn radial_terms_lanes(&self, r: F64s) -> RadialTerms {
        let (dw_dr, _) = self.kernel.derivative_lanes(r);
        let r2 = r * r;
        let r2_eta2 = r2 + F64s::splat(self.eta2);
        let inv = F64s::ONE / (r * r2_eta2).fast_max(F64s::splat(f64::MIN_POSITIVE));
        RadialTerms {
            k: dw_dr * inv,
            r2,
            r2_eta2,
        }
    }
}

/// k = W'(r)/(r (r² + η²)), r² and r² + η² of a pair: F = W'/r = k (r² + η²) and the
/// Laplacian factor r² F/(r² + η²) = k r² (Eq. 27). At r = 0, W'(0) = 0 makes k = 0.
#[derive(Clone, Copy, Debug)]
pub struct RadialTerms {
    pub k: F64s,
    pub r2: F64s,
    pub r2_eta2: F64s,
}
