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

use super::{first_block, unsuitable, vertical, Case, Measured, ProbeCurves, ValidationError};
use crate::math::rotation::{apply, inverse_on_span};
use crate::scene::trajectory::Path as Motion;
use crate::scene::{BodyMotion, ProbeField, Scene};
use std::f64::consts::PI;
use std::path::Path;

pub const DETAILS: [&str; 6] = [
    "reference_height",
    "wavelength",
    "gauges",
    "height_error_min",
    "height_error_max",
    "height_error_mean",
];

/// Periods after a gauge's front has passed before its window may start.
const SETTLING_PERIODS: f64 = 2.0;

/// The flume of a scene: the wave maker's motion, the water, and the gauges' distances from
/// the piston's face.
#[derive(Clone, Debug)]
pub struct Flume {
    /// ω [rad/s] and the stroke S [m].
    pub frequency: f64,
    pub stroke: f64,
    /// h [m] and |g| [m/s²].
    pub depth: f64,
    pub gravity: f64,
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
            .filter_map(|b| match &b.motion {
                BodyMotion::Prescribed(t) => Some((b, t)),
                _ => None,
            })
            .collect();
        let [(piston, trajectory)] = pistons[..] else {
            return refuse("needs one prescribed body, the piston");
        };
        let (amplitude, period) = match &trajectory.path {
            Motion::Sinusoid {
                amplitude,
                angle,
                period,
            } if *angle == 0.0 && amplitude[1..].iter().all(|&a| a == 0.0) && amplitude[0] != 0.0 => {
                (amplitude[0].abs(), *period)
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
        let face = piston.shape.bounds().max[0];
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
            stroke: 2.0 * amplitude,
            depth,
            gravity,
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
        self.stroke * 2.0 * (kh2.cosh() - 1.0) / (kh2.sinh() + kh2)
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
    let c = apply(&inverse_on_span(&m), r);
    2.0 * c[1].hypot(c[2])
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
    let values = [
        reference,
        2.0 * PI / flume.wavenumber(),
        n,
        errors.iter().copied().fold(f64::INFINITY, f64::min),
        errors.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        errors.iter().sum::<f64>() / n,
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
            stroke: 1.0,
            depth: 0.2,
            gravity: 9.81,
            length: 4.41,
            gauges: Vec::new(),
        };
        assert!((2.0 * PI / flume.wavenumber() - 1.212369).abs() < 1e-6);
        assert!((flume.reference_height() - 1.015056).abs() < 1e-6);
        assert!((flume.group_velocity() - 0.927450).abs() < 1e-6);
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
