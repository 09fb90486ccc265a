//! SPH discretisation: the operators of Eq. (20)–(27) written as per-particle sums over the
//! pair loop of `neighbours`.

pub mod free_surface;
pub mod interface;
pub mod probe;

use crate::boundary::ghosts::{self, behind_walls, ghost_velocity, Face};
use crate::math::kernel::{Kernel, KernelKind};
use crate::math::lanes::{F64s, Sum};
use crate::math::lattice::for_each_lattice_point;
use crate::neighbours::Lanes;
use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};

/// Summation density ρ_i = Σ_j m_j (ρ0_i/ρ0_j) W_ij = ρ0_i Σ_j V_j W_ij (self included): the
/// familiar Σ_j m_j W_ij where the support holds one fluid, while across the interface of two
/// fluids each neighbour counts with its volume (Hu & Adams 2006), so that water beside oil is not
/// taken for expanded (below 0.9 ρ0 it would be spray: `free_surface::spray_density`) nor the oil
/// for compressed. The kernel's `density_scale` makes it ρ0 on the rest lattice.
pub fn density<const D: usize>(nb: &Neighbours<D>, p: &Particles<D>, i: usize) -> f64 {
    let mut sum = DensitySum::new(p, i);
    nb.for_each_lanes(i, |l| sum.add(nb, p, l));
    sum.total(nb, p, i).0
}

/// The summation density of `density` and, from the same walk, the distance from particle i
/// to its nearest neighbour of any kind (infinite where it has none), which the particle
/// disorder of `stats.csv` is measured from, chunk by chunk: for a walk that sums them beside
/// others (the support moments', in the free-surface stage).
pub struct DensitySum {
    rho: Sum,
    rho0_i: F64s,
    nearest: F64s,
}

impl DensitySum {
    /// The sums at particle i.
    pub fn new<const D: usize>(p: &Particles<D>, i: usize) -> Self {
        Self {
            rho: Sum::ZERO,
            rho0_i: F64s::splat(p.rest_density[i]),
            nearest: F64s::splat(f64::INFINITY),
        }
    }

    /// Adds the lanes `l`.
    #[inline(always)]
    pub fn add<const D: usize>(&mut self, nb: &Neighbours<D>, p: &Particles<D>, l: &Lanes<D>) {
        self.rho += (mass_at_density(p, self.rho0_i, l) * nb.kernel.w_lanes(l.r)) & l.mask;
        self.nearest = self
            .nearest
            .fast_min(l.mask.select(l.r, F64s::splat(f64::INFINITY)));
    }

    /// ρ_i, with particle i's own share, and the distance to its nearest neighbour.
    pub fn total<const D: usize>(
        &self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        i: usize,
    ) -> (f64, f64) {
        let rho = (p.mass[i] * nb.kernel.w(0.0) + self.rho.total()) * nb.kernel.density_scale();
        let nearest = self
            .nearest
            .to_array()
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        (rho, nearest)
    }
}

/// m_j ρ0_i/ρ0_j = ρ0_i V_j of the lanes: the mass of neighbour j's volume at particle i's rest
/// density, exactly m_j where the two share one (a wall takes the first fluid's).
#[inline(always)]
pub fn mass_at_density<const D: usize>(
    p: &Particles<D>,
    rest_density_i: F64s,
    l: &Lanes<D>,
) -> F64s {
    l.load(&p.mass) * (rest_density_i / l.load(&p.rest_density))
}

/// V_j F(r_ij) of the lanes (zero in the masked ones), with V_j = m_j/ρ0_j: the weight of
/// r_ij in the gradients of Eq. (20) and the moments of Eq. (25).
#[inline(always)]
pub fn volume_gradient_factor<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    l: &Lanes<D>,
) -> F64s {
    (l.load(&p.mass) / l.load(&p.rest_density) * nb.kernel.grad_factor_lanes(l.r)) & l.mask
}

