//! Walls: layers of fixed dummy particles that fill the kernel support beyond the boundary.
//!
//! A wall particle carries no unknown of the pressure solve. Every fluid particle i sees each
//! wall neighbour b as the continuation of its own pressure field under the Neumann condition
//! of the projection, ∂P/∂n = ρ0 g·n on a wall at rest:
//!
//!   P_b = P_i + ρ0 g·N_b (r_b − r_i),                                               (ghost)
//!
//! N_b the projector on the normals of the walls b lies behind: n nᵀ behind a plane wall, the
//! identity in a corner of the container (behind two walls in 2D, three in 3D; behind two
//! walls of a 3D box, the projector on their plane). The walls are axis-aligned (container and
//! box obstacles), so N_b keeps the axes along which b's normal has a component. Only the
//! normal part of the hydrostatic gradient is carried into the wall: along the wall the fluid
//! may be accelerating (a column falling beside a wall, a surge running along the floor), and a
//! hydrostatic gradient along the wall there would suck fluid into dry wall above it. Because the ghost difference P_b − P_i does
//! not depend on the unknowns, the wall pairs of a PPE row are known numbers: the Neumann condition
//! becomes a source term and the matrix couples fluid particles only.
//!
//! The kinematic condition u·n = 0 enters the PPE source through the velocity divergence, where
//! the wall particles take the wall velocity (zero) plus the fluid particle's own predictor
//! increment (see `ppe::source`).

use crate::neighbours::Lanes;
use crate::particles::{Kind, Particles};
use crate::scene::Aabb;
use crate::sph::Neighbours;
use wide::{f64x4, CmpNe};

/// P_b − P_i = −ρ0_i g·N_b r_ib of the ghost pressures of the wall particles b in lanes `l`
/// seen from fluid particle i (r_ib = r_i − r_b, the lanes' r_ij).
#[inline(always)]
pub fn ghost_pressure_difference<const D: usize>(
    p: &Particles<D>,
    gravity: [f64; D],
    i: usize,
    l: &Lanes<D>,
) -> f64x4 {
    let across = behind_walls(p, l, l.rij);
    let g_r = (0..D).fold(f64x4::ZERO, |s, d| {
        f64x4::splat(gravity[d]).mul_add(across[d], s)
    });
    f64x4::splat(-p.rest_density[i]) * g_r
}

/// N_b r: the part of r across the walls the wall particles b in lanes `l` lie behind (see
/// the module doc).
#[inline(always)]
pub fn behind_walls<const D: usize>(p: &Particles<D>, l: &Lanes<D>, r: [f64x4; D]) -> [f64x4; D] {
    std::array::from_fn(|d| r[d] & l.load(&p.normal[d]).cmp_ne(f64x4::ZERO))
}

/// The velocities the wall particles b in lanes `l` take in the velocity gradients of fluid
/// particle i (the
/// divergence of the PPE source, the strain rate of the eddy viscosity, the Taylor correction
/// of shifting): the fluid's own velocity `u_i` with its normal part `u_n` (relative to the wall,
/// at rest) removed, N_b here as for the pressure ghosts. The wall is then felt only through
/// the normal velocity, the kinematic condition; along the wall it continues the fluid, a
/// free-slip ghost. At rest in these gradients (no-slip), the wall shows a shear of order
/// U/dx, which the kernel correction mixes into the divergence where the support is truncated
/// (a surge front) and which a shift across it turns into a spurious change of velocity.
#[inline(always)]
pub fn ghost_velocity<const D: usize>(
    p: &Particles<D>,
    l: &Lanes<D>,
    u_i: [f64; D],
    u_n: [f64; D],
) -> [f64x4; D] {
    let across = behind_walls(p, l, u_n.map(f64x4::splat));
    std::array::from_fn(|d| f64x4::splat(u_i[d]) - across[d])
}

/// What the ghost pressures of the walls are made of, borrowed apart from the pressures
/// themselves (the wall pressure is written beside the fluid's it is computed from).
pub struct Ghosts<'a, const D: usize> {
    pub rest_density: &'a [f64],
    pub normal: &'a [Vec<f64>; D],
    pub gravity: [f64; D],
}

impl<const D: usize> Ghosts<'_, D> {
    /// Pressure of wall particle b for output and wall loads: the kernel-weighted mean of the
    /// ghost pressures its fluid neighbours give it (zero where no fluid is in reach), with
    /// `fluid_pressure` the pressures of the fluid particles.
    pub fn wall_pressure(&self, nb: &Neighbours<D>, fluid_pressure: &[f64], b: usize) -> f64 {
        // P_b − P_f = −ρ0_f g·N_b r_fb (see the module doc), r_fb = −r_bf; N_b is b's own.
        let g_across: [f64x4; D] = std::array::from_fn(|d| {
            f64x4::splat(if self.normal[d][b] != 0.0 {
                self.gravity[d]
            } else {
                0.0
            })
        });
        let (mut sum, mut weights) = (f64x4::ZERO, f64x4::ZERO);
        nb.for_each_lanes_of(b, &[Kind::Fluid], |l| {
            let w = nb.kernel.w4(l.r) & l.mask;
            let g_r = (0..D).fold(f64x4::ZERO, |s, d| g_across[d].mul_add(l.rij[d], s));
            let ghost = l
                .load(self.rest_density)
                .mul_add(g_r, l.load(fluid_pressure));
            sum = w.mul_add(ghost, sum);
            weights += w;
        });
        let (sum, weights) = (sum.reduce_add(), weights.reduce_add());
        if weights > 0.0 {
            sum / weights
        } else {
            0.0
        }
    }
}

