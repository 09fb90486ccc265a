//! Where the fluids differ in rest density, each fluid particle's distance to the nearest
//! interface and normal across it (`sph::interface`): the PPE rows and the pressure gradient
//! weigh the pairs across it.

use super::{Stage, StepSettings};
use crate::boundary::faces::Faces;
use crate::math::memory::ArraySize;
use crate::math::reduce::fill_scalar_and_vector;
use crate::math::vector::unit;
use crate::neighbours::Neighbours;
use crate::particles::{components, Particles};
use crate::sph::interface::{self, Interfaces};

pub const NAME: &str = "interface distance";

pub struct InterfaceDistance<const D: usize> {
    /// The kernel's table of distances to an interface.
    table: Interfaces,
    distance: Vec<f64>,
    normal: [Vec<f64>; D],
}

impl<const D: usize> InterfaceDistance<D> {
    pub fn new(table: Interfaces) -> Self {
        Self {
            table,
            distance: Vec::new(),
            normal: components(),
        }
    }

    /// The distances and normals of the `nf` fluid particles, from the other fluid's share of
    /// each kernel, the container's faces mirroring the fluid.
    pub fn run(&mut self, nb: &Neighbours<D>, p: &Particles<D>, faces: &Faces, nf: usize) {
        let support = nb.kernel.support();
        self.distance.resize(nf, 0.0);
        for n in &mut self.normal {
            n.resize(nf, 0.0);
        }
        let table = &self.table;
        fill_scalar_and_vector(&mut self.distance, &mut self.normal, |i| {
            let mirrors = faces.container_faces_within(p.position(i), support);
            let (share, gradient) = interface::other_fluid_share(nb, p, mirrors, i);
            (table.distance(share), unit(gradient))
        });
    }

    /// The distances and normals of the last `run`.
    pub fn field(&self) -> interface::Field<'_, D> {
        interface::Field {
            distance: &self.distance,
            normal: &self.normal,
        }
    }
}

impl<const D: usize> Stage<D> for InterfaceDistance<D> {
    fn name(&self) -> &'static str {
        NAME
    }

    fn describe(&self, _: &StepSettings<D>) -> String {
        "each fluid particle's distance to the nearest interface between fluids of different rest density and the normal across it, from the other fluid's share of its kernel (the walls mirroring the fluid), for the pairs across it".into()
    }

    fn arrays(&self) -> Vec<ArraySize> {
        vec![
            ArraySize::of("interface distance", &self.distance),
            ArraySize::of_components("interface normal", &self.normal),
        ]
    }
}
