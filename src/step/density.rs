//! Summation density, with each fluid particle's distance to its nearest neighbour from the
//! same walk (for the disorder of `stats.csv`, `diagnostics`), and, where the fluids differ in
//! rest density, each fluid particle's distance to the nearest interface (`interface_distance`).

use super::interface_distance::InterfaceDistance;
use super::{Stage, StepSettings};
use crate::boundary::faces::Faces;
use crate::math::memory::ArraySize;
use crate::math::reduce::fill_pair;
use crate::neighbours::Neighbours;
use crate::particles::Particles;
use crate::sph::{self, interface};

pub const NAME: &str = "density";

pub struct Density<const D: usize> {
    /// Summation density of the step (copied into the particles).
    density: Vec<f64>,
    /// Distance to the nearest neighbour.
    nearest: Vec<f64>,
    /// With fluids of different rest density (None: one density).
    interfaces: Option<InterfaceDistance<D>>,
}

impl<const D: usize> Density<D> {
    /// `interfaces`: the kernel's table of distances to an interface, where the fluids differ.
    pub fn new(interfaces: Option<interface::Interfaces>) -> Self {
        Self {
            density: Vec::new(),
            nearest: Vec::new(),
            interfaces: interfaces.map(InterfaceDistance::new),
        }
    }

    /// The summation density of the `nf` fluid particles (walls keep their rest density), the
    /// distances to their nearest neighbours and, where the fluids differ, to the interfaces.
    pub fn run(&mut self, nb: &Neighbours<D>, p: &Particles<D>, faces: &Faces, nf: usize) {
        self.density.resize(nf, 0.0);
        self.nearest.resize(nf, 0.0);
        fill_pair(&mut self.density, &mut self.nearest, |i| {
            let (density, nearest) = sph::density_and_nearest(nb, p, i);
            [density, nearest]
        });
        if let Some(interfaces) = &mut self.interfaces {
            interfaces.run(nb, p, faces, nf);
        }
    }

    /// The summation density of the last `run`.
    pub fn density(&self) -> &[f64] {
        &self.density
    }

    /// Each fluid particle's distance to its nearest neighbour, from the last `run`.
    pub fn nearest(&self) -> &[f64] {
        &self.nearest
    }

    /// The interfaces' distances and normals of the last `run`, where the fluids differ in
    /// rest density.
    pub fn interfaces(&self) -> Option<interface::Field<'_, D>> {
        self.interfaces.as_ref().map(InterfaceDistance::field)
    }
}

impl<const D: usize> Stage<D> for Density<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        match self.interfaces {
            Some(_) => "summation density ρ_i = ρ0_i Σ_j V_j W_ij (fluids of different density); the distance to the nearest neighbour (the disorder in stats.csv); each fluid particle's distance to the nearest interface and normal across it, from the other fluid's share of its kernel (the walls mirroring the fluid), for the pairs across it".into(),
            None => "summation density ρ_i = Σ_j m_j W_ij; walls keep ρ0; the distance to the nearest neighbour (the disorder in stats.csv)".into(),
        }
    }

    fn arrays(&self) -> Vec<ArraySize> {
        let mut arrays = vec![
            ArraySize::of("density", &self.density),
            ArraySize::of("nearest neighbour", &self.nearest),
        ];
        arrays.extend(self.interfaces.iter().flat_map(InterfaceDistance::arrays));
        arrays
    }
}
