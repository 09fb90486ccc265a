//! Wall pressures of the dam break of Lobovsky et al. (2014), J. Fluids Struct. 48, 407–434,
//! H = 300 mm: the probes P1–P4 of the scene (`scenes/dam_break_lobovsky_2d.toml`, or `_3d` in
//! the experiment's tank 150 mm wide), on the far wall at the heights of the centres of the
//! paper's sensors 1–4 (3, 15, 30, 80 mm, scaled by H/300 mm), against the experiment's curves
//! (docs/accuracy/lobovsky_2014/, with their sources). Time is T = t √(g/H), pressure
//! P/(ρ0 g H), as in the paper.
//!
//! The impact peaks scatter widely between the experiment's repeats; two features do not, and
//! are compared, each measured in the same way on the experiment's curve and on probes.csv:
//! - the onset: the first T at which P/(ρ0 g H) exceeds `ONSET_LEVEL` (0.1), linearly
//!   interpolated between samples: a level well above the noise before the impact (below 0.03)
//!   and well below the plateau (0.5–0.7), crossed in under 0.05 in T at sensors 1–3;
//! - the plateau: the mean of P/(ρ0 g H) over T in `PLATEAU` (3.5–5.5), the integral of the
//!   piecewise-linear curve over the window divided by its length: the experiment's curves have
//!   come down from the impact by T = 3.4 (sensor 3's falls to 0.63 at 3.34) and stay between
//!   0.46 and 0.71 until the wave that plunged back from the wall hits again at T ≈ 5.8.
//!
//! The flow that brings the water to the wall is compared too, where the scene has the
//! experiment's water-level gauges H1–H4 (wave gauges, `field = "elevation"`, on the vertical
//! lines 300, 865, 1114 and 1362.5 mm from the column's wall, scaled by H/300 mm): the mean of
//! h/H over T in `LEVEL_WINDOW` (0.5–5.5, from just after the release until the wave that
//! plunged back from the wall reaches H4), against the experiment's (a dry gauge reads h = 0,
//! as the experiment's).
//!
//! The error is the mean of |T_onset − T_onset,exp| / T_onset,exp over the four sensors.
//! Details, per sensor k: `onset_error_Pk` and `plateau_error_Pk` (signed, relative to the
//! experiment's), `onset_Pk` (T) and `plateau_Pk` (P/(ρ0 g H)) of the run; per gauge k,
//! `level_error_Hk`, the run's mean level relative to the experiment's (signed). A plateau or
//! a level whose window the run did not reach, an onset it did not, or a gauge the scene
//! lacks, is NaN.

use super::{
    first_block, surge_vertical, unsuitable, Case, Measured, ProbeCurves, ValidationError,
};
use crate::scene::{ProbeField, Scene};
use std::path::Path;

pub const DETAILS: [&str; 20] = [
    "onset_error_P1",
    "onset_error_P2",
    "onset_error_P3",
    "onset_error_P4",
    "plateau_error_P1",
    "plateau_error_P2",
    "plateau_error_P3",
    "plateau_error_P4",
    "onset_P1",
    "onset_P2",
    "onset_P3",
    "onset_P4",
    "plateau_P1",
    "plateau_P2",
    "plateau_P3",
    "plateau_P4",
    "level_error_H1",
    "level_error_H2",
    "level_error_H3",
    "level_error_H4",
];

/// The level of P/(ρ0 g H) whose first crossing is the onset.
pub const ONSET_LEVEL: f64 = 0.1;

/// The window of T over which the plateau is averaged.
pub const PLATEAU: (f64, f64) = (3.5, 5.5);

/// The window of T over which the water levels are averaged.
pub const LEVEL_WINDOW: (f64, f64) = (0.5, 5.5);

/// The experiment's column height [m]: sensor heights scale with H/EXPERIMENT_HEIGHT.
const EXPERIMENT_HEIGHT: f64 = 0.3;

/// A sensor of the experiment: its probe's name, the height of its centre above the floor in the
/// experiment [m], and its curve (T, P/(ρ0 g H)) as a CSV file of `docs/accuracy/lobovsky_2014/`.
pub struct Sensor {
    pub name: &'static str,
    pub height: f64,
    pub csv: &'static str,
}

pub const SENSORS: [Sensor; 4] = [
    Sensor {
        name: "P1",
        height: 0.003,
        csv: include_str!("../../../docs/accuracy/lobovsky_2014/sensor1.csv"),
    },
    Sensor {
        name: "P2",
        height: 0.015,
        csv: include_str!("../../../docs/accuracy/lobovsky_2014/sensor2.csv"),
    },
    Sensor {
        name: "P3",
        height: 0.030,
        csv: include_str!("../../../docs/accuracy/lobovsky_2014/sensor3.csv"),
    },
    Sensor {
        name: "P4",
        height: 0.080,
        csv: include_str!("../../../docs/accuracy/lobovsky_2014/sensor4.csv"),
    },
];

