//! Frame times: every multiple of `output_interval` and the end time, with a multiple that
//! rounds to within a sliver of the end time taken for the end time (11 × 0.03 =
//! 0.32999999999999996 against 0.33: the run ends on the multiple), so that no step is cut to
//! a sliver (which blows the flow up and leaves that state in the end checkpoint:
//! docs/stabilisation.md, "A short step relaxes less"); the steps cut to land on a frame read
//! the flow's pressure; a frame holds the fluid where it stands at the frame's time.

use std::f64::consts::PI;

use crate::common::{
    read_frame, run_scene, scene_from_text, shipped_scene, stats_column, water_block_scene, TempDir,
};
use isph::io::probes;
use isph::scene::{Probe, ProbeField, Scene};

fn scene(end_time: f64, interval: f64) -> Scene {
    let text = water_block_scene(end_time).replace(
        "output_interval = 0.02",
        &format!("output_interval = {interval}"),
    );
    scene_from_text(&text)
}

/// Runs to `until`, checks the frame times against `expected` and that no step was shorter
/// than `shortest_allowed`.
fn assert_frames(
    end_time: f64,
    interval: f64,
    until: f64,
    expected: &[f64],
    shortest_allowed: f64,
) {
    let dir = TempDir::new("frame_times");
    let summary = run_scene(&scene(end_time, interval), dir.path(), until);
    let times: Vec<f64> = summary.frames.iter().map(|f| f.time).collect();
    assert_eq!(times, expected, "frame times");
    let shortest = stats_column(dir.path(), "dt")
        .into_iter()
        .fold(f64::MAX, f64::min);
    assert!(shortest >= shortest_allowed, "a step of {shortest:e} s");
    // The water falls from 0.2 m at most: √(2 g 0.2) = 2 m/s, splashes a bit faster.
    let fastest = stats_column(dir.path(), "max_speed")
        .into_iter()
        .fold(0.0, f64::max);
    assert!(fastest < 4.0, "max speed {fastest} m/s");
}

#[test]
fn a_frame_time_that_rounds_next_to_the_end_time_is_the_end_time() {
    // The run ends on the scheduled frame, 11 × 0.03 = 0.32999999999999996.
    let expected: Vec<f64> = (0..12).map(|k| k as f64 * 0.03).collect();
    assert_frames(0.33, 0.03, 0.33, &expected, 1e-4);
    // The same past a frame: `--until` a sliver after 0.04 ends on the frame at 0.04.
    assert_frames(0.1, 0.02, 0.04000000000001, &[0.0, 0.02, 0.04], 1e-4);
    // A run shorter than the rounding still has its frame 0 at t = 0 (and one at its end).
    assert_frames(0.1, 0.02, 1e-8, &[0.0, 1e-8], 1e-8);
}

/// A step cut far shorter than the step limit, to land on an end time just past a frame
/// (`--until` 4e-8 s after it), moves the flow by as little as its length says: the
/// density-invariance term relaxes the density error over the step limit, not over the short
/// step (with α(ρ0 − ρ)/Δt², as Eq. (6) is printed, the velocity it corrects by grows as 1/Δt:
/// docs/stabilisation.md, "A short step relaxes less"). What remains is the projection itself,
/// which removes the divergence u* has at the new positions however short the step (a few per
/// cent of the max speed here; asserted below 5%).
#[test]
fn a_short_last_step_does_not_kick_the_flow() {
    let s = scene(0.1, 0.02);
    let speed_at = |until: f64| {
        let dir = TempDir::new("short_step");
        run_scene(&s, dir.path(), until);
        let speeds = stats_column(dir.path(), "max_speed");
        let dt = stats_column(dir.path(), "dt");
        (speeds[speeds.len() - 1], dt[dt.len() - 1])
    };
    let (at_frame, _) = speed_at(0.04);
    for tail in [4e-6, 4e-8] {
        let (after, dt) = speed_at(0.04 + tail);
        assert!((dt - tail).abs() < 1e-3 * tail, "last step {dt:e} s");
        assert!(
            (after - at_frame).abs() < 0.05 * at_frame,
            "{tail:e} s past the frame: max speed {after} m/s, {at_frame} m/s at the frame"
        );
    }
}

