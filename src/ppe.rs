//! The pressure Poisson equation of Eq. (6), assembled matrix-free:
//!
//! * interior fluid rows:  −∇²P_i = −(ρ0/Δt) ∇·u*_i − α (ρ0 − ρ_i)/Δt²  with the Laplacian of
//!   Eq. (27), made first-order consistent where the free surface truncates the kernel;
//! * free-surface rows:    P_i = 0 (Dirichlet);
//! * wall rows:            P_w = Σ_f c_wf (P_f + ρ_f (g·n)(r_w − r_f)·n), the Neumann condition
//!   ∂P/∂n = ρ g·n through the linear fit of `wall`;
//! * walls with no fluid in reach: P_w = 0.
//!
//! After the solve, negative fluid pressures are clipped to zero and the wall rows re-evaluated
//! (see `PressureOperator::clipped`).
//!
//! The wall rows make the system non-symmetric, hence BiCGSTAB.

use crate::free_surface::Support;
use crate::linsolve::LinearOperator;
use crate::particles::{Kind, Particles};
use crate::reduce::fill;
use crate::sph::{laplacian_coefficient, velocity_gradient, Correction, Neighbours};
use crate::wall::WallFit;

/// The role of a particle in the pressure solve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Fluid with a full neighbourhood: the Laplacian row.
    Interior,
    /// Fluid at the free surface: P = 0.
    Surface,
    /// Wall particle with fluid in reach: the Neumann extrapolation row.
    Wall,
    /// Wall particle no fluid reaches: P = 0.
    Idle,
}

/// Assigns roles: fluid on the free surface (see `free_surface`) takes P = 0; walls are active when a fluid particle lies
/// in their support. If the fluid has no free surface at all (a full closed box) the PPE is
/// singular; the highest fluid particle is then pinned to P = 0.
pub fn assign_roles<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    supports: &[Support<D>],
    gravity: [f64; D],
    roles: &mut Vec<Role>,
) {
    roles.resize(p.len(), Role::Idle);
    fill(roles, |i| match p.kind[i] {
        Kind::Fluid if supports[i].is_free_surface(nb, i, p.density[i] / p.rest_density[i]) => {
            Role::Surface
        }
        Kind::Fluid => Role::Interior,
        Kind::Wall => {
            let mut near_fluid = false;
            nb.for_each(i, |j, _, _| near_fluid |= p.is_fluid(j));
            if near_fluid {
                Role::Wall
            } else {
                Role::Idle
            }
        }
    });
    if !roles.contains(&Role::Surface) {
        let height = |i: usize| -(0..D).map(|d| gravity[d] * p.pos[d][i]).sum::<f64>();
        let top = (0..p.len())
            .filter(|&i| roles[i] == Role::Interior)
            .max_by(|&a, &b| height(a).total_cmp(&height(b)).then(b.cmp(&a)));
        if let Some(top) = top {
            roles[top] = Role::Surface;
        }
    }
}

/// Marks fluid particles whose kernel support holds no free-surface particle: there the
/// summation density measures compression, not the truncation of the kernel at the surface.
pub fn full_support<const D: usize>(nb: &Neighbours<D>, roles: &[Role], full: &mut Vec<bool>) {
    full.resize(roles.len(), false);
    fill(full, |i| {
        if roles[i] != Role::Interior {
            return false;
        }
        let mut any_surface = false;
        nb.for_each(i, |j, _, _| any_surface |= roles[j] == Role::Surface);
        !any_surface
    });
}

