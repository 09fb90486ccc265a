//! isph: a stabilised incompressible SPH solver (Hassaballah, Aly & Abdelnaim 2020).
//!
//! A scene file becomes a [`scene::Scene`], whose particles ([`lattice`]) advance by the
//! projection step of [`simulation::Simulation`]; [`run`] drives a whole run with its output
//! and checkpoints, and continues one from a checkpoint ([`resume`]).

// Axis and tensor loops index several arrays by the same d (or a, b), as the equations do.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod child;
pub mod faces;
pub mod free_surface;
pub mod grid;
pub mod interface;
pub mod io;
pub mod kernel;
pub mod lanes;
pub mod lattice;
pub mod linsolve;
pub mod memory;
pub mod multigrid;
pub mod neighbours;
pub mod particles;
pub mod plan;
pub mod ppe;
pub mod progress;
pub mod reduce;
pub mod resume;
pub mod run;
pub mod scene;
pub mod shifting;
pub mod simulation;
pub mod sph;
pub mod step;
pub mod study;
pub mod timings;
pub mod turbulence;
pub mod validation;
pub mod vector;
pub mod wall;