/// The last frame of a run that ends a sliver past a frame (a step of 1e-5 or 4e-8 s after
/// steps of 0.01 s) reads the flow's pressure, not the divergence the last step's drift left
/// divided by the sliver: a sliver takes what the particles carry into it out over the last
/// step's Δt (docs/stabilisation.md, "A short step relaxes less"). Taken out over the sliver,
/// the mean fluid pressure read 37 kPa after 1e-5 s and 9.2 MPa after 4e-8 s, against 434 Pa at
/// the frame. Measured: 466.5 Pa after both. The two tails agree to 1%, and they are within
/// 10% of the frame: the frame's step reads the pressure at the middle of its 0.01 s drift,
/// and over 0.01 s this collapsing block's mean pressure rises by 8% (427 Pa at 0.035 s, 463 Pa
/// at 0.045 s with frames every 0.005 s).
#[test]
fn a_short_last_step_reads_the_flows_pressure() {
    let s = scene(0.1, 0.02);
    let mean_fluid_pressure = |dir: &TempDir, frame: usize| {
        let kind: Vec<i32> = read_frame(dir.path(), frame, "kind");
        let pressure: Vec<f64> = read_frame(dir.path(), frame, "pressure");
        let fluid: Vec<f64> = (0..kind.len())
            .filter(|&i| kind[i] == 0)
            .map(|i| pressure[i])
            .collect();
        fluid.iter().sum::<f64>() / fluid.len() as f64
    };
    let after = |tail: f64| {
        let dir = TempDir::new("short_step_pressure");
        let summary = run_scene(&s, dir.path(), 0.04 + tail);
        let last = summary.frames.len() - 1;
        let at_frame = mean_fluid_pressure(&dir, last - 1);
        let after = mean_fluid_pressure(&dir, last);
        eprintln!("{tail:e} s past the frame: mean pressure {after} Pa, {at_frame} Pa at it");
        (at_frame, after)
    };
    let (at_frame, after_long) = after(1e-5);
    let (_, after_short) = after(4e-8);
    assert!(
        (after_short - after_long).abs() < 0.01 * after_long,
        "mean fluid pressure {after_long} Pa 1e-5 s past the frame, {after_short} Pa 4e-8 s past it"
    );
    assert!(
        (after_long - at_frame).abs() < 0.1 * at_frame,
        "mean fluid pressure {after_long} Pa 1e-5 s past the frame, {at_frame} Pa at the frame"
    );
}

/// The steps cut to land on a frame read the flow's pressure. The Taylor–Green vortex's pressure
/// is all the projection's answer to the divergence the particles' drift makes, half of it
/// carried into a step from the last one's drift and taken out over this one's Δt, so a step
/// cut to a fraction of the one before reads (1 + Δt_prev/Δt)/2 of it (docs/stabilisation.md,
/// "A short step relaxes less"). The frames here fall 13.06 step limits apart (the viscous
/// step, 0.0072 s, holds the whole run). Cut over the last two steps, the first of them read
/// 1.47 times the exact pressure at the vortex's centres and the step after the frame 0.75
/// times it. Spread over the last eight steps (`time_step::length`), the worst step reads
/// within 0.5/7 of it by that ratio, and measured within 7.3% (the steady steps within 2%).
#[test]
fn steps_cut_to_land_on_a_frame_read_the_flows_pressure() {
    let mut scene = shipped_scene("taylor_green_2d.toml");
    scene.output_interval = 0.094;
    // The pressure's extremes, ±ρU²/2 e^(−4νk²t) (U = 1 m/s, ρ = 1000 kg/m³).
    scene.probes = [("high", 0.5), ("low", 0.25)]
        .into_iter()
        .map(|(name, at)| Probe {
            name: name.into(),
            point: vec![at, at],
            field: ProbeField::Pressure,
        })
        .collect();
    let dir = TempDir::new("cut_steps_pressure");
    run_scene(&scene, dir.path(), 0.3);
    let (time, dt) = (
        stats_column(dir.path(), "time"),
        stats_column(dir.path(), "dt"),
    );
    let cut_steps = dt.iter().filter(|&&step| step < 0.99 * dt[0]).count();
    assert!(cut_steps >= 6, "{cut_steps} steps shorter than the limit");
    let decay = 4.0 * 0.01 * (2.0 * PI).powi(2);
    let (columns, rows) = probes::read(dir.path()).unwrap();
    for (name, sign) in [("high", 1.0), ("low", -1.0)] {
        let col = columns.iter().position(|c| c == name).unwrap();
        let pressure: Vec<f64> = rows.iter().map(|r| r[col]).collect();
        // Past the first steps from rest; each step's pressure at the middle of its drift.
        for k in (0..time.len()).filter(|&k| time[k] > 0.05) {
            let exact = sign * 500.0 * (-decay * (time[k] - 0.5 * dt[k])).exp();
            let ratio = pressure[k] / exact;
            assert!(
                (ratio - 1.0).abs() < 0.1,
                "{name}: {ratio} times the exact pressure at t = {} s after a step of {} s",
                time[k],
                dt[k]
            );
        }
    }
}

