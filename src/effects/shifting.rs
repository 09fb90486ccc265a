//! Particle shifting, Eq. (9)–(10): Fickian shifting δr = −D ∇C against the disorder that the
//! Lagrangian motion creates — where the flow stretches the fluid, particles line up across the
//! stretching direction and leave gaps between the lines.
//!
//! * ∇C_i = Σ_j V_j (1 + R (W_ij/W(dx))⁴) ∇W_ij with R = 0.2 (Lind et al. 2012, J. Comput.
//!   Phys. 231): the second term pushes apart pairs closer than dx, which breaks up the lines
//!   that ∇C of evenly spaced lines alone does not see.
//! * D = A h U Δt with A = 2 (Skillen et al. 2013; DualSPHysics), U the largest fluid speed:
//!   a displacement of at most A·C·h dx·|∇C| per step (C the CFL number on the spacing),
//!   independent of Δt per unit of flow
//!   travel. The particle's own speed would leave disorder untouched near stagnation points,
//!   where the flow still stretches the fluid.
//! * D is capped at `MAX_DIFFUSION_NUMBER` h²: the shift is one explicit step of a diffusion
//!   of the particle concentration (δC ≈ D ∇²C), stable only below a diffusion number of about
//!   one, and with U Δt ≤ C dx the number A h U Δt / h² reaches A·C dx/h, 0.67 at the
//!   defaults (C = 0.4, h/dx = 1.2) but 1.67 at CFL 1.0. On the a/30 impact the cap lowers the
//!   mean density error at the largest steps and changes little at CFL 0.6 (docs/stabilisation.md,
//!   "Particle shifting"); at the default CFL 0.4 it never acts.
//! * Where the free surface truncates the kernel support, ∇C points out of the fluid; there
//!   only the part tangential to the surface is kept (normal of `free_surface`).
//! * Each component is capped at 0.1 dx.
//!
//! A, R and the cap are the scene's `[effects.shifting]` (`ShiftingSettings`); the values above
//! are their defaults.
//!
//! Velocity and pressure are then carried to the shifted position by Eq. (9),
//! φ' = φ + (∇φ)·δr.

use crate::math::lanes::{F64s, Sum};
use crate::neighbours::{Lanes, Neighbours};
use crate::particles::Particles;
use crate::scene::ShiftingSettings;
use crate::sph::volume_gradient_factor;

/// Largest diffusion number D/h² of the shift (module doc).
const MAX_DIFFUSION_NUMBER: f64 = 0.8;

/// The shifting of one step: D and the reference kernel value W(dx).
pub struct Shifting {
    diffusion: f64,
    w_dx: f64,
    cap: f64,
    clustering_weight: f64,
}

impl Shifting {
    /// Shifting for a step of `dt` with largest fluid speed `max_speed` at spacing `spacing`.
    pub fn new<const D: usize>(
        nb: &Neighbours<D>,
        settings: &ShiftingSettings,
        spacing: f64,
        max_speed: f64,
        dt: f64,
    ) -> Self {
        Self {
            diffusion: (settings.coefficient * nb.kernel.width() * max_speed * dt)
                .min(MAX_DIFFUSION_NUMBER * nb.kernel.width() * nb.kernel.width()),
            w_dx: nb.kernel.w(spacing),
            cap: settings.max_shift * spacing,
            clustering_weight: settings.clustering_weight,
        }
    }

    /// δr_i of Eq. (10) for fluid particle i; `full_support` says that no free-surface particle
    /// is in its kernel support (then the whole ∇C is used, else its part tangential to the
    /// free surface of outward normal `surface_normal`).
    pub fn displacement<const D: usize>(
        &self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        surface_normal: [f64; D],
        full_support: bool,
        i: usize,
    ) -> [f64; D] {
        let mut grad = [Sum::ZERO; D];
        nb.for_each_lanes(i, |l| {
            self.add_pairs(nb, l, volume_gradient_factor(nb, p, l), &mut grad)
        });
        self.of_gradient(grad, surface_normal, full_support)
    }

    /// Adds the pairs of the lanes `l`, whose V_j ∇W_ij factor is `vf`
    /// (`volume_gradient_factor`), to the sum `grad` of ∇C_i: a walk of its own
    /// (`displacement`) or another's (`sph::velocity_gradient_and`).
    #[inline(always)]
    pub fn add_pairs<const D: usize>(
        &self,
        nb: &Neighbours<D>,
        l: &Lanes<D>,
        vf: F64s,
        grad: &mut [Sum; D],
    ) {
        let (inv_w_dx, weight) = (
            F64s::splat(1.0 / self.w_dx),
            F64s::splat(self.clustering_weight),
        );
        let ratio = nb.kernel.w_lanes(l.r) * inv_w_dx;
        let ratio2 = ratio * ratio;
        let c = vf * weight.mul_add(ratio2 * ratio2, F64s::ONE);
        for d in 0..D {
            grad[d] = grad[d].mul_add(c, l.rij[d]);
        }
    }

    /// δr_i of Eq. (10) from the sum of ∇C_i over i's neighbours (`add_pairs`).
    pub fn of_gradient<const D: usize>(
        &self,
        grad: [Sum; D],
        surface_normal: [f64; D],
        full_support: bool,
    ) -> [f64; D] {
        let mut grad_c = grad.map(|g| g.total());
        if !full_support {
            let n = surface_normal;
            let normal_part: f64 = (0..D).map(|d| grad_c[d] * n[d]).sum();
            for d in 0..D {
                grad_c[d] -= normal_part * n[d];
            }
        }
        grad_c.map(|g| (-self.diffusion * g).clamp(-self.cap, self.cap))
    }
}
