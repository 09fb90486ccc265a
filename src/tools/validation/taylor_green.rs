//! The 2D Taylor–Green vortex of a periodic square of side L (`[initial_velocity]
//! field = "taylor_green"`): the exact solution decays in shape, its velocity as exp(−8π²νt/L²)
//! and its kinetic energy as the square of that.
//!
//! The error is the relative error of the velocity decay rate, fitted by least squares to
//! ½ ln E(t) of every step in stats.csv (E the kinetic energy), against 8π²ν/L². Details: that
//! fitted rate [1/s]; the L2 error of the velocity field of the last frame against the exact
//! field at the frame's time and positions, relative to the exact field's L2 norm; and the
//! largest excess of the kinetic energy over the exact field's at the same positions, E/E_exact
//! − 1 over every frame after the first (negative where the vortex never carries more than the
//! exact one): a start-up that injects energy shows there, where the fitted rate hides it. A
//! frame's particles stand where the step's velocity belongs, half the last drift back
//! (`Simulation::present_positions`): read at the advection's end positions instead, a
//! vortex's velocity lags by (Δt/2)|Du/Dt| (docs/accuracy.md, "Where a frame's particles
//! stand").

use super::{fluid, unsuitable, Case, Measured, ValidationError};
use crate::io::frames::{Frame, FrameReader};
use crate::io::stats::read_column;
use crate::scene::{InitialVelocity, Scene};
use std::f64::consts::PI;
use std::path::Path;

pub const DETAILS: [&str; 3] = ["decay_rate", "velocity_l2_error", "energy_excess_max"];

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

    let frames = FrameReader::open(run_dir)?;
    let count = frames.times()?.len();
    if count < 2 {
        return Err(ValidationError::Run {
            case,
            dir: run_dir.to_owned(),
            message: "its particles.h5 needs a frame after the first".into(),
        });
    }
    let sums = (1..count)
        .map(|index| Ok(against_exact(&frames.read(index)?, field, rate, scene)))
        .collect::<Result<Vec<_>, ValidationError>>()?;
    let energy_excess_max = sums
        .iter()
        .map(|(_, energy, exact_energy)| energy / exact_energy - 1.0)
        .fold(f64::NEG_INFINITY, f64::max);
    let (error, _, exact_energy) = sums[sums.len() - 1];
    let velocity_l2 = (error / exact_energy).sqrt();
    Ok(Measured::new(
        (fitted - rate).abs() / rate,
        &DETAILS,
        &[fitted, velocity_l2, energy_excess_max],
    ))
}

/// Σ|u − u_exact|², Σ|u|² and Σ|u_exact|² over the fluid particles of `frame`, the exact field
/// the initial one times exp(−rate t) at the frame's time and positions.
fn against_exact(
    frame: &Frame,
    field: InitialVelocity,
    rate: f64,
    scene: &Scene,
) -> (f64, f64, f64) {
    let decay = (-rate * frame.time).exp();
    let (mut error, mut energy, mut exact_energy) = (0.0, 0.0, 0.0);
    for i in fluid(frame) {
        let ([x, y, _], u) = (frame.position[i], frame.velocity[i]);
        let exact = field.at(&scene.container, [x, y]).map(|u| u * decay);
        error += (u[0] - exact[0]).powi(2) + (u[1] - exact[1]).powi(2);
        energy += u[0].powi(2) + u[1].powi(2);
        exact_energy += exact[0].powi(2) + exact[1].powi(2);
    }
    (error, energy, exact_energy)
}
