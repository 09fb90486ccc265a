//! Start-up Poiseuille flow: fluid at rest between two plates L apart (the walls of the one
//! bounded axis), periodic along the flow, driven from t = 0 by a body force F along a periodic
//! axis (the scene's gravity). Morris, Fox & Zhu (1997), Eq. (21):
//!
//!   u(y, t) = F y (L − y)/(2ν) − Σ_n 4FL²/(νπ³(2n+1)³) sin(π(2n+1)y/L) exp(−(2n+1)²π²νt/L²),
//!
//! y measured from one plate; steady centre velocity u_max = FL²/(8ν).
//!
//! The error is the rms over the fluid particles of the last frame of (u − u_exact)/u_max for
//! the velocity along the flow. Details: the largest |u − u_exact|/u_max, and the largest
//! velocity across the channel over u_max.

use super::{fluid, last_frame, unsuitable, Case, Measured, ValidationError};
use crate::scene::Scene;
use std::f64::consts::PI;
use std::path::Path;

pub const DETAILS: [&str; 2] = ["max_error", "cross_velocity"];

/// Terms of the series: the last one is below 1e-9 of the first.
const TERMS: usize = 400;

/// The channel: body force F [m/s²], width L [m], kinematic viscosity ν [m²/s], and the axes
/// of the flow and across the channel.
#[derive(Clone, Copy, Debug)]
pub struct Channel {
    pub force: f64,
    pub width: f64,
    pub viscosity: f64,
    pub flow: usize,
    pub across: usize,
}

impl Channel {
    /// The channel of `scene`: one bounded axis (the plates), every other axis periodic, and
    /// gravity (the driving force) along one periodic axis.
    pub fn of(scene: &Scene) -> Result<Channel, ValidationError> {
        let Some((flow, across)) = axes(scene) else {
            return Err(unsuitable(
                Case::Poiseuille,
                scene,
                "needs one bounded axis (the plates), every other axis periodic, and gravity (the driving force) along one periodic axis",
            ));
        };
        Ok(Channel {
            force: scene.gravity[flow].abs(),
            width: scene.container.max[across] - scene.container.min[across],
            viscosity: scene.fluids[0].viscosity,
            flow,
            across,
        })
    }

    /// The steady centre velocity F L²/(8ν).
    pub fn max_velocity(&self) -> f64 {
        self.force * self.width * self.width / (8.0 * self.viscosity)
    }

    /// u(y, t) of Morris et al. Eq. (21), y from the plate.
    pub fn velocity(&self, y: f64, t: f64) -> f64 {
        let (f, l, nu) = (self.force, self.width, self.viscosity);
        let steady = f * y * (l - y) / (2.0 * nu);
        let transient: f64 = (0..TERMS)
            .map(|n| {
                let m = (2 * n + 1) as f64;
                4.0 * f * l * l / (nu * PI.powi(3) * m.powi(3))
                    * (PI * m * y / l).sin()
                    * (-m * m * PI * PI * nu * t / (l * l)).exp()
            })
            .sum();
        steady - transient
    }
}

/// The flow axis (the one along gravity, periodic) and the channel axis (the one bounded axis).
fn axes(scene: &Scene) -> Option<(usize, usize)> {
    let dims = scene.dimensions;
    let forced: Vec<usize> = (0..dims).filter(|&d| scene.gravity[d] != 0.0).collect();
    let bounded: Vec<usize> = (0..dims).filter(|&d| !scene.periodic[d]).collect();
    match (&forced[..], &bounded[..]) {
        ([flow], [across]) if scene.periodic[*flow] => Some((*flow, *across)),
        _ => None,
    }
}

pub fn measure(scene: &Scene, run_dir: &Path) -> Result<Measured, ValidationError> {
    let case = Case::Poiseuille;
    let channel = Channel::of(scene)?;
    let (flow, across) = (channel.flow, channel.across);
    let frame = last_frame(case, run_dir)?;
    let u_max = channel.max_velocity();
    let sign = scene.gravity[flow].signum();
    let (mut square, mut worst, mut cross, mut count) = (0.0, 0.0_f64, 0.0_f64, 0);
    for i in fluid(&frame) {
        let y = frame.position[i][across] - scene.container.min[across];
        let error = (sign * frame.velocity[i][flow] - channel.velocity(y, frame.time)) / u_max;
        square += error * error;
        worst = worst.max(error.abs());
        cross = cross.max(frame.velocity[i][across].abs() / u_max);
        count += 1;
    }
    Ok(Measured::new(
        (square / count as f64).sqrt(),
        &DETAILS,
        &[worst, cross],
    ))
}
