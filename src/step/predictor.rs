//! Predictor, Eq. (5): u* = uⁿ + Δt (∇·((ν + ν_t)∇uⁿ) + τ_w + f), with ν_t the Smagorinsky
//! eddy viscosity (Eq. 3–4), τ_w the turbulent wall shear where the scene runs LES (and its
//! wall function) and f the body force: gravity, or where it varies the field of
//! `body_forces`.
//!
//! A laminar scene (no LES) takes the viscous term to second order in the step, and takes the
//! kernel's smoothing out of it, where the kernel's support holds one fluid only: with
//! a = νLuⁿ Eq. (26)'s acceleration and L the SPH Laplacian (`sph::field_laplacian`),
//!
//!     u* = uⁿ + Δt (a + (ν Δt/2 − σ²/4) L a + f).
//!
//! The ν Δt/2 term is the second-order Taylor term of the viscous decay over the step,
//! (Δt²/2) ν² ∇⁴u (Euler's step alone decays every mode too fast by (νk²Δt)²/2 a step); the
//! −σ²/4 term takes out the kernel's smoothing of the Laplacian, which is short of −|k|² by
//! σ²|k|⁴/4 (σ the kernel's standard deviation). Both are the one field L a, a second pair loop
//! over the fluid. Without them a viscous Taylor–Green vortex at Re = 50 decayed too slowly and
//! ended 1.4% of its energy above the exact one at 40 particles across (docs/accuracy.md, "The
//! viscous operator"). Where the support reaches a wall, a body, another fluid or the free
//! surface, L a is truncated or crosses a jump of a, and the step keeps Euler's a. With LES the
//! eddy viscosity is a model whose constant dwarfs this error, and the pass is not run.

use super::{Stage, StepSettings};
use crate::boundary::ghosts::{self, BodyForce};
use crate::effects::les;
use crate::math::memory::ArraySize;
use crate::math::reduce::{fill_scalar_and_vector, fill_vector};
use crate::neighbours::Neighbours;
use crate::particles::{components, Kind, Particles};
use crate::sph;

pub const NAME: &str = "predictor";

pub struct Predictor<const D: usize> {
    /// u* of each fluid particle, from the predictor to the corrector, which leaves ∇Pⁿ⁺¹ in
    /// its place for the shifting's Taylor step (Eq. 9): the same gradient, not computed twice.
    u_star: [Vec<f64>; D],
    /// In a laminar scene with a viscosity, the fields of L a.
    laminar: Option<Laminar<D>>,
}

/// The fields the laminar step's L a is computed from.
struct Laminar<const D: usize> {
    /// Eq. (26)'s viscous acceleration a of each fluid particle.
    viscous: [Vec<f64>; D],
    /// Whether a fluid particle's support is all of its own fluid (no wall, body, other fluid or
    /// free surface in it).
    fluid_support: Vec<bool>,
}

impl<const D: usize> Predictor<D> {
    pub fn new(set: &StepSettings<D>) -> Self {
        Self {
            u_star: components(),
            laminar: (set.effects.les.is_none() && set.max_viscosity > 0.0).then(|| Laminar {
                viscous: components(),
                fluid_support: Vec::new(),
            }),
        }
    }

