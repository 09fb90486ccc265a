//! SPH discretisation: the operators of Eq. (20)–(27) written as per-particle sums over the
//! pair loop of `neighbours`.

pub use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};
use crate::wall::{self, behind_walls, ghost_velocity, Face};

/// Summation density ρ_i = Σ_j m_j W_ij (self included).
pub fn density<const D: usize>(nb: &Neighbours<D>, p: &Particles<D>, i: usize) -> f64 {
    let mut rho = p.mass[i] * nb.kernel.w(0.0);
    nb.for_each(i, |j, _, r| rho += p.mass[j] * nb.kernel.w(r));
    rho
}

/// Viscous acceleration ∇·(ν∇u)_i of Eq. (26) with ν = ν_fluid + ν_t, ν_t the eddy viscosity
/// of the Smagorinsky model (Eq. 3–4) where the scene runs LES (`eddy`; None: ν_t = 0). Wall
/// particles take the fluid's laminar viscosity (the turbulent stress at a wall is the law of
/// the wall's, `turbulence::wall_shear`) and the no-slip velocity of Morris, Fox & Zhu (1997),
/// with `face` the nearest wall's in the kernel support (`wall::nearest_face`):
/// u_b = −(d_b/d_i) u_i with d the distances to the wall face, which puts u = 0 on the face
/// itself, so u_i − u_b = β u_i with β = 1 + d_b/d_i = n_b·r_ib/d_i, capped at
/// `MORRIS_BETA_MAX` for the wall particles deep behind the face. (Walls simply at rest, β = 1, put
/// the no-slip line about half a spacing behind the face: a Poiseuille channel 20 particles wide
/// then flows 12% too fast.)
pub fn viscous_acceleration<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    eddy: Option<&[f64]>,
    face: Option<Face<D>>,
    i: usize,
) -> [f64; D] {
    let nu_t = |j: usize| eddy.map_or(0.0, |e| e[j]);
    let (rho_i, nu_i) = (p.rest_density[i], p.viscosity[i] + nu_t(i));
    let d_i = face.map_or(f64::INFINITY, |f| f.distance);
    let u_i = p.velocity(i);
    let mut acc = [0.0; D];
    nb.for_each(i, |j, r_ij, r| {
        let (nu_i, nu_j, du) = match p.kind[j] {
            Kind::Wall => {
                let beta = (wall::dot(p.wall_normal(j), r_ij) / d_i).clamp(1.0, MORRIS_BETA_MAX);
                (p.viscosity[i], p.viscosity[i], u_i.map(|u| beta * u))
            }
            Kind::Fluid => (
                nu_i,
                p.viscosity[j] + nu_t(j),
                std::array::from_fn(|d| u_i[d] - p.vel[d][j]),
            ),
        };
        let rho_j = p.rest_density[j];
        let c =
            p.mass[j] * (rho_i * nu_i + rho_j * nu_j) / (rho_i * rho_j) * nb.laplacian_factor(r);
        for d in 0..D {
            acc[d] += c * du[d];
        }
    });
    acc
}

/// Cap on β of the no-slip wall velocity. Morris, Fox & Zhu take 1.5 against particles right
/// at the face (d_i → 0); here d_i ≥ dx/4 (`wall::Face::distance`) bounds β anyway, and a cap of
/// 1.5 leaves the Poiseuille channel 4.2% too fast (4: 0.48%, no cap: 0.47%).
const MORRIS_BETA_MAX: f64 = 4.0;

/// Corrected gradient of a velocity field, G[b][a] = ∂u_a/∂x_b = Σ_c L_bc Σ_j V_j (u_j − u_i)_a ∂_c W_ij
/// (Eq. 20 with Eq. 24–25), with `u(j)` the velocity taken for particle j.
pub fn velocity_gradient<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    l: &Correction<D>,
    u: impl Fn(usize) -> [f64; D],
    i: usize,
) -> [[f64; D]; D] {
    let ui = u(i);
    let mut g = [[0.0; D]; D];
    nb.for_each(i, |j, rij, r| {
        let vf = p.mass[j] / p.rest_density[j] * nb.kernel.grad_factor(r);
        let uj = u(j);
        for a in 0..D {
            let du = uj[a] - ui[a];
            for b in 0..D {
                g[b][a] += vf * du * rij[b];
            }
        }
    });
    std::array::from_fn(|b| {
        std::array::from_fn(|a| match l {
            Some(l) => (0..D).map(|c| l[b][c] * g[c][a]).sum(),
            None => g[b][a],
        })
    })
}

