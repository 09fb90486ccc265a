//! Collapse of a 2:1 water column (the scene's first fluid block, standing against the
//! container's min-x wall): the surge front against Martin & Moyce (1952), 2D or 3D.
//!
//! With a the width of the column (along x) and g = |gravity|, time is T = t √(2g/a) and the
//! front Z = x/a, x the largest distance from the back wall of a fluid particle that is not
//! spray (`Role::Splash`: too isolated to carry a pressure gradient). Once the surge has thinned
//! to a layer a particle or two thick, single particles slide off its tip one behind the other,
//! well ahead of the water; the experiment's front is that of the water body, and counted,
//! the loose particles make the error jump with small changes of the tank's length
//! (docs/accuracy.md, "Dam break (2D): the surge front against Martin & Moyce"). The error is
//! the mean relative error |Z − Z_ref| / Z_ref over the tabulated points whose time the run
//! reached, each against the frame nearest its time; points whose front lies beyond 90% of the
//! way to the far wall are left out (the wall stops the surge there). Details: the largest of
//! those errors, how many points were compared, and the height of the water at the back wall
//! (within a/4 of it) over the initial height, at the last compared time.
//!
//! The point error mixes two things: when the experiment's column started to fall (its gate
//! took a finite time to lift) and how fast the simulated surge runs. Two more details part
//! them, both from the front of every frame, Z_sim(T) linear between frames:
//! - the front's speed dZ/dT, the least-squares slope over the frames with T in [1.6, 3.3]
//!   (past the column's first acceleration, before the surge thins), next to the same fit to
//!   the experiment's tabulated points in that window (T = 1.997 and 2.547: 1.278); NaN unless
//!   the compared points reach past the window;
//! - the lead τ, the time shift in T that best aligns the simulated front with the compared
//!   points: it minimises Σ_k (Z_sim(T_k − τ) − Z_k)², so τ > 0 when the simulation reaches a
//!   given Z earlier than the experiment. Z_sim is held at its first frame's value before it
//!   (the column stands still until released) and at its last frame's after it. The minimum
//!   is sought over τ in [−1, 1.5] by a scan 0.01 apart refined by golden-section search.
//!   `front_rms` and `lead_residual_rms` are the rms of Z_sim(T_k − τ) − Z_k (in widths a)
//!   without and with the shift: how much of the discrepancy a late start explains.

use super::{
    first_block, fluid, no_frames, surge_vertical, unsuitable, Case, Measured, ValidationError,
};
use crate::io::frames::{Frame, FrameReader};
use crate::scene::Scene;
use crate::solver::ppe::Role;
use std::path::Path;

pub const DETAILS: [&str; 8] = [
    "front_error_max",
    "front_points",
    "column_height",
    "front_speed",
    "front_speed_experiment",
    "lead",
    "front_rms",
    "lead_residual_rms",
];

/// Martin & Moyce (1952), n² = 2, a = 2.25 in: (T = t √(2g/a), Z = x/a), as tabulated in
/// PySPH's `db_exp_data.py` (`mm_data_2`) from their Figure 3.
pub const MARTIN_MOYCE_FRONT: [(f64, f64); 15] = [
    (0.832, 1.217),
    (1.219, 1.474),
    (1.997, 2.292),
    (2.547, 2.995),
    (3.345, 4.134),
    (4.034, 4.944),
    (4.418, 5.881),
    (5.091, 6.980),
    (5.685, 7.945),
    (6.306, 8.966),
    (6.822, 9.986),
    (7.439, 10.963),
    (8.031, 11.977),
    (8.633, 13.005),
    (9.237, 13.970),
];

/// The largest distance in T between a tabulated time and the frame compared with it: frames
/// 0.1 apart in T (output_interval = 0.1 / √(2g/a)) always have one within 0.05, with a
/// little room for the rounding of frame times.
pub const MAX_GAP: f64 = 0.051;