impl Sensor {
    /// The experiment's curve: (T, P/(ρ0 g H)).
    pub fn curve(&self) -> Vec<(f64, f64)> {
        curve_of(self.csv)
    }
}

/// A water-level gauge of the experiment: its probe's name, the distance of its vertical line
/// from the column's wall in the experiment [m], and its curve (T, h/H) as a CSV file of
/// `docs/accuracy/lobovsky_2014/`.
pub struct Gauge {
    pub name: &'static str,
    pub distance: f64,
    pub csv: &'static str,
}

pub const GAUGES: [Gauge; 4] = [
    Gauge {
        name: "H1",
        distance: 0.3,
        csv: include_str!("../../../docs/accuracy/lobovsky_2014/gauge1.csv"),
    },
    Gauge {
        name: "H2",
        distance: 0.865,
        csv: include_str!("../../../docs/accuracy/lobovsky_2014/gauge2.csv"),
    },
    Gauge {
        name: "H3",
        distance: 1.114,
        csv: include_str!("../../../docs/accuracy/lobovsky_2014/gauge3.csv"),
    },
    Gauge {
        name: "H4",
        distance: 1.3625,
        csv: include_str!("../../../docs/accuracy/lobovsky_2014/gauge4.csv"),
    },
];

impl Gauge {
    /// The experiment's curve: (T, h/H).
    pub fn curve(&self) -> Vec<(f64, f64)> {
        curve_of(self.csv)
    }
}

/// The (T, value) rows of an experiment's CSV file in its order (`#` lines and the header
/// skipped).
fn curve_of(csv: &str) -> Vec<(f64, f64)> {
    csv.lines()
        .filter_map(|l| {
            let (t, p) = l.split_once(',')?;
            Some((t.parse().ok()?, p.parse().ok()?))
        })
        .collect()
}

/// The first T at which the curve exceeds `level`, linearly interpolated; None if it never does.
pub fn onset(curve: &[(f64, f64)], level: f64) -> Option<f64> {
    let k = curve.iter().position(|&(_, p)| p > level)?;
    let Some(&(t0, p0)) = k.checked_sub(1).map(|j| &curve[j]) else {
        return Some(curve[k].0);
    };
    let (t1, p1) = curve[k];
    Some(t0 + (t1 - t0) * (level - p0) / (p1 - p0))
}

/// The mean of the piecewise-linear curve over T in [a, b]: its integral over the window over
/// b − a. None if the curve does not span the window.
pub fn window_mean(curve: &[(f64, f64)], (a, b): (f64, f64)) -> Option<f64> {
    let (first, last) = (curve.first()?.0, curve.last()?.0);
    if first > a || last < b {
        return None;
    }
    let mut integral = 0.0;
    for pair in curve.windows(2) {
        let ((t0, p0), (t1, p1)) = (pair[0], pair[1]);
        let (lo, hi) = (t0.max(a), t1.min(b));
        if hi <= lo {
            continue;
        }
        let at = |t: f64| p0 + (p1 - p0) * (t - t0) / (t1 - t0);
        integral += 0.5 * (at(lo) + at(hi)) * (hi - lo);
    }
    Some(integral / (b - a))
}

/// The tank of a scene: what turns probes.csv into the paper's T, P/(ρ0 g H) and h/H.
#[derive(Clone, Copy, Debug)]
pub struct Tank {
    /// √(g/H) [1/s]: T = t · time_scale.
    pub time_scale: f64,
    /// ρ0 g H [Pa].
    pub pressure_scale: f64,
    /// The floor's height [m] and H [m]: h/H = (z − floor)/H.
    pub floor: f64,
    pub height: f64,
    /// Whether the scene has each of the gauges H1–H4.
    pub gauges: [bool; 4],
}

