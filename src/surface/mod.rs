//! Water surfaces from particles (the paper's §3.3–3.4): a density lattice c(x) = Σ V_i D(x − x_i)
//! with one of the four kernels of Eq. (28)–(31), normalised so that c = 1 inside the fluid,
//! and its iso-surface by marching cubes (3D) or marching squares (2D).
//!
//! The pipeline, each stage naming what it reads and returning what it makes:
//! `lattice::Lattice::of` (the cube edge and the blocks near particles) → `density::sample`
//! (c at the lattice points of those blocks) → `marching_cubes::extract` /
//! `marching_squares::extract` (cells with vertices shared across cubes) →
//! `attributes::fill` (vertex normals and velocities). Everything is deterministic: blocks are
//! independent, and every sum runs in particle order, whatever the thread count.

mod attributes;
mod density;
mod extract;
pub mod kernels;
pub mod lattice;
pub mod mesh;
pub mod table;

pub use mesh::Mesh;

use crate::scene::SurfaceSettings;
use kernels::Kernel;
use lattice::Lattice;
use table::Table;

/// The fluid particles a surface is built from.
#[derive(Clone, Debug, Default)]
pub struct Points {
    /// 2 or 3.
    pub dimensions: usize,
    /// The particle spacing dx: the particles' volume is dx^D.
    pub spacing: f64,
    /// (x, y, z) of each particle; z = 0 in 2D.
    pub position: Vec<[f64; 3]>,
    pub velocity: Vec<[f64; 3]>,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SurfaceError {
    #[error("a cube edge of {edge} m over the particles' box {extent:?} m makes {cubes:.3e} cubes, more than the limit of {limit:.0e}: choose a larger cube size or fewer cubes")]
    TooManyCubes {
        edge: f64,
        extent: [f64; 3],
        cubes: f64,
        limit: f64,
    },
    #[error("a kernel of {radius} spacings over cubes of {cube} spacings would store {points:.3e} lattice points, more than the limit of {limit:.0e} (4 bytes each): choose larger cubes or a smaller radius")]
    TooManyPoints {
        radius: f64,
        cube: f64,
        points: f64,
        limit: f64,
    },
}

/// The surface of `points` (an empty mesh when there are none).
pub fn reconstruct(points: &Points, settings: &SurfaceSettings) -> Result<Mesh, SurfaceError> {
    match points.dimensions {
        2 => reconstruct_in::<2>(points, settings, &Table::squares()),
        3 => reconstruct_in::<3>(points, settings, &Table::cubes()),
        d => unreachable!("particles live in 2 or 3 dimensions, not {d}"),
    }
}

fn reconstruct_in<const D: usize>(
    points: &Points,
    settings: &SurfaceSettings,
    table: &Table<D>,
) -> Result<Mesh, SurfaceError> {
    if points.position.is_empty() {
        return Ok(Mesh {
            dimensions: D,
            ..Mesh::default()
        });
    }
    let kernel = Kernel::new(
        settings.kernel,
        settings.radius * points.spacing,
        points.spacing,
        D,
    );
    let edge = lattice::cube_edge::<D>(points, settings.cubes, kernel.support)?;
    let lattice = Lattice::<D>::of(points, edge, kernel.support);
    let stored = (lattice.valued.len() * lattice.points_per_block()) as f64;
    if stored > lattice::MAX_POINTS {
        return Err(SurfaceError::TooManyPoints {
            radius: settings.radius,
            cube: edge / points.spacing,
            points: stored,
            limit: lattice::MAX_POINTS,
        });
    }
    let values = density::sample(&lattice, points, &kernel);
    let surface = extract::extract(&lattice, &values, table, settings.iso);
    let velocity = attributes::velocities(
        &lattice,
        points,
        &kernel,
        &surface.positions,
        &surface.blocks,
        &surface.vertex_starts,
    );
    Ok(Mesh {
        dimensions: D,
        positions: surface
            .positions
            .iter()
            .map(|p| p.map(|c| c as f32))
            .collect(),
        normals: surface.normals,
        velocity,
        cells: surface.cells,
    })
}
