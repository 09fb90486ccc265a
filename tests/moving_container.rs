//! A moving container, solved in its frame (docs/bodies.md, "Moving containers"): a tank tilted
//! slowly keeps its water level in the laboratory; the SPHERIC 10 sloshing tank, rolled by the
//! experiment's roll, hits its wall when the experiment's does.

use crate::common::{over_draws, read_frame, run_scene, shipped_scene, tank, TempDir};
use isph::io::probes;
use isph::tools::validation::dam_break::slope;
use isph::Scene;

/// The slope of the free surface in frame `frame`: a line through the top fluid particle of
/// each column two spacings wide, 5 cm and more from the side walls of a tank `width` wide.
fn surface_slope(out: &std::path::Path, frame: usize, spacing: f64, width: f64) -> f64 {
    let kind: Vec<i32> = read_frame(out, frame, "kind");
    let pos: Vec<f64> = read_frame(out, frame, "position");
    let mut tops = std::collections::BTreeMap::new();
    for i in (0..kind.len()).filter(|&i| kind[i] == 0) {
        let top = tops
            .entry((pos[3 * i] / (2.0 * spacing)).floor() as i64)
            .or_insert(f64::MIN);
        *top = pos[3 * i + 1].max(*top);
    }
    let points: Vec<(f64, f64)> = tops
        .iter()
        .map(|(c, y)| ((*c as f64 + 0.5) * 2.0 * spacing, *y))
        .filter(|(x, _)| *x > 0.05 && *x < width - 0.05)
        .collect();
    slope(&points)
}

#[test]
fn a_tank_tilted_slowly_keeps_its_water_level_in_the_laboratory() {
    // Tilted to 10° along a table (a half-cosine ramp over 2 s, then held): in the tank's frame
    // the surface must slope at −tan 10°, the laboratory's level. The ramp leaves a slosh of
    // the first mode (period 0.99 s); the mean over 3–4 s takes it out.
    let dir = TempDir::new("moving-tilt");
    let mut table = String::from("time,x,y,angle\n");
    for k in -2..=40 {
        let t = k as f64 * 0.05;
        let ramp = 0.5 * (1.0 - (std::f64::consts::PI * t.clamp(0.0, 2.0) / 2.0).cos());
        table += &format!("{t:?},0,0,{:?}\n", 10.0 * ramp);
    }
    table += "10.0,0,0,10.0\n";
    std::fs::write(dir.path().join("tilt.csv"), table).unwrap();
    let trajectory = "[container.trajectory]\npivot = [0.3, 0.0]\ntable = \"tilt.csv\"\n";
    let text = tank(2, 0.01, [0.6, 0.4, 0.0], 0.2, 0.05, trajectory);
    let path = dir.path().join("tilt.toml");
    std::fs::write(&path, text).unwrap();
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("out");
    run_scene(&scene, &out, 4.0);
    let slopes: Vec<f64> = (60..=80)
        .map(|f| surface_slope(&out, f, 0.01, 0.6))
        .collect();
    let slope = slopes.iter().sum::<f64>() / slopes.len() as f64;
    let expected = -(10f64.to_radians().tan());
    eprintln!("slope {slope} against {expected}");
    assert!(
        (slope / expected - 1.0).abs() < 0.03,
        "mean surface slope {slope} over 3–4 s against −tan 10° = {expected}"
    );
}

