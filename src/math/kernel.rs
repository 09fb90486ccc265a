//! The smoothing kernels a scene may choose (`solver.kernel`): the quintic spline of Eq. (19)
//! (Schoenberg / Morris 1997, support radius 3h), the paper's and the default, and the Wendland
//! C2 and C4 functions (Wendland 1995; Dehnen & Aly 2012, support radius 2h), which reach fewer
//! neighbours at a given h/dx and never pair particles up (their Fourier transforms are
//! positive).

use crate::math::lanes::F64s;
use crate::math::lattice::for_each_lattice_point;
use std::f64::consts::PI;

/// The kernel's function of q = r/h.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelKind {
    /// Eq. (19): (3 − q)⁵₊ − 6 (2 − q)⁵₊ + 15 (1 − q)⁵₊.
    Quintic,
    /// (1 − q/2)⁴₊ (1 + 2q).
    WendlandC2,
    /// (1 − q/2)⁶₊ (1 + 3q + 35q²/12).
    WendlandC4,
}

impl KernelKind {
    /// The names the scene key takes.
    pub const NAMES: [&'static str; 3] = ["quintic", "wendland_c2", "wendland_c4"];

    const ALL: [KernelKind; 3] = [
        KernelKind::Quintic,
        KernelKind::WendlandC2,
        KernelKind::WendlandC4,
    ];

    /// The scene key's name of the kernel.
    pub fn name(self) -> &'static str {
        Self::NAMES[Self::ALL.iter().position(|&k| k == self).expect("listed")]
    }

    /// The kernel the scene key names, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::NAMES
            .iter()
            .position(|&n| n == name)
            .map(|k| Self::ALL[k])
    }

    /// Support radius in units of the smoothing length h.
    pub fn support_in_h(self) -> f64 {
        match self {
            KernelKind::Quintic => 3.0,
            KernelKind::WendlandC2 | KernelKind::WendlandC4 => 2.0,
        }
    }

    /// h/dx when the scene gives none (docs/accuracy.md, "Kernels").
    pub fn default_h_over_dx(self) -> f64 {
        match self {
            KernelKind::Quintic => 1.2,
            KernelKind::WendlandC2 | KernelKind::WendlandC4 => 1.8,
        }
    }

    /// The h/dx a scene may set: a support of at least two spacings and at most six.
    pub fn h_over_dx_range(self) -> std::ops::RangeInclusive<f64> {
        match self {
            KernelKind::Quintic => 1.0..=2.0,
            KernelKind::WendlandC2 | KernelKind::WendlandC4 => 1.0..=3.0,
        }
    }
}

/// A kernel of `KernelKind` in `D` dimensions with smoothing length h, on particles of
/// spacing dx.
#[derive(Clone, Copy, Debug)]
pub struct Kernel<const D: usize> {
    kind: KernelKind,
    h: f64,
    inv_h: f64,
    /// α_d: ∫W dV = 1.
    norm: f64,
    /// 1/(Σ_j W(|r_j|) dx^D) over the points r_j of the cubic lattice of spacing dx (the
    /// Wendland functions; 1 for the quintic): the summation density of particles at rest on
    /// their lattice is then ρ0 (`sph::density`).
    density_scale: f64,
    /// The smoothing length of the quintic of the same standard deviation (`width`).
    width: f64,
    /// σ, the kernel's standard deviation along an axis (`deviation`).
    deviation: f64,
}

impl<const D: usize> Kernel<D> {
    /// The kernel `kind` with h = `h_over_dx` × `spacing`.
    pub fn new(kind: KernelKind, spacing: f64, h_over_dx: f64) -> Self {
        let h = h_over_dx * spacing;
        // α_d, so that ∫W = 1 (checked by a test); the quintic's are Eq. (19)'s with the
        // paper's typos corrected.
        let norm = match (kind, D) {
            (KernelKind::Quintic, 1) => 1.0 / (120.0 * h),
            (KernelKind::Quintic, 2) => 7.0 / (478.0 * PI * h * h),
            (KernelKind::Quintic, 3) => 1.0 / (120.0 * PI * h * h * h),
            (KernelKind::WendlandC2, 1) => 3.0 / (4.0 * h),
            (KernelKind::WendlandC2, 2) => 7.0 / (4.0 * PI * h * h),
            (KernelKind::WendlandC2, 3) => 21.0 / (16.0 * PI * h * h * h),
            (KernelKind::WendlandC4, 1) => 27.0 / (32.0 * h),
            (KernelKind::WendlandC4, 2) => 9.0 / (4.0 * PI * h * h),
            (KernelKind::WendlandC4, 3) => 495.0 / (256.0 * PI * h * h * h),
            _ => panic!("the kernels are defined for 1, 2 and 3 dimensions"),
        };
        let mut kernel = Self {
            kind,
            h,
            inv_h: 1.0 / h,
            norm,
            density_scale: 1.0,
            width: h,
            deviation: 0.0,
        };
        kernel.deviation = h * kernel.deviation_over_h();
        if kind != KernelKind::Quintic {
            kernel.density_scale = 1.0 / kernel.lattice_sum(spacing);
            let quintic = Kernel::<D>::new(KernelKind::Quintic, 1.0, 1.0);
            kernel.width = kernel.deviation / quintic.deviation_over_h();
        }
        kernel
    }

