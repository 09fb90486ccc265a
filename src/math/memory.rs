//! The sizes of per-particle arrays: what `isph plan` adds up per stage, and what the tests
//! compare with the arrays a step has actually allocated.

/// Which particles an array has an element for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Holds {
    /// Every particle, walls included.
    EveryParticle,
    /// The fluid particles only (they come first in the sorted order; the unknowns of the PPE).
    Fluid,
    /// Some particles only (those near the free surface, say): a list whose size depends on
    /// the state and is not known before a step.
    Some,
}

/// One per-particle (or per-fluid-particle) array.
#[derive(Clone, Debug, PartialEq)]
pub struct ArraySize {
    pub name: &'static str,
    /// Bytes per element: element size × components.
    pub bytes_per_element: usize,
    /// Elements it holds now (0: not allocated yet, or not used by this scene).
    pub len: usize,
    /// Bytes allocated now (capacity × element size, over its components).
    pub allocated: usize,
    pub holds: Holds,
}

impl ArraySize {
    /// A scalar array with an element per particle.
    pub fn of<T>(name: &'static str, v: &Vec<T>) -> Self {
        Self::of_components(name, std::slice::from_ref(v))
    }

    /// A vector field stored as one array per component, an element per particle.
    pub fn of_components<T>(name: &'static str, v: &[Vec<T>]) -> Self {
        let size = std::mem::size_of::<T>();
        Self {
            name,
            bytes_per_element: size * v.len(),
            len: v.first().map_or(0, Vec::len),
            allocated: v.iter().map(|c| c.capacity() * size).sum(),
            holds: Holds::EveryParticle,
        }
    }

    /// The same array, with an element per fluid particle only.
    pub fn fluid(self) -> Self {
        Self {
            holds: Holds::Fluid,
            ..self
        }
    }

    /// A list with an element for some particles only: its allocation counts, its size is not
    /// known before a step.
    pub fn sparse<T>(name: &'static str, v: &Vec<T>) -> Self {
        Self {
            holds: Holds::Some,
            ..Self::of(name, v)
        }
    }

    /// The elements the array holds in a scene of `particles` particles, `fluid` of them fluid
    /// (0 for a sparse list).
    pub fn elements(&self, particles: usize, fluid: usize) -> usize {
        match self.holds {
            Holds::EveryParticle => particles,
            Holds::Fluid => fluid,
            Holds::Some => 0,
        }
    }
}

/// The `field: n kB` line of a /proc file (`/proc/self/status`, `/proc/meminfo`) in bytes; the
/// error says why it could not be read.
pub fn proc_bytes(path: &str, field: &str) -> Result<u64, String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    text.lines()
        .find_map(|l| l.strip_prefix(field)?.strip_prefix(':'))
        .and_then(|v| v.trim().strip_suffix("kB"))
        .and_then(|v| v.trim().parse::<u64>().ok())
        .map(|kib| kib * 1024)
        .ok_or_else(|| format!("no `{field}: … kB` line"))
}
