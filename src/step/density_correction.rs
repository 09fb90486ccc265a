//! Density correction: the density-invariance term of Eq. (6) applied to the positions only,
//! δr = −(Δt²/ρ0)∇P_α, with P_α the solution of the PPE whose source is that term alone
//! (`pressure_solve`), as Hu & Adams (2007, J. Comput. Phys. 227) correct the density of their
//! projection. The advection adds δr to Δt uⁿ⁺¹ (and to the shifting's displacement, which then
//! carries u and P to the new position by Eq. 9).
//!
//! Solved together with the divergence, as Eq. (6) prints it, P_α moves the particles by the
//! same δr in the step, but also leaves −(Δt/ρ0)∇P_α in the velocity, and there it stays. The
//! summation density of moving, shifted particles is never uniform (0.3% rms on a
//! Taylor–Green vortex at any resolution), so every step gives the velocity a kick of about
//! α (δρ/ρ0) dx/Δt, a fixed fraction of the flow speed at a fixed CFL number: a particle-scale
//! noise that the viscosity damps more slowly than the steps feed it, and an error that stops
//! converging at about 1% (docs/accuracy.md, "The start-up error of the Taylor–Green vortex").
//! As a displacement the correction removes the same density error and adds no momentum.

use super::free_surface::Surface;
use super::{Stage, StepSettings};
use crate::boundary::faces::{self, Faces};
use crate::math::memory::ArraySize;
use crate::math::reduce::update_vectors;
use crate::particles::{components, Kind, Particles};
use crate::solver::ppe::Role;

pub const NAME: &str = "density correction";

pub struct DensityCorrection<const D: usize> {
    /// δr of each fluid particle.
    displacement: [Vec<f64>; D],
}

impl<const D: usize> Default for DensityCorrection<D> {
    fn default() -> Self {
        Self {
            displacement: components(),
        }
    }
}

impl<const D: usize> DensityCorrection<D> {
    /// The array the corrector sums ∇P_α into, in its walk for ∇Pⁿ⁺¹ (`Corrector::run`, the
    /// corrector's gradient with mirror walls): `run` turns it into δr in place.
    pub fn gradient_slot(&mut self) -> &mut [Vec<f64>; D] {
        &mut self.displacement
    }

    /// δr of the fluid particles over a step of `dt` from ∇P_α, which the corrector left in
    /// the array; splashes stay in place, and no particle touching a wall face moves into it.
    pub fn run(
        &mut self,
        p: &Particles<D>,
        set: &StepSettings<D>,
        faces: &Faces,
        surface: &Surface<D>,
        dt: f64,
    ) -> &mut [Vec<f64>; D] {
        let touch = faces::touching_distance(set.spacing);
        update_vectors([&mut self.displacement], |i, [grad]| {
            // Splashes stay in place; a body's particles move rigidly (`rigid_bodies`).
            if surface.roles[i] == Role::Splash || p.kind[i] == Kind::Body {
                return [[0.0; D]];
            }
            let scale = -dt * dt / p.rest_density[i];
            [faces.no_penetration(p.position(i), grad.map(|g| scale * g), touch)]
        });
        &mut self.displacement
    }
}

impl<const D: usize> Stage<D> for DensityCorrection<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, set: &StepSettings<D>) -> String {
        format!(
            "the density-invariance term of Eq. (6) on the positions only: δr = −(Δt²/ρ0)∇P_α, α = {}, the corrector's gradient with mirror walls, summed in the corrector's walk (Hu & Adams 2007); no momentum",
            set.alpha
        )
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![ArraySize::of_components("δr (density)", &self.displacement)]
    }
}
