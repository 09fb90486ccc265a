//! The pure parts of the error measures (`isph::tools::validation`): synthetic fronts, frames and
//! columns with known answers.

use isph::io::frames::Frame;
use isph::tools::validation::dam_break::{
    experiment_speed, front_speed, interpolate, lead, pick_frames, relative_errors, shifted_rms,
    speed, Column, MARTIN_MOYCE_FRONT,
};
use isph::tools::validation::hydrostatic::WaterColumn;
use isph::tools::validation::Case;

/// A frame of fluid particles (kind 0) at `points` (x, y), plus one wall particle far away.
fn frame(points: &[(f64, f64)]) -> Frame {
    let mut position: Vec<[f64; 3]> = points.iter().map(|&(x, y)| [x, y, 0.0]).collect();
    position.push([100.0, 100.0, 0.0]);
    let n = position.len();
    let mut kind = vec![0; n];
    kind[n - 1] = 1;
    Frame {
        time: 0.0,
        position,
        velocity: vec![[0.0; 3]; n],
        pressure: vec![0.0; n],
        density: vec![1000.0; n],
        kind,
        fluid: vec![0; n],
        free_surface: vec![0; n],
    }
}

fn column() -> Column {
    Column {
        vertical: 1,
        back: -0.5,
        width: 2.0,
        height: 4.0,
        floor: 1.0,
        time_scale: 1.0,
        far_wall: 20.0,
    }
}

#[test]
fn case_names_round_trip_and_unknown_names_are_listed() {
    for case in Case::ALL {
        assert_eq!(case.name().parse::<Case>().unwrap(), case);
    }
    let e = "couette".parse::<Case>().unwrap_err().to_string();
    assert!(
        e.contains("\"hydrostatic\", \"dam_break_front\", \"poiseuille\", \"taylor_green\""),
        "{e}"
    );
}

#[test]
fn front_and_column_height_ignore_walls_and_count_from_the_back_wall() {
    let c = column();
    // Fronts at x = 3.5 (4 from the back wall: Z = 2); near the wall (x − back < a/4 = 0.5)
    // the highest particle is at y = 3 (2 above the floor: half the initial height).
    let f = frame(&[(-0.4, 3.0), (0.2, 4.5), (3.5, 1.1), (1.0, 1.5)]);
    assert_eq!(c.front(&f), 2.0);
    assert_eq!(c.height_at_wall(&f), 0.5);
}

#[test]
fn the_front_is_the_water_body_not_spray_ahead_of_it() {
    let c = column();
    let mut f = frame(&[(3.5, 1.1), (1.0, 1.5), (7.5, 1.05)]);
    // The particle at x = 7.5 slid off the tip: the solver flagged it as spray (code 2).
    f.free_surface[2] = 2;
    assert_eq!(c.front(&f), 2.0);
    f.free_surface[2] = 1;
    assert_eq!(c.front(&f), 4.0);
}

#[test]
fn a_front_on_the_tabulated_curve_has_no_error_and_a_late_one_its_lag() {
    let times: Vec<f64> = (0..=45).map(|k| 0.1 * k as f64).collect();
    let picks = pick_frames(&times, &MARTIN_MOYCE_FRONT).unwrap();
    // Reached: the points up to T = 4.418 (within MAX_GAP of the last frame, 4.5).
    assert_eq!(picks.len(), 7);
    for &(k, f) in &picks {
        assert!((times[f] - MARTIN_MOYCE_FRONT[k].0).abs() <= 0.05 + 1e-12);
    }
    let exact: Vec<(f64, f64)> = MARTIN_MOYCE_FRONT.iter().map(|&(_, z)| (z, z)).collect();
    assert!(relative_errors(&exact).iter().all(|&e| e == 0.0));
    let ahead: Vec<(f64, f64)> = MARTIN_MOYCE_FRONT
        .iter()
        .map(|&(_, z)| (1.1 * z, z))
        .collect();
    assert!(relative_errors(&ahead)
        .iter()
        .all(|&e| (e - 0.1).abs() < 1e-12));
}