/// Right-hand side b of the PPE rows (same sign convention as `PressureOperator`).
#[allow(clippy::too_many_arguments)]
pub fn source<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    roles: &[Role],
    full: &[bool],
    corrections: &[Correction<D>],
    u_star: &[Vec<f64>; D],
    dt: f64,
    alpha: f64,
    gravity: [f64; D],
    walls: &[WallFit<D>],
    b: &mut Vec<f64>,
) {
    b.resize(p.len(), 0.0);
    fill(b, |i| match roles[i] {
        Role::Interior => interior_source(nb, p, &corrections[i], u_star, full[i], dt, alpha, i),
        Role::Wall => {
            // Σ_f c_wf ρ_f g_w·(r_w − r_f): the Neumann condition of the fit (see `wall`).
            let fit = &walls[i];
            let g = fit.carried_gravity(gravity);
            let mut b = 0.0;
            nb.for_each(i, |j, rij, r| {
                if p.is_fluid(j) {
                    let g_r: f64 = (0..D).map(|d| g[d] * rij[d]).sum();
                    b += fit.weight(rij, r, nb) * p.rest_density[j] * g_r;
                }
            });
            b
        }
        Role::Surface | Role::Idle => 0.0,
    });
}

/// Right-hand side of an interior fluid row: −(ρ0/Δt) ∇·u* − α (ρ0 − ρ_i)/Δt², Eq. (6), with
/// ∇·u* corrected by Eq. (24)–(25) so that it is exact for linear velocity fields also where
/// the free surface truncates the kernel support.
#[allow(clippy::too_many_arguments)]
fn interior_source<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    l: &Correction<D>,
    u_star: &[Vec<f64>; D],
    full_support: bool,
    dt: f64,
    alpha: f64,
    i: usize,
) -> f64 {
    let rho_i = p.density[i];
    // Walls take the fluid's own predictor increment u*_i − uⁿ_i: the body force is carried by
    // the wall rows, the wall's kinematic condition by the divergence.
    let wall_u: [f64; D] = std::array::from_fn(|d| u_star[d][i] - p.vel[d][i]);
    let velocity = |j: usize| -> [f64; D] {
        match p.kind[j] {
            Kind::Wall => wall_u,
            Kind::Fluid => std::array::from_fn(|d| u_star[d][j]),
        }
    };
    // ∇·u* = trace of the corrected velocity gradient, Eq. (22) with Eq. (24)–(25).
    let grad_u = velocity_gradient(nb, p, l, velocity, i);
    let div: f64 = (0..D).map(|a| grad_u[a][a]).sum();
    let rho0 = p.rest_density[i];
    // Where the free surface truncates the kernel the summation density is low because
    // neighbours are missing, not because the fluid expanded: there only compression counts.
    let density_deviation = if full_support {
        rho0 - rho_i
    } else {
        (rho0 - rho_i).min(0.0)
    };
    let density_term = alpha * density_deviation / (dt * dt);
    -(rho0 / dt * div + density_term)
}

/// First-order consistency of the Laplacian of Eq. (27). Where the free surface truncates the
/// kernel support, Eq. (27) applied to a linear field P is not zero but −c_i·∇P_i, with
/// c_i = 2 Σ_j (m_j/ρ_i) r_ij r_ij·∇W_ij/(r_ij² + η²) (zero for a full support). Subtracting
/// that term, with ∇P_i the corrected gradient L_i Σ_j V_j (P_j − P_i)∇W_ij, gives the row
/// Σ_j (a_ij − V_j (L_iᵀc_i)·∇W_ij)(P_i − P_j), still one pass over the neighbours. Without it
/// the pressure bends under the free surface and pushes a still surface off its rest position.
/// Returns ĉ_i = L_iᵀ c_i (zero for particles that are not interior fluid).
pub fn laplacian_correction<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    roles: &[Role],
    l: &Correction<D>,
    i: usize,
) -> [f64; D] {
    if roles[i] != Role::Interior {
        return [0.0; D];
    }
    let mut c = [0.0; D];
    nb.for_each(i, |j, rij, r| {
        let cl = 2.0 * p.mass[j] / p.rest_density[i] * nb.laplacian_factor(r);
        for d in 0..D {
            c[d] += cl * rij[d];
        }
    });
    match l {
        Some(l) => std::array::from_fn(|a| (0..D).map(|b| l[b][a] * c[b]).sum()),
        None => c,
    }
}