/// Viscous acceleration ∇·(ν∇u)_i of Eq. (26) with ν = ν_fluid + ν_t, ν_t the eddy viscosity
/// of the Smagorinsky model (Eq. 3–4) where the scene runs LES (`eddy`; None: ν_t = 0). Wall
/// particles take the fluid's laminar viscosity (the turbulent stress at a wall is the law of
/// the wall's, `les::wall_shear`) and the no-slip velocity of Morris, Fox & Zhu (1997)
/// (`ghosts::no_slip_difference`), with `face` the nearest wall's in the kernel support
/// (`ghosts::nearest_face`).
pub fn viscous_acceleration<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    eddy: Option<&[f64]>,
    face: Option<Face<D>>,
    bodies: Option<&[f64]>,
    i: usize,
) -> [f64; D] {
    let (rho_i, nu_laminar) = (p.rest_density[i], p.viscosity[i]);
    let nu_t_i = eddy.map_or(0.0, |e| e[i]);
    let nu_i = nu_laminar + nu_t_i;
    let d_i = F64s::splat(face.map_or(f64::INFINITY, |f| f.distance));
    let u_i = p.velocity(i);
    let no_slip = bodies.and_then(|distances| body_no_slip(p, distances, i));
    let mut acc = [Sum::ZERO; D];
    nb.for_each_lanes(i, |l| {
        let (nu_i, nu_j, du): (F64s, F64s, [F64s; D]) = match l.kind {
            Kind::Wall => {
                let nu = F64s::splat(nu_laminar);
                (nu, nu, ghosts::no_slip_difference(p, l, u_i, d_i))
            }
            Kind::Fluid | Kind::Body => {
                let nu_t = eddy.map_or(F64s::ZERO, |e| l.load(e));
                let du = std::array::from_fn(|d| F64s::splat(u_i[d]) - l.load(&p.vel[d]));
                match no_slip {
                    // The laminar viscosity of a pair of a fluid and a body particle takes β,
                    // the eddy viscosity's part not (as at a wall, whose pairs are laminar).
                    Some(b) => {
                        let beta = b.factor(p, l);
                        let nu_i = F64s::splat(nu_laminar).mul_add(beta, F64s::splat(nu_t_i));
                        (nu_i, l.load(&p.viscosity).mul_add(beta, nu_t), du)
                    }
                    None => (F64s::splat(nu_i), l.load(&p.viscosity) + nu_t, du),
                }
            }
        };
        let (rho_j, rho_i) = (l.load(&p.rest_density), F64s::splat(rho_i));
        let (_, laplacian_factor) = nb.gradient_and_laplacian_factors_lanes(l.r);
        let c = (l.load(&p.mass) * rho_i.mul_add(nu_i, rho_j * nu_j) / (rho_i * rho_j)
            * laplacian_factor)
            & l.mask;
        for d in 0..D {
            acc[d] = acc[d].mul_add(c, du[d]);
        }
    });
    acc.map(|a| a.total())
}

/// The no-slip of a body for the viscous term of particle i (`viscous_acceleration`): the
/// pairs of a fluid particle and a body's particle take the factor β of Morris, Fox & Zhu
/// (1997) on their velocity difference, as a fluid particle's pairs with a wall's do
/// (`ghosts::no_slip_difference`), so that the body's velocity holds on its surface, not half a
/// spacing inside it. Both particles of a pair take the same β, so the viscous forces between
/// the fluid and a body stay equal and opposite and the body feels what it does to the fluid.
#[derive(Clone, Copy)]
enum BodyNoSlip<'a, const D: usize> {
    /// i is a fluid particle at `distance` from the nearest body's surface: a body particle b
    /// takes β = n_b·r_ib/distance (its outward normal in `Particles::normal`, zero for a
    /// fluid particle, whose β is 1).
    Fluid { distance: f64 },
    /// i is a body particle with outward normal `normal`: a fluid particle j takes
    /// β = n_i·r_ji/d_j, d_j from `distances` (infinite for a body particle: β = 1).
    Body {
        normal: [f64; D],
        distances: &'a [f64],
    },
}

