//! Particle storage: structure of arrays, one `Vec` per component, permuted together
//! whenever the particles are re-sorted by cell. `id` is stable across sorts.

use crate::math::reduce;

/// What a particle is (the `kind` column of the output).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Kind {
    Fluid = 0,
    /// Fixed dummy wall particle (container walls and obstacles).
    Wall = 1,
    /// A particle of a rigid body (`bodies`): sorted and paired as fluid, since the pressure
    /// solve treats it as fluid of the body's density (Eq. 11–16), then moved rigidly.
    Body = 2,
}

impl Kind {
    /// The kind the cell sort groups the particle with (`cell_list::KINDS`): a body's
    /// particles go with the fluid, whose operators they take part in.
    #[inline]
    pub fn sorted_as(self) -> Kind {
        match self {
            Kind::Fluid | Kind::Body => Kind::Fluid,
            Kind::Wall => Kind::Wall,
        }
    }

    /// The kind whose `as u8` code is `code` (how checkpoints store it).
    pub fn from_code(code: u8) -> Option<Kind> {
        [Kind::Fluid, Kind::Wall, Kind::Body]
            .into_iter()
            .find(|k| *k as u8 == code)
    }
}

/// `fluid` index stored for particles that belong to no fluid (walls).
pub const NO_FLUID: u16 = u16::MAX;

#[derive(Clone, Debug)]
pub struct Particles<const D: usize> {
    pub pos: [Vec<f64>; D],
    pub vel: [Vec<f64>; D],
    /// Unit normal of the wall at a wall particle, pointing into the fluid; at a body's
    /// particle its body's outward surface normal (`bodies::SurfacePoint`), for the no-slip of
    /// the viscous term; zero for fluid.
    pub normal: [Vec<f64>; D],
    pub pressure: Vec<f64>,
    /// Summation density ρ_i = Σ_j m_j W_ij (fluid); the rest density for walls.
    pub density: Vec<f64>,
    pub mass: Vec<f64>,
    /// ρ0 of the particle's fluid (walls: the reference density of the first fluid).
    pub rest_density: Vec<f64>,
    /// Kinematic viscosity ν of the particle's fluid (walls: 0, they take the fluid's ν).
    pub viscosity: Vec<f64>,
    pub kind: Vec<Kind>,
    /// How the last pressure solve saw the particle (0 interior or wall, 1 free surface,
    /// 2 splash): written to the frames for inspection, not used by the step.
    pub free_surface: Vec<u8>,
    /// The thickness across the free surface of a free-surface particle's volume, relative to
    /// the particle spacing dx: the surface lies half of it beyond the particle's centre
    /// (`step::surface_thickness`). 1 for every other particle.
    pub surface_thickness: Vec<f64>,
    /// The index of a fluid particle's fluid in the scene, of a body particle's body; NO_FLUID
    /// for walls.
    pub fluid: Vec<u16>,
    pub id: Vec<u64>,
}

