//! The 2D Taylor–Green vortex of a periodic square of side L (`[initial_velocity]
//! field = "taylor_green"`): the exact solution decays in shape, its velocity as exp(−8π²νt/L²)
//! and its kinetic energy as the square of that.
//!
//! The error is the relative error of the velocity decay rate, fitted by least squares to
//! ½ ln E(t) of every step in stats.csv (E the kinetic energy), against 8π²ν/L². Details: that
//! fitted rate [1/s], and the L2 error of the velocity field of the last frame against the
//! exact field, relative to the exact field's L2 norm: at the particles' positions, and at the
//! midpoint of their last drift.
//!
//! The projection makes a step's velocity divergence-free at the midpoint of the drift it moves
//! the particles by (`ppe::divergence_source`), and the particles keep it over the whole drift:
//! the field a frame holds is the one of the particles' places half a drift back, r − (Δt/2) u
//! (its viscous decay is the whole step's). In a vortex a particle's velocity turns along its
//! path, so read at the frame's positions it lags by (Δt/2) |Du/Dt|, an error first order in
//! the last step's Δt; read at the midpoint of the drift, what remains is the flow's own error
//! (docs/accuracy.md, "What a frame reads of the last steps").

use super::{fluid, last_frame, unsuitable, Case, Measured, ValidationError};
use crate::io::stats::read_column;
use crate::scene::{InitialVelocity, Scene};
use std::f64::consts::PI;
use std::path::Path;

pub const DETAILS: [&str; 3] = [
    "decay_rate",
    "velocity_l2_error",
    "velocity_l2_error_mid_drift",
];

/// The velocity decay rate 8π²ν/L² [1/s] of the vortex of side L.
pub fn decay_rate(viscosity: f64, side: f64) -> f64 {
    8.0 * PI * PI * viscosity / (side * side)
}

/// The least-squares slope of y against t.
pub fn slope(t: &[f64], y: &[f64]) -> f64 {
    let n = t.len() as f64;
    let (mt, my) = (t.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let cov: f64 = t.iter().zip(y).map(|(t, y)| (t - mt) * (y - my)).sum();
    let var: f64 = t.iter().map(|t| (t - mt) * (t - mt)).sum();
    cov / var
}

/// The vortex of a scene: its initial field and the exact decay rate.
#[derive(Clone, Copy, Debug)]
pub struct Vortex {
    pub field: InitialVelocity,
    /// 8π²ν/L² [1/s].
    pub rate: f64,
}

impl Vortex {
    /// The vortex of `scene`, which needs `[initial_velocity] field = "taylor_green"` and a
    /// viscous fluid.
    pub fn of(scene: &Scene) -> Result<Vortex, ValidationError> {
        let scene_error = |message: &str| unsuitable(Case::TaylorGreen, scene, message);
        let Some(field @ InitialVelocity::TaylorGreen { .. }) = scene.initial_velocity else {
            return Err(scene_error(
                "has no `[initial_velocity] field = \"taylor_green\"`",
            ));
        };
        let nu = scene.fluids[0].viscosity;
        if nu <= 0.0 {
            return Err(scene_error(
                "has an inviscid fluid: the vortex does not decay",
            ));
        }
        let side = scene.container.max[0] - scene.container.min[0];
        Ok(Vortex {
            field,
            rate: decay_rate(nu, side),
        })
    }
}

pub fn measure(scene: &Scene, run_dir: &Path) -> Result<Measured, ValidationError> {
    let case = Case::TaylorGreen;
    let Vortex { field, rate } = Vortex::of(scene)?;

    let time = read_column(run_dir, "time")?;
    let energy = read_column(run_dir, "kinetic_energy")?;
    if time.len() < 2 || energy.iter().any(|&e| e <= 0.0) {
        return Err(ValidationError::Run {
            case,
            dir: run_dir.to_owned(),
            message: "its stats.csv needs two steps or more, all with kinetic energy".into(),
        });
    }
    let half_log: Vec<f64> = energy.iter().map(|e| 0.5 * e.ln()).collect();
    let fitted = -slope(&time, &half_log);

    let frame = last_frame(case, run_dir)?;
    let last_dt =
        step_before(&time, &read_column(run_dir, "dt")?, frame.time).ok_or_else(|| {
            ValidationError::Run {
                case,
                dir: run_dir.to_owned(),
                message: format!(
                    "its stats.csv has no step ending at the last frame's time {}",
                    frame.time
                ),
            }
        })?;
    // The exact field at the last frame's time: the initial field times exp(−rate t), read
    // `lag` back along each particle's path, at r − lag u.
    let decay = (-rate * frame.time).exp();
    let velocity_l2 = |lag: f64| {
        let (mut error, mut norm) = (0.0, 0.0);
        for i in fluid(&frame) {
            let ([x, y, _], u) = (frame.position[i], frame.velocity[i]);
            let at = [x - lag * u[0], y - lag * u[1]];
            let exact = field.at(&scene.container, at).map(|u| u * decay);
            error += (u[0] - exact[0]).powi(2) + (u[1] - exact[1]).powi(2);
            norm += exact[0].powi(2) + exact[1].powi(2);
        }
        (error / norm).sqrt()
    };
    Ok(Measured::new(
        (fitted - rate).abs() / rate,
        &DETAILS,
        &[fitted, velocity_l2(0.0), velocity_l2(0.5 * last_dt)],
    ))
}

/// Δt of the step of `stats.csv` that ends at `frame_time` (its `time` column within a
/// rounding of it).
fn step_before(time: &[f64], dt: &[f64], frame_time: f64) -> Option<f64> {
    let tolerance = 1e-9 * frame_time.abs().max(1.0);
    time.iter()
        .zip(dt)
        .find(|(t, _)| (**t - frame_time).abs() <= tolerance)
        .map(|(_, dt)| *dt)
}