    /// σ/h, with σ² = ∫ r² W dV / D the kernel's variance along an axis (midpoint rule, 4000
    /// intervals over the support: 1e-7 relative). The quintic's is 0.695 in 2D, 0.683 in 3D;
    /// Wendland C2's 0.527 and 0.516, C4's 0.461 and 0.453.
    fn deviation_over_h(&self) -> f64 {
        const INTERVALS: usize = 4000;
        let step = self.support() / INTERVALS as f64;
        let (mut mass, mut second) = (0.0, 0.0);
        for k in 0..INTERVALS {
            let r = (k as f64 + 0.5) * step;
            let shell = self.w(r) * r.powi(D as i32 - 1);
            mass += shell;
            second += shell * r * r;
        }
        (second / mass / D as f64).sqrt() / self.h
    }

    /// σ, with σ² = ∫ x² W dV the kernel's variance along an axis: the SPH Laplacian of Eq.
    /// (26) falls short of a Fourier mode's by σ²|k|²/4 of it (`sph::field_laplacian`).
    pub fn deviation(&self) -> f64 {
        self.deviation
    }

    /// The smoothing length of the quintic with this kernel's standard deviation: h for the
    /// quintic, 0.76 h for Wendland C2, 0.66 h for C4 (2D; 3D within 1.5%). The time step's
    /// viscous and body-force limits, the shifting's diffusion and the free surface's scan were
    /// set on the quintic's h; on the width they ask the same of a narrower kernel (a Wendland
    /// C4 at h/dx = 1.5 is as wide as a quintic at 0.99 dx, and its viscous limit on h would be
    /// 2.3 times the quintic's on the same width).
    pub fn width(&self) -> f64 {
        self.width
    }

    /// Σ_j W(|r_j|) dx^D over the cubic lattice of spacing dx, origin included. On a lattice
    /// the Wendland functions sum up to 1.8% above 1 at h/dx 1.2–2 (C2 in 2D: 1.8% at 1.2,
    /// 0.51% at 1.5, 0.21% at 1.8; their lattice sums converge slowly with h/dx); the quintic
    /// at h/dx = 1.2 sums within 6e-5 of 1 in 2D and 3D and is left as Eq. (19) has it.
    fn lattice_sum(&self, spacing: f64) -> f64 {
        let reach = (self.support() / spacing).ceil() as i64;
        let mut sum = 0.0;
        for_each_lattice_point([-reach; D], [reach + 1; D], |k| {
            let r2: f64 = k.iter().map(|&o| (o as f64 * spacing).powi(2)).sum();
            sum += self.w(r2.sqrt());
        });
        sum * spacing.powi(D as i32)
    }

    /// The factor that makes the summation density of the rest lattice ρ0 (`density_scale`).
    pub fn density_scale(&self) -> f64 {
        self.density_scale
    }

    pub fn kind(&self) -> KernelKind {
        self.kind
    }

    pub fn h(&self) -> f64 {
        self.h
    }

    /// Radius beyond which W and ∇W vanish.
    pub fn support(&self) -> f64 {
        self.kind.support_in_h() * self.h
    }

    /// W(r).
    #[inline]
    pub fn w(&self, r: f64) -> f64 {
        let q = r * self.inv_h;
        let shape = match self.kind {
            KernelKind::Quintic => {
                let (a, b, c) = ((3.0 - q).max(0.0), (2.0 - q).max(0.0), (1.0 - q).max(0.0));
                let p5 = |x: f64| (x * x) * (x * x) * x;
                p5(a) - 6.0 * p5(b) + 15.0 * p5(c)
            }
            KernelKind::WendlandC2 => (1.0 - 0.5 * q).max(0.0).powi(4) * (1.0 + 2.0 * q),
            KernelKind::WendlandC4 => {
                (1.0 - 0.5 * q).max(0.0).powi(6) * (1.0 + 3.0 * q + 35.0 / 12.0 * q * q)
            }
        };
        self.norm * shape
    }

    /// F(r) = W'(r) / r, so that ∇_i W_ij = r_ij F(|r_ij|) with r_ij = r_i − r_j.
    /// F ≤ 0 everywhere; F(0) is the finite limit W''(0).
    #[inline]
    pub fn grad_factor(&self, r: f64) -> f64 {
        let q = r * self.inv_h;
        let inv_h2 = self.inv_h * self.inv_h;
        match self.kind {
            KernelKind::Quintic if r > 0.0 => {
                let (a, b, c) = ((3.0 - q).max(0.0), (2.0 - q).max(0.0), (1.0 - q).max(0.0));
                let p4 = |x: f64| (x * x) * (x * x);
                let dw_dq = -5.0 * (p4(a) - 6.0 * p4(b) + 15.0 * p4(c));
                self.norm * dw_dq * self.inv_h / r
            }
            // lim_{r→0} W'(r)/r = W''(0) = α (20 (27 − 6·8 + 15)) / h² (d²/dq² of Eq. 19 at 0).
            KernelKind::Quintic => self.quintic_second_derivative_at_zero(),
            // (dW/dq)/q over α_d, as `wendland_factor`.
            KernelKind::WendlandC2 => self.norm * inv_h2 * -5.0 * (1.0 - 0.5 * q).max(0.0).powi(3),
            KernelKind::WendlandC4 => {
                self.norm
                    * inv_h2
                    * (-14.0 / 3.0)
                    * (1.0 - 0.5 * q).max(0.0).powi(5)
                    * (1.0 + 2.5 * q)
            }
        }
    }