/// Height over width of the tabulated column (n² = 2).
const ASPECT: f64 = 2.0;

/// Tabulated fronts beyond this fraction of the way to the far wall are not compared.
const REACH: f64 = 0.9;

/// The window of T over which the front's speed is fitted.
pub const SPEED_WINDOW: (f64, f64) = (1.6, 3.3);

/// The time shifts, in T, among which the lead is sought.
pub const LEAD_BRACKET: (f64, f64) = (-1.0, 1.5);

/// The spacing of the scan for the lead, in T: finer than the frames (0.1 apart), so the scan's
/// best shift lies in the basin of the least-squares minimum.
const LEAD_SCAN_STEP: f64 = 0.01;

/// The width in T to which golden-section search narrows the lead.
const LEAD_TOLERANCE: f64 = 1e-9;

/// The back-wall strip whose highest fluid particle gives the column height, in widths a.
const HEIGHT_STRIP: f64 = 0.25;

/// The column's geometry, from the scene.
#[derive(Clone, Copy, Debug)]
pub struct Column {
    /// The vertical axis (the one gravity points down).
    pub vertical: usize,
    /// The back wall's x [m].
    pub back: f64,
    /// Width a [m] and initial height [m].
    pub width: f64,
    pub height: f64,
    /// The floor's height [m].
    pub floor: f64,
    /// √(2g/a) [1/s]: T = t · time_scale.
    pub time_scale: f64,
    /// Distance from the back wall to the far wall, in widths a.
    pub far_wall: f64,
}

impl Column {
    pub fn new(scene: &Scene) -> Result<Self, ValidationError> {
        let case = Case::DamBreakFront;
        let (v, g) = surge_vertical(case, scene)?;
        let region = &first_block(case, scene)?.region;
        let back = scene.container.min[0];
        let scene_error = |message: String| unsuitable(case, scene, message);
        if region.min[0] - back > scene.spacing {
            return Err(scene_error(format!(
                "the first fluid block (x from {}) must stand against the container's min-x wall (x = {back})",
                region.min[0]
            )));
        }
        let width = region.max[0] - back;
        let height = region.max[v] - region.min[v];
        if (height / width - ASPECT).abs() > 0.02 * ASPECT {
            return Err(scene_error(format!(
                "Martin & Moyce's fronts are for a column twice as high as wide; the first fluid block is {height} m high and {width} m wide (from the back wall)"
            )));
        }
        Ok(Self {
            vertical: v,
            back,
            width,
            height,
            floor: region.min[v],
            time_scale: (2.0 * g / width).sqrt(),
            far_wall: (scene.container.max[0] - back) / width,
        })
    }

    /// The tabulated points the container leaves room for.
    pub fn reference(&self) -> Vec<(f64, f64)> {
        MARTIN_MOYCE_FRONT
            .into_iter()
            .filter(|&(_, z)| z <= REACH * self.far_wall)
            .collect()
    }

    /// Z: the largest distance of a fluid particle that is not spray from the back wall, over a.
    pub fn front(&self, frame: &Frame) -> f64 {
        fluid(frame)
            .filter(|&i| frame.free_surface[i] != i32::from(Role::Splash.code()))
            .map(|i| frame.position[i][0] - self.back)
            .fold(0.0, f64::max)
            / self.width
    }

    /// The height of the highest fluid particle within a/4 of the back wall, over the
    /// initial height.
    pub fn height_at_wall(&self, frame: &Frame) -> f64 {
        fluid(frame)
            .filter(|&i| frame.position[i][0] - self.back < HEIGHT_STRIP * self.width)
            .map(|i| frame.position[i][self.vertical] - self.floor)
            .fold(0.0, f64::max)
            / self.height
    }
}

/// A tabulated time with no frame within `MAX_GAP`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gap {
    pub t_ref: f64,
    /// T of the nearest frame.
    pub nearest: f64,
}