#[test]
fn the_spheric_10_tank_hits_its_wall_near_the_experiments_onsets() {
    // The experiment's impact onsets (pressure above 1 kPa on the left-wall sensor) are 2.375
    // and 4.050 s, the benchmark's tolerance 0.03 s. The scene rolls the tank by the
    // experiment's roll (tools/spheric10_roll.py). A run is one draw of the bore that breaks
    // against the wall: frames every 0.05 (the scene's), 0.04 and 0.03 s land other steps on
    // them, and the second onset moves by 0.03 s between draws; so the median of three.
    // Measured (the first sample above 1 kPa): −0.0047 / −0.0007 / −0.0038 s and −0.0515 /
    // −0.0196 / −0.0474 s, medians −0.0038 and −0.0474 s (docs/bodies.md, "SPHERIC benchmark
    // 10": over six trajectories at this spacing the second comes 0.020–0.052 s early, median
    // 0.048 s; at 3.1 mm the median is within the 0.03 s); the bound on the second holds it there.
    let scene = shipped_scene("sloshing_spheric10_2d.toml");
    let draws = over_draws(&scene, &[0.05, 0.04, 0.03], |scene| {
        let dir = TempDir::new("moving-spheric10");
        run_scene(scene, dir.path(), 4.2);
        let onsets = impact_onsets(dir.path());
        assert_eq!(onsets.len(), 2, "impact onsets {onsets:?}");
        onsets
    });
    for (k, (expected, bound)) in [(2.375, 0.03), (4.050, 0.05)].into_iter().enumerate() {
        let mut onsets: Vec<f64> = draws.iter().map(|d| d[k]).collect();
        onsets.sort_by(f64::total_cmp);
        assert!(
            (onsets[1] - expected).abs() < bound,
            "impact {}: onsets {onsets:?} s, median against the experiment's {expected} s",
            k + 1
        );
    }
}

#[test]
fn the_3d_spheric_10_tank_hits_its_wall_near_the_experiments_first_onset() {
    // The shipped 3D tank (the 2D scene across the experiment's 62 mm) at 15.5 mm, which fits
    // the depth (6 particles) and the thickness (4) exactly (1,392 fluid particles), to its
    // first impact: the benchmark's 0.03 s. Measured (the first sample above 1 kPa): 2.3581 s,
    // 0.017 s early. At the shipped 6.2 mm three trajectories read 0.008–0.016 s early
    // (docs/bodies.md, "SPHERIC benchmark 10").
    let dir = TempDir::new("moving-spheric10-3d");
    let mut scene = shipped_scene("sloshing_spheric10_3d.toml");
    scene.spacing = 0.0155;
    run_scene(&scene, dir.path(), 2.6);
    let onsets = impact_onsets(dir.path());
    assert_eq!(onsets.len(), 1, "impact onsets {onsets:?}");
    assert!(
        (onsets[0] - 2.375).abs() < 0.03,
        "an impact at {} s against the experiment's 2.375 s",
        onsets[0]
    );
}

/// The times at which the probe `sensor` of the run in `out` first reads above 1 kPa in each
/// impact (impacts at least 0.8 s apart; the benchmark's onset).
fn impact_onsets(out: &std::path::Path) -> Vec<f64> {
    let (columns, rows) = probes::read(out).unwrap();
    let sensor = columns.iter().position(|c| c == "sensor").unwrap();
    let mut onsets: Vec<f64> = Vec::new();
    for r in &rows {
        let (t, p) = (r[0], r[sensor]);
        if p > 1000.0 && onsets.last().is_none_or(|last| t > last + 0.8) {
            onsets.push(t);
        }
    }
    eprintln!("onsets {onsets:?}");
    onsets
}

#[test]
fn the_first_sloshing_mode_keeps_the_period_of_linear_theory_in_shallow_water() {
    // SPHERIC 10's water: 0.9 m long, 0.093 m deep (kh = 0.32), 15 particles in the depth.
    // Before the free-surface rows carried the surface's thickness and the dynamic pressure
    // between the particle and the surface: +1.55%, the period of water half a spacing
    // shallower. Measured: −0.05%.
    let error = first_mode_period_error(0.093, 0.2);
    assert!(
        error.abs() < 0.005,
        "the first mode's period off linear theory's by {error:+.4}"
    );
}

#[test]
fn the_first_sloshing_mode_keeps_the_period_of_linear_theory_in_deeper_water() {
    // The same tank twice as deep (kh = 0.65), 30 particles in the depth, where the dynamic
    // pressure over the surface particle's half spacing weighs as much as the thickness: +0.61%
    // with neither, −0.34% with the thickness alone. Measured: −0.05%.
    let error = first_mode_period_error(0.186, 0.1);
    assert!(
        error.abs() < 0.0025,
        "the first mode's period off linear theory's by {error:+.4}"
    );
}

