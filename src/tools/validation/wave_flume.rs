//! Regular waves from a piston wave maker against linear theory: a flume of still water of
//! depth h (the first fluid block's top over the container's floor, gravity down the last
//! axis), a prescribed body moving as X(t) = (S/2) sin(ωt) along x (the piston, its face
//! towards the water the body's largest x), and wave gauges (`[[probe]]` with
//! `field = "elevation"`) down the flume.
//!
//! The reference is Biesel's transfer function of a piston, the first-order wave height for a
//! stroke S, H/S = 2 (cosh 2kh − 1)/(sinh 2kh + 2kh), with k from ω² = g k tanh kh. Each gauge's
//! height is its first harmonic at ω, 2√(a² + b²) from the least-squares fit of a₀ + a cos ωt +
//! b sin ωt to probes.csv over whole periods: the last periods before the far wall's
//! reflection returns, and after the wave train's front, which travels at the group velocity
//! c_g = (ω/k)(1 + 2kh/sinh 2kh)/2, has passed by two periods. The piston starts at its largest
//! speed, and that impulsive start also sends long waves, as fast as √(gh): they are the first
//! to come back from the far wall (in the shipped flume at 4.41 m, a gauge one wavelength from
//! the piston read the first harmonic 1.00 times Biesel's over 4–5 s and 1.14–1.16 times it from
//! 6 s, where the reflection at c_g would return at 8.2 s and at √(gh) returns at 5.4 s). A
//! higher harmonic (the crests' steepening) does not enter the first harmonic, so the fit reads
//! the height linear theory gives at any steepness the flume can carry.
//!
//! The error is the mean over the gauges of |H/H_Biesel − 1|, over the gauges that have two
//! whole periods between the front and the reflection. Details: H_Biesel, the wavelength, the
//! count of those gauges, and their signed errors' smallest, largest and mean.
//!
//! The details also hold the water's force on the piston (`bodies.csv`'s fx) against the
//! linear theory of the wave maker (`Flume::paddle_force`): its mean against the hydrostatic
//! thrust, and its first harmonic's amplitude and phase, fitted as the gauges' are over the
//! whole periods from the second on, before the fastest waves come back from the far wall. The
//! fit needs frames at least four times a period (eight keep the third harmonic out); with
//! fewer, the three details are NaN.

use super::{first_block, unsuitable, vertical, Case, Measured, ProbeCurves, ValidationError};
use crate::io::bodies_csv;
use crate::math::rotation::{apply, inverse_on_span};
use crate::scene::trajectory::Path as Motion;
use crate::scene::{BodyMotion, ProbeField, Scene};
use std::f64::consts::PI;
use std::path::Path;

pub const DETAILS: [&str; 9] = [
    "reference_height",
    "wavelength",
    "gauges",
    "height_error_min",
    "height_error_max",
    "height_error_mean",
    "paddle_force_mean_error",
    "paddle_force_amplitude_error",
    "paddle_force_phase_error_deg",
];

/// Evanescent modes summed in the wave maker's added-mass force: the n-th term falls as n⁻³.
const EVANESCENT_MODES: usize = 400;

/// Periods after a gauge's front has passed before its window may start.
const SETTLING_PERIODS: f64 = 2.0;

/// The flume of a scene: the wave maker's motion, the water, and the gauges' distances from
/// the piston's face.
#[derive(Clone, Debug)]
pub struct Flume {
    /// ω [rad/s].
    pub frequency: f64,
    /// a of the piston's motion X(t) = a sin ωt [m]: the stroke is S = 2|a|.
    pub amplitude: f64,
    /// h [m], |g| [m/s²] and the water's ρ0 [kg/m³].
    pub depth: f64,
    pub gravity: f64,
    pub density: f64,
    /// The piston's index among the scene's bodies, and its width across the flume [m] (1 in
    /// 2D: forces per unit width).
    pub piston: usize,
    pub width: f64,
    /// From the piston's face to the far wall [m].
    pub length: f64,
    /// Each gauge's column in probes.csv and its distance from the piston's face [m].
    pub gauges: Vec<(String, f64)>,
}