/// The velocity of neighbour j in a velocity gradient at fluid particle i: its own for fluid,
/// the free-slip ghost of u_i for walls (`wall::ghost_velocity`).
#[inline]
pub fn fluid_velocity<const D: usize>(p: &Particles<D>, i: usize, j: usize) -> [f64; D] {
    match p.kind[j] {
        Kind::Fluid => p.velocity(j),
        Kind::Wall => {
            let u_i = p.velocity(i);
            ghost_velocity(p, j, u_i, u_i)
        }
    }
}

/// Smallest determinant of the moment matrix M_i for which the kernel gradient correction is
/// applied; below it (splashes, thin sheets, lone particles) the plain gradient is used.
const MIN_CORRECTION_DETERMINANT: f64 = 0.1;

/// The moments of a fluid particle's kernel support, from one pass over its neighbours.
#[derive(Clone, Copy, Debug)]
pub struct Moments<const D: usize> {
    /// M_i = Σ_j V_j ∇W_ij ⊗ r_ji of Eq. (25), walls included (symmetric; the identity for a
    /// full support).
    pub m: [[f64; D]; D],
    /// M_i with each wall neighbour's r_bi replaced by its part across the walls, N_b r_bi:
    /// the moment of a pressure field whose wall ghosts carry only the normal gradient (see
    /// `wall`).
    pub m_neumann: [[f64; D]; D],
    /// ∇C_i = Σ_j V_j ∇W_ij, the concentration gradient.
    pub grad_c: [f64; D],
}

/// The support moments of particle i.
pub fn support_moments<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    i: usize,
) -> Moments<D> {
    let mut mo = Moments {
        m: [[0.0; D]; D],
        m_neumann: [[0.0; D]; D],
        grad_c: [0.0; D],
    };
    nb.for_each(i, |j, rij, r| {
        let vf = p.mass[j] / p.rest_density[j] * nb.kernel.grad_factor(r);
        // The part of r_ij the pressure of j follows: all of it for fluid, the normal part for
        // a wall ghost.
        let followed = match p.kind[j] {
            Kind::Fluid => rij,
            Kind::Wall => behind_walls(p, j, rij),
        };
        for a in 0..D {
            mo.grad_c[a] += vf * rij[a];
            for b in 0..D {
                mo.m[a][b] -= vf * rij[a] * rij[b];
                mo.m_neumann[a][b] -= vf * rij[a] * followed[b];
            }
        }
    });
    mo
}

/// Kernel gradient correction L_i = M_i⁻¹, Eq. (24)–(25), so that L_i Σ_j V_j (φ_j − φ_i) ∇W_ij
/// is exact for linear φ even where the support is truncated. None where M_i is near-singular.
pub fn gradient_correction<const D: usize>(m: [[f64; D]; D]) -> Correction<D> {
    invert(m)
        .filter(|(_, det)| *det > MIN_CORRECTION_DETERMINANT)
        .map(|(l, _)| l)
}

/// Inverse and determinant of a small matrix (Gauss–Jordan with partial pivoting).
pub fn invert<const D: usize>(mut m: [[f64; D]; D]) -> Option<([[f64; D]; D], f64)> {
    let mut inv = [[0.0; D]; D];
    for (k, row) in inv.iter_mut().enumerate() {
        row[k] = 1.0;
    }
    let mut det = 1.0;
    for c in 0..D {
        let pivot = (c..D).max_by(|&a, &b| m[a][c].abs().total_cmp(&m[b][c].abs()))?;
        if m[pivot][c] == 0.0 {
            return None;
        }
        if pivot != c {
            m.swap(pivot, c);
            inv.swap(pivot, c);
            det = -det;
        }
        let d = m[c][c];
        det *= d;
        for k in 0..D {
            m[c][k] /= d;
            inv[c][k] /= d;
        }
        for r in (0..D).filter(|&r| r != c) {
            let f = m[r][c];
            for k in 0..D {
                m[r][k] -= f * m[c][k];
                inv[r][k] -= f * inv[c][k];
            }
        }
    }
    Some((inv, det))
}

