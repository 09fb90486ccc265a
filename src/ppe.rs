//! The pressure Poisson equation of Eq. (6), assembled matrix-free:
//!
//! * interior fluid rows:  −∇²P_i = −(ρ0/Δt) ∇·u*_i − α (ρ0 − ρ_i)/Δt²  with the Laplacian of
//!   Eq. (27), made first-order consistent where the free surface truncates the kernel;
//! * free-surface rows:    P_i = 0 (Dirichlet);
//! * wall rows:            P_w = Σ_f ω_wf (P_f + ρ_f (g − a_t,f)·(r_w − r_f)), ω_wf = W_wf/Σ_f W_wf,
//!   the discrete Neumann condition (the kernel-weighted fluid pressure carried to the wall
//!   particle by the fluid's momentum balance, after Adami et al. 2012; a_t is the fluid's
//!   acceleration along the wall), plus the kinematic term for free-surface particles moving
//!   into the wall;
//! * walls with no fluid in reach: P_w = 0.
//!
//! After the solve, negative fluid pressures are clipped to zero (see `clip_tension`).
//!
//! The wall rows make the system non-symmetric, hence BiCGSTAB.

use crate::linsolve::LinearOperator;
use crate::particles::{Kind, Particles};
use crate::reduce::fill;
use crate::sph::{laplacian_coefficient, velocity_gradient, Correction, Neighbours};

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

/// Assigns roles: fluid with ∇·r below `threshold` is free surface; walls are active when a
/// fluid particle lies in their support. If the fluid has no free surface at all (a full
/// closed box) the PPE is singular; the highest fluid particle is then pinned to P = 0.
pub fn assign_roles<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    div_r: &[f64],
    threshold: f64,
    gravity: [f64; D],
    roles: &mut Vec<Role>,
) {
    roles.resize(p.len(), Role::Idle);
    fill(roles, |i| match p.kind[i] {
        // ∇·r barely sees near-coincident neighbours, so a particle squeezed against a wall or
        // into a clump can look like free surface; one denser than rest never is.
        Kind::Fluid if div_r[i] < threshold && p.density[i] < p.rest_density[i] => Role::Surface,
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
    wall_normal: impl Fn([f64; D]) -> [f64; D] + Sync,
    b: &mut Vec<f64>,
) {
    b.resize(p.len(), 0.0);
    fill(b, |i| match roles[i] {
        Role::Interior => interior_source(nb, p, &corrections[i], u_star, full[i], dt, alpha, i),
        Role::Wall => {
            // ρ (g − a_t)·(r_w − r_f): the fluid's momentum balance ∇P = ρ (g − a) with a_t the
            // tangential part (along the wall, normal n) of the fluid's acceleration in the last
            // step; the wall itself does not accelerate (Adami et al. 2012). For still water the
            // hydrostatic term; along a wall where the fluid falls freely it vanishes, so dry
            // wall above a falling surface does not suck the fluid in.
            let n = wall_normal(p.position(i));
            let (mut wsum, mut hydro) = (0.0, 0.0);
            nb.for_each(i, |j, rij, r| {
                if p.is_fluid(j) {
                    let w = nb.kernel.w(r);
                    let a: [f64; D] = std::array::from_fn(|d| p.acceleration[d][j]);
                    let a_n: f64 = (0..D).map(|d| a[d] * n[d]).sum();
                    let f_dot_r: f64 = (0..D)
                        .map(|d| (gravity[d] - (a[d] - a_n * n[d])) * rij[d])
                        .sum();
                    // A free-surface particle has no PPE row, so the wall's kinematic condition
                    // ∂P/∂n = (ρ/Δt) uⁿ·n for flow into the wall enters through the wall row.
                    let approach = if roles[j] == Role::Surface {
                        let u_n: f64 = (0..D).map(|d| p.vel[d][j] * n[d]).sum();
                        let r_n: f64 = (0..D).map(|d| rij[d] * n[d]).sum();
                        u_n.min(0.0) / dt * r_n
                    } else {
                        0.0
                    };
                    wsum += w;
                    hydro += w * p.rest_density[j] * (f_dot_r + approach);
                }
            });
            hydro / wsum
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

/// Clips negative fluid pressures to zero after the solve, as SPlisHSPlasH's implicit solvers
/// do: tension would pull particles into clumps. Wall pressures are kept as solved: above the
/// free surface the hydrostatic extrapolation is negative, and only with the values the solve
/// used does the corrector keep a still surface at rest where it meets a wall.
pub fn clip_tension(pressure: &mut [f64], kind: &[Kind]) {
    for (pressure, kind) in pressure.iter_mut().zip(kind) {
        if *kind == Kind::Fluid {
            *pressure = pressure.max(0.0);
        }
    }
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
}

impl<const D: usize> PressureOperator<'_, D> {
    /// Coefficient of (x_i − x_j) in the interior row i: a_ij − V_j ĉ_i·∇W_ij.
    #[inline]
    fn interior_coefficient(&self, i: usize, j: usize, rij: [f64; D], r: f64) -> f64 {
        let (nb, p) = (self.nb, self.p);
        let c_dot_r: f64 = (0..D).map(|d| self.consistency[d][i] * rij[d]).sum();
        laplacian_coefficient(nb, p, i, j, r)
            - p.mass[j] / p.rest_density[j] * nb.kernel.grad_factor(r) * c_dot_r
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
                let (mut wsum, mut wx) = (0.0, 0.0);
                nb.for_each(i, |j, _, r| {
                    if p.is_fluid(j) {
                        let w = nb.kernel.w(r);
                        wsum += w;
                        wx += w * x[j];
                    }
                });
                x[i] - wx / wsum
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