/// For each reference point whose time the frames reach (within `MAX_GAP` of the last), the
/// index of the frame nearest its time: (reference index, frame index). `times` are the
/// frames' T, ascending.
pub fn pick_frames(times: &[f64], reference: &[(f64, f64)]) -> Result<Vec<(usize, usize)>, Gap> {
    let Some(&last) = times.last() else {
        return Ok(Vec::new());
    };
    reference
        .iter()
        .enumerate()
        .take_while(|(_, (t_ref, _))| *t_ref <= last + MAX_GAP)
        .map(|(k, &(t_ref, _))| {
            let nearest = (0..times.len())
                .min_by(|&a, &b| {
                    (times[a] - t_ref)
                        .abs()
                        .total_cmp(&(times[b] - t_ref).abs())
                })
                .expect("times is not empty");
            if (times[nearest] - t_ref).abs() > MAX_GAP {
                Err(Gap {
                    t_ref,
                    nearest: times[nearest],
                })
            } else {
                Ok((k, nearest))
            }
        })
        .collect()
}

/// |Z − Z_ref| / Z_ref of each (measured Z, reference Z).
pub fn relative_errors(pairs: &[(f64, f64)]) -> Vec<f64> {
    pairs
        .iter()
        .map(|(z, z_ref)| (z - z_ref).abs() / z_ref)
        .collect()
}

/// The least-squares slope of the line through `points` (x, y); NaN for fewer than two
/// distinct x.
pub fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let mean_x = points.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_y = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = points
        .iter()
        .map(|&(x, y)| (x - mean_x) * (y - mean_y))
        .sum();
    let sxx: f64 = points.iter().map(|&(x, _)| (x - mean_x).powi(2)).sum();
    if points.len() < 2 || sxx == 0.0 {
        return f64::NAN;
    }
    sxy / sxx
}

/// dZ/dT fitted to the (T, Z) of `front` inside `SPEED_WINDOW`.
pub fn speed(front: &[(f64, f64)]) -> f64 {
    let inside: Vec<(f64, f64)> = front
        .iter()
        .copied()
        .filter(|&(t, _)| (SPEED_WINDOW.0..=SPEED_WINDOW.1).contains(&t))
        .collect();
    slope(&inside)
}

/// The simulated front's `speed`, or NaN unless the `compared` points reach past
/// `SPEED_WINDOW` (the run lasted, and the tank is long enough, for the whole window).
pub fn front_speed(front: &[(f64, f64)], compared: &[(f64, f64)]) -> f64 {
    match compared.last() {
        Some(&(t, _)) if t >= SPEED_WINDOW.1 => speed(front),
        _ => f64::NAN,
    }
}

/// The speed of the experiment's front: the fit to its tabulated points inside `SPEED_WINDOW`.
pub fn experiment_speed() -> f64 {
    speed(&MARTIN_MOYCE_FRONT)
}

/// Z at `t` on `front` ((T, Z), T ascending), linear between its points and held at its first
/// and last values outside them.
pub fn interpolate(front: &[(f64, f64)], t: f64) -> f64 {
    let after = front.partition_point(|&(tf, _)| tf <= t);
    if after == 0 {
        return front[0].1;
    }
    if after == front.len() {
        return front[after - 1].1;
    }
    let (t0, z0) = front[after - 1];
    let (t1, z1) = front[after];
    z0 + (z1 - z0) * (t - t0) / (t1 - t0)
}

/// The rms of Z_sim(T_k − `lead`) − Z_k over the `reference` points (T_k, Z_k).
pub fn shifted_rms(front: &[(f64, f64)], reference: &[(f64, f64)], lead: f64) -> f64 {
    let sum: f64 = reference
        .iter()
        .map(|&(t, z)| (interpolate(front, t - lead) - z).powi(2))
        .sum();
    (sum / reference.len() as f64).sqrt()
}

