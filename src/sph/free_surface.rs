//! Free-surface detection after Marrone et al. (2010), "Fast free-surface detection and
//! level-set function definition in SPH solvers", J. Comput. Phys. 229, 3652–3663.
//!
//! 1. λ_i, the smallest eigenvalue of the moment matrix M_i = Σ_j V_j ∇W_ij ⊗ r_ji (whose
//!    inverse is the correction L_i of Eq. 25), measures how well the neighbours fill the kernel
//!    support in its emptiest direction: 1 inside the fluid, about 0.5 on a flat surface, 0 for a
//!    lone particle. Wall particles count, so fluid pressed against a wall is never taken for
//!    free surface. λ_i ≤ 0.2: free surface (splashes, thin sheets, drops); λ_i > 0.75:
//!    interior, with no further test.
//! 2. In between, the scan region decides: i is at the free surface exactly when no particle
//!    (fluid or wall) lies in the umbrella beyond it along some direction n — the cone of
//!    half-angle 45° around n within √2 h of r_i, capped by the ball of radius h around
//!    r_i + h n (h the kernel's `width`). Marrone et al. scan along the normal
//!    n_i = −∇C_i/|∇C_i|, ∇C_i = Σ_j V_j ∇W_ij; that normal misleads where walls fill one
//!    side (at the tip of a surge on the floor it points up while the fluid is missing ahead),
//!    so the scan also runs both ways along the eigenvector of λ_i, the direction in which the
//!    support is emptiest. A particle inside a gap of the fluid or squeezed against a wall has
//!    a neighbour in every umbrella; one on the surface has none in at least one.
//! 3. A particle whose summation density is below 0.9 ρ0 (at h/dx = 1.2, scaled with the kernel's
//!    reach: `spray_density`) is free surface whatever λ_i says: spray — loose particles at a
//!    breaking front or an impact, each with some neighbour in every umbrella but no fluid around
//!    it — and sparse fluid beside a wall, whose wall particles fill the moment matrix. A Laplacian
//!    row there sees a few neighbours converging at impact speed and answers with a pressure spike
//!    that blows the spray apart.
//! 4. A particle whose summation density exceeds ρ0 is never free surface, whatever the other
//!    rules say: a truncated support holds less mass than a full one, so one that holds more
//!    is compressed, and a free-surface row (a fixed pressure) cannot push back. A particle
//!    squeezed between a no-slip floor and the water behind it at the tip of a surge would
//!    otherwise answer with a pressure spike that shoots it out ahead of the front
//!    (docs/stabilisation.md, "Compressed fluid is never free surface").

use crate::math::kernel::{Kernel, KernelKind};
use crate::math::lattice::for_each_lattice_point;
use crate::math::vector::{dot, norm};
use crate::neighbours::Neighbours;

/// λ_i at or below which a particle is free surface without the scan (Marrone et al.).
const SPLASH_EIGENVALUE: f64 = 0.2;
/// λ_i above which a particle is interior without the scan (Marrone et al.).
const INTERIOR_EIGENVALUE: f64 = 0.75;
/// ρ_i/ρ0 below which a particle is spray or sparse fluid at h/dx = `SPRAY_H_OVER_DX`
/// (`spray_density` scales it to other h/dx): on a lattice at h/dx = 1.2 the summation density
/// is 0.73 ρ0 on a flat free surface, 0.97 ρ0 one row below it and 0.93 ρ0 at the corner of a
/// 3D block one layer in.
const SPRAY_DENSITY: f64 = 0.9;
/// The h/dx `SPRAY_DENSITY` was set at.
const SPRAY_H_OVER_DX: f64 = 1.2;