/// The `BodyNoSlip` of particle i from the distances of the fluid particles to the nearest
/// body's surface (`step::body_surfaces`); None where every β is 1.
fn body_no_slip<'a, const D: usize>(
    p: &Particles<D>,
    distances: &'a [f64],
    i: usize,
) -> Option<BodyNoSlip<'a, D>> {
    match p.kind[i] {
        Kind::Fluid => distances[i].is_finite().then_some(BodyNoSlip::Fluid {
            distance: distances[i],
        }),
        Kind::Body => {
            let n = p.wall_normal(i);
            n.iter().any(|&c| c != 0.0).then_some(BodyNoSlip::Body {
                normal: n,
                distances,
            })
        }
        Kind::Wall => None,
    }
}

impl<const D: usize> BodyNoSlip<'_, D> {
    /// β of the pairs of particle i with the particles in lanes `l` (of the fluid's group).
    #[inline(always)]
    fn factor(&self, p: &Particles<D>, l: &Lanes<D>) -> F64s {
        match *self {
            BodyNoSlip::Fluid { distance } => {
                ghosts::morris_factor(ghosts::normal_projection(p, l), F64s::splat(distance))
            }
            BodyNoSlip::Body { normal, distances } => {
                // r_ji = −r_ij.
                let n_r = (0..D).fold(F64s::ZERO, |s, d| {
                    F64s::splat(-normal[d]).mul_add(l.rij[d], s)
                });
                ghosts::morris_factor(n_r, l.load(distances))
            }
        }
    }
}

/// The SPH Laplacian of a vector field `f` of the fluid particles at fluid particle i, from its
/// fluid neighbours: Eq. (26) with ν = 1 and the rest densities equal,
/// Σ_j 2 V_j (f_i − f_j) r_ij·∇W_ij/(r_ij² + η²). For a Fourier mode of wave vector k it gives
/// −|k|² (1 − σ²|k|²/4 + …) of the mode, σ the kernel's standard deviation
/// (`Kernel::deviation`): in the integral form the symbol is 2∫ (1 − cos k·r) F dV, F = W'/r,
/// and to fourth order in k·r, with ∫ rⁿ F dV = −(n + D − 2) ∫ rⁿ⁻² W dV and the angular means
/// 1/D of (k̂·r̂)² and 3/(D (D + 2)) of (k̂·r̂)⁴, it is −|k|² + σ²|k|⁴/4 in any dimension D.
pub fn field_laplacian<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    f: &[Vec<f64>; D],
    i: usize,
) -> [f64; D] {
    let f_i: [F64s; D] = std::array::from_fn(|d| F64s::splat(f[d][i]));
    let mut acc = [Sum::ZERO; D];
    nb.for_each_lanes_of(i, &[Kind::Fluid], |l| {
        let (_, laplacian_factor) = nb.gradient_and_laplacian_factors_lanes(l.r);
        let c = (F64s::splat(2.0) * l.load(&p.mass) / l.load(&p.rest_density) * laplacian_factor)
            & l.mask;
        for d in 0..D {
            acc[d] = acc[d].mul_add(c, f_i[d] - l.load(&f[d]));
        }
    });
    acc.map(|a| a.total())
}

/// Corrected gradient of a velocity field, G[b][a] = ∂u_a/∂x_b = Σ_c L_bc Σ_j V_j (u_j − u_i)_a ∂_c
/// W_ij (Eq. 20 with Eq. 24–25), with `u_i` the velocity of particle i and `u(l)` the velocities
/// taken for the neighbours in lanes `l`.
pub fn velocity_gradient<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    l: &Correction<D>,
    u_i: [f64; D],
    u: impl Fn(&Lanes<D>) -> [F64s; D],
    i: usize,
) -> [[f64; D]; D] {
    velocity_gradient_and(nb, p, l, u_i, u, i, |_, _| {})
}

