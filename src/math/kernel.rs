//! The quintic spline kernel of Eq. (19) (Schoenberg / Morris 1997), support radius 3h.

use crate::math::lanes::F64s;
use std::f64::consts::PI;

/// Support radius in units of the smoothing length h.
pub const SUPPORT_IN_H: f64 = 3.0;

/// Quintic spline in `D` dimensions with smoothing length `h`.
#[derive(Clone, Copy, Debug)]
pub struct Quintic<const D: usize> {
    h: f64,
    inv_h: f64,
    /// α_d of Eq. (19).
    norm: f64,
}

impl<const D: usize> Quintic<D> {
    pub fn new(h: f64) -> Self {
        // α_d of Eq. (19), with the paper's typos corrected so that ∫W = 1 (checked by a test).
        let norm = match D {
            1 => 1.0 / (120.0 * h),
            2 => 7.0 / (478.0 * PI * h * h),
            3 => 1.0 / (120.0 * PI * h * h * h),
            _ => panic!("the quintic kernel is defined for 1, 2 and 3 dimensions"),
        };
        Self {
            h,
            inv_h: 1.0 / h,
            norm,
        }
    }

    pub fn h(&self) -> f64 {
        self.h
    }

    /// Radius beyond which W and ∇W vanish.
    pub fn support(&self) -> f64 {
        SUPPORT_IN_H * self.h
    }

    /// W(r), Eq. (19).
    #[inline]
    pub fn w(&self, r: f64) -> f64 {
        let q = r * self.inv_h;
        let (a, b, c) = ((3.0 - q).max(0.0), (2.0 - q).max(0.0), (1.0 - q).max(0.0));
        let p5 = |x: f64| (x * x) * (x * x) * x;
        self.norm * (p5(a) - 6.0 * p5(b) + 15.0 * p5(c))
    }

    /// F(r) = W'(r) / r, so that ∇_i W_ij = r_ij F(|r_ij|) with r_ij = r_i − r_j.
    /// F ≤ 0 everywhere; F(0) is the finite limit W''(0).
    #[inline]
    pub fn grad_factor(&self, r: f64) -> f64 {
        let q = r * self.inv_h;
        let (a, b, c) = ((3.0 - q).max(0.0), (2.0 - q).max(0.0), (1.0 - q).max(0.0));
        let p4 = |x: f64| (x * x) * (x * x);
        let dw_dq = -5.0 * (p4(a) - 6.0 * p4(b) + 15.0 * p4(c));
        if r > 0.0 {
            self.norm * dw_dq * self.inv_h / r
        } else {
            // lim_{r→0} W'(r)/r = W''(0) = α (20 (27 − 6·8 + 15)) / h² (from d²/dq² of Eq. 19 at q = 0)
            self.norm * 20.0 * (27.0 - 48.0 + 15.0) * self.inv_h * self.inv_h
        }
    }

    /// W(r) in lanes.
    #[inline(always)]
    pub fn w_lanes(&self, r: F64s) -> F64s {
        let [a, b, c] = self.spline_terms_lanes(r);
        let p5 = |x: F64s| (x * x) * (x * x) * x;
        F64s::splat(self.norm)
            * F64s::splat(15.0).mul_add(p5(c), F64s::splat(-6.0).mul_add(p5(b), p5(a)))
    }

    /// F(r) = W'(r)/r in lanes (W''(0) where r = 0, as `grad_factor`).
    #[inline(always)]
    pub fn grad_factor_lanes(&self, r: F64s) -> F64s {
        let (dw_dr, at_zero) = self.derivative_lanes(r);
        at_zero.select(F64s::splat(self.grad_factor(0.0)), dw_dr / r)
    }

    /// W'(r) in lanes, and the mask of the lanes with r = 0.
    #[inline(always)]
    pub fn derivative_lanes(&self, r: F64s) -> (F64s, F64s) {
        let [a, b, c] = self.spline_terms_lanes(r);
        let p4 = |x: F64s| (x * x) * (x * x);
        let dw_dq = F64s::splat(-5.0)
            * F64s::splat(15.0).mul_add(p4(c), F64s::splat(-6.0).mul_add(p4(b), p4(a)));
        (
            F64s::splat(self.norm * self.inv_h) * dw_dq,
            r.simd_eq(F64s::ZERO),
        )
    }

    /// (3 − q)₊, (2 − q)₊, (1 − q)₊ with q = r/h.
    #[inline(always)]
    fn spline_terms_lanes(&self, r: F64s) -> [F64s; 3] {
        let q = r * F64s::splat(self.inv_h);
        [3.0, 2.0, 1.0].map(|k| (F64s::splat(k) - q).fast_max(F64s::ZERO))
    }
}
