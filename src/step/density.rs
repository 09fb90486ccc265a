//! Summation density and, where the fluids differ in rest density,
//! each fluid particle's distance to the nearest interface (`interface_distance`).

use super::interface_distance::InterfaceDistance;
use super::{Stage, StepSettings};
use crate::boundary::faces::Faces;
use crate::math::memory::ArraySize;
use crate::math::reduce::fill;
use crate::neighbours::Neighbours;
use crate::particles::Particles;
use crate::sph::{self, interface};

pub const NAME: &str = "density";

pub struct Density<const D: usize> {
    /// Summation density of the step (copied into the particles).
    density: Vec<f64>,
    /// With fluids of different rest density (None: one density).
    interfaces: Option<InterfaceDistance<D>>,
}

impl<const D: usize> Density<D> {
    /// `interfaces`: the kernel's table of distances to an interface, where the fluids differ.
    pub fn new(interfaces: Option<interface::Interfaces>) -> Self {
        Self {
            density: Vec::new(),
            interfaces: interfaces.map(InterfaceDistance::new),
        }
    }

    /// The summation density of the `nf` fluid particles (walls keep their rest density).
    pub fn run(&mut self, nb: &Neighbours<D>, p: &Particles<D>, nf: usize) -> &[f64] {
        self.density.resize(nf, 0.0);
        fill(&mut self.density, |i| sph::density(nb, p, i));
        &self.density
    }

    /// The interfaces' distances and normals, where the fluids differ in rest density.
    pub fn interfaces(
        &mut self,
        nb: &Neighbours<D>,
        p: &Particles<D>,
        faces: &Faces,
        nf: usize,
    ) -> Option<interface::Field<'_, D>> {
        let interfaces = self.interfaces.as_mut()?;
        Some(interfaces.run(nb, p, faces, nf))
    }
}

impl<const D: usize> Stage<D> for Density<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        match self.interfaces {
            Some(_) => "summation density ρ_i = ρ0_i Σ_j V_j W_ij (fluids of different density); each fluid particle's distance to the nearest interface and normal across it, from the other fluid's share of its kernel (the walls mirroring the fluid), for the pairs across it".into(),
            None => "summation density ρ_i = Σ_j m_j W_ij; walls keep ρ0".into(),
        }
    }

    fn arrays(&self) -> Vec<ArraySize> {
        let mut arrays = vec![ArraySize::of("density", &self.density)];
        arrays.extend(self.interfaces.iter().flat_map(InterfaceDistance::arrays));
        arrays
    }
}