/// `velocity_gradient`, handing `also` each chunk of the walk with its V_j ∇W_ij factor
/// (`volume_gradient_factor`): another sum over the same neighbours in the same walk.
pub fn velocity_gradient_and<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    l: &Correction<D>,
    u_i: [f64; D],
    u: impl Fn(&Lanes<D>) -> [F64s; D],
    i: usize,
    mut also: impl FnMut(&Lanes<D>, F64s),
) -> [[f64; D]; D] {
    let mut g = VelocityGradientSum::new(u_i);
    nb.for_each_lanes(i, |lanes| {
        let vf = volume_gradient_factor(nb, p, lanes);
        also(lanes, vf);
        g.add(lanes, vf, u(lanes));
    });
    corrected_gradient(l, g.total())
}

/// The sum Σ_j V_j (u_j − u_i) ⊗ ∇W_ij of a velocity gradient (`velocity_gradient`) before its
/// correction, chunk by chunk: for a walk that sums it beside others (the eddy viscosity's, in
/// the free surface's walk of the support moments).
pub struct VelocityGradientSum<const D: usize> {
    /// [b][a]: Σ_j V_j (u_j − u_i)_a ∂_b W_ij.
    g: [[Sum; D]; D],
    u_i: [F64s; D],
}

impl<const D: usize> VelocityGradientSum<D> {
    /// The sum at a particle of velocity `u_i`.
    pub fn new(u_i: [f64; D]) -> Self {
        Self {
            g: [[Sum::ZERO; D]; D],
            u_i: u_i.map(F64s::splat),
        }
    }

    /// Adds the lanes `l` with their factor V_j ∇W_ij/r_ij `vf` and velocities `u_j`.
    #[inline(always)]
    pub fn add(&mut self, l: &Lanes<D>, vf: F64s, u_j: [F64s; D]) {
        for a in 0..D {
            let du = vf * (u_j[a] - self.u_i[a]);
            for b in 0..D {
                self.g[b][a] = self.g[b][a].mul_add(du, l.rij[b]);
            }
        }
    }

    /// The uncorrected gradient, [b][a] = ∂u_a/∂x_b.
    pub fn total(&self) -> [[f64; D]; D] {
        self.g.map(|row| row.map(|x| x.total()))
    }
}

/// The gradient `g` ([b][a] = ∂u_a/∂x_b) corrected by L_i (Eq. 24–25; None: as it is).
pub fn corrected_gradient<const D: usize>(l: &Correction<D>, g: [[f64; D]; D]) -> [[f64; D]; D] {
    std::array::from_fn(|b| {
        std::array::from_fn(|a| match l {
            Some(l) => (0..D).map(|c| l[b][c] * g[c][a]).sum(),
            None => g[b][a],
        })
    })
}

/// The velocities of the neighbours in lanes `l` in a velocity gradient at fluid particle i of
/// velocity `u_i`: their own for fluid, the free-slip ghost of u_i for walls
/// (`ghosts::ghost_velocity`).
#[inline(always)]
pub fn fluid_velocity<const D: usize>(p: &Particles<D>, u_i: [f64; D], l: &Lanes<D>) -> [F64s; D] {
    match l.kind {
        Kind::Fluid | Kind::Body => std::array::from_fn(|d| l.load(&p.vel[d])),
        Kind::Wall => ghost_velocity(p, l, u_i, u_i),
    }
}

/// Smallest determinant of the moment matrix M_i for which the kernel gradient correction is
/// applied at h/dx = `CORRECTION_H_OVER_DX`; below it (splashes, thin sheets, lone particles)
/// the plain gradient is used. `min_correction_determinant` scales it to other h/dx.
const MIN_CORRECTION_DETERMINANT: f64 = 0.1;
/// The h/dx `MIN_CORRECTION_DETERMINANT` was set at.
const CORRECTION_H_OVER_DX: f64 = 1.2;

