//! Who is near whom: the cell list that sorts the particles by kind and cell, and the pair loop
//! over the neighbours within the kernel's support that every operator is built on.

pub mod cell_list;
mod pairs;

pub use pairs::{Lanes, Neighbours, RadialTerms};