/// ρ_i/ρ0 below which a particle is spray or sparse fluid (rule 3 above), for the quintic
/// kernel at `h_over_dx`: 0.9 at h/dx = 1.2, scaled with the summation density of the most
/// truncated particle that is not on the surface of a block of fluid, the corner of its
/// second layer, which the rule must leave alone. A wider kernel reaches further out of the
/// water: that corner holds 0.98 ρ0 at h/dx = 1.0, 0.93 at 1.2, 0.82 at 1.5 and 0.65 at 2.0 in
/// 3D (0.99, 0.95, 0.87, 0.74 in 2D), so a fixed 0.9 would take it, and from h/dx ≈ 1.75 on a
/// whole flat second row, for spray, fix their pressure at the surface's and let the water's
/// top fall (docs/accuracy.md, "Smoothing length above 1.5: still water").
pub fn spray_density<const D: usize>(kernel: KernelKind, h_over_dx: f64) -> f64 {
    SPRAY_DENSITY
        * (second_corner_density::<D>(Kernel::new(kernel, 1.0, h_over_dx))
            / second_corner_density::<D>(Kernel::new(KernelKind::Quintic, 1.0, SPRAY_H_OVER_DX)))
}

/// Σ_j W_ij dx^D at the corner of the second layer of a block filling the negative quadrant
/// (octant) of a lattice of unit spacing: the lattice points at most one spacing from it
/// along every axis towards the outside.
fn second_corner_density<const D: usize>(kernel: Kernel<D>) -> f64 {
    let reach = kernel.support().ceil() as i64;
    let mut sum = 0.0;
    for_each_lattice_point([-reach; D], [reach + 1; D], |k| {
        let offset = k.map(|o| o as f64);
        if offset.iter().all(|&o| o <= 1.0) {
            sum += kernel.w(norm(offset));
        }
    });
    sum * kernel.density_scale()
}

/// How the neighbours fill the kernel support of a fluid particle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Support<const D: usize> {
    /// Smallest eigenvalue λ_i of the moment matrix.
    pub lambda: f64,
    /// Unit normal out of the fluid, −∇C_i/|∇C_i| (zero where ∇C_i vanishes).
    pub normal: [f64; D],
    /// Unit eigenvector of λ_i (zero where the support is isotropic).
    axis: [f64; D],
}

impl<const D: usize> Support<D> {
    /// A full support (wall particles, and fluid far from the surface).
    pub const FULL: Self = Self {
        lambda: 1.0,
        normal: [0.0; D],
        axis: [0.0; D],
    };

    /// From the moment matrix M_i and the concentration gradient ∇C_i.
    pub fn new(m: &[[f64; D]; D], grad_c: [f64; D]) -> Self {
        let (lambda, axis) = min_eigenpair(m);
        let len = norm(grad_c);
        let normal = if len > 0.0 {
            grad_c.map(|g| -g / len)
        } else {
            [0.0; D]
        };
        Self {
            lambda,
            normal,
            axis,
        }
    }

    /// A splash, thin sheet or drop: too few neighbours to define a surface.
    pub fn is_splash(&self) -> bool {
        self.lambda <= SPLASH_EIGENVALUE
    }

    /// Whether fluid particle `i` with this support and summation density ρ_i = `density_ratio`
    /// ρ0 lies on the free surface; `spray_density` is the kernel's `spray_density`.
    pub fn is_free_surface(
        &self,
        nb: &Neighbours<D>,
        i: usize,
        density_ratio: f64,
        spray_density: f64,
    ) -> bool {
        if density_ratio > 1.0 {
            return false;
        }
        if self.is_splash() || density_ratio < spray_density {
            return true;
        }
        if self.lambda > INTERIOR_EIGENVALUE {
            return false;
        }
        let directions = [self.normal, self.axis, self.axis.map(|v| -v)];
        let h = nb.kernel.width();
        let mut covered = [false; 3];
        nb.for_each(i, |_, rij, r| {
            for (n, covered) in directions.iter().zip(&mut covered) {
                *covered |= in_umbrella(rij, r, *n, h);
            }
        });
        covered.iter().any(|c| !c)
    }
}

