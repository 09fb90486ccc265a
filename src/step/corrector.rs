//! Corrector, Eq. (7): uⁿ⁺¹ = u* − (Δt/ρ0)∇Pⁿ⁺¹ with the corrected gradient and the walls as
//! ghosts; particles touching a wall face keep no velocity into it (`Faces::no_penetration`).
//! Leaves ∇Pⁿ⁺¹ in place of u*. With α > 0 the same walk sums the density correction's ∇P_α
//! (`density_correction`), the two gradients sharing the walk, the distances and the kernel
//! gradient, each with the bits of a walk of its own.

use super::free_surface::Surface;
use super::{Stage, StepSettings};
use crate::boundary::faces::{self, Faces};
use crate::boundary::ghosts::{self, BodyForce};
use crate::math::lanes::F64s;
use crate::math::memory::ArraySize;
use crate::math::reduce::{fill_vector_and_update, update_vectors};
use crate::neighbours::Neighbours;
use crate::particles::{components, Kind, Particles};
use crate::solver::ppe::Role;
use crate::sph::{self, interface};

pub const NAME: &str = "corrector";

pub struct Corrector<const D: usize> {
    /// uⁿ⁺¹ of each fluid particle (copied into the particles).
    velocity: [Vec<f64>; D],
}

impl<const D: usize> Default for Corrector<D> {
    fn default() -> Self {
        Self {
            velocity: components(),
        }
    }
}

impl<const D: usize> Corrector<D> {
    /// uⁿ⁺¹ of the fluid particles from `u_star`, which then holds ∇Pⁿ⁺¹; `ghost` is the body
    /// force the wall ghosts carry where it is not gravity alone (`body_forces`). With α > 0,
    /// `density` is the density correction's P_α and the array its gradient goes into
    /// (`density_correction`, with mirror walls), summed in the same walk as ∇Pⁿ⁺¹.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        set: &StepSettings<D>,
        faces: &Faces,
        surface: &Surface<D>,
        interfaces: Option<interface::Field<D>>,
        ghost: Option<&[Vec<f64>; D]>,
        u_star: &mut [Vec<f64>; D],
        density: Option<(&[f64], &mut [Vec<f64>; D])>,
        dt: f64,
    ) -> &[Vec<f64>; D] {
        let n = surface.roles.len();
        for a in &mut self.velocity {
            a.resize(n, 0.0);
        }
        let touch = faces::touching_distance(set.spacing);
        let ghost = set.ghost_force(ghost);
        // Eq. (7), and no velocity into a wall face.
        let correct = |i: usize, u_star: [f64; D], grad: [f64; D]| {
            let rho0 = p.rest_density[i];
            let u = std::array::from_fn(|d| u_star[d] - dt * grad[d] / rho0);
            faces.no_penetration(p.position(i), u, touch)
        };
        match density {
            None => fill_vector_and_update(&mut self.velocity, u_star, |i, u_star| {
                let grad = pressure_gradient(nb, p, &p.pressure, surface, ghost, interfaces, i);
                (correct(i, u_star, grad), grad)
            }),
            Some((density_pressure, density_gradient)) => {
                for a in density_gradient.iter_mut() {
                    a.resize(n, 0.0);
                }
                let mirror = BodyForce::Uniform([0.0; D]);
                let fields = [(&p.pressure[..], ghost), (density_pressure, mirror)];
                update_vectors(
                    [&mut self.velocity, u_star, density_gradient],
                    |i, [_, u_star, _]| {
                        let [grad, grad_density] =
                            pressure_gradients(nb, p, fields, surface, interfaces, i);
                        [correct(i, u_star, grad), grad, grad_density]
                    },
                );
            }
        }
        &self.velocity
    }

    /// The velocity array, free once copied into the particles: the shifting's scratch.
    pub fn velocity_scratch(&mut self) -> &mut [Vec<f64>; D] {
        &mut self.velocity
    }
}

impl<const D: usize> Stage<D> for Corrector<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, set: &StepSettings<D>) -> String {
        format!(
            "Eq. (7): u = u* − (Δt/ρ0)∇P, ∇P {} with the walls as ghosts; no velocity into a wall face within half a spacing of it",
            if set.effects.kernel_correction { "corrected by L'_i (Eq. 20, 24–25)" } else { "of Eq. (20)" }
        )
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![ArraySize::of_components("velocity", &self.velocity)]
    }
}

