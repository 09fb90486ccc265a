//! One integration-test binary (habit 7 of STYLE.md): physics, numerics, output and bad input.

// Matrix and axis loops index several arrays by the same index, as the equations do.
#![allow(clippy::needless_range_loop)]

mod common;

mod bad_input;
mod bench;
mod bodies;
mod checkpoint;
mod dam_break;
mod determinism;
mod effects;
mod frame_times;
mod free_surface;
mod hydrostatic;
mod interface;
mod kernel;
mod krylov;
mod layering;
mod moving_container;
mod neighbours;
mod operators;
mod output_readers;
mod periodic_flows;
mod probes;
mod render;
mod simd;
mod stability;
mod study;
mod surface;
mod surface_runs;
mod two_fluids;
mod validation;
mod wall_contact;
mod waves;