/// Whether the neighbour at r_ij = r_i − r_j (|r_ij| = r) lies in the umbrella of i along the
/// unit vector n.
fn in_umbrella<const D: usize>(rij: [f64; D], r: f64, n: [f64; D], h: f64) -> bool {
    // r_ji split into its parts along n and across it.
    let along = -dot(rij, n);
    let across = (r * r - along * along).max(0.0).sqrt();
    if r < std::f64::consts::SQRT_2 * h {
        // |n·r_jT| + |τ·r_ji| < h, r_T = r_i + h n: the 45° cone and its mirror beyond r_T.
        (along - h).abs() + across < h
    } else {
        // |r_j − r_T| < h.
        (along - h).powi(2) + across * across < h * h
    }
}

/// Smallest eigenvalue of a symmetric D×D matrix (D ≤ 3) and a unit eigenvector of it.
pub fn min_eigenpair<const D: usize>(m: &[[f64; D]; D]) -> (f64, [f64; D]) {
    let lambda = min_eigenvalue(m);
    // The eigenvector is orthogonal to every row of M − λI: in 2D the perpendicular of the
    // longest row, in 3D the longest cross product of two rows.
    let row = |r: usize| -> [f64; D] {
        std::array::from_fn(|c| m[r][c] - if r == c { lambda } else { 0.0 })
    };
    let candidates: Vec<[f64; D]> = match D {
        1 => vec![[1.0; D]],
        2 => (0..2)
            .map(|r| {
                let a = row(r);
                std::array::from_fn(|c| if c == 0 { -a[1] } else { a[0] })
            })
            .collect(),
        _ => [(0, 1), (0, 2), (1, 2)]
            .iter()
            .map(|&(r, s)| {
                let (a, b) = (row(r), row(s));
                std::array::from_fn(|c| {
                    let (k, l) = ((c + 1) % 3, (c + 2) % 3);
                    a[k] * b[l] - a[l] * b[k]
                })
            })
            .collect(),
    };
    let best = candidates
        .into_iter()
        .max_by(|a, b| dot(*a, *a).total_cmp(&dot(*b, *b)))
        .expect("at least one candidate");
    let len = norm(best);
    if len > 0.0 {
        (lambda, best.map(|x| x / len))
    } else {
        // M = λI: every direction is an eigenvector; the support is isotropic.
        (lambda, [0.0; D])
    }
}

/// Smallest eigenvalue of a symmetric D×D matrix (D ≤ 3), in closed form.
pub fn min_eigenvalue<const D: usize>(m: &[[f64; D]; D]) -> f64 {
    match D {
        1 => m[0][0],
        2 => {
            let (mean, diff) = (0.5 * (m[0][0] + m[1][1]), 0.5 * (m[0][0] - m[1][1]));
            mean - (diff * diff + m[0][1] * m[1][0]).max(0.0).sqrt()
        }
        3 => min_eigenvalue_3(m),
        _ => panic!("eigenvalues are implemented for D ≤ 3"),
    }
}

/// Smallest eigenvalue of a symmetric 3×3 matrix by the trigonometric method (Smith 1961).
fn min_eigenvalue_3<const D: usize>(m: &[[f64; D]; D]) -> f64 {
    let off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    if off == 0.0 {
        return m[0][0].min(m[1][1]).min(m[2][2]);
    }
    let q = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
    let dev = |k: usize| m[k][k] - q;
    let s = ((dev(0).powi(2) + dev(1).powi(2) + dev(2).powi(2) + 2.0 * off) / 6.0).sqrt();
    // B = (M − qI)/s; det(B)/2 = cos 3φ.
    let b = |r: usize, c: usize| (m[r][c] - if r == c { q } else { 0.0 }) / s;
    let det = b(0, 0) * (b(1, 1) * b(2, 2) - b(1, 2) * b(2, 1))
        - b(0, 1) * (b(1, 0) * b(2, 2) - b(1, 2) * b(2, 0))
        + b(0, 2) * (b(1, 0) * b(2, 1) - b(1, 1) * b(2, 0));
    let phi = (0.5 * det).clamp(-1.0, 1.0).acos() / 3.0;
    q + 2.0 * s * (phi + 2.0 * std::f64::consts::PI / 3.0).cos()
}
