//! What a fluid particle sees of a boundary particle: its ghost pressure, its velocity in the
//! velocity gradients and its no-slip velocity in the viscous term, each written with the
//! boundary particle's velocity u_b and acceleration a_b (`Motion`). The boundary particles are
//! layers of dummy particles that fill the kernel support beyond the boundary: the container's
//! walls and the obstacles, at rest (u_b = a_b = 0).
//!
//! A wall particle carries no unknown of the pressure solve. Every fluid particle i sees each
//! wall neighbour b as the continuation of its own pressure field under the Neumann condition
//! of the projection, ∂P/∂n = ρ0 (g − a_b)·n:
//!
//!   P_b = P_i + ρ0 (g − a_b)·N_b (r_b − r_i),                                         (ghost)
//!
//! N_b the projector on the normals of the walls b lies behind: n nᵀ behind a plane wall, the
//! identity in a corner of the container (behind two walls in 2D, three in 3D; behind two walls of
//! a 3D box, the projector on their plane). The walls are axis-aligned (container and box
//! obstacles), so N_b keeps the axes along which b's normal has a component. Only the normal part
//! of the hydrostatic gradient is carried into the wall: along the wall the fluid may be
//! accelerating (a column falling beside a wall, a surge running along the floor), and a
//! hydrostatic gradient along the wall there would suck fluid into dry wall above it. Because the
//! ghost difference P_b − P_i does not depend on the unknowns, the wall pairs of a PPE row are
//! known numbers: the Neumann condition becomes a source term and the matrix couples fluid
//! particles only.
//!
//! The kinematic condition u·n = 0 enters the PPE source through the velocity divergence, where
//! the wall particles take the wall velocity (zero) plus the fluid particle's own predictor
//! increment (see `ppe::source`).

use crate::math::lanes::{F64s, Sum};
use crate::math::vector::{dot, norm};
use crate::neighbours::Lanes;
use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};

/// How the boundary particles in a chunk of lanes move, as the fluid sees them: their velocity
/// u_b and acceleration a_b, which every boundary term below is written with. The boundary
/// particles are the container's walls and the obstacles, at rest: both are zero, and each term
/// is the fixed-wall one at no cost (the zeros fold away at compile time). A moving boundary
/// (a moving wall, a rigid body) is a boundary particle whose motion this gives.
#[derive(Clone, Copy, Debug)]
pub struct Motion<const D: usize> {
    pub velocity: [F64s; D],
    pub acceleration: [F64s; D],
}

impl<const D: usize> Motion<D> {
    pub const AT_REST: Motion<D> = Motion {
        velocity: [F64s::ZERO; D],
        acceleration: [F64s::ZERO; D],
    };
}

/// The motion of the boundary particles in lanes `l`: every boundary particle is a wall at
/// rest.
#[inline(always)]
pub fn motion<const D: usize>(_p: &Particles<D>, _l: &Lanes<D>) -> Motion<D> {
    Motion::AT_REST
}

/// The body force per unit mass on the fluid particles, which the Neumann condition of the
/// wall ghosts carries: gravity alone, or a field over the fluid particles where it varies
/// (a moving container's frame, `moving_frame`; a body's external force).
#[derive(Clone, Copy, Debug)]
pub enum BodyForce<'a, const D: usize> {
    Uniform([f64; D]),
    /// f_i of each fluid particle i, by component.
    Field(&'a [Vec<f64>; D]),
}

impl<const D: usize> BodyForce<'_, D> {
    /// f_i of fluid particle i.
    #[inline(always)]
    pub fn at(&self, i: usize) -> [f64; D] {
        match self {
            BodyForce::Uniform(g) => *g,
            BodyForce::Field(f) => std::array::from_fn(|d| f[d][i]),
        }
    }

    /// The unit vector against f_i, the way up for fluid particle i; None where f_i = 0.
    pub fn up(&self, i: usize) -> Option<[f64; D]> {
        let f = self.at(i);
        let magnitude = norm(f);
        (magnitude > 0.0).then(|| f.map(|x| -x / magnitude))
    }

    /// f_j of the fluid particles j in lanes `l`.
    #[inline(always)]
    pub fn lanes(&self, l: &Lanes<D>) -> [F64s; D] {
        match self {
            BodyForce::Uniform(g) => g.map(F64s::splat),
            BodyForce::Field(f) => std::array::from_fn(|d| l.load(&f[d])),
        }
    }
}

/// P_b − P_i = −ρ0_i (f_i − a_b)·N_b r_ib of the ghost pressures of the wall particles b in
/// lanes `l` seen from fluid particle i (r_ib = r_i − r_b, the lanes' r_ij): the Neumann
/// condition ∂P/∂n = ρ0 (f − a_b)·n of a wall accelerating at a_b (`motion`), with f_i the
/// body force on i (gravity, in a moving container the frame's, `moving_frame`).
#[inline(always)]
pub fn ghost_pressure_difference<const D: usize>(
    p: &Particles<D>,
    force: [f64; D],
    i: usize,
    l: &Lanes<D>,
) -> F64s {
    let across = behind_walls(p, l, l.rij);
    let a_b = motion(p, l).acceleration;
    let g_r = (0..D).fold(F64s::ZERO, |s, d| {
        (F64s::splat(force[d]) - a_b[d]).mul_add(across[d], s)
    });
    F64s::splat(-p.rest_density[i]) * g_r
}