/// The wall particle b nearest to particle i closer than `within`, with r_ib and |r_ib|, if any.
pub fn nearest_wall<const D: usize>(
    nb: &Neighbours<D>,
    within: f64,
    i: usize,
) -> Option<(usize, [f64; D], f64)> {
    let mut nearest = (within, None);
    nb.for_each_of(i, &[Kind::Wall], |j, rij, r| {
        if r < nearest.0 {
            nearest = (r, Some((j, rij)));
        }
    });
    nearest.1.map(|(j, rij)| (j, rij, nearest.0))
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
    let (b, r_ib, reach) = nearest_wall(nb, within, i)?;
    let normal = p.wall_normal(b);
    Some(Face {
        distance: (dot(r_ib, normal) - 0.5 * spacing).max(0.25 * spacing),
        normal,
        reach,
    })
}

/// `contact` of a particle touching no wall.
pub const NO_CONTACT: u32 = u32::MAX;

/// The wall particle a fluid particle touches: the nearest one closer than the spacing dx
/// (nearer than at rest), or `NO_CONTACT`.
pub fn contact<const D: usize>(nb: &Neighbours<D>, spacing: f64, i: usize) -> u32 {
    nearest_wall(nb, spacing, i).map_or(NO_CONTACT, |(b, _, _)| b as u32)
}

/// The normal of the wall a particle touches (`contact`), zero where it touches none.
pub fn contact_normal<const D: usize>(p: &Particles<D>, contact: u32) -> [f64; D] {
    if contact == NO_CONTACT {
        [0.0; D]
    } else {
        p.wall_normal(contact as usize)
    }
}

/// The kinematic wall condition v·n ≥ 0 for a velocity or displacement v of a fluid particle
/// touching a wall of normal n (see `contact_normal`): v ← v − min(v·n, 0) n. The pressure
/// keeps fluid with neighbours off the walls; this catches what it cannot hold, a drop of spray
/// with no fluid around it, which meets the wall inelastically.
pub fn no_penetration<const D: usize>(v: [f64; D], n: [f64; D]) -> [f64; D] {
    let v_n = dot(v, n).min(0.0);
    std::array::from_fn(|d| v[d] - v_n * n[d])
}

pub fn dot<const D: usize>(a: [f64; D], b: [f64; D]) -> f64 {
    (0..D).map(|d| a[d] * b[d]).sum()
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

/// What `face_contact` did to a particle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Contact {
    /// Nothing: the particle is more than `gap` inside the container and outside every obstacle.
    Clear,
    /// Put back `gap` off a face it had come closer to than `gap`, without crossing it.
    Near,
    /// Put back from beyond a face: its centre was outside the container or inside an
    /// obstacle (a penetration).
    Crossed,
}

/// Hard contact with the walls' faces, the last line of the wall condition: a fluid particle
/// whose step ended within `gap` of a face of the container or inside an obstacle (a fast
/// particle at a large CFL number can cross the half spacing between the fluid and a face in
/// one step, where the ghost pressure has had no time to stop it) is put back `gap` inside the
/// fluid's side of that face, and its velocity loses the part into the face (an inelastic
/// contact, as `no_penetration`).
pub fn face_contact<const D: usize>(
    container: &Aabb,
    periodic: [bool; D],
    obstacles: &[Aabb],
    gap: f64,
    x: &mut [f64; D],
    u: &mut [f64; D],
) -> Contact {
    let mut contact = Contact::Clear;
    // A periodic axis has no faces.
    for d in (0..D).filter(|&d| !periodic[d]) {
        let (lo, hi) = (container.min[d] + gap, container.max[d] - gap);
        if x[d] < container.min[d] || x[d] > container.max[d] {
            contact = Contact::Crossed;
        } else if contact == Contact::Clear && (x[d] < lo || x[d] > hi) {
            contact = Contact::Near;
        }
        if x[d] < lo {
            (x[d], u[d]) = (lo, u[d].max(0.0));
        } else if x[d] > hi {
            (x[d], u[d]) = (hi, u[d].min(0.0));
        }
    }
    for o in obstacles {
        if !o.contains(x.as_slice()) {
            continue;
        }
        // Out through the nearest face: along axis d, towards −1 (min face) or +1 (max face).
        let (mut depth, mut d, mut sign) = (f64::INFINITY, 0, 0.0);
        for axis in 0..D {
            for (inside, s) in [(x[axis] - o.min[axis], -1.0), (o.max[axis] - x[axis], 1.0)] {
                if inside < depth {
                    (depth, d, sign) = (inside, axis, s);
                }
            }
        }
        x[d] = if sign < 0.0 {
            o.min[d] - gap
        } else {
            o.max[d] + gap
        };
        if u[d] * sign < 0.0 {
            u[d] = 0.0;
        }
        contact = Contact::Crossed;
    }
    contact
}
