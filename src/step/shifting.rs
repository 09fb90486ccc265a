//! Particle shifting δr = −D ∇C (Eq. 10, `effects::shifting`) at rⁿ, then velocity and
//! pressure carried to the shifted position by Eq. (9); the shift itself is the advection's.

use super::cavitation;
use super::free_surface::Surface;
use super::{Stage, StepSettings};
use crate::boundary::faces::{self, Faces};
use crate::effects::shifting as fickian;
use crate::math::lanes::Sum;
use crate::math::memory::ArraySize;
use crate::math::reduce;
use crate::neighbours::{Lanes, Neighbours};
use crate::particles::{components, Kind, Particles};
use crate::scene::ShiftingSettings;
use crate::solver::ppe::Role;
use crate::sph::{self, Corrections};
use rayon::prelude::*;

pub const NAME: &str = "shifting";

pub struct Shifting<const D: usize> {
    settings: ShiftingSettings,
    /// Shifting displacement δr of each fluid particle.
    shift: [Vec<f64>; D],
}

impl<const D: usize> Shifting<D> {
    pub fn new(settings: ShiftingSettings) -> Self {
        Self {
            settings,
            shift: components(),
        }
    }

    /// δr of the fluid particles plus `density` (the density correction's displacement, if
    /// any), and into `velocity` their velocity at the position so displaced (Eq. 9) from the
    /// velocity gradient (corrected by `corrections`). Returns that whole displacement.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        set: &StepSettings<D>,
        faces: &Faces,
        surface: &Surface<D>,
        corrections: Corrections<D>,
        velocity: &mut [Vec<f64>; D],
        density: Option<&[Vec<f64>; D]>,
        dt: f64,
    ) -> &[Vec<f64>; D] {
        let n = surface.roles.len();
        for a in &mut self.shift {
            a.resize(n, 0.0);
        }
        let max_speed = reduce::max(n, |i| p.speed(i));
        let shifting = fickian::Shifting::new(nb, &self.settings, set.spacing, max_speed, dt);
        let normals = surface
            .normals
            .expect("the free-surface stage keeps normals for shifting");
        let (roles, full) = (surface.roles, surface.full_support);
        let touch = faces::touching_distance(set.spacing);
        reduce::fill_vector_and_update(&mut self.shift, velocity, |i, u_i| {
            // A body's particles move rigidly (`rigid_bodies`): no shift; splashes are left in
            // place: ∇C means nothing there.
            let shifted = p.kind[i] != Kind::Body && roles[i] != Role::Splash;
            // Where the free surface is in reach the velocity gradient is no longer that of a
            // filled support, and shifting moves particles into the thinning, faster parts of a
            // stretching flow: the Taylor step there feeds the flow energy
            // (docs/stabilisation.md, "Near the free surface only: the divergence correction
            // and the Taylor step"). Where it runs, ∇C is summed in the same walk.
            let mut grad_c = [Sum::ZERO; D];
            let g = full[i].then(|| {
                let u = |l: &Lanes<D>| sph::fluid_velocity(p, u_i, l);
                let c = corrections.of(i);
                sph::velocity_gradient_and(nb, p, c, u_i, u, i, |l, vf| {
                    if shifted {
                        shifting.add_pairs(nb, l, vf, &mut grad_c)
                    }
                })
            });
            let own = if shifted {
                let dr = match g {
                    Some(_) => shifting.of_gradient(grad_c, normals[i], full[i]),
                    None => shifting.displacement(nb, p, normals[i], full[i], i),
                };
                faces.no_penetration(p.position(i), dr, touch)
            } else {
                [0.0; D]
            };
            let dr = match density {
                Some(x) => std::array::from_fn(|d| own[d] + x[d][i]),
                None => own,
            };
            let u = match g {
                Some(g) => {
                    std::array::from_fn(|a| u_i[a] + (0..D).map(|b| dr[b] * g[b][a]).sum::<f64>())
                }
                None => u_i,
            };
            (dr, u)
        });
        &self.shift
    }
}

/// The fluid pressures carried to the shifted positions by Eq. (9), P += ∇Pⁿ⁺¹·δr, with ∇Pⁿ⁺¹
/// at rⁿ as the corrector left it (the walls' pressures for a frame do not enter it); clipped
/// for cavitation as the solve's (`clip`, `roles`).
pub fn carry_pressure<const D: usize>(
    pressure: &mut [f64],
    grad_p: &[Vec<f64>; D],
    shift: &[Vec<f64>; D],
    clip: bool,
    roles: &[Role],
) {
    pressure.par_iter_mut().enumerate().for_each(|(i, p)| {
        let (g, dr) = (vector(grad_p, i), vector(shift, i));
        *p = cavitation(
            clip,
            roles[i],
            *p + (0..D).map(|d| g[d] * dr[d]).sum::<f64>(),
        );
    });
}

/// Component vector i of a SoA vector field.
#[inline]
fn vector<const D: usize>(a: &[Vec<f64>; D], i: usize) -> [f64; D] {
    std::array::from_fn(|d| a[d][i])
}

impl<const D: usize> Stage<D> for Shifting<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        let s = self.settings;
        format!(
            "Fickian shifting δr = −D∇C (Eq. 10), D = {} h U Δt, anti-clustering weight R = {}, each component at most {} dx, tangential at the free surface; u and P Taylor-corrected to the new position (Eq. 9)",
            s.coefficient, s.clustering_weight, s.max_shift
        )
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![ArraySize::of_components("δr", &self.shift)]
    }
}