/// N_b r: the part of r across the walls the wall particles b in lanes `l` lie behind (see
/// the module doc).
#[inline(always)]
pub fn behind_walls<const D: usize>(p: &Particles<D>, l: &Lanes<D>, r: [F64s; D]) -> [F64s; D] {
    std::array::from_fn(|d| r[d] & l.load(&p.normal[d]).simd_ne(F64s::ZERO))
}

/// The velocities the wall particles b in lanes `l` take in the velocity gradients of fluid
/// particle i (the divergence of the PPE source, the strain rate of the eddy viscosity, the
/// Taylor correction of shifting): the fluid's own velocity `u_i` with the normal part of
/// `u_n` relative to the wall's velocity u_b removed, u_i − N_b (u_n − u_b), N_b here as for
/// the pressure ghosts. The wall is then felt only through the normal velocity, the kinematic
/// condition; along the wall it continues the fluid, a free-slip ghost. At rest in these
/// gradients (no-slip), the wall shows a shear of order U/dx, which the kernel correction
/// mixes into the divergence where the support is truncated (a surge front) and which a shift
/// across it turns into a spurious change of velocity.
#[inline(always)]
pub fn ghost_velocity<const D: usize>(
    p: &Particles<D>,
    l: &Lanes<D>,
    u_i: [f64; D],
    u_n: [f64; D],
) -> [F64s; D] {
    let u_b = motion(p, l).velocity;
    let relative = std::array::from_fn(|d| F64s::splat(u_n[d]) - u_b[d]);
    let across = behind_walls(p, l, relative);
    std::array::from_fn(|d| F64s::splat(u_i[d]) - across[d])
}

/// The velocities the ghost particles b of fixed and prescribed bodies in lanes `l` take in
/// the divergence of fluid particle i (`ppe::Role::Ghost`), as the walls' (`ghost_velocity`)
/// with the body's normal n_b and velocity u_b: u_own − n_b n_b·(u_i − u_b), the fluid's own
/// velocity with its normal velocity relative to the body taken out.
#[inline(always)]
pub fn body_ghost_velocity<const D: usize>(
    p: &Particles<D>,
    l: &Lanes<D>,
    u_own: [f64; D],
    u_i: [f64; D],
) -> [F64s; D] {
    let n: [F64s; D] = std::array::from_fn(|d| l.load(&p.normal[d]));
    let relative = (0..D).fold(F64s::ZERO, |s, d| {
        n[d].mul_add(F64s::splat(u_i[d]) - l.load(&p.vel[d]), s)
    });
    std::array::from_fn(|d| F64s::splat(u_own[d]) - n[d] * relative)
}

/// u_i − u_b of the no-slip wall particles b in lanes `l` in the viscous term of fluid particle
/// i, after Morris, Fox & Zhu (1997): the wall particle takes u_b = −(d_b/d_i) u_i relative to
/// the wall (d the distances to the wall face, `d_i` fluid particle i's), which puts the wall's
/// velocity on the face itself, so the difference is β (u_i − u_wall) with
/// β = 1 + d_b/d_i = n_b·r_ib/d_i, capped at `MORRIS_BETA_MAX` for the wall particles deep
/// behind the face. (Walls simply at rest, β = 1, put the no-slip line about half a spacing
/// behind the face, and a Poiseuille channel flows too fast: docs/accuracy.md, "Poiseuille
/// flow".)
#[inline(always)]
pub fn no_slip_difference<const D: usize>(
    p: &Particles<D>,
    l: &Lanes<D>,
    u_i: [f64; D],
    d_i: F64s,
) -> [F64s; D] {
    let beta = morris_factor(normal_projection(p, l), d_i);
    let u_b = motion(p, l).velocity;
    std::array::from_fn(|d| beta * (F64s::splat(u_i[d]) - u_b[d]))
}

/// n_b·r_ib of the particles b in lanes `l` seen from particle i, with n_b their normals
/// (`Particles::normal`: zero for fluid).
#[inline(always)]
pub fn normal_projection<const D: usize>(p: &Particles<D>, l: &Lanes<D>) -> F64s {
    (0..D).fold(F64s::ZERO, |s, d| l.load(&p.normal[d]).mul_add(l.rij[d], s))
}