impl Flume {
    pub fn of(scene: &Scene) -> Result<Flume, ValidationError> {
        let case = Case::WaveFlume;
        let refuse = |message: &str| Err(unsuitable(case, scene, message));
        let (up, gravity) = vertical(case, scene)?;
        if up != scene.dimensions - 1 || up == 0 {
            return refuse("needs gravity down the last axis, the flume along x");
        }
        let pistons: Vec<_> = scene
            .bodies
            .iter()
            .enumerate()
            .filter_map(|(i, b)| match &b.motion {
                BodyMotion::Prescribed(t) => Some((i, b, t)),
                _ => None,
            })
            .collect();
        let [(index, piston, trajectory)] = pistons[..] else {
            return refuse("needs one prescribed body, the piston");
        };
        let (amplitude, period) = match &trajectory.path {
            Motion::Sinusoid {
                amplitude,
                angle,
                period,
            } if *angle == 0.0 && amplitude[1..].iter().all(|&a| a == 0.0) && amplitude[0] != 0.0 => {
                (amplitude[0], *period)
            }
            _ => {
                return refuse(
                    "needs the piston's trajectory a sinusoid along x only (`period` and `amplitude = [A, 0.0]`)",
                )
            }
        };
        if piston.release.is_some() {
            return refuse("needs the piston held on its trajectory for the whole run");
        }
        let bounds = piston.shape.bounds();
        let face = bounds.max[0];
        let block = first_block(case, scene)?;
        let depth = block.region.max[up] - scene.container.min[up];
        let gauges: Vec<(String, f64)> = scene
            .probes
            .iter()
            .filter(|p| p.field == ProbeField::Elevation && p.point[0] > face)
            .map(|p| (p.name.clone(), p.point[0] - face))
            .collect();
        if gauges.is_empty() {
            return refuse("needs a wave gauge (`[[probe]]` with `field = \"elevation\"`) beyond the piston's face");
        }
        Ok(Flume {
            frequency: 2.0 * PI / period,
            amplitude,
            depth,
            gravity,
            density: scene.fluids[block.fluid].density,
            piston: index,
            width: if scene.dimensions == 3 {
                bounds.max[2] - bounds.min[2]
            } else {
                1.0
            },
            length: scene.container.max[0] - face,
            gauges,
        })
    }

    /// k of ω² = g k tanh(kh), by Newton's method from the deep- or shallow-water guess.
    pub fn wavenumber(&self) -> f64 {
        let (w2, g, h) = (self.frequency.powi(2), self.gravity, self.depth);
        let mut k = (w2 / g).max(self.frequency / (g * h).sqrt());
        for _ in 0..50 {
            let t = (k * h).tanh();
            let f = g * k * t - w2;
            let df = g * (t + k * h * (1.0 - t * t));
            k -= f / df;
        }
        k
    }

    /// Biesel's first-order wave height of the piston's stroke.
    pub fn reference_height(&self) -> f64 {
        let kh2 = 2.0 * self.wavenumber() * self.depth;
        let stroke = 2.0 * self.amplitude.abs();
        stroke * 2.0 * (kh2.cosh() - 1.0) / (kh2.sinh() + kh2)
    }

    /// The linear wave maker's force on the piston along x (Havelock 1929; Dean & Dalrymple
    /// 1991, §6.2): the mean, the water's hydrostatic thrust −ρ g h²/2, and the first harmonic
    /// [F_c, F_s] of F_c cos ωt + F_s sin ωt, the dynamic pressure −ρ ∂φ/∂t over the face, all
    /// times the width. The potential that moves the face at aω cos ωt is the progressive wave
    /// and the evanescent modes cos k_n(z + h) e^(−k_n x), ω² = −g k_n tan k_n h; projected on
    /// them, F_c = −4ρω²a sinh² kh / (k² (2kh + sinh 2kh)), in phase with the velocity (the
    /// wave the piston radiates), and F_s = 4ρω²a Σ sin² k_n h / (k_n² (2k_n h + sin 2k_n h)),
    /// against the acceleration (the added mass).
    pub fn paddle_force(&self) -> (f64, [f64; 2]) {
        let (h, w2) = (self.depth, self.frequency.powi(2));
        let scale = 4.0 * self.density * w2 * self.amplitude * self.width;
        let k = self.wavenumber();
        let kh = k * h;
        let radiated = -scale * kh.sinh().powi(2) / (k * k * (2.0 * kh + (2.0 * kh).sinh()));
        let added: f64 = (1..=EVANESCENT_MODES)
            .map(|n| {
                let kn = self.evanescent_wavenumber(n);
                let knh = kn * h;
                knh.sin().powi(2) / (kn * kn * (2.0 * knh + (2.0 * knh).sin()))
            })
            .sum();
        let thrust = -0.5 * self.density * self.gravity * h * h * self.width;
        (thrust, [radiated, scale * added])
    }

