//! The pressure Poisson equation and its solution: the PPE's rows, source and matrix-free
//! operator (`ppe`, over the particles), and the linear algebra that solves it, which never
//! sees a particle: BiCGSTAB (`krylov`) preconditioned by aggregation multigrid (`multigrid`).

pub mod krylov;
pub mod multigrid;
pub mod ppe;