/// The PPE matrix A, applied on the fly from positions (no matrix, no per-pair list).
pub struct PressureOperator<'a, const D: usize> {
    pub nb: &'a Neighbours<'a, D>,
    pub p: &'a Particles<D>,
    pub roles: &'a [Role],
    /// ĉ_i of `laplacian_correction`.
    pub consistency: &'a [Vec<f64>; D],
    /// The extrapolation of each wall row.
    pub walls: &'a [WallFit<D>],
}

impl<const D: usize> PressureOperator<'_, D> {
    /// The pressure after the solve: negative fluid pressures clipped to zero, as
    /// SPlisHSPlasH's implicit solvers do (the fluid cannot sustain tension, which would pull
    /// particles into clumps), and each wall row re-evaluated from the clipped fluid pressures,
    /// P_w = b_w + Σ_f c_wf P_f, so that no wall pulls fluid in where the fluid itself does not.
    /// Still water is untouched: nothing is clipped there.
    pub fn clipped(&self, b: &[f64], solved: &[f64], out: &mut [f64]) {
        let (nb, p) = (self.nb, self.p);
        fill(out, |i| match self.roles[i] {
            Role::Interior | Role::Surface => solved[i].max(0.0),
            Role::Wall => {
                let fit = &self.walls[i];
                let mut pw = b[i];
                nb.for_each(i, |j, rij, r| {
                    if p.is_fluid(j) {
                        pw += fit.weight(rij, r, nb) * solved[j].max(0.0);
                    }
                });
                pw
            }
            Role::Idle => solved[i],
        });
    }

    /// Coefficient of (x_i − x_j) in the interior row i: max(a_ij − V_j ĉ_i·∇W_ij, 0).
    #[inline]
    fn interior_coefficient(&self, i: usize, j: usize, rij: [f64; D], r: f64) -> f64 {
        let (nb, p) = (self.nb, self.p);
        let c_dot_r: f64 = (0..D).map(|d| self.consistency[d][i] * rij[d]).sum();
        let coefficient = laplacian_coefficient(nb, p, i, j, r)
            - p.mass[j] / p.rest_density[j] * nb.kernel.grad_factor(r) * c_dot_r;
        // Where the support is badly truncated (a surge tip, spray) the correction can turn a
        // weight negative; clipped at zero the row keeps non-negative neighbour weights (an
        // M-matrix row) and the solve no pressure spikes. Still water never needs the clip.
        coefficient.max(0.0)
    }

    /// (A x)_i.
    #[inline]
    fn row(&self, x: &[f64], i: usize) -> f64 {
        let (nb, p) = (self.nb, self.p);
        match self.roles[i] {
            Role::Interior => {
                let mut ax = 0.0;
                nb.for_each(i, |j, rij, r| {
                    ax += self.interior_coefficient(i, j, rij, r) * (x[i] - x[j])
                });
                ax
            }
            Role::Wall => {
                let fit = &self.walls[i];
                let mut wx = 0.0;
                nb.for_each(i, |j, rij, r| {
                    if p.is_fluid(j) {
                        wx += fit.weight(rij, r, nb) * x[j];
                    }
                });
                x[i] - wx
            }
            Role::Surface | Role::Idle => x[i],
        }
    }
}

impl<const D: usize> LinearOperator for PressureOperator<'_, D> {
    fn len(&self) -> usize {
        self.p.len()
    }

    fn apply(&self, x: &[f64], y: &mut [f64]) {
        fill(y, |i| self.row(x, i));
    }

    fn diagonal(&self, diag: &mut [f64]) {
        fill(diag, |i| match self.roles[i] {
            Role::Interior => {
                let mut d = 0.0;
                self.nb
                    .for_each(i, |j, rij, r| d += self.interior_coefficient(i, j, rij, r));
                d
            }
            Role::Wall | Role::Surface | Role::Idle => 1.0,
        });
    }
}