/// One per-particle array of `Particles::arrays_mut`, by element type.
pub enum ArrayMut<'a> {
    F64(&'a mut Vec<f64>),
    U64(&'a mut Vec<u64>),
    U16(&'a mut Vec<u16>),
    U8(&'a mut Vec<u8>),
    Kind(&'a mut Vec<Kind>),
}

impl ArrayMut<'_> {
    /// Bytes per particle of the array.
    pub fn element_bytes(&self) -> usize {
        match self {
            ArrayMut::F64(_) => size_of::<f64>(),
            ArrayMut::U64(_) => size_of::<u64>(),
            ArrayMut::U16(_) => size_of::<u16>(),
            ArrayMut::U8(_) => size_of::<u8>(),
            ArrayMut::Kind(_) => size_of::<Kind>(),
        }
    }
}

/// Everything needed to create one particle.
#[derive(Clone, Copy, Debug)]
pub struct NewParticle<const D: usize> {
    pub pos: [f64; D],
    pub kind: Kind,
    /// Wall normal (walls only).
    pub normal: [f64; D],
    pub fluid: u16,
    pub mass: f64,
    pub rest_density: f64,
    pub viscosity: f64,
}

/// D empty component vectors.
pub fn components<const D: usize>() -> [Vec<f64>; D] {
    std::array::from_fn(|_| Vec::new())
}

impl<const D: usize> Default for Particles<D> {
    fn default() -> Self {
        Self {
            pos: components(),
            vel: components(),
            normal: components(),
            pressure: Vec::new(),
            density: Vec::new(),
            mass: Vec::new(),
            rest_density: Vec::new(),
            viscosity: Vec::new(),
            kind: Vec::new(),
            free_surface: Vec::new(),
            surface_thickness: Vec::new(),
            fluid: Vec::new(),
            id: Vec::new(),
        }
    }
}

impl<const D: usize> Particles<D> {
    pub fn len(&self) -> usize {
        self.id.len()
    }

    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }

    /// Appends a particle at rest with zero pressure; its id is its creation index.
    pub fn push(&mut self, p: NewParticle<D>) {
        for d in 0..D {
            self.pos[d].push(p.pos[d]);
            self.vel[d].push(0.0);
            self.normal[d].push(p.normal[d]);
        }
        self.id.push(self.id.len() as u64);
        self.pressure.push(0.0);
        self.density.push(p.rest_density);
        self.mass.push(p.mass);
        self.rest_density.push(p.rest_density);
        self.viscosity.push(p.viscosity);
        self.kind.push(p.kind);
        self.free_surface.push(0);
        self.surface_thickness.push(1.0);
        self.fluid.push(p.fluid);
    }

    #[inline]
    pub fn position(&self, i: usize) -> [f64; D] {
        std::array::from_fn(|d| self.pos[d][i])
    }

    #[inline]
    pub fn velocity(&self, i: usize) -> [f64; D] {
        std::array::from_fn(|d| self.vel[d][i])
    }

    #[inline]
    pub fn wall_normal(&self, i: usize) -> [f64; D] {
        std::array::from_fn(|d| self.normal[d][i])
    }

    /// |u_i|.
    #[inline]
    pub fn speed(&self, i: usize) -> f64 {
        (0..D)
            .map(|d| self.vel[d][i] * self.vel[d][i])
            .sum::<f64>()
            .sqrt()
    }

    /// The largest speed of the fluid and body particles (thread-count independent).
    pub fn max_fluid_speed(&self) -> f64 {
        reduce::max(self.len(), |i| {
            if self.kind[i] != Kind::Wall {
                self.speed(i)
            } else {
                0.0
            }
        })
    }

    #[inline]
    pub fn is_fluid(&self, i: usize) -> bool {
        self.kind[i] == Kind::Fluid
    }

    pub fn fluid_count(&self) -> usize {
        self.kind.iter().filter(|&&k| k == Kind::Fluid).count()
    }

    /// Every per-particle array under a stable name: position_x, …, id. `permute` and the
    /// checkpoints walk this one list, so an array added to `Particles` is re-sorted and saved
    /// once it is listed here; the exhaustive destructuring below makes forgetting it a compile
    /// error.
    pub fn arrays_mut(&mut self) -> Vec<(&'static str, ArrayMut<'_>)> {
        let Particles {
            pos,
            vel,
            normal,
            pressure,
            density,
            mass,
            rest_density,
            viscosity,
            kind,
            free_surface,
            surface_thickness,
            fluid,
            id,
        } = self;
        let vectors = [
            (pos, ["position_x", "position_y", "position_z"]),
            (vel, ["velocity_x", "velocity_y", "velocity_z"]),
            (normal, ["normal_x", "normal_y", "normal_z"]),
        ];
        let mut arrays = Vec::with_capacity(3 * D + 10);
        for (v, names) in vectors {
            for (name, component) in names.into_iter().zip(v.iter_mut()) {
                arrays.push((name, ArrayMut::F64(component)));
            }
        }
        arrays.extend([
            ("pressure", ArrayMut::F64(pressure)),
            ("density", ArrayMut::F64(density)),
            ("mass", ArrayMut::F64(mass)),
            ("rest_density", ArrayMut::F64(rest_density)),
            ("viscosity", ArrayMut::F64(viscosity)),
            ("kind", ArrayMut::Kind(kind)),
            ("free_surface", ArrayMut::U8(free_surface)),
            ("surface_thickness", ArrayMut::F64(surface_thickness)),
            ("fluid", ArrayMut::U16(fluid)),
            ("id", ArrayMut::U64(id)),
        ]);
        arrays
    }

    /// Reorders every array so that new index k holds old particle `order[k]`.
    pub fn permute(&mut self, order: &[u32], scratch: &mut Vec<f64>) {
        for (_, array) in self.arrays_mut() {
            match array {
                ArrayMut::F64(a) => permute_with(a, order, scratch),
                ArrayMut::U64(a) => *a = gathered(a, order),
                ArrayMut::U16(a) => *a = gathered(a, order),
                ArrayMut::U8(a) => *a = gathered(a, order),
                ArrayMut::Kind(a) => *a = gathered(a, order),
            }
        }
    }

    /// Index of each id: `index_of_id[id] = i` (for writing frames in id order).
    pub fn index_by_id(&self) -> Vec<u32> {
        let mut by_id = vec![0u32; self.len()];
        for (i, &id) in self.id.iter().enumerate() {
            by_id[id as usize] = i as u32;
        }
        by_id
    }
}

/// a[order] as a new vector.
fn gathered<T: Copy>(a: &[T], order: &[u32]) -> Vec<T> {
    order.iter().map(|&o| a[o as usize]).collect()
}

/// a ← a[order], through a reusable scratch buffer.
fn permute_with(a: &mut Vec<f64>, order: &[u32], scratch: &mut Vec<f64>) {
    scratch.clear();
    scratch.extend(order.iter().map(|&o| a[o as usize]));
    std::mem::swap(a, scratch);
}
