//! Stokes flow through a square array of cylinders: one fixed circle in a square 2D box
//! periodic along both axes, the fluid driven by a body force g along an axis (the scene's
//! gravity). The same flow as under a mean pressure gradient ρ0 g, whose force on each
//! cylinder of an array of period L is ρ0 g L²; Sangani & Acrivos (1982) give it as the
//! dimensionless drag K = ρ0 g L²/(μ U), U the superficial velocity (the flow rate over the
//! box's width, the cylinders counted: Darcy's), as a function of the solid fraction
//! Φ = πa²/L². Their Table 1, computed from a multipole series, is the reference; between its
//! rows, K is their small-Φ series (Hasimoto's with their corrections),
//!
//!   K_s = 4π / (−½ ln Φ − 0.738 + Φ − 0.887 Φ² + 2.038 Φ³),
//!
//! times the table's ratio to it, interpolated linearly in Φ (1.0004 at Φ = 0.05, 1.015 at 0.2,
//! 1.14 at 0.3).
//!
//! The error is K of the last frame over the reference, less 1. U is the mean over the box of
//! the velocity along the force: each fluid particle holds dx² of the box, the body's particles
//! none. Details: K itself, the reference, Φ of the circle and Φ of the
//! body's lattice points.

use super::{last_frame, unsuitable, Case, Measured, ValidationError};
use crate::particles::Kind;
use crate::scene::{BodyMotion, Scene, Shape};
use std::f64::consts::PI;
use std::path::Path;

pub const DETAILS: [&str; 4] = ["drag", "reference", "solid_fraction", "lattice_fraction"];

/// Sangani & Acrivos (1982), Table 1: Φ and K = F/(μU) of a square array.
const TABLE: [(f64, f64); 9] = [
    (0.05, 15.56),
    (0.10, 24.83),
    (0.20, 51.53),
    (0.30, 102.90),
    (0.40, 217.89),
    (0.50, 532.55),
    (0.60, 1.763e3),
    (0.70, 1.352e4),
    (0.75, 1.263e5),
];

/// The array's cell: its side L, the solid fraction Φ, the body force g along axis `flow`,
/// and the fluid's kinematic viscosity ν.
#[derive(Clone, Copy, Debug)]
pub struct Cell {
    pub side: f64,
    pub solid_fraction: f64,
    pub force: f64,
    pub flow: usize,
    pub viscosity: f64,
}

impl Cell {
    /// The cell of `scene`: 2D, a square box periodic along both axes, one fluid, one fixed
    /// circular body of solid fraction within the table's range, gravity along one axis.
    pub fn of(scene: &Scene) -> Result<Cell, ValidationError> {
        let refuse = |message: &str| Err(unsuitable(Case::CylinderArray, scene, message));
        let (c, dims) = (&scene.container, scene.dimensions);
        let side = c.max[0] - c.min[0];
        if dims != 2
            || !scene.periodic.iter().all(|&p| p)
            || (c.max[1] - c.min[1] - side).abs() > 1e-9 * side
        {
            return refuse("needs a 2D container that is square and periodic along both axes");
        }
        let forced: Vec<usize> = (0..dims).filter(|&d| scene.gravity[d] != 0.0).collect();
        let [flow] = forced[..] else {
            return refuse("needs gravity (the driving force) along one axis");
        };
        let radius = match &scene.bodies[..] {
            [body] => match (&body.shape, &body.motion) {
                (Shape::Ball { radius, .. }, BodyMotion::Fixed) => *radius,
                _ => return refuse("needs its body to be a fixed circle"),
            },
            _ => return refuse("needs one body, the cylinder"),
        };
        if scene.fluids.len() != 1 {
            return refuse("needs one fluid");
        }
        let solid_fraction = PI * radius * radius / (side * side);
        let (lo, hi) = (TABLE[0].0, TABLE[TABLE.len() - 1].0);
        if !(lo..=hi).contains(&solid_fraction) {
            return refuse(&format!(
                "its circle fills {solid_fraction:.4} of the box, outside the reference's {lo} … {hi}"
            ));
        }
        Ok(Cell {
            side,
            solid_fraction,
            force: scene.gravity[flow].abs(),
            flow,
            viscosity: scene.fluids[0].viscosity,
        })
    }

    /// K = ρ0 g L²/(μ U) = g L²/(ν U) of a flow of superficial velocity `u`.
    pub fn drag(&self, u: f64) -> f64 {
        self.force * self.side * self.side / (self.viscosity * u)
    }
}

/// Sangani & Acrivos's small-Φ series of K.
fn series(phi: f64) -> f64 {
    4.0 * PI / (-0.5 * phi.ln() - 0.738 + phi - 0.887 * phi * phi + 2.038 * phi.powi(3))
}

/// K of Sangani & Acrivos at solid fraction Φ within the table's range.
pub fn reference_drag(phi: f64) -> f64 {
    let k = TABLE
        .windows(2)
        .position(|w| phi <= w[1].0)
        .unwrap_or(TABLE.len() - 2);
    let ((p0, k0), (p1, k1)) = (TABLE[k], TABLE[k + 1]);
    let (r0, r1) = (k0 / series(p0), k1 / series(p1));
    series(phi) * (r0 + (r1 - r0) * (phi - p0) / (p1 - p0))
}

pub fn measure(scene: &Scene, run_dir: &Path) -> Result<Measured, ValidationError> {
    let cell = Cell::of(scene)?;
    let frame = last_frame(Case::CylinderArray, run_dir)?;
    let area = scene.spacing * scene.spacing;
    let sign = scene.gravity[cell.flow].signum();
    let (mut flow, mut body) = (0.0, 0usize);
    for i in 0..frame.kind.len() {
        if frame.kind[i] == Kind::Fluid as i32 {
            flow += sign * frame.velocity[i][cell.flow] * area;
        } else if frame.kind[i] == Kind::Body as i32 {
            body += 1;
        }
    }
    let box_area = cell.side * cell.side;
    let drag = cell.drag(flow / box_area);
    let reference = reference_drag(cell.solid_fraction);
    Ok(Measured::new(
        drag / reference - 1.0,
        &DETAILS,
        &[
            drag,
            reference,
            cell.solid_fraction,
            body as f64 * area / box_area,
        ],
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_runs_through_the_table_and_follows_the_series_at_small_fractions() {
        for (phi, k) in TABLE {
            assert!((reference_drag(phi) / k - 1.0).abs() < 1e-12, "Φ = {phi}");
        }
        // Below 0.1 the series is the table within 0.1%.
        assert!((series(0.05) / 15.56 - 1.0).abs() < 1e-3);
        assert!((series(0.1) / 24.83 - 1.0).abs() < 1e-3);
        let mid = reference_drag(0.15);
        assert!(mid > 24.83 && mid < 51.53 && (mid / series(0.15) - 1.0).abs() < 0.01);
    }
}