/// L_i of Eq. (25), or None where the correction is not applied.
pub type Correction<const D: usize> = Option<[[f64; D]; D]>;

/// The corrections L_i of the particles: every particle's (`dense`), only those of the
/// particles that have one (`sparse`: a slot per particle into a list), or the identity for all
/// of them where the scene turns the kernel correction off (then no array of them exists).
#[derive(Clone, Copy, Debug)]
pub struct Corrections<'a, const D: usize>(Option<Stored<'a, D>>);

#[derive(Clone, Copy, Debug)]
enum Stored<'a, const D: usize> {
    Dense(&'a [Correction<D>]),
    Sparse {
        slot: &'a [u32],
        list: &'a [Correction<D>],
    },
}

/// The slot of a particle with no correction in a sparse `Corrections`.
pub const NO_SLOT: u32 = u32::MAX;

impl<'a, const D: usize> Corrections<'a, D> {
    /// `l` (one per particle) where the correction is `on`, else the identity everywhere.
    pub fn new(on: bool, l: &'a [Correction<D>]) -> Self {
        Self(on.then_some(Stored::Dense(l)))
    }

    /// `list[slot[i]]` for the particles with a slot, the identity for the others (`NO_SLOT`)
    /// and for all where the correction is off.
    pub fn sparse(on: bool, slot: &'a [u32], list: &'a [Correction<D>]) -> Self {
        Self(on.then_some(Stored::Sparse { slot, list }))
    }

    /// L_i.
    #[inline]
    pub fn of(self, i: usize) -> &'a Correction<D> {
        match self.0 {
            Some(Stored::Dense(l)) => &l[i],
            Some(Stored::Sparse { slot, list }) => match slot[i] {
                NO_SLOT => &None,
                k => &list[k as usize],
            },
            None => &None,
        }
    }
}

/// Applies L_i to a vector (identity where the correction is off).
#[inline]
pub fn apply_correction<const D: usize>(l: &Correction<D>, v: [f64; D]) -> [f64; D] {
    match l {
        Some(l) => std::array::from_fn(|a| (0..D).map(|b| l[a][b] * v[b]).sum()),
        None => v,
    }
}

/// Corrected gradient of a scalar field, ∇φ_i = L_i Σ_j V_j (φ_j − φ_i) ∇W_ij, Eq. (20) with
/// Eq. (24)–(25), with `difference(j, r_ij)` = φ_j − φ_i: exact for linear φ also where the
/// kernel support is truncated.
#[inline]
pub fn gradient<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    l: &Correction<D>,
    i: usize,
    difference: impl Fn(usize, [f64; D]) -> f64,
) -> [f64; D] {
    let mut grad = [0.0; D];
    nb.for_each(i, |j, rij, r| {
        let c = p.mass[j] / p.rest_density[j] * difference(j, rij) * nb.kernel.grad_factor(r);
        for d in 0..D {
            grad[d] += c * rij[d];
        }
    });
    apply_correction(l, grad)
}

/// Coefficient a_ij ≥ 0 of the negative Laplacian of Eq. (27):
/// −∇²P_i = Σ_j a_ij (P_i − P_j), a_ij = −(2 m_j/ρ_i) r_ij·∇W_ij/(r_ij² + η²).
#[inline]
pub fn laplacian_coefficient<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    i: usize,
    j: usize,
    r: f64,
) -> f64 {
    -2.0 * p.mass[j] / p.rest_density[i] * nb.laplacian_factor(r)
}