    /// u* of the `nf` fluid particles over `dt`; `eddy` is ν_t with LES, `force` the body
    /// force, `bodies` the distance of each to the nearest body's surface in a scene with
    /// bodies (`body_surfaces`), `full_support` whether a fluid particle's support holds no
    /// free-surface particle.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        set: &StepSettings<D>,
        eddy: Option<&[f64]>,
        force: BodyForce<D>,
        bodies: Option<&[f64]>,
        full_support: &[bool],
        dt: f64,
        nf: usize,
    ) -> &mut [Vec<f64>; D] {
        for a in &mut self.u_star {
            a.resize(nf, 0.0);
        }
        let spacing = set.spacing;
        match &mut self.laminar {
            Some(laminar) => {
                laminar.run(nb, p, spacing, bodies, full_support, nf);
                let (viscous, fluid_support) = (&laminar.viscous, &laminar.fluid_support);
                let smoothing = nb.kernel.deviation().powi(2) / 4.0;
                fill_vector(&mut self.u_star, |i| {
                    let la = if fluid_support[i] {
                        sph::field_laplacian(nb, p, viscous, i)
                    } else {
                        [0.0; D]
                    };
                    let c = 0.5 * p.viscosity[i] * dt - smoothing;
                    let f = force.at(i);
                    std::array::from_fn(|d| {
                        p.vel[d][i] + dt * (c.mul_add(la[d], viscous[d][i]) + f[d])
                    })
                });
            }
            None => {
                let wall_function = set.effects.les.is_some_and(|les| les.wall_function);
                let support = nb.kernel.support();
                fill_vector(&mut self.u_star, |i| {
                    // The nearest wall, for the no-slip wall velocity and the wall function.
                    let face = ghosts::nearest_face(nb, p, spacing, support, i);
                    let visc = sph::viscous_acceleration(nb, p, eddy, face, bodies, i);
                    let wall = if wall_function {
                        les::wall_shear(p, spacing, face, i)
                    } else {
                        [0.0; D]
                    };
                    let f = force.at(i);
                    std::array::from_fn(|d| p.vel[d][i] + dt * (visc[d] + wall[d] + f[d]))
                });
            }
        }
        &mut self.u_star
    }
}

impl<const D: usize> Laminar<D> {
    /// a of Eq. (26) at every fluid particle, and whether its support holds its own fluid only.
    fn run(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        spacing: f64,
        bodies: Option<&[f64]>,
        full_support: &[bool],
        nf: usize,
    ) {
        let support = nb.kernel.support();
        for a in &mut self.viscous {
            a.resize(nf, 0.0);
        }
        self.fluid_support.resize(nf, false);
        // Bodies and a second fluid (another ν or ρ0: a jumps across the interface) are
        // looked for only where the scene has them.
        let mixed =
            p.kind[..nf].contains(&Kind::Body) || p.fluid[..nf].iter().any(|&f| f != p.fluid[0]);
        fill_scalar_and_vector(&mut self.fluid_support, &mut self.viscous, |i| {
            let face = ghosts::nearest_face(nb, p, spacing, support, i);
            let fluid_support = full_support[i]
                && p.kind[i] == Kind::Fluid
                && face.is_none()
                && !(mixed && touches_another_material(nb, p, i));
            (
                fluid_support,
                sph::viscous_acceleration(nb, p, None, face, bodies, i),
            )
        });
    }
}

/// Whether a body's particle or another fluid's lies in fluid particle i's support.
fn touches_another_material<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    i: usize,
) -> bool {
    let mut touches = false;
    nb.for_each_of(i, &[Kind::Fluid], |j, _, _| {
        touches |= p.kind[j] != Kind::Fluid || p.fluid[j] != p.fluid[i];
    });
    touches
}

impl<const D: usize> Stage<D> for Predictor<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, set: &StepSettings<D>) -> String {
        match set.effects.les {
            Some(les) if les.wall_function => "Eq. (5): u* = u + Δt (∇·((ν + ν_t)∇u) (Eq. 26) + τ_w + f), no-slip laminar wall pairs, τ_w the log-law wall shear on the particles touching a wall".into(),
            Some(_) => "Eq. (5): u* = u + Δt (∇·((ν + ν_t)∇u) (Eq. 26) + f), no-slip laminar wall pairs".into(),
            None if self.laminar.is_some() => "Eq. (5): u* = u + Δt (a + (νΔt/2 − σ²/4) L a + f), a = ν∇²u of Eq. (26) with no-slip wall pairs, L a its SPH Laplacian where the support holds one fluid only (second order in Δt, the kernel's smoothing taken out)".into(),
            None => "Eq. (5): u* = u + Δt (∇·(ν∇u) (Eq. 26) + f), no-slip wall pairs".into(),
        }
    }

    fn arrays(&self) -> Vec<ArraySize> {
        let mut arrays = vec![ArraySize::of_components("u*, then ∇P", &self.u_star)];
        if let Some(laminar) = &self.laminar {
            arrays.push(ArraySize::of_components("a = ν∇²u", &laminar.viscous));
            arrays.push(ArraySize::of("support all fluid", &laminar.fluid_support));
        }
        arrays
    }
}
