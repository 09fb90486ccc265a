//! Advection, Eq. (8): rⁿ⁺¹ = rⁿ + Δt uⁿ⁺¹ + δr, δr the density correction's and the
//! shifting's displacements (either may be off), then the hard contact with
//! the wall faces (`Faces::contact`) for the particles the walls' pressure did not stop.

use super::{Stage, StepSettings};
use crate::boundary::faces::{Contact, Faces};
use crate::particles::Particles;
use rayon::prelude::*;

pub const NAME: &str = "advection";

pub struct Advection;

impl Advection {
    /// Moves the `nf` fluid particles over `dt` (plus `shift`, the displacement of the density
    /// correction and the shifting, if either runs), then puts those
    /// that crossed a wall face back a quarter spacing inside (at rest the fluid sits half a
    /// spacing off the faces). Returns how many crossed: the penetrations of `stats.csv`.
    pub fn run<const D: usize>(
        &self,
        p: &mut Particles<D>,
        nf: usize,
        dt: f64,
        shift: Option<&[Vec<f64>; D]>,
        faces: &Faces,
        spacing: f64,
    ) -> usize {
        for d in 0..D {
            let vel = &p.vel[d];
            let shift = shift.map(|s| &s[d]);
            p.pos[d][..nf]
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, x)| {
                    let s = shift.map_or(0.0, |s| s[i]);
                    *x += dt * vel[i] + s;
                });
        }
        keep_off_the_faces(p, faces, 0.25 * spacing)
    }
}

/// `Faces::contact` for every fluid particle, `gap` off the faces; returns the penetrations.
fn keep_off_the_faces<const D: usize>(p: &mut Particles<D>, faces: &Faces, gap: f64) -> usize {
    let mut penetrations = 0;
    for i in 0..p.len() {
        if !p.is_fluid(i) {
            continue;
        }
        let (mut x, mut u) = (p.position(i), p.velocity(i));
        match faces.contact(gap, &mut x, &mut u) {
            Contact::Clear => continue,
            Contact::Near => {}
            Contact::Crossed => penetrations += 1,
        }
        for d in 0..D {
            (p.pos[d][i], p.vel[d][i]) = (x[d], u[d]);
        }
    }
    penetrations
}

impl<const D: usize> Stage<D> for Advection {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, set: &StepSettings<D>) -> String {
        format!(
            "Eq. (8): r += Δt u{}; a particle that crossed a wall face is put back a quarter spacing inside (counted in penetrations)",
            if set.effects.shifting.is_some() || set.alpha > 0.0 { " + δr" } else { "" }
        )
    }
}