#[test]
fn sparse_frames_are_refused_and_a_short_run_compares_nothing() {
    let sparse: Vec<f64> = (0..=10).map(|k| 0.5 * k as f64).collect();
    let gap = pick_frames(&sparse, &MARTIN_MOYCE_FRONT).unwrap_err();
    assert_eq!(gap.t_ref, 0.832);
    assert_eq!(gap.nearest, 1.0);
    assert!(pick_frames(&[0.0, 0.1, 0.2], &MARTIN_MOYCE_FRONT)
        .unwrap()
        .is_empty());
}

#[test]
fn the_container_bounds_the_points_compared() {
    // A far wall 7 widths away (dam_break_2d.toml): fronts up to Z = 6.3.
    let c = Column {
        far_wall: 7.0,
        ..column()
    };
    let reference = c.reference();
    assert_eq!(reference.len(), 7);
    assert!(reference.iter().all(|&(_, z)| z <= 6.3));
}

/// A front (T, Z) every 0.1 in T from 0 to 10, Z = `z(T)`.
fn sampled_front(z: impl Fn(f64) -> f64) -> Vec<(f64, f64)> {
    (0..=100)
        .map(|k| {
            let t = 0.1 * k as f64;
            (t, z(t))
        })
        .collect()
}

#[test]
fn the_speed_is_the_slope_inside_the_window_only() {
    // Z = 1 + 1.7 T between T = 1.6 and 3.3, anything else outside.
    let front = sampled_front(|t| {
        if (1.55..3.35).contains(&t) {
            1.0 + 1.7 * t
        } else {
            100.0 * t
        }
    });
    assert!((speed(&front) - 1.7).abs() < 1e-12);
    // The experiment's points inside the window: T = 1.997 and 2.547 only.
    let chord = (2.995 - 2.292) / (2.547 - 1.997);
    assert!((experiment_speed() - chord).abs() < 1e-12);
    assert!((experiment_speed() - 1.278).abs() < 5e-4);
}

#[test]
fn the_front_speed_needs_the_compared_points_to_pass_the_window() {
    let front = sampled_front(|t| 1.0 + 1.5 * t);
    assert!((front_speed(&front, &MARTIN_MOYCE_FRONT[..5]) - 1.5).abs() < 1e-12);
    // The fourth point is at T = 2.547: the run, or the tank, stopped inside the window.
    assert!(front_speed(&front, &MARTIN_MOYCE_FRONT[..4]).is_nan());
}

#[test]
fn the_front_is_linear_between_frames_and_held_outside_them() {
    let front = [(0.0, 1.0), (1.0, 3.0), (2.0, 3.5)];
    assert_eq!(interpolate(&front, -1.0), 1.0);
    assert_eq!(interpolate(&front, 0.25), 1.5);
    assert_eq!(interpolate(&front, 1.0), 3.0);
    assert_eq!(interpolate(&front, 1.5), 3.25);
    assert_eq!(interpolate(&front, 7.0), 3.5);
}

/// The experiment's curve run `tau` earlier: a frame at each of its times less `tau` (so that
/// the frames hold every corner of the shifted curve), after the standing column at T = 0.
fn experiment_shifted(tau: f64) -> Vec<(f64, f64)> {
    let mut front = vec![(0.0, 1.0)];
    front.extend(MARTIN_MOYCE_FRONT.iter().map(|&(t, z)| (t - tau, z)));
    front
}

#[test]
fn the_lead_of_the_experiment_run_early_or_late_is_that_shift() {
    for tau in [0.3, 0.137, 0.03, -0.2] {
        let front = experiment_shifted(tau);
        let found = lead(&front, &MARTIN_MOYCE_FRONT);
        assert!((found - tau).abs() < 1e-6, "shift {tau}: lead {found}");
        assert!(shifted_rms(&front, &MARTIN_MOYCE_FRONT, found) < 1e-5);
        assert!(shifted_rms(&front, &MARTIN_MOYCE_FRONT, 0.0) > 0.02);
    }
    // Shifted by less than 0.045 ahead or 0.38 behind, the window holds the same two points
    // as the experiment's: the same speed.
    for tau in [0.03, -0.2] {
        assert!((speed(&experiment_shifted(tau)) - experiment_speed()).abs() < 1e-12);
    }
}