/// The smallest determinant of the moment matrix M'_i of the pressure gradient (`Moments::
/// m_neumann`) for which the kernel gradient correction is applied, for the quintic at
/// `h_over_dx`: 0.1 at h/dx = 1.2, scaled with the determinant of the most truncated support
/// that must keep its correction, the top of the water where two side walls meet (in 2D,
/// where the surface meets a wall). Its lattice determinant falls as the kernel reaches
/// further (3D: 0.148 at h/dx = 1.2, 0.116 at 1.5, 0.098 at 1.8, 0.090 at 2.0), and a fixed 0.1
/// would take that particle for a splash from h/dx ≈ 1.75, set its pressure to 0 and let the
/// corners of still water in a 3D tank fall (`tests/hydrostatic.rs`,
/// `still_water_in_a_3d_tank_stays_still_with_a_wide_kernel`; docs/accuracy.md, "Smoothing
/// length above 1.5: still water").
pub fn min_correction_determinant<const D: usize>(kernel: KernelKind, h_over_dx: f64) -> f64 {
    MIN_CORRECTION_DETERMINANT
        * (wall_corner_determinant::<D>(Kernel::new(kernel, 1.0, h_over_dx))
            / wall_corner_determinant::<D>(Kernel::new(
                KernelKind::Quintic,
                1.0,
                CORRECTION_H_OVER_DX,
            )))
}

/// det M'_i at the top of the water in the corner of the walls, on a lattice of unit spacing:
/// the particle at the origin, fluid where no index is positive, the walls where one of the
/// first D − 1 indices is (at every height; each counts the offset along the axes it lies
/// behind, `ghosts::behind_walls`), air above the water.
fn wall_corner_determinant<const D: usize>(kernel: Kernel<D>) -> f64 {
    let reach = kernel.support().ceil() as i64;
    let mut m = [[0.0; D]; D];
    for_each_lattice_point([-reach; D], [reach + 1; D], |k| {
        let offset = k.map(|o| o as f64);
        let r = offset.iter().map(|o| o * o).sum::<f64>().sqrt();
        if r == 0.0 || r >= kernel.support() {
            return;
        }
        let behind: [bool; D] = std::array::from_fn(|d| d < D - 1 && offset[d] >= 1.0);
        let followed: [f64; D] = match (behind.iter().any(|&b| b), offset.iter().all(|&o| o <= 0.0))
        {
            (true, _) => std::array::from_fn(|d| if behind[d] { offset[d] } else { 0.0 }),
            (false, true) => offset,
            (false, false) => return,
        };
        // ∇_i W_ij ⊗ r_ji with r_ij = −offset.
        let factor = kernel.grad_factor(r);
        for a in 0..D {
            for b in 0..D {
                m[a][b] -= factor * offset[a] * followed[b];
            }
        }
    });
    invert(m).map_or(0.0, |(_, det)| det)
}

/// The moments of a fluid particle's kernel support, from one pass over its neighbours.
#[derive(Clone, Copy, Debug)]
pub struct Moments<const D: usize> {
    /// M_i = Σ_j V_j ∇W_ij ⊗ r_ji of Eq. (25), walls included (symmetric; the identity for a
    /// full support).
    pub m: [[f64; D]; D],
    /// M_i with each wall neighbour's r_bi replaced by its part across the walls, N_b r_bi:
    /// the moment of a pressure field whose wall ghosts carry only the normal gradient (see
    /// `boundary::ghosts`).
    pub m_neumann: [[f64; D]; D],
    /// ∇C_i = Σ_j V_j ∇W_ij, the concentration gradient.
    pub grad_c: [f64; D],
    /// The fluid particles in the kernel support.
    pub fluid_neighbours: usize,
}

/// The support moments of particle i.
pub fn support_moments<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    i: usize,
) -> Moments<D> {
    support_moments_and(nb, p, i, |_, _, _| {})
}