    /// k_n of ω² = −g k_n tan(k_n h) in ((n − ½)π/h, nπ/h), where the right side rises from −∞
    /// to 0, by bisection.
    fn evanescent_wavenumber(&self, n: usize) -> f64 {
        let (h, w2, g) = (self.depth, self.frequency.powi(2), self.gravity);
        let (mut lo, mut hi) = ((n as f64 - 0.5) * PI / h, n as f64 * PI / h);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if w2 + g * mid * (mid * h).tan() > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// c_g = (ω/k)(1 + 2kh/sinh 2kh)/2.
    pub fn group_velocity(&self) -> f64 {
        let k = self.wavenumber();
        let kh2 = 2.0 * k * self.depth;
        0.5 * self.frequency / k * (1.0 + kh2 / kh2.sinh())
    }

    /// The window of whole periods a gauge `distance` from the piston is read over in a run that
    /// ends at `end`: the latest that ends before the far wall's reflection of the fastest
    /// waves (√(gh)) arrives and starts `SETTLING_PERIODS` after the wave train's front (c_g);
    /// none shorter than two periods.
    pub fn window(&self, distance: f64, end: f64) -> Option<(f64, f64)> {
        let (period, cg) = (2.0 * PI / self.frequency, self.group_velocity());
        let fastest = (self.gravity * self.depth).sqrt();
        let start = distance / cg + SETTLING_PERIODS * period;
        let stop = ((2.0 * self.length - distance) / fastest).min(end);
        let periods = ((stop - start) / period).floor();
        (periods >= 2.0).then_some((stop - periods * period, stop))
    }
}

/// The first harmonic's height at ω, 2√(a² + b²), of the least-squares fit of a₀ + a cos ωt +
/// b sin ωt to `samples` (t, η).
pub fn first_harmonic_height(samples: &[(f64, f64)], frequency: f64) -> f64 {
    let [_, a, b] = first_harmonic(samples, frequency);
    2.0 * a.hypot(b)
}

/// [a₀, a, b] of the least-squares fit of a₀ + a cos ωt + b sin ωt to `samples` (t, y).
fn first_harmonic(samples: &[(f64, f64)], frequency: f64) -> [f64; 3] {
    // Normal equations of the three functions [1, cos, sin].
    let mut m = [[0.0; 3]; 3];
    let mut r = [0.0; 3];
    for &(t, eta) in samples {
        let f = [1.0, (frequency * t).cos(), (frequency * t).sin()];
        for i in 0..3 {
            r[i] += f[i] * eta;
            for j in 0..3 {
                m[i][j] += f[i] * f[j];
            }
        }
    }
    // Symmetric positive definite for samples that span a period.
    apply(&inverse_on_span(&m), r)
}

/// The piston's force in `run_dir`'s bodies.csv against `Flume::paddle_force`: the mean's
/// relative error, the first harmonic's amplitude's, and its phase's [degrees, in (−180, 180]];
/// NaN without four rows a period over the window.
fn paddle_force_errors(flume: &Flume, run_dir: &Path) -> Result<[f64; 3], ValidationError> {
    let rows = bodies_csv::read(run_dir)?;
    let end = rows.last().map_or(0.0, |r| r.0);
    let period = 2.0 * PI / flume.frequency;
    let Some((start, stop)) = flume.window(0.0, end) else {
        return Ok([f64::NAN; 3]);
    };
    let samples: Vec<(f64, f64)> = rows
        .iter()
        .filter(|(t, b, _)| *b == flume.piston && (start..=stop).contains(t))
        .map(|(t, _, numbers)| (*t, numbers[bodies_csv::FX]))
        .collect();
    if (samples.len() as f64) < 4.0 * (stop - start) / period {
        return Ok([f64::NAN; 3]);
    }
    let [mean, c, s] = first_harmonic(&samples, flume.frequency);
    let (thrust, [tc, ts]) = flume.paddle_force();
    let phase = (s.atan2(c) - ts.atan2(tc)).to_degrees();
    let phase = phase - 360.0 * (phase / 360.0).round();
    Ok([mean / thrust - 1.0, c.hypot(s) / tc.hypot(ts) - 1.0, phase])
}

pub fn measure(scene: &Scene, run_dir: &Path) -> Result<Measured, ValidationError> {
    let flume = Flume::of(scene)?;
    let probes = ProbeCurves::read(Case::WaveFlume, run_dir)?;
    let end = probes.end();
    let reference = flume.reference_height();
    let mut errors = Vec::new();
    for (name, distance) in &flume.gauges {
        let curve = probes.curve(name)?;
        let Some((start, stop)) = flume.window(*distance, end) else {
            continue;
        };
        let samples: Vec<(f64, f64)> = curve
            .into_iter()
            .filter(|(t, _)| (start..=stop).contains(t))
            .collect();
        if samples.iter().any(|s| !s.1.is_finite()) {
            return Err(probes.error(format!(
                "the gauge {name} reads no water (NaN) between t = {start} and {stop} s"
            )));
        }
        let height = first_harmonic_height(&samples, flume.frequency);
        errors.push(height / reference - 1.0);
    }
    if errors.is_empty() {
        return Err(probes.error(format!(
            "the run, to t = {end} s, or the flume holds less than two whole periods at every gauge between the wave train's front (at c_g = {:.3} m/s, plus {SETTLING_PERIODS} periods) and the far wall's reflection (at √(gh) = {:.3} m/s): a longer run or flume, or a gauge nearer the piston",
            flume.group_velocity(),
            (flume.gravity * flume.depth).sqrt()
        )));
    }
    let n = errors.len() as f64;
    let mean_abs = errors.iter().map(|e| e.abs()).sum::<f64>() / n;
    let [force_mean, force_amplitude, force_phase] = paddle_force_errors(&flume, run_dir)?;
    let values = [
        reference,
        2.0 * PI / flume.wavenumber(),
        n,
        errors.iter().copied().fold(f64::INFINITY, f64::min),
        errors.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        errors.iter().sum::<f64>() / n,
        force_mean,
        force_amplitude,
        force_phase,
    ];
    Ok(Measured::new(mean_abs, &DETAILS, &values))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Biesel's height and the dispersion relation at the shipped flume's kh = 1.037 (T = 1 s,
    /// h = 0.2 m): L = 1.2124 m, H/S = 1.0151, c_g = 0.9274 m/s (computed independently).
    #[test]
    fn linear_theory_of_the_shipped_flume() {
        let flume = Flume {
            frequency: 2.0 * PI,
            amplitude: 0.5,
            depth: 0.2,
            gravity: 9.81,
            density: 1000.0,
            piston: 0,
            width: 1.0,
            length: 4.41,
            gauges: Vec::new(),
        };
        assert!((2.0 * PI / flume.wavenumber() - 1.212369).abs() < 1e-6);
        assert!((flume.reference_height() - 1.015056).abs() < 1e-6);
        assert!((flume.group_velocity() - 0.927450).abs() < 1e-6);
        // The wave maker's force for a = 0.5 m (the same series in another implementation:
        // F_c = −745.984, F_s = 5.51078, per metre of width).
        let (thrust, [c, s]) = flume.paddle_force();
        assert!((thrust + 196.2).abs() < 1e-9);
        assert!((c + 745.9844).abs() < 1e-3 && (s - 5.51078).abs() < 1e-4);
        // In shallow water the piston radiates the long wave ρ c h U, c = √(gh), and sees no
        // added mass: kh = 0.02.
        let shallow = Flume {
            frequency: 2.0 * PI / 10.0,
            depth: 0.01,
            ..flume.clone()
        };
        let (_, [c, s]) = shallow.paddle_force();
        let long_wave = -1000.0 * 0.5 * shallow.frequency * 0.01 * (9.81f64 * 0.01).sqrt();
        assert!((c / long_wave - 1.0).abs() < 1e-3 && s.abs() < 1e-3 * c.abs());
        // A sinusoid of height 0.03 m on a mean of 0.2 m, with a second harmonic, sampled over
        // three periods: its first harmonic's height.
        let samples: Vec<(f64, f64)> = (0..300)
            .map(|i| {
                let t = 4.0 + 3.0 * i as f64 / 300.0;
                (
                    t,
                    0.2 + 0.015 * (2.0 * PI * t + 0.4).sin() + 0.002 * (4.0 * PI * t).cos(),
                )
            })
            .collect();
        assert!((first_harmonic_height(&samples, 2.0 * PI) - 0.03).abs() < 1e-9);
    }
}
