//! The mathematics every layer shares, which knows nothing of particles or scenes: small
//! vectors, SIMD lanes, thread-count-independent parallel loops and sums, the kernels (Eq. (19) and Wendland's),
//! the walk over lattice points, the sizes of arrays, rotations and the shapes of bodies.

pub(crate) mod aabb;
pub mod kernel;
pub mod lanes;
pub(crate) mod lattice;
pub mod memory;
pub mod mesh;
pub mod reduce;
pub mod rotation;
pub mod shape;
pub mod vector;