/// ∇P_i of the fluid pressures `pressure` at fluid particle i with the gradient corrected by
/// `surface`'s pressure corrections (Eq. 20, 24–25), the differences taken from the pressure
/// reference of its role there (`pressure_reference`), and the walls
/// as ghosts of P_i (see `ghosts`) carrying the body force `ghost_force` (zero: mirror ghosts): a particle whose pressure exceeds p_ref is pushed off a wall it
/// presses on, but not out through a free surface; across the interface of two fluids
/// (`interfaces`, the distances to it) each difference is weighted by ρ0_i/ρ̄_ij
/// (`interface::Side::across`).
pub(super) fn pressure_gradient<const D: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    pressure: &[f64],
    surface: &Surface<D>,
    ghost_force: BodyForce<D>,
    interfaces: Option<interface::Field<D>>,
    i: usize,
) -> [f64; D] {
    let [grad] = pressure_gradients(nb, p, [(pressure, ghost_force)], surface, interfaces, i);
    grad
}

/// The gradients of `pressure_gradient` of K pressure fields, each with the body force its
/// wall ghosts carry, in one walk (`sph::gradients`): each with the bits of its own walk.
fn pressure_gradients<const D: usize, const K: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    fields: [(&[f64], BodyForce<D>); K],
    surface: &Surface<D>,
    interfaces: Option<interface::Field<D>>,
    i: usize,
) -> [[f64; D]; K] {
    let (role, full) = (surface.roles[i], surface.full_support[i]);
    let p_ref = pressure_references(nb, p, fields.map(|(pressure, _)| pressure), role, full, i)
        .map(F64s::splat);
    let l = surface.pressure_corrections.of(i);
    let side = interface::Side::of(p, interfaces, i);
    // A wall ghost mirrors P_i itself: P_b − p_ref = (P_i − p_ref) + (P_b − P_i).
    let own: [F64s; K] = std::array::from_fn(|k| F64s::splat(fields[k].0[i]) - p_ref[k]);
    let force = fields.map(|(_, ghost_force)| ghost_force.at(i));
    sph::gradients(nb, p, l, i, |lanes| match lanes.kind {
        Kind::Fluid | Kind::Body => {
            // One weight across an interface for the K fields (`Side::across`).
            let weight = side.weight(p, interfaces, lanes);
            std::array::from_fn(|k| {
                let difference = lanes.load(fields[k].0) - p_ref[k];
                weight.map_or(difference, |w| difference * w)
            })
        }
        Kind::Wall => std::array::from_fn(|k| {
            own[k] + ghosts::ghost_pressure_difference(p, force[k], i, lanes)
        }),
    })
}

/// The pressures (of each of the K fields `pressures`) at fluid particle i that its pressure
/// gradients take the differences P_j − P_i from, the K fits in one walk: P_i itself, but for
/// an unknown of the PPE with the free surface in its kernel support (`role` Interior, not
/// `full_support`) the value P̃_i of the linear function fitted to its fluid neighbours'
/// pressures (`sph::fitted_values`; P_i where they fix none).
/// Both are exact for a linear field. Where the surface truncates the support, the difference
/// form carries the term −P_i L'_i Σ_j V_j ∇W_ij, which points out of the fluid: a particle
/// whose pressure dips below its neighbours' is pushed towards the surface, and the projection
/// feeds the velocity that lowered its pressure. On the still tank of `hydrostatic_2d` the
/// step's velocity map, u ← u − (Δt/ρ0)∇P of the PPE of u, then amplifies a zig-zag of the row
/// under the surface (its largest eigenvalue at rest, by power iteration, exceeds 1), and the
/// tank sloshes; with P̃_i the largest eigenvalue is 1, the divergence-free fields'
/// (docs/stabilisation.md, "The pressure reference near the free surface").
fn pressure_references<const D: usize, const K: usize>(
    nb: &Neighbours<D>,
    p: &Particles<D>,
    pressures: [&[f64]; K],
    role: Role,
    full_support: bool,
    i: usize,
) -> [f64; K] {
    let own = pressures.map(|pressure| pressure[i]);
    if role == Role::Interior && !full_support {
        sph::fitted_values(nb, p, pressures, i).unwrap_or(own)
    } else {
        own
    }
}
