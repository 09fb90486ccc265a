//! The container's walls and obstacles as the fluid sees them: the faces (their geometry,
//! the hard contact and the kinematic condition) and the ghost values a fluid particle reads
//! from a boundary particle in every operator.

pub mod faces;
pub(crate) mod ghosts;
