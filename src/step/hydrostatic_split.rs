//! The fluid's hydrostatic pressure through a body's surface. The pressure solve takes a body's
//! particles for fluid of the body's density and weights each pair's pressure difference
//! across a change of rest density by ρ0_i/ρ̄_ij (`sph::interface`): between two fluids that is
//! the kink of the hydrostatic pressure at their interface, and at a body it makes the added
//! mass implicit (docs/bodies.md, "The coupling"). But a body holds no hydrostatic column of its
//! own density: the fluid's hydrostatic pressure continues through it,
//! P_j − P_i = h_ij = ρ0_f f·(r_j − r_i) with ρ0_f and f the rest density and body force of the
//! pair's fluid particle, and weighted by ρ0_i/ρ̄_ij ≠ 1 that difference gives the fluid beside a
//! body's side a gradient other than its weight. A body heavier than the water then draws a
//! current down its sides, a lighter one up, even held still.
//!
//! Here each pair of a fluid and a body particle takes the weighting on its departure from h_ij
//! alone: the pressure gradient sees w_ij (P_j − P_i) + (1 − w_ij) h_ij, w_ij = ρ0_i/ρ̄_ij. The
//! second term is known before the solve, so it is an acceleration −E_i/ρ0_i added to u*, with
//! E_i = Σ_j V_j (1 − w_ij) h_ij L_i ∇W_ij: the solve and the corrector see it together, the
//! operator (and with it the added mass) is unchanged, and the fluid's hydrostatic pressure
//! through a body at rest is a solution. A held body takes the water's density in the solve
//! (`Bodies::set_solve_densities`): its pairs have w_ij = 1 and need none of this.
//! Runs only in a scene with a free body whose rest density differs from a fluid's.

use super::free_surface::Surface;
use super::{Stage, StepSettings};
use crate::math::lanes::F64s;
use crate::math::memory::ArraySize;
use crate::neighbours::Neighbours;
use crate::particles::{Kind, Particles};
use crate::sph::{self, interface};
use rayon::prelude::*;

pub const NAME: &str = "hydrostatic split";

#[derive(Default)]
pub struct HydrostaticSplit<const D: usize> {
    /// 1 at a body's particle, 0 at a fluid particle (of the fluid and body particles).
    body: Vec<f64>,
    /// The particles within reach of a body's surface and their −E_i/ρ0_i.
    acceleration: Vec<(u32, [f64; D])>,
}

impl<const D: usize> HydrostaticSplit<D> {
    /// −E_i/ρ0_i of the `nf` fluid and body particles within reach of an interface, with
    /// `force` the body force of the fluid particles and `surface`'s kernel corrections.
    pub fn run(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        surface: &Surface<D>,
        interfaces: interface::Field<D>,
        force: &[Vec<f64>; D],
        nf: usize,
    ) {
        self.body.clear();
        self.body
            .extend((0..nf).map(|i| f64::from(p.kind[i] == Kind::Body)));
        let support = nb.kernel.support();
        let body = &self.body;
        self.acceleration = (0..nf)
            .into_par_iter()
            .filter(|&i| interfaces.distance[i] < support)
            .filter_map(|i| {
                let e = surface_excess(nb, p, surface, interfaces, body, force, i);
                let rho0 = p.rest_density[i];
                e.iter()
                    .any(|&e| e != 0.0)
                    .then(|| (i as u32, e.map(|e| -e / rho0)))
            })
            .collect();
    }

    /// Adds the accelerations over `dt` to `u_star`.
    pub fn apply(&self, u_star: &mut [Vec<f64>; D], dt: f64) {
        for &(i, a) in &self.acceleration {
            for d in 0..D {
                u_star[d][i as usize] += dt * a[d];
            }
        }
    }
}

/// E_i = Σ_j V_j (1 − w_ij) h_ij L_i ∇W_ij over the pairs of particle i with particles of the
/// other side of a body's surface (a fluid particle's with body particles, a body particle's
/// with fluid particles; `body` flags the body particles), h_ij = ρ0_f f_f·(r_j − r_i).
pub(super) fn surface_excess<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    surface: &Surface<D>,
    interfaces: interface::Field<D>,
    body: &[f64],
    force: &[Vec<f64>; D],
    i: usize,
) -> [f64; D] {
    let side = interface::Side::of(p, Some(interfaces), i);
    let body_i = body[i] == 1.0;
    let l = surface.pressure_corrections.of(i);
    sph::gradient(nb, p, l, i, |lanes| {
        if lanes.kind == Kind::Wall {
            return F64s::ZERO;
        }
        let w = side.weight(p, Some(interfaces), lanes).unwrap_or(F64s::ONE);
        let body_j = lanes.load(body);
        // ρ0_f f_f·(r_j − r_i) = −ρ0_f f_f·r_ij, and whether the pair straddles a body's surface.
        let (fluid_density, other) = if body_i {
            (lanes.load(&p.rest_density), F64s::ONE - body_j)
        } else {
            (side.rest_density, body_j)
        };
        let f_dot_r = (0..D).fold(F64s::ZERO, |s, d| {
            let f = if body_i {
                lanes.load(&force[d])
            } else {
                F64s::splat(force[d][i])
            };
            f.mul_add(lanes.rij[d], s)
        });
        -(F64s::ONE - w) * fluid_density * f_dot_r * other
    })
}

impl<const D: usize> Stage<D> for HydrostaticSplit<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        "the fluid's hydrostatic pressure continued through the bodies: each fluid–body pair's ρ0_i/ρ̄_ij weighting taken on its departure from ρ0_f f·r_ji alone, as an acceleration added to u* beside the bodies' surfaces".into()
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![
            ArraySize::of("body flag", &self.body),
            ArraySize::sparse("accelerations beside the bodies", &self.acceleration),
        ]
    }
}