/// The shift τ in `LEAD_BRACKET` that minimises `shifted_rms`: the best of a scan
/// `LEAD_SCAN_STEP` apart (the first, if several tie), refined by golden-section search within
/// one step either side. Z_sim is piecewise linear, so the sum of squares may have several
/// local minima over the bracket; the scan finds the basin of the lowest.
pub fn lead(front: &[(f64, f64)], reference: &[(f64, f64)]) -> f64 {
    let rms = |tau: f64| shifted_rms(front, reference, tau);
    let (low, high) = LEAD_BRACKET;
    let steps = ((high - low) / LEAD_SCAN_STEP).round() as usize;
    let best = (0..=steps)
        .map(|i| low + i as f64 * LEAD_SCAN_STEP)
        .min_by(|&a, &b| rms(a).total_cmp(&rms(b)))
        .expect("the scan has points");
    golden_section(
        rms,
        (best - LEAD_SCAN_STEP).max(low),
        (best + LEAD_SCAN_STEP).min(high),
    )
}

/// The minimum of `f` on [a, b], assumed unimodal there, to within `LEAD_TOLERANCE`.
fn golden_section(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    while b - a > LEAD_TOLERANCE {
        if fc <= fd {
            b = d;
            (d, fd) = (c, fc);
            c = b - ratio * (b - a);
            fc = f(c);
        } else {
            a = c;
            (c, fc) = (d, fd);
            d = a + ratio * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}

pub fn measure(scene: &Scene, run_dir: &Path) -> Result<Measured, ValidationError> {
    let case = Case::DamBreakFront;
    let column = Column::new(scene)?;
    let reader = FrameReader::open(run_dir)?;
    let times: Vec<f64> = reader
        .times()?
        .into_iter()
        .map(|t| t * column.time_scale)
        .collect();
    let reference = column.reference();
    let run_error = |message: String| ValidationError::Run {
        case,
        dir: run_dir.to_owned(),
        message,
    };
    let Some(&last) = times.last() else {
        return Err(no_frames(case, run_dir));
    };
    let picks = pick_frames(&times, &reference).map_err(|gap| {
        run_error(format!(
            "no frame within {MAX_GAP} of T = t√(2g/a) = {} (nearest: T = {:.3}); write frames at least every 0.1 in T: `simulation.output_interval` ≤ {:.3e} s",
            gap.t_ref,
            gap.nearest,
            0.1 / column.time_scale
        ))
    })?;
    if picks.is_empty() {
        let first = MARTIN_MOYCE_FRONT[0].0;
        return Err(run_error(format!(
            "it ends at T = t√(2g/a) = {last:.3}, before Martin & Moyce's first time T = {first} (t = {:.4} s), or the container is too short for their first front Z = {}",
            first / column.time_scale,
            MARTIN_MOYCE_FRONT[0].1
        )));
    }
    let front: Vec<(f64, f64)> = times
        .iter()
        .enumerate()
        .map(|(f, &t)| Ok((t, column.front(&reader.read(f)?))))
        .collect::<Result<_, ValidationError>>()?;
    let pairs: Vec<(f64, f64)> = picks
        .iter()
        .map(|&(k, f)| (front[f].1, reference[k].1))
        .collect();
    let last_pick = picks[picks.len() - 1].1;
    let height = column.height_at_wall(&reader.read(last_pick)?);
    let errors = relative_errors(&pairs);
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let max = errors.iter().copied().fold(0.0, f64::max);
    let compared: Vec<(f64, f64)> = picks.iter().map(|&(k, _)| reference[k]).collect();
    let shift = lead(&front, &compared);
    Ok(Measured::new(
        mean,
        &DETAILS,
        &[
            max,
            errors.len() as f64,
            height,
            front_speed(&front, &compared),
            experiment_speed(),
            shift,
            shifted_rms(&front, &compared, 0.0),
            shifted_rms(&front, &compared, shift),
        ],
    ))
}