/// The relative error of the first sloshing mode's period against linear theory,
/// T1 = 2π/√(g k tanh kh), k = π/L, in a tank 0.9 m long holding water `depth` deep at
/// dx = 6.2 mm. The tank is tilted about the middle of its floor to `tilt` degrees and back over
/// one period T1, from rest to rest (a start at a finite roll rate would leave the water turning
/// with the tank's first rotation: Kelvin's theorem in the tank's frame), then left to slosh.
/// The period is read off the difference of the pressures at the foot of the two end walls,
/// which holds the antisymmetric modes only (the first, and the third at about 1% of its
/// amplitude): twice the mean spacing of its zero crossings from T1 + 0.3 s to 8 s, the signal
/// smoothed over 0.1 s first (docs/bodies.md, "Sloshing period").
fn first_mode_period_error(depth: f64, tilt: f64) -> f64 {
    let (length, spacing) = (0.9, 0.0062);
    let k = std::f64::consts::PI / length;
    let period = 2.0 * std::f64::consts::PI / (9.81 * k * (k * depth).tanh()).sqrt();
    // One directory per depth: the two tests run at once in one process.
    let dir = TempDir::new(&format!("moving-sloshing-period-{depth}"));
    let mut table = String::from("time,x,y,angle\n");
    for step in 0..=1000 {
        let t = step as f64 * 0.01;
        let angle = if t < period {
            0.5 * tilt * (1.0 - (2.0 * std::f64::consts::PI * t / period).cos())
        } else {
            0.0
        };
        table += &format!("{t:?},0,0,{angle:?}\n");
    }
    std::fs::write(dir.path().join("roll.csv"), table).unwrap();
    let sections = format!(
        "[container.trajectory]\npivot = [{:?}, 0.0]\ntable = \"roll.csv\"\n\n\
         [[probe]]\nname = \"left\"\npoint = [0.0, {:?}]\nfield = \"pressure\"\n\n\
         [[probe]]\nname = \"right\"\npoint = [{length:?}, {:?}]\nfield = \"pressure\"\n",
        0.5 * length,
        0.5 * spacing,
        0.5 * spacing
    );
    let path = dir.path().join("sloshing.toml");
    let size = [length, depth + 0.12, 0.0];
    std::fs::write(&path, tank(2, spacing, size, depth, 1.0, &sections)).unwrap();
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("out");
    run_scene(&scene, &out, 8.0);
    let (columns, rows) = probes::read(&out).unwrap();
    let column = |name: &str| columns.iter().position(|c| c == name).unwrap();
    let (left, right) = (column("left"), column("right"));
    let measured = 2.0 * mean_zero_crossing_spacing(&rows, period + 0.3, |r| r[left] - r[right]);
    eprintln!("first mode: {measured} s against {period} s");
    measured / period - 1.0
}

/// The mean spacing of the zero crossings after `from` of the signal `f` of the probes.csv
/// rows (time first), resampled every 5 ms, less its mean and smoothed over 0.1 s: the
/// least-squares slope of the crossing times against their count.
fn mean_zero_crossing_spacing(rows: &[Vec<f64>], from: f64, f: impl Fn(&[f64]) -> f64) -> f64 {
    let (dt, window) = (0.005, 20);
    let end = rows.last().unwrap()[0];
    let mut k = 0;
    let samples: Vec<f64> = (0..)
        .map(|n| from + n as f64 * dt)
        .take_while(|&t| t <= end)
        .map(|t| {
            while rows[k + 1][0] < t {
                k += 1;
            }
            let (a, b) = (&rows[k], &rows[k + 1]);
            let s = (t - a[0]) / (b[0] - a[0]);
            (1.0 - s) * f(a) + s * f(b)
        })
        .collect();
    let smooth: Vec<f64> = samples
        .windows(window)
        .map(|w| w.iter().sum::<f64>() / window as f64)
        .collect();
    let mean = smooth.iter().sum::<f64>() / smooth.len() as f64;
    let crossings: Vec<f64> = smooth
        .windows(2)
        .enumerate()
        .filter(|(_, w)| (w[0] - mean) * (w[1] - mean) < 0.0)
        .map(|(n, w)| (n as f64 + (mean - w[0]) / (w[1] - w[0])) * dt)
        .collect();
    assert!(crossings.len() >= 4, "{} zero crossings", crossings.len());
    let numbered: Vec<(f64, f64)> = crossings
        .iter()
        .enumerate()
        .map(|(n, &t)| (n as f64, t))
        .collect();
    slope(&numbered)
}