#[test]
fn the_lead_falls_between_frames_and_scan_points() {
    // A front at 1.5 a per unit T, 0.137 ahead, sampled every 0.1 (the frames of a run).
    let front = sampled_front(|t| 1.0 + 1.5 * (t + 0.137));
    let reference: Vec<(f64, f64)> = MARTIN_MOYCE_FRONT
        .iter()
        .map(|&(t, _)| (t, 1.0 + 1.5 * t))
        .collect();
    let found = lead(&front, &reference);
    assert!((found - 0.137).abs() < 1e-6, "lead {found}");
    assert!((shifted_rms(&front, &reference, 0.0) - 1.5 * 0.137).abs() < 1e-12);
}

#[test]
fn hydrostatic_errors_of_an_exact_and_a_shifted_column() {
    let c = WaterColumn {
        rho_g: 1000.0 * 9.81,
        floor: 0.0,
        top: 1.0,
    };
    let exact: Vec<(f64, f64)> = (0..20)
        .map(|k| {
            let y = 0.025 + 0.05 * k as f64;
            (y, c.rho_g * (1.0 - y))
        })
        .collect();
    assert!(c.rms_error(&exact).unwrap() < 1e-12);
    assert!(c.bottom_error(&exact, 0.05).unwrap().abs() < 1e-12);
    // 1% of ρgH too much everywhere, the surface layer (top 15%) excepted from the rms.
    let high: Vec<(f64, f64)> = exact
        .iter()
        .map(|&(y, p)| (y, p + 0.01 * c.floor_pressure()))
        .collect();
    assert!((c.rms_error(&high).unwrap() - 0.01).abs() < 1e-12);
    assert!((c.bottom_error(&high, 0.05).unwrap() - 0.01).abs() < 1e-12);
    assert!(c.rms_error(&[(0.95, 0.0)]).is_none());
}

/// `measure` refuses a run made from another scene (it measured one against the other and
/// reported a meaningless error) and accepts the run's own scene with another end time.
#[test]
fn a_run_is_measured_only_against_its_own_scene() {
    let dir = crate::common::TempDir::new("measure-own-scene");
    let scene = crate::common::shipped_scene("hydrostatic_2d.toml");
    crate::common::run_scene(&scene, dir.path(), 0.02);
    let mut longer = scene.clone();
    longer.end_time *= 2.0;
    assert!(isph::tools::validation::measure(Case::Hydrostatic, &longer, dir.path()).is_ok());
    let mut other = scene.clone();
    other.solver.alpha = 0.2;
    let e = isph::tools::validation::measure(Case::Hydrostatic, &other, dir.path()).unwrap_err();
    assert!(e.to_string().contains("another scene"), "{e}");
}

#[test]
fn lobovsky_onset_and_plateau_of_a_known_curve() {
    use isph::tools::validation::lobovsky::{onset, window_mean};
    let curve = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.2), (4.0, 0.6), (6.0, 0.6)];
    assert!((onset(&curve, 0.1).unwrap() - 1.5).abs() < 1e-12);
    assert_eq!(onset(&curve, 1.0), None);
    // (0.55 × 0.5 + 0.6 × 1.5) / 2
    assert!((window_mean(&curve, (3.5, 5.5)).unwrap() - 0.5875).abs() < 1e-12);
    assert_eq!(window_mean(&curve, (3.5, 6.5)), None);
}