    /// W''(0) of the quintic, the limit of W'(r)/r at r = 0.
    fn quintic_second_derivative_at_zero(&self) -> f64 {
        self.norm * 20.0 * (27.0 - 48.0 + 15.0) * self.inv_h * self.inv_h
    }

    /// W(r) in lanes.
    #[inline(always)]
    pub fn w_lanes(&self, r: F64s) -> F64s {
        let q = r * F64s::splat(self.inv_h);
        let norm = F64s::splat(self.norm);
        match self.kind {
            KernelKind::Quintic => {
                let [a, b, c] = quintic_terms(q);
                let p5 = |x: F64s| (x * x) * (x * x) * x;
                norm * F64s::splat(15.0).mul_add(p5(c), F64s::splat(-6.0).mul_add(p5(b), p5(a)))
            }
            KernelKind::WendlandC2 => {
                let t = wendland_term(q);
                let t2 = t * t;
                norm * (t2 * t2) * F64s::splat(2.0).mul_add(q, F64s::ONE)
            }
            KernelKind::WendlandC4 => {
                let t = wendland_term(q);
                let t3 = t * t * t;
                let poly = (F64s::splat(35.0 / 12.0) * q + F64s::splat(3.0)).mul_add(q, F64s::ONE);
                norm * (t3 * t3) * poly
            }
        }
    }

    /// F(r) = W'(r)/r in lanes (W''(0) where r = 0, as `grad_factor`).
    #[inline(always)]
    pub fn grad_factor_lanes(&self, r: F64s) -> F64s {
        match self.kind {
            KernelKind::Quintic => {
                let (dw_dr, at_zero) = self.derivative_lanes(r);
                let at_zero_value = F64s::splat(self.quintic_second_derivative_at_zero());
                at_zero.select(at_zero_value, dw_dr / r)
            }
            // W'(r)/r is a polynomial in q (`wendland_factor`): no division, finite at r = 0.
            KernelKind::WendlandC2 | KernelKind::WendlandC4 => {
                F64s::splat(self.norm * self.inv_h * self.inv_h)
                    * self.wendland_factor(r * F64s::splat(self.inv_h))
            }
        }
    }

    /// W'(r) in lanes, and the mask of the lanes with r = 0 (where W'(0) = 0 for every kernel).
    #[inline(always)]
    pub fn derivative_lanes(&self, r: F64s) -> (F64s, F64s) {
        let q = r * F64s::splat(self.inv_h);
        let dw_dq = match self.kind {
            KernelKind::Quintic => {
                let [a, b, c] = quintic_terms(q);
                let p4 = |x: F64s| (x * x) * (x * x);
                F64s::splat(-5.0)
                    * F64s::splat(15.0).mul_add(p4(c), F64s::splat(-6.0).mul_add(p4(b), p4(a)))
            }
            KernelKind::WendlandC2 | KernelKind::WendlandC4 => q * self.wendland_factor(q),
        };
        (
            F64s::splat(self.norm * self.inv_h) * dw_dq,
            r.simd_eq(F64s::ZERO),
        )
    }

    /// (dW/dq)/q of the Wendland functions over α_d: −5 (1 − q/2)³₊ for C2,
    /// −(14/3)(1 + 5q/2)(1 − q/2)⁵₊ for C4.
    #[inline(always)]
    fn wendland_factor(&self, q: F64s) -> F64s {
        let t = wendland_term(q);
        match self.kind {
            KernelKind::WendlandC2 => F64s::splat(-5.0) * (t * t * t),
            KernelKind::WendlandC4 => {
                let t2 = t * t;
                F64s::splat(-14.0 / 3.0) * (t2 * t2 * t) * F64s::splat(2.5).mul_add(q, F64s::ONE)
            }
            KernelKind::Quintic => unreachable!("the quintic is not a Wendland function"),
        }
    }
}

/// (3 − q)₊, (2 − q)₊, (1 − q)₊ of Eq. (19).
#[inline(always)]
fn quintic_terms(q: F64s) -> [F64s; 3] {
    [3.0, 2.0, 1.0].map(|k| (F64s::splat(k) - q).fast_max(F64s::ZERO))
}

/// (1 − q/2)₊ of the Wendland functions.
#[inline(always)]
fn wendland_term(q: F64s) -> F64s {
    F64s::splat(-0.5).mul_add(q, F64s::ONE).fast_max(F64s::ZERO)
}