/// The support moments of particle i, handing each chunk of neighbours `l` on to `also` with
/// its V_j ∇W_ij factor (`volume_gradient_factor`) and the part of r_ij a pressure field follows
/// there (`Moments::m_neumann`): sums over the same support in the same walk (the PPE's row
/// vector, `ppe::LaplacianTruncation`; the eddy viscosity's velocity gradient).
#[inline(always)]
pub fn support_moments_and<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    i: usize,
    mut also: impl FnMut(&Lanes<D>, F64s, &[F64s; D]),
) -> Moments<D> {
    let (mut m, mut m_neumann) = ([[Sum::ZERO; D]; D], [[Sum::ZERO; D]; D]);
    let (mut grad_c, mut fluid_neighbours) = ([Sum::ZERO; D], 0);
    nb.for_each_lanes(i, |l| {
        let vf = volume_gradient_factor(nb, p, l);
        // The part of r_ij the pressure of j follows: all of it for fluid, the normal part for
        // a wall ghost.
        let followed = match l.kind {
            Kind::Fluid | Kind::Body => {
                fluid_neighbours += l.count();
                l.rij
            }
            Kind::Wall => behind_walls(p, l, l.rij),
        };
        also(l, vf, &followed);
        for a in 0..D {
            let v = vf * l.rij[a];
            grad_c[a] += v;
            for b in 0..D {
                m[a][b] = m[a][b].mul_add(-v, l.rij[b]);
                m_neumann[a][b] = m_neumann[a][b].mul_add(-v, followed[b]);
            }
        }
    });
    let sum = |x: [[Sum; D]; D]| x.map(|row| row.map(|v| v.total()));
    Moments {
        m: sum(m),
        m_neumann: sum(m_neumann),
        grad_c: grad_c.map(|v| v.total()),
        fluid_neighbours,
    }
}

/// Kernel gradient correction L_i = M_i⁻¹, Eq. (24)–(25), so that L_i Σ_j V_j (φ_j − φ_i) ∇W_ij
/// is exact for linear φ even where the support is truncated. None where M_i is near-singular:
/// its determinant at most `min_determinant` (`min_correction_determinant`).
pub fn gradient_correction<const D: usize>(
    m: [[f64; D]; D],
    min_determinant: f64,
) -> Correction<D> {
    invert(m)
        .filter(|(_, det)| *det > min_determinant)
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

/// Smallest det C / (tr C / D)^D of the neighbours' positions for which `fitted_value` fits
/// a linear function: 1 for an isotropic spread, 0.77 for a particle on a flat free surface,
/// 0.63 in a sheet two particles thick (2D lattice, h = 1.2 dx), 0 on a line.
const MIN_FIT_ISOTROPY: f64 = 0.01;

/// φ̃_i, the value at x_i of the linear function φ̄ + b·(x − x̄) fitted to the values φ_j
/// (`values`) of the fluid neighbours of i's own fluid (same rest density: across an interface
/// the hydrostatic pressure bends) by least squares weighted by W_ij, particle i itself left
/// out; x̄ and φ̄ are their weighted means and b = C⁻¹ Σ_j W_ij (x_j − x̄)(φ_j − φ̄), C their
/// weighted covariance. None where the neighbours do not fix a linear function: fewer than
/// D + 1 of them, or spread along too few directions (a thin sheet, a line of particles):
/// det C below `MIN_FIT_ISOTROPY` of (tr C / D)^D, the value of an isotropic spread.
/// Exact for linear φ, like φ_i, but blind to φ_i itself (see `step::pressure_reference`).
pub fn fitted_value<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    values: &[f64],
    i: usize,
) -> Option<f64> {
    fitted_values(nb, p, [values], i).map(|[value]| value)
}

