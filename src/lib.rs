//! isph: a stabilised incompressible SPH solver (Hassaballah, Aly & Abdelnaim 2020).
//!
//! A scene file becomes a [`Scene`]; [`fill`] puts its particles on the lattice, and they
//! advance by the projection step of `step` (one file per stage), which [`Simulation`] repeats;
//! [`run()`] drives a whole run with its output and checkpoints, and [`resume()`] continues one.
//!
//! The layers, lowest first (a module imports only from its own folder and the layers before
//! it; `tests/layering.rs` holds this): [`math`], [`scene`], [`particles`], [`bodies`], [`neighbours`],
//! [`boundary`], [`sph`], [`solver`], `effects`, [`fill`], [`surface`], [`io`], `step`,
//! [`simulation`], [`run`], [`render`], [`tools`].

// Axis and tensor loops index several arrays by the same d (or a, b), as the equations do.
#![allow(clippy::needless_range_loop)]

pub mod bodies;
pub mod boundary;
pub(crate) mod effects;
pub mod fill;
pub mod io;
pub mod math;
pub mod neighbours;
pub mod particles;
pub mod render;
pub mod run;
pub mod scene;
pub mod simulation;
pub mod solver;
pub mod sph;
pub(crate) mod step;
pub mod surface;
pub mod tools;

// The facade: what the command line (`main.rs`) and a program driving isph use.
pub use run::resume::ResumeOptions;
pub use run::{resume, run, RunError, RunOptions, RunSummary, StopSignal};
pub use scene::{Scene, SceneError};
pub use simulation::{NoFluid, NumericalFailure, Simulation};
pub use tools::child::RunReport;
pub use tools::plan::Plan;
pub use tools::{bench, study, validation};