/// The experiment's onsets and plateaus, and its gauges' mean levels, as docs/accuracy.md gives
/// them.
#[test]
fn lobovsky_experiment_onsets_and_plateaus() {
    use isph::tools::validation::lobovsky::{
        onset, window_mean, GAUGES, LEVEL_WINDOW, ONSET_LEVEL, PLATEAU, SENSORS,
    };
    let expected = [
        (2.408, 0.594),
        (2.458, 0.662),
        (2.517, 0.585),
        (2.763, 0.520),
    ];
    for (gauge, h) in GAUGES.iter().zip([0.6499, 0.2267, 0.1491, 0.1021]) {
        let level = window_mean(&gauge.curve(), LEVEL_WINDOW).unwrap();
        assert!((level - h).abs() < 5e-4, "{}: level {level}", gauge.name);
    }
    for (sensor, (t, p)) in SENSORS.iter().zip(expected) {
        let curve = sensor.curve();
        let on = onset(&curve, ONSET_LEVEL).unwrap();
        let plateau = window_mean(&curve, PLATEAU).unwrap();
        assert!((on - t).abs() < 5e-4, "{}: onset {on}", sensor.name);
        assert!(
            (plateau - p).abs() < 5e-4,
            "{}: plateau {plateau}",
            sensor.name
        );
    }
}

#[test]
fn a_scene_without_the_sensors_is_not_measured_against_lobovsky() {
    let mut scene = crate::common::shipped_scene("dam_break_lobovsky_2d.toml");
    isph::tools::validation::check(Case::LobovskyPressure, &scene).unwrap();
    scene.probes[3].point[1] = 0.1;
    let e = isph::tools::validation::check(Case::LobovskyPressure, &scene).unwrap_err();
    assert!(e.to_string().contains("probe P4 is at [1.61, 0.1]"), "{e}");
    scene.probes.remove(0);
    let e = isph::tools::validation::check(Case::LobovskyPressure, &scene).unwrap_err();
    assert!(e.to_string().contains("no pressure probe named P1"), "{e}");
}

/// The experiment's tank in 3D is measured as the 2D scene is: the sensors' heights along z.
#[test]
fn the_experiments_tank_in_3d_is_measured_as_the_2d_scene() {
    let mut scene = crate::common::shipped_scene("dam_break_lobovsky_3d.toml");
    isph::tools::validation::check(Case::LobovskyPressure, &scene).unwrap();
    scene.probes[1].point[2] = 0.03;
    let e = isph::tools::validation::check(Case::LobovskyPressure, &scene).unwrap_err();
    assert!(
        e.to_string().contains("probe P2 is at [1.61, 0.075, 0.03]"),
        "{e}"
    );
}

/// The water-level gauges are optional, but one the scene has stands where the experiment's
/// does.
#[test]
fn a_lobovsky_gauge_stands_where_the_experiments_does() {
    let mut scene = crate::common::shipped_scene("dam_break_lobovsky_2d.toml");
    let k = scene.probes.iter().position(|p| p.name == "H3").unwrap();
    scene.probes[k].point[0] = 1.2;
    let e = isph::tools::validation::check(Case::LobovskyPressure, &scene).unwrap_err();
    assert!(e.to_string().contains("gauge 3 is a wave gauge"), "{e}");
    scene.probes.remove(k);
    isph::tools::validation::check(Case::LobovskyPressure, &scene).unwrap();
}

/// `density`: the worst step's density error, its mean over the steps that measured one (a NaN
/// step measured nothing) and the wall crossings summed over the run.
#[test]
fn density_measure_takes_the_worst_step_and_the_mean_of_the_measured_ones() {
    let dir = crate::common::TempDir::new("measure-density");
    std::fs::write(
        dir.path().join("stats.csv"),
        "step,density_error,penetrations\n1,0.002,0\n2,NaN,1\n3,0.008,2\n4,0.005,0\n",
    )
    .unwrap();
    let scene = crate::common::shipped_scene("violent_impact_2d.toml");
    let m = isph::tools::validation::measure(Case::Density, &scene, dir.path()).unwrap();
    assert_eq!(m.error, 0.008);
    assert_eq!(m.details[0], ("density_error_mean".to_string(), 0.005));
    assert_eq!(m.details[1], ("penetrations".to_string(), 3.0));
    std::fs::write(
        dir.path().join("stats.csv"),
        "step,density_error,penetrations\n1,NaN,0\n",
    )
    .unwrap();
    let e = isph::tools::validation::measure(Case::Density, &scene, dir.path()).unwrap_err();
    assert!(
        e.to_string().contains("no step with a density error"),
        "{e}"
    );
}
