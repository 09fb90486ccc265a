//! The optional physics of the step, each switched by the scene's `[effects]`: particle
//! shifting, Eq. (9)–(10), and Smagorinsky LES with a log-law wall function, Eq. (3)–(4).

pub mod les;
pub mod shifting;