impl Tank {
    /// Checks that the scene's first fluid block is the column (height H) and that it has the
    /// pressure probes P1–P4 on the far (max-x) wall, within half a spacing of its face, at the
    /// sensors' heights scaled by H/300 mm (within half of the sensors' 4.2 mm), and that
    /// those of the gauges H1–H4 it has stand at their distances from the column's wall scaled
    /// by H/300 mm, within half a spacing.
    pub fn new(scene: &Scene) -> Result<Self, ValidationError> {
        let case = Case::LobovskyPressure;
        let (v, g) = surge_vertical(case, scene)?;
        let scene_error = |message: String| unsuitable(case, scene, message);
        let column = &first_block(case, scene)?.region;
        let height = column.max[v] - column.min[v];
        let scale = height / EXPERIMENT_HEIGHT;
        let wall = scene.container.max[0];
        for sensor in &SENSORS {
            let probe = scene
                .probes
                .iter()
                .find(|p| p.name == sensor.name && p.field == ProbeField::Pressure)
                .ok_or_else(|| {
                    scene_error(format!(
                        "has no pressure probe named {} (the sensors are the [[probe]]s P1-P4)",
                        sensor.name
                    ))
                })?;
            let y = column.min[v] + sensor.height * scale;
            let on_wall = (probe.point[0] - wall).abs() <= 0.5 * scene.spacing;
            let at_height = (probe.point[v] - y).abs() <= 0.0021 * scale;
            if !(on_wall && at_height) {
                return Err(scene_error(format!(
                    "probe {} is at {:?}; sensor {} sits on the far wall (x = {wall}) at height {y:.4} m ({} mm scaled by H/300 mm)",
                    sensor.name,
                    probe.point,
                    &sensor.name[1..],
                    sensor.height * 1e3
                )));
            }
        }
        let mut gauges = [false; 4];
        for (k, gauge) in GAUGES.iter().enumerate() {
            let Some(probe) = scene.probes.iter().find(|p| p.name == gauge.name) else {
                continue;
            };
            let x = column.min[0] + gauge.distance * scale;
            if probe.field != ProbeField::Elevation
                || (probe.point[0] - x).abs() > 0.5 * scene.spacing
            {
                return Err(scene_error(format!(
                    "probe {} is a {} probe at {:?}; gauge {} is a wave gauge (field = \"elevation\") at x = {x:.4} m ({} mm from the column's wall scaled by H/300 mm)",
                    gauge.name,
                    probe.field.name(),
                    probe.point,
                    &gauge.name[1..],
                    gauge.distance * 1e3
                )));
            }
            gauges[k] = true;
        }
        let rho = scene.fluids[scene.blocks[0].fluid].density;
        Ok(Self {
            time_scale: (g / height).sqrt(),
            pressure_scale: rho * g * height,
            floor: column.min[v],
            height,
            gauges,
        })
    }
}

pub fn measure(scene: &Scene, run_dir: &Path) -> Result<Measured, ValidationError> {
    let case = Case::LobovskyPressure;
    let tank = Tank::new(scene)?;
    let probes = ProbeCurves::read(case, run_dir)?;
    let mut values = [f64::NAN; 20];
    for (k, sensor) in SENSORS.iter().enumerate() {
        let run: Vec<(f64, f64)> = probes
            .curve(sensor.name)?
            .into_iter()
            .map(|(t, p)| (t * tank.time_scale, p / tank.pressure_scale))
            .collect();
        let experiment = sensor.curve();
        let exp_onset = onset(&experiment, ONSET_LEVEL).expect("every sensor's curve rises");
        let exp_plateau = window_mean(&experiment, PLATEAU).expect("every curve spans it");
        let (run_onset, run_plateau) = (onset(&run, ONSET_LEVEL), window_mean(&run, PLATEAU));
        let nan = f64::NAN;
        values[k] = run_onset.map_or(nan, |t| (t - exp_onset) / exp_onset);
        values[4 + k] = run_plateau.map_or(nan, |p| (p - exp_plateau) / exp_plateau);
        values[8 + k] = run_onset.unwrap_or(nan);
        values[12 + k] = run_plateau.unwrap_or(nan);
    }
    // h/H of a gauge's height z; a dry gauge (NaN) reads no water, as the experiment's.
    let level = |z: f64| {
        if z.is_nan() {
            0.0
        } else {
            (z - tank.floor) / tank.height
        }
    };
    for (k, gauge) in GAUGES.iter().enumerate().filter(|&(k, _)| tank.gauges[k]) {
        let run: Vec<(f64, f64)> = probes
            .curve(gauge.name)?
            .into_iter()
            .map(|(t, z)| (t * tank.time_scale, level(z)))
            .collect();
        let experiment = window_mean(&gauge.curve(), LEVEL_WINDOW).expect("every curve spans it");
        values[16 + k] =
            window_mean(&run, LEVEL_WINDOW).map_or(f64::NAN, |h| (h - experiment) / experiment);
    }
    if values[..4].iter().all(|e| e.is_nan()) {
        let end = probes.end();
        return Err(probes.error(format!(
            "no probe reached {ONSET_LEVEL} ρ0 g H by its end at t = {end} s (T = {:.3})",
            end * tank.time_scale
        )));
    }
    let error = values[..4].iter().map(|e| e.abs()).sum::<f64>() / 4.0;
    Ok(Measured::new(error, &DETAILS, &values))
}