/// β = 1 + d_b/d_i of the no-slip velocity of Morris, Fox & Zhu (1997) of a boundary particle
/// b whose outward normal (into the fluid) projected on r_ib is `n_r` = d_b + d_i, seen from a
/// fluid particle at `d_i` from the boundary's face; at least 1, at most `MORRIS_BETA_MAX`.
/// The walls' (`no_slip_difference`) and the bodies' (`sph::viscous_acceleration`).
#[inline(always)]
pub fn morris_factor(n_r: F64s, d_i: F64s) -> F64s {
    (n_r / d_i)
        .fast_max(F64s::ONE)
        .fast_min(F64s::splat(MORRIS_BETA_MAX))
}

/// Cap on β of the no-slip wall velocity. Morris, Fox & Zhu take 1.5 against particles right
/// at the face (d_i → 0); here d_i ≥ dx/4 (`Face::distance`) bounds β anyway, and a cap of 1.5
/// leaves the Poiseuille channel too fast where 4 is as good as no cap (docs/accuracy.md,
/// "Poiseuille flow").
const MORRIS_BETA_MAX: f64 = 4.0;

/// What the ghost pressures of the walls are made of, borrowed apart from the pressures
/// themselves (the wall pressure is written beside the fluid's it is computed from).
pub struct Ghosts<'a, const D: usize> {
    pub rest_density: &'a [f64],
    pub normal: &'a [Vec<f64>; D],
    /// The body force the ghosts carry (zero with mirror ghosts).
    pub force: BodyForce<'a, D>,
}

impl<const D: usize> Ghosts<'_, D> {
    /// Pressure of wall particle b for the frames: the kernel-weighted mean of the
    /// ghost pressures its fluid neighbours give it (zero where no fluid is in reach), with
    /// `fluid_pressure` the pressures of the fluid particles.
    pub fn wall_pressure(&self, nb: &Neighbours<D>, fluid_pressure: &[f64], b: usize) -> f64 {
        // P_b − P_f = −ρ0_f f_f·N_b r_fb (see the module doc), r_fb = −r_bf; N_b is b's own.
        let behind: [bool; D] = std::array::from_fn(|d| self.normal[d][b] != 0.0);
        let (mut sum, mut weights) = (Sum::ZERO, Sum::ZERO);
        nb.for_each_lanes_of(b, &[Kind::Fluid], |l| {
            let w = nb.kernel.w_lanes(l.r) & l.mask;
            let f = self.force.lanes(l);
            let g_r = (0..D).fold(F64s::ZERO, |s, d| {
                if behind[d] {
                    f[d].mul_add(l.rij[d], s)
                } else {
                    s
                }
            });
            let ghost = l
                .load(self.rest_density)
                .mul_add(g_r, l.load(fluid_pressure));
            sum = sum.mul_add(w, ghost);
            weights += w;
        });
        let (sum, weights) = (sum.total(), weights.total());
        if weights > 0.0 {
            sum / weights
        } else {
            0.0
        }
    }
}

/// The boundary particle b nearest to particle i closer than `within`, among the particles of
/// `kinds` that `keep` takes (a wall's; a body's, sorted with the fluid), with r_ib and |r_ib|,
/// if any.
pub fn nearest_boundary<const D: usize>(
    nb: &Neighbours<D>,
    within: f64,
    i: usize,
    kinds: &[Kind],
    keep: impl Fn(usize) -> bool,
) -> Option<(usize, [f64; D], f64)> {
    let mut nearest = (within, None);
    nb.for_each_of(i, kinds, |j, rij, r| {
        if r < nearest.0 && keep(j) {
            nearest = (r, Some((j, rij)));
        }
    });
    nearest.1.map(|(j, rij)| (j, rij, nearest.0))
}

/// Distance to a boundary's face of a particle at r_ib from boundary particle b, whose
/// outward normal is `normal` and whose centre lies `depth` behind the face: n·r_ib − depth,
/// at least a quarter spacing (a particle pressed against the face).
pub fn face_distance<const D: usize>(
    normal: [f64; D],
    r_ib: [f64; D],
    depth: f64,
    spacing: f64,
) -> f64 {
    (dot(r_ib, normal) - depth).max(0.25 * spacing)
}

/// The face of the wall nearest to a fluid particle.
#[derive(Clone, Copy, Debug)]
pub struct Face<const D: usize> {
    /// Distance from the particle to the face: the nearest wall particle's separation along
    /// its normal less the half spacing from a wall particle's centre to the face, and at
    /// least a quarter spacing (a particle pressed against the face).
    pub distance: f64,
    /// The wall's normal, into the fluid.
    pub normal: [f64; D],
    /// Distance from the particle to the nearest wall particle.
    pub reach: f64,
}

/// The face of the nearest wall whose particles come closer to fluid particle i than
/// `within`, if any.
pub fn nearest_face<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    spacing: f64,
    within: f64,
    i: usize,
) -> Option<Face<D>> {
    let (b, r_ib, reach) = nearest_boundary(nb, within, i, &[Kind::Wall], |_| true)?;
    let normal = p.wall_normal(b);
    Some(Face {
        // A wall particle's centre lies half a spacing behind the face.
        distance: face_distance(normal, r_ib, 0.5 * spacing, spacing),
        normal,
        reach,
    })
}
