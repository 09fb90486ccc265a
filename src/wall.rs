//! Wall pressure: the Neumann condition ∂P/∂n = ρ g·n carried to the dummy wall particles.
//!
//! Each wall particle w with fluid in reach takes the value at r_w of the linear pressure field
//! fitted to its fluid neighbours by weighted least squares, with the normal slope fixed by the
//! boundary condition:
//!
//!   P(r_w + x) = a + b·x_t + ρ (g·n)(x·n),   x_t the part of x along the wall,
//!
//! so that P_w = a = Σ_f c_wf (P_f + ρ (g·n)(r_w − r_f)·n), with weights c_wf = W_wf (q_0 +
//! s·(r_f − r_w)) from the fit (Σ_f c_wf = 1). Along the wall the fit follows whatever the fluid
//! pressure does — hydrostatic beside still water, flat beside a falling column — and across it
//! only the boundary condition counts. The fit is part of the linear system, so the wall
//! pressure responds to the solve and needs no quantity from the last step (which, fed back
//! through the walls, grows into an instability along the floor under a fast surge). Where
//! the fluid neighbours do not determine a slope along the wall (a lone particle, a thin
//! column, a corner far beyond the last fluid particle), the fit falls back to the kernel-weighted
//! mean carried hydrostatically to the wall particle, P_w = Σ_f ω_wf (P_f + ρ g·(r_w − r_f))
//! (Adami et al. 2012).

use crate::particles::Particles;
use crate::scene::Aabb;
use crate::sph::{invert, Neighbours};

/// Smallest determinant of the normalised fit matrix Σ W φφᵀ / Σ W (φ in units of h) for
/// which the slope along the wall is fitted.
const MIN_FIT_DETERMINANT: f64 = 1.0e-4;
/// Largest Σ_f |c_wf| accepted from the fit: larger means extrapolating far beyond the fluid.
const MAX_FIT_NORM: f64 = 2.0;

/// The fitted extrapolation of one wall particle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallFit<const D: usize> {
    /// Unit wall normal pointing into the fluid.
    pub normal: [f64; D],
    /// Whether the slope along the wall is fitted; if not, the pressure is taken hydrostatic
    /// along the wall too.
    fitted: bool,
    /// q_0 and s of the weights c_wf = W_wf (q_0 + s·(r_f − r_w)).
    base: f64,
    slope: [f64; D],
}

impl<const D: usize> WallFit<D> {
    /// No fit: fluid particles and walls no fluid reaches.
    pub const NONE: Self = Self {
        normal: [0.0; D],
        fitted: false,
        base: 0.0,
        slope: [0.0; D],
    };

    /// The fit of wall particle `w` with wall normal `normal`.
    pub fn new(nb: &Neighbours<D>, p: &Particles<D>, normal: [f64; D], w: usize) -> Self {
        let h = nb.kernel.h();
        let t = tangents(normal);
        // φ(x) = [1, x·t_1/h, …, x·t_{D−1}/h].
        let phi = |x: [f64; D]| -> [f64; D] {
            std::array::from_fn(|k| if k == 0 { 1.0 } else { dot(x, t[k - 1]) / h })
        };
        let (mut a, mut wsum) = ([[0.0; D]; D], 0.0);
        nb.for_each(w, |f, rwf, r| {
            if p.is_fluid(f) {
                let (weight, ph) = (nb.kernel.w(r), phi(rwf.map(|v| -v)));
                wsum += weight;
                for k in 0..D {
                    for l in 0..D {
                        a[k][l] += weight * ph[k] * ph[l];
                    }
                }
            }
        });
        let shepard = Self {
            normal,
            fitted: false,
            base: 1.0 / wsum,
            slope: [0.0; D],
        };
        let Some((inv, det)) = invert(a.map(|row| row.map(|v| v / wsum))) else {
            return shepard;
        };
        if det < MIN_FIT_DETERMINANT {
            return shepard;
        }
        // q = A⁻¹ e_0 (A symmetric), so c_f = W_f q·φ_f = W_f (q_0 + s·x_f).
        let q: [f64; D] = std::array::from_fn(|k| inv[k][0] / wsum);
        let mut slope = [0.0; D];
        for k in 1..D {
            for d in 0..D {
                slope[d] += q[k] * t[k - 1][d] / h;
            }
        }
        let fit = Self {
            normal,
            fitted: true,
            base: q[0],
            slope,
        };
        let mut norm = 0.0;
        nb.for_each(w, |f, rwf, r| {
            if p.is_fluid(f) {
                norm += fit.weight(rwf, r, nb).abs();
            }
        });
        if norm > MAX_FIT_NORM {
            shepard
        } else {
            fit
        }
    }

