//! How thick each free-surface particle's volume is across the surface, which places the
//! surface beyond it (`ppe::surface_row_vector`: P = 0 on the surface, half the thickness beyond
//! the particle's centre).
//!
//! A particle on the surface of water at rest on its lattice stands for a volume dx thick across
//! the surface. The volume is the particle's for good, but its shape follows the flow: where
//! the surface is stretched along itself the layer under it thins, where it is squeezed the
//! layer thickens, at the rate of the strain across the surface, e·∇u·e with e the way up
//! (against the body force, as the surface row extrapolates, `ppe::surface_row_vector`;
//! ∇·u = 0). A surface particle's thickness τ_i (in spacings; 1 at rest) therefore follows
//! dτ/dt = τ e·∇u·e over the steps it stays on the surface: τ ← τ exp(Δt e·∇uⁿ⁺¹·e), with the
//! drift's velocity uⁿ⁺¹.
//!
//! Held at dx the thickness puts the surface where the particle layer is, not where the water
//! is: a standing wave lifts the surface particles by what it lifts the water dx/2 below the
//! surface, and in shallow water that is short of the surface's lift by dx/(2h). With the
//! thickness fixed the tank's first sloshing mode had the period of water half a spacing
//! shallower, 1.5% long at 15 particles in the depth (docs/bodies.md, "Sloshing period").
//!
//! A body's particles keep τ = 1: their surface rows sit on the body's own surface
//! (`ppe::surface_depth`, δ = 0).
//!
//! A particle that joins the surface starts at τ = 1 (the water it comes from is at rest on
//! average), one that leaves it returns to 1. τ is kept within [`MIN_THICKNESS`,
//! `MAX_THICKNESS`]: on a surface stretched or squeezed for long the shifting refills and
//! thins the layer, and a particle's own strain no longer measures the layer it stands in.

use super::free_surface::Surface;
use super::{Stage, StepSettings};
use crate::boundary::ghosts::BodyForce;
use crate::math::reduce::update;
use crate::neighbours::{Lanes, Neighbours};
use crate::particles::{Kind, Particles};
use crate::solver::ppe::Role;
use crate::sph::{fluid_velocity, velocity_gradient};

pub const NAME: &str = "surface thickness";

/// Bounds of a surface particle's thickness τ, in spacings (see the module doc): the surface
/// stays between a quarter and three quarters of a spacing beyond the particle's centre.
pub const MIN_THICKNESS: f64 = 0.5;
pub const MAX_THICKNESS: f64 = 1.5;

/// The stage: it holds no array of its own, τ lives with the particles.
#[derive(Default)]
pub struct SurfaceThickness;

impl SurfaceThickness {
    /// τ of the fluid particles (`thickness`, the particles' own array, taken out of them for
    /// the pass) after a step of length `dt`, from their τ before it and the drift's velocity
    /// uⁿ⁺¹ (the particles' velocity), on the step's free surface, with `force` the body force
    /// (the way up is against it; none: τ stays 1). τ_i depends on its own old value only, so
    /// it is updated in place.
    pub fn run<const D: usize>(
        &self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        surface: &Surface<D>,
        force: BodyForce<D>,
        dt: f64,
        thickness: &mut [f64],
    ) {
        update(thickness, |i, tau| {
            match (surface.roles[i], force.up(i), p.kind[i]) {
                (Role::Surface, Some(up), Kind::Fluid) => {
                    let strain = strain_rate_along(nb, p, surface, up, i);
                    (tau * (dt * strain).exp()).clamp(MIN_THICKNESS, MAX_THICKNESS)
                }
                _ => 1.0,
            }
        });
    }
}

/// e·∇u·e at fluid particle i: the velocity gradient corrected by L'_i where the kernel
/// correction is on (the surface cuts the kernel), the walls as free-slip ghosts of u_i (as in
/// the PPE's divergence).
fn strain_rate_along<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    surface: &Surface<D>,
    e: [f64; D],
    i: usize,
) -> f64 {
    let u_i = p.velocity(i);
    let velocity = |l: &Lanes<D>| fluid_velocity(p, u_i, l);
    // G[b][a] = ∂u_a/∂x_b.
    let g = velocity_gradient(nb, p, surface.pressure_corrections.of(i), u_i, velocity, i);
    (0..D)
        .map(|b| (0..D).map(|a| e[b] * g[b][a] * e[a]).sum::<f64>())
        .sum()
}

impl<const D: usize> Stage<D> for SurfaceThickness {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        format!("each free-surface particle's thickness across the surface, which places the surface beyond it: τ ← τ exp(Δt e·∇uⁿ⁺¹·e), e against the body force, while it stays on the surface, 1 elsewhere, within [{MIN_THICKNESS}, {MAX_THICKNESS}] spacings")
    }
}