/// `fitted_value` of K fields in one walk, the neighbours' weights and positions shared: each
/// value with the bits of its own fit. None where the neighbours fix no linear function (the
/// same for every field).
pub fn fitted_values<const D: usize, const K: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    values: [&[f64]; K],
    i: usize,
) -> Option<[f64; K]> {
    let own_fluid = F64s::splat(p.rest_density[i]);
    // Weighted sums of 1, d = x_j − x_i, φ, d dᵀ and d φ.
    let (mut w_sum, mut phi_sum) = (Sum::ZERO, [Sum::ZERO; K]);
    let mut d_sum = [Sum::ZERO; D];
    let mut dd_sum = [[Sum::ZERO; D]; D];
    let mut dphi_sum = [[Sum::ZERO; D]; K];
    nb.for_each_lanes_of(i, &[Kind::Fluid], |l| {
        let same = l.load(&p.rest_density).simd_eq(own_fluid);
        let w = nb.kernel.w_lanes(l.r) & l.mask & same;
        let phi = values.map(|values| l.load(values) & l.mask);
        w_sum += w;
        for k in 0..K {
            phi_sum[k] = phi_sum[k].mul_add(w, phi[k]);
        }
        for a in 0..D {
            let wd = -w * l.rij[a];
            d_sum[a] += wd;
            for k in 0..K {
                dphi_sum[k][a] = dphi_sum[k][a].mul_add(wd, phi[k]);
            }
            for b in a..D {
                dd_sum[a][b] = dd_sum[a][b].mul_add(wd, -l.rij[b]);
            }
        }
    });
    let w = w_sum.total();
    let d_mean = d_sum.map(|x| x.total() / w);
    let covariance: [[f64; D]; D] = std::array::from_fn(|a| {
        std::array::from_fn(|b| dd_sum[a.min(b)][a.max(b)].total() - w * d_mean[a] * d_mean[b])
    });
    let spread = (0..D).map(|a| covariance[a][a]).sum::<f64>() / D as f64;
    let (inverse, det) = invert(covariance)?;
    let spans = w > 0.0 && det > MIN_FIT_ISOTROPY * spread.powi(D as i32);
    if !spans {
        return None;
    }
    Some(std::array::from_fn(|k| {
        let phi_mean = phi_sum[k].total() / w;
        let cross: [f64; D] =
            std::array::from_fn(|a| dphi_sum[k][a].total() - w * d_mean[a] * phi_mean);
        let slope = apply_correction(&Some(inverse), cross);
        phi_mean - (0..D).map(|a| slope[a] * d_mean[a]).sum::<f64>()
    }))
}

/// Corrected gradient of a scalar field, ∇φ_i = L_i Σ_j V_j (φ_j − φ_i) ∇W_ij, Eq. (20) with
/// Eq. (24)–(25), with `difference(l)` = φ_j − φ_i of the neighbours in lanes `l`: exact for
/// linear φ also where the kernel support is truncated.
#[inline]
pub fn gradient<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    l: &Correction<D>,
    i: usize,
    difference: impl Fn(&Lanes<D>) -> F64s,
) -> [f64; D] {
    let [grad] = gradients(nb, p, l, i, |lanes| [difference(lanes)]);
    grad
}

/// The corrected gradients of `gradient` of K scalar fields in one walk, with
/// `differences(l)` the K fields' φ_j − φ_i: each with the bits of its own walk.
#[inline]
pub fn gradients<const D: usize, const K: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    l: &Correction<D>,
    i: usize,
    differences: impl Fn(&Lanes<D>) -> [F64s; K],
) -> [[f64; D]; K] {
    let mut grad = [[Sum::ZERO; D]; K];
    nb.for_each_lanes(i, |lanes| {
        let vf = volume_gradient_factor(nb, p, lanes);
        let differences = differences(lanes);
        for k in 0..K {
            let c = vf * differences[k];
            for d in 0..D {
                grad[k][d] = grad[k][d].mul_add(c, lanes.rij[d]);
            }
        }
    });
    grad.map(|g| apply_correction(l, g.map(|g| g.total())))
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