    /// g_w, the body force carried from each fluid neighbour to the wall particle: its normal
    /// part (g·n)n where the fit supplies the slope along the wall, all of g where it does not.
    pub fn carried_gravity(&self, gravity: [f64; D]) -> [f64; D] {
        if self.fitted {
            let g_n = dot(gravity, self.normal);
            self.normal.map(|n| g_n * n)
        } else {
            gravity
        }
    }

    /// c_wf for the fluid neighbour at r_wf = r_w − r_f, |r_wf| = r.
    #[inline]
    pub fn weight(&self, rwf: [f64; D], r: f64, nb: &Neighbours<D>) -> f64 {
        nb.kernel.w(r) * (self.base - dot(self.slope, rwf))
    }
}

/// The wall a fluid particle touches: the normal of the nearest wall particle closer than the
/// spacing dx (nearer than at rest), or zero where there is none.
pub fn contact_normal<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    walls: &[WallFit<D>],
    spacing: f64,
    i: usize,
) -> [f64; D] {
    let mut nearest = (spacing, None);
    nb.for_each(i, |j, _, r| {
        if !p.is_fluid(j) && r < nearest.0 {
            nearest = (r, Some(j));
        }
    });
    nearest.1.map_or([0.0; D], |j| walls[j].normal)
}

/// The kinematic wall condition v·n ≥ 0 for a velocity or displacement v of a fluid particle
/// touching a wall of normal n (see `contact_normal`): v ← v − min(v·n, 0) n, the particle does
/// not move further into the wall. The PPE cannot impose it: the Neumann condition slaves the
/// wall pressure to the fluid's, so it resists no approach beyond the hydrostatic; the fluid
/// meets the wall inelastically, as it does.
pub fn no_penetration<const D: usize>(v: [f64; D], n: [f64; D]) -> [f64; D] {
    let v_n = dot(v, n).min(0.0);
    std::array::from_fn(|d| v[d] - v_n * n[d])
}

fn dot<const D: usize>(a: [f64; D], b: [f64; D]) -> f64 {
    (0..D).map(|d| a[d] * b[d]).sum()
}

/// D − 1 unit vectors orthogonal to the unit vector n and to each other.
fn tangents<const D: usize>(n: [f64; D]) -> [[f64; D]; 2] {
    let mut t = [[0.0; D]; 2];
    match D {
        1 => {}
        2 => {
            t[0][0] = -n[1];
            t[0][1] = n[0];
        }
        3 => {
            // t_1 = n × e_a / |…| with e_a the axis least aligned with n, t_2 = n × t_1.
            let a = (0..3)
                .min_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
                .expect("three axes");
            let mut e = [0.0; D];
            e[a] = 1.0;
            let t1 = cross(n, e);
            let len = dot(t1, t1).sqrt();
            t[0] = t1.map(|v| v / len);
            t[1] = cross(n, t[0]);
        }
        _ => panic!("walls are implemented for D ≤ 3"),
    }
    t
}

fn cross<const D: usize>(a: [f64; D], b: [f64; D]) -> [f64; D] {
    std::array::from_fn(|c| {
        let (k, l) = ((c + 1) % 3, (c + 2) % 3);
        a[k] * b[l] - a[l] * b[k]
    })
}

/// Unit normal of the wall at wall particle position x, pointing into the fluid: towards the
/// container for container walls, out of the nearest face for obstacle particles.
pub fn wall_normal<const D: usize>(container: &Aabb, obstacles: &[Aabb], x: [f64; D]) -> [f64; D] {
    let to_box: [f64; D] =
        std::array::from_fn(|d| x[d].clamp(container.min[d], container.max[d]) - x[d]);
    let len = to_box.iter().map(|v| v * v).sum::<f64>().sqrt();
    if len > 0.0 {
        return to_box.map(|v| v / len);
    }
    let mut best = (f64::INFINITY, [0.0; D]);
    for o in obstacles {
        for d in 0..D {
            for (gap, sign) in [(x[d] - o.min[d], -1.0), (o.max[d] - x[d], 1.0)] {
                if gap.abs() < best.0 {
                    let mut n = [0.0; D];
                    n[d] = sign;
                    best = (gap.abs(), n);
                }
            }
        }
    }
    best.1
}
