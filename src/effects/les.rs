//! Turbulence: the Smagorinsky large-eddy model of Eq. (3)–(4) inside the fluid, and the shear
//! stress of a turbulent boundary layer at the walls.
//!
//! The eddy viscosity ν_t = (Cs Δ)² |S| is computed with the walls as free-slip ghosts: at a
//! no-slip wall the resolved strain rate is of order U/dx, and ν_t from it overestimates the wall
//! shear stress by an order of magnitude (a surge on a dry floor then drags along the floor like
//! a viscous film). The wall stress comes instead from the law of the wall: with U the speed of
//! the first fluid particle along the wall at distance y from it,
//!
//!   U/u_τ = (1/κ) ln(y u_τ/ν) + B,   κ = 0.41, B = 5.2   (log layer, y u_τ/ν > 11)
//!
//! and τ_w = ρ u_τ². The laminar viscous term already applies ν U/y-like friction through the
//! no-slip wall pairs of Eq. (26); the turbulent excess u_τ² − ν U/y acts on the layer of
//! particles touching the wall (thickness dx), against their velocity along it.
//!
//! That stress has to cross the log layer, as it does in a turbulent boundary layer, where the
//! eddy viscosity κ u_τ y carries it: ρ κ u_τ y ∂U/∂y = ρ u_τ² for the log profile. Smagorinsky's
//! (Cs dx)² |S|, with |S| blind to the wall, is a hundredth of that a few spacings out, so the
//! momentum the wall takes would come from the first layer alone: a layer one spacing thick,
//! slowed more as the spacing shrinks, which the adverse pressure gradient at the foot of a wall
//! that a surge runs into turns back into a vortex (docs/accuracy.md, "Wall pressures against
//! Lobovsky et al. 2014"). So within a kernel support of a wall the eddy viscosity is at least
//! κ u_τ y, u_τ from the particle's own speed along the wall at its distance y
//! (`wall_layer_viscosity`).
//!
//! Cs and whether the wall function applies are the scene's `[effects.les]` (`LesSettings`).

use crate::boundary::ghosts::Face;
use crate::math::vector::{dot, norm};
use crate::particles::Particles;

/// von Kármán constant κ.
const KARMAN: f64 = 0.41;
/// Additive constant B of the log law for a smooth wall.
const LOG_LAW_B: f64 = 5.2;
/// y⁺ below which the first particle lies in the viscous sublayer (u⁺ = y⁺).
const SUBLAYER_Y_PLUS: f64 = 11.0;

/// |S| = (2 S_ab S_ab)^½ of the velocity gradient `grad`, S its symmetric part, the strain
/// rate (Eq. 4).
pub fn strain_rate<const D: usize>(grad: [[f64; D]; D]) -> f64 {
    let mut ss = 0.0;
    for a in 0..D {
        for b in 0..D {
            let s = 0.5 * (grad[a][b] + grad[b][a]);
            ss += s * s;
        }
    }
    (2.0 * ss).sqrt()
}

/// Smagorinsky eddy viscosity ν_t = (Cs Δ)² |S| (Eq. 3), with `strain_rate` |S| of the
/// velocity gradient, corrected where L_i applies (the walls free-slip ghosts,
/// `sph::fluid_velocity`), and Δ the particle spacing.
pub fn eddy_viscosity(strain_rate: f64, cs: f64, spacing: f64) -> f64 {
    let cs_delta = cs * spacing;
    cs_delta * cs_delta * strain_rate
}

/// The acceleration of fluid particle i by the turbulent part of the wall shear stress, with
/// `face` the nearest wall's (`ghosts::nearest_face`): zero unless a wall particle lies within
/// 1.5 dx (the particle touches the wall) and the particle sits in the log layer.
pub fn wall_shear<const D: usize>(
    p: &Particles<D>,
    spacing: f64,
    face: Option<Face<D>>,
    i: usize,
) -> [f64; D] {
    let Some(Face {
        distance: y,
        normal: n,
        ..
    }) = face.filter(|f| f.reach < 1.5 * spacing)
    else {
        return [0.0; D];
    };
    let u_t = velocity_along(p, n, i);
    let speed = norm(u_t);
    let nu = p.viscosity[i];
    if speed == 0.0 || nu == 0.0 {
        return [0.0; D];
    }
    let excess = friction_velocity(speed, y, nu).powi(2) - nu * speed / y;
    if excess <= 0.0 {
        return [0.0; D];
    }
    u_t.map(|x| -excess / spacing * x / speed)
}

/// The eddy viscosity of the log layer, κ u_τ y, at fluid particle i at distance y from the
/// wall `face`, u_τ from its speed along the wall (`friction_velocity`): the viscosity that
/// carries the wall's shear stress ρ u_τ² across the layer.
pub fn wall_layer_viscosity<const D: usize>(p: &Particles<D>, face: Face<D>, i: usize) -> f64 {
    let y = face.distance;
    let speed = norm(velocity_along(p, face.normal, i));
    let nu = p.viscosity[i];
    if speed == 0.0 || nu == 0.0 {
        return 0.0;
    }
    KARMAN * friction_velocity(speed, y, nu) * y
}

/// The velocity of fluid particle i along a wall of normal `n`: its normal part taken out.
fn velocity_along<const D: usize>(p: &Particles<D>, n: [f64; D], i: usize) -> [f64; D] {
    let u = p.velocity(i);
    let u_n = dot(u, n);
    std::array::from_fn(|d| u[d] - u_n * n[d])
}

/// u_τ of the law of the wall for speed `u` at distance `y` from a smooth wall, kinematic
/// viscosity `nu`: the viscous sublayer u = u_τ² y/ν below y⁺ = 11, the log law above
/// (Newton's method from the sublayer value).
pub fn friction_velocity(u: f64, y: f64, nu: f64) -> f64 {
    let laminar = (nu * u / y).sqrt();
    if laminar * y / nu < SUBLAYER_Y_PLUS {
        return laminar;
    }
    let mut u_tau = laminar;
    for _ in 0..50 {
        let log = (y * u_tau / nu).ln() / KARMAN + LOG_LAW_B;
        let step = (u_tau * log - u) / (log + 1.0 / KARMAN);
        u_tau -= step;
        if step.abs() <= 1e-12 * u_tau {
            break;
        }
    }
    u_tau
}
