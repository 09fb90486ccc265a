//! The container's walls and obstacles as the fluid sees them: the faces (their geometry,
//! the hard contact and the kinematic condition) and the ghost values a fluid particle reads
//! from a boundary particle in every operator; a moving container's frame and the body force
//! it adds.

pub mod faces;
pub mod ghosts;
pub mod moving_frame;
