//! The sizes of per-particle arrays: what `isph plan` adds up per stage, and what the tests
//! compare with the arrays a step has actually allocated.

/// One per-particle (or per-unknown) array.
#[derive(Clone, Debug, PartialEq)]
pub struct ArraySize {
    pub name: &'static str,
    /// Bytes per particle: element size × components.
    pub bytes_per_particle: usize,
    /// Particles it holds now (0: not allocated yet, or not used by this scene).
    pub len: usize,
    /// Bytes allocated now (capacity × element size, over its components).
    pub allocated: usize,
    /// One element per particle; false for a list of some particles only (`sparse`), whose
    /// size depends on the state and is not in `bytes_per_particle`.
    pub per_particle: bool,
}

impl ArraySize {
    /// A scalar array.
    pub fn of<T>(name: &'static str, v: &Vec<T>) -> Self {
        Self::of_components(name, std::slice::from_ref(v))
    }

    /// A vector field stored as one array per component.
    pub fn of_components<T>(name: &'static str, v: &[Vec<T>]) -> Self {
        let size = std::mem::size_of::<T>();
        Self {
            name,
            bytes_per_particle: size * v.len(),
            len: v.first().map_or(0, Vec::len),
            allocated: v.iter().map(|c| c.capacity() * size).sum(),
            per_particle: true,
        }
    }

    /// A list with an element for some particles only (those near the free surface, say): its
    /// allocation counts, its size per particle is not known before a step.
    pub fn sparse<T>(name: &'static str, v: &Vec<T>) -> Self {
        Self {
            bytes_per_particle: 0,
            per_particle: false,
            ..Self::of(name, v)
        }
    }
}
