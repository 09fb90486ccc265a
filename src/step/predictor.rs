//! Predictor, Eq. (5): u* = uⁿ + Δt (∇·((ν + ν_t)∇uⁿ) + τ_w + f), with ν_t the Smagorinsky
//! eddy viscosity (Eq. 3–4), τ_w the turbulent wall shear where the scene runs LES (and its
//! wall function) and f the body force: gravity, or where it varies the field of
//! `body_forces`.

use super::{Stage, StepSettings};
use crate::boundary::ghosts::{self, BodyForce};
use crate::effects::les;
use crate::math::memory::ArraySize;
use crate::math::reduce::fill_vector;
use crate::neighbours::Neighbours;
use crate::particles::{components, Particles};
use crate::sph;

pub const NAME: &str = "predictor";

pub struct Predictor<const D: usize> {
    /// u* of each fluid particle, from the predictor to the corrector, which leaves ∇Pⁿ⁺¹ in
    /// its place for the shifting's Taylor step (Eq. 9): the same gradient, not computed twice.
    u_star: [Vec<f64>; D],
}

impl<const D: usize> Default for Predictor<D> {
    fn default() -> Self {
        Self {
            u_star: components(),
        }
    }
}

impl<const D: usize> Predictor<D> {
    /// u* of the `nf` fluid particles over `dt`; `eddy` is ν_t with LES, `force` the body
    /// force.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        set: &StepSettings<D>,
        eddy: Option<&[f64]>,
        force: BodyForce<D>,
        dt: f64,
        nf: usize,
    ) -> &mut [Vec<f64>; D] {
        for a in &mut self.u_star {
            a.resize(nf, 0.0);
        }
        let spacing = set.spacing;
        let wall_function = set.effects.les.is_some_and(|les| les.wall_function);
        let support = nb.kernel.support();
        fill_vector(&mut self.u_star, |i| {
            // The nearest wall, for the no-slip wall velocity and the wall function.
            let face = ghosts::nearest_face(nb, p, spacing, support, i);
            let visc = sph::viscous_acceleration(nb, p, eddy, face, i);
            let wall = if wall_function {
                les::wall_shear(p, spacing, face, i)
            } else {
                [0.0; D]
            };
            let f = force.at(i);
            std::array::from_fn(|d| p.vel[d][i] + dt * (visc[d] + wall[d] + f[d]))
        });
        &mut self.u_star
    }
}

impl<const D: usize> Stage<D> for Predictor<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, set: &StepSettings<D>) -> String {
        match set.effects.les {
            Some(les) if les.wall_function => "Eq. (5): u* = u + Δt (∇·((ν + ν_t)∇u) (Eq. 26) + τ_w + f), no-slip laminar wall pairs, τ_w the log-law wall shear on the particles touching a wall".into(),
            Some(_) => "Eq. (5): u* = u + Δt (∇·((ν + ν_t)∇u) (Eq. 26) + f), no-slip laminar wall pairs".into(),
            None => "Eq. (5): u* = u + Δt (∇·(ν∇u) (Eq. 26) + f), no-slip wall pairs".into(),
        }
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![ArraySize::of_components("u*, then ∇P", &self.u_star)]
    }
}