/// A block of water falling freely, VALIDATION.md's exact check: height z0 − g t²/2, velocity
/// −g t. A frame holds the fluid half the last drift back from where the advection left it,
/// where the step's velocity belongs (docs/accuracy.md, "Where a frame's particles stand").
/// Over the six equal steps to the first frame (the body-force limit, cut evenly to land on
/// 0.05 s) the block's mean height is exact but for the solve's small pressures (measured:
/// 5e-8 m), where the advection's positions lead by (Δt/2) g t = 2.0 mm. Where the step then
/// shrinks as the block gathers speed (the CFL limit, from 8.3 to 2.0 ms), the advection's
/// positions lead by Σ g Δt_k²/2 and a frame by that less (Δt/2) g t of the last step:
/// measured 1.46 and 2.77 mm at 0.1 and 0.2 s against 3.3 and 4.7 mm. The velocity is −g t at
/// every frame.
#[test]
fn a_falling_block_follows_free_fall_in_its_frames() {
    let g = 9.81;
    let scene = scene_from_text(
        r#"[simulation]
dimensions = 2
spacing = 0.01
end_time = 0.2
output_interval = 0.05
gravity = [0.0, -9.81]

[[fluid]]
name = "water"
density = 1000.0
viscosity = 1e-6

[[fluid_block]]
fluid = "water"
min = [0.4, 0.6]
max = [0.6, 0.8]

[container]
min = [0.0, 0.0]
max = [1.0, 1.0]
"#,
    );
    let dir = TempDir::new("free_fall");
    run_scene(&scene, dir.path(), 0.2);
    let (time, dt) = (
        stats_column(dir.path(), "time"),
        stats_column(dir.path(), "dt"),
    );
    let mean_of_fluid = |frame: usize, name: &str| {
        let kind: Vec<i32> = read_frame(dir.path(), frame, "kind");
        let vectors: Vec<f64> = read_frame(dir.path(), frame, name);
        let heights: Vec<f64> = (0..kind.len())
            .filter(|&i| kind[i] == 0)
            .map(|i| vectors[3 * i + 1])
            .collect();
        heights.iter().sum::<f64>() / heights.len() as f64
    };
    // Steps of one length but for the rounding of the cut that lands on a frame.
    let even = |steps: &[f64]| {
        steps
            .iter()
            .all(|&d| (d - steps[0]).abs() < 1e-12 * steps[0])
    };
    let start = mean_of_fluid(0, "position");
    for frame in 1..=4 {
        let t = 0.05 * frame as f64;
        let last = time.iter().position(|&s| (s - t).abs() < 1e-12).unwrap();
        let velocity = mean_of_fluid(frame, "velocity");
        assert!(
            (velocity + g * t).abs() < 1e-9,
            "mean velocity {velocity} m/s at {t} s"
        );
        let lead = start - 0.5 * g * t * t - mean_of_fluid(frame, "position");
        let advection_lead = lead + 0.5 * dt[last] * g * t;
        if even(&dt[..=last]) {
            assert!(lead.abs() < 1e-6, "{lead:e} m off z0 − g t²/2 at {t} s");
        } else {
            assert!(
                lead.abs() < 0.7 * advection_lead,
                "{lead:e} m off z0 − g t²/2 at {t} s, the advection {advection_lead:e} m"
            );
        }
    }
    assert!(
        even(&dt[..6]) && (time[5] - 0.05).abs() < 1e-12,
        "six equal steps to the first frame: {:?}",
        &dt[..6]
    );
}
