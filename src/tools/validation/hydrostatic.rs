//! Still water in a tank: the pressure of the last frame against the hydrostatic
//! P = ρ0 |g| (H − y), H the top of the scene's first fluid block.
//!
//! The error is the rms over the fluid particles deeper than 15% of the water depth (the
//! surface layer carries the free-surface condition, not the hydrostatic value) of
//! (P − ρ0|g|(H − y)) / (ρ0|g|D), D the depth of the block. Details: the bottom pressure error
//! (the lowest row carried to the floor by its own hydrostatic gradient, over ρ0|g|D, minus 1)
//! and the largest `max_speed` of any step [m/s].

use super::{first_block, fluid, last_frame, vertical, Case, Measured, ValidationError};
use crate::io::stats::read_column;
use crate::scene::Scene;
use std::path::Path;

pub const DETAILS: [&str; 2] = ["bottom_pressure_error", "max_speed"];

/// Particles nearer the surface than this fraction of the depth are not compared.
const SURFACE_LAYER: f64 = 0.15;

/// A column of still water: weight ρ0|g| per metre, floor and surface heights.
#[derive(Clone, Copy, Debug)]
pub struct WaterColumn {
    pub rho_g: f64,
    pub floor: f64,
    pub top: f64,
}

impl WaterColumn {
    /// ρ0 |g| D: the pressure on the floor.
    pub fn floor_pressure(&self) -> f64 {
        self.rho_g * (self.top - self.floor)
    }

    /// The rms of (P − ρ0|g|(H − y)) / ρ0|g|D over the (height, pressure) samples below the
    /// surface layer; None when there is none.
    pub fn rms_error(&self, samples: &[(f64, f64)]) -> Option<f64> {
        let depth = self.top - self.floor;
        let errors: Vec<f64> = samples
            .iter()
            .filter(|(y, _)| self.top - y > SURFACE_LAYER * depth)
            .map(|(y, p)| (p - self.rho_g * (self.top - y)) / self.floor_pressure())
            .collect();
        (!errors.is_empty())
            .then(|| (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt())
    }

    /// The mean pressure of the samples less than `dx` above the floor, each carried down to
    /// the floor by the hydrostatic gradient, over ρ0|g|D, minus 1; None when there is none.
    pub fn bottom_error(&self, samples: &[(f64, f64)], dx: f64) -> Option<f64> {
        let bottom: Vec<f64> = samples
            .iter()
            .filter(|(y, _)| y - self.floor < dx)
            .map(|(y, p)| p + self.rho_g * (y - self.floor))
            .collect();
        (!bottom.is_empty())
            .then(|| bottom.iter().sum::<f64>() / bottom.len() as f64 / self.floor_pressure() - 1.0)
    }
}

pub fn measure(scene: &Scene, run_dir: &Path) -> Result<Measured, ValidationError> {
    let case = Case::Hydrostatic;
    let (v, g) = vertical(case, scene)?;
    let block = first_block(case, scene)?;
    let column = WaterColumn {
        rho_g: scene.fluids[block.fluid].density * g,
        floor: block.region.min[v],
        top: block.region.max[v],
    };
    let frame = last_frame(case, run_dir)?;
    let samples: Vec<(f64, f64)> = fluid(&frame)
        .map(|i| (frame.position[i][v], frame.pressure[i]))
        .collect();
    let missing = |what: &str| ValidationError::Run {
        case,
        dir: run_dir.to_owned(),
        message: format!(
            "its last frame (t = {} s) has no fluid particle {what}",
            frame.time
        ),
    };
    let error = column
        .rms_error(&samples)
        .ok_or_else(|| missing("below the surface layer"))?;
    let bottom = column
        .bottom_error(&samples, scene.spacing)
        .ok_or_else(|| missing("within one spacing of the floor"))?;
    let max_speed = read_column(run_dir, "max_speed")?
        .into_iter()
        .fold(0.0, f64::max);
    Ok(Measured::new(error, &DETAILS, &[bottom, max_speed]))
}
