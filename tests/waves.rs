//! Waves: a piston wave maker's regular waves against Biesel's transfer function, read by wave
//! gauges (`field = "elevation"`) down the flume (`scenes/wave_flume_2d.toml`; docs/accuracy.md,
//! "Waves from a piston").

use crate::common::{run_scene, shipped_scene, TempDir};
use isph::tools::validation::{measure, Case};

/// Runs the shipped flume at `spacing` to its end and checks that each of its three gauges, at
/// 1, 1.5 and 2 wavelengths from the piston, reads the first harmonic of the wave within 10% of
/// Biesel's height: the check the literature gives a wave maker (SPH codes land 3–10% under the
/// target 1–1.5 wavelengths from the paddle). The water's force on the piston, from frames ten
/// times a period: its mean within 5% of the hydrostatic thrust ρ g h²/2 (a first-order error
/// in dx, −3.0% at h/20 in still water) and its first harmonic within 10% and 15° of the
/// linear wave maker's, 22 N/m in phase with the piston's velocity (the wave it radiates).
/// Measured at h/20 −2.3%, −2.6%, +8.9° (with frames every 0.02 s −2.4%, +0.4%, +4.0°: single
/// periods scatter by 2–8°), at h/40 −1.5%, −4.1%, +2.1° (−1.5%, −1.0%, +2.0°) (2026-12-07,
/// Zen 3).
fn assert_biesel_height(spacing: f64) {
    let mut scene = shipped_scene("wave_flume_2d.toml");
    scene.spacing = spacing;
    scene.output_interval = 0.1;
    let dir = TempDir::new("wave-flume");
    run_scene(&scene, dir.path(), scene.end_time);
    let m = measure(Case::WaveFlume, &scene, dir.path()).unwrap_or_else(|e| panic!("{e}"));
    let detail = |name: &str| m.details.iter().find(|(n, _)| n == name).unwrap().1;
    eprintln!("{m:?}");
    assert_eq!(detail("gauges"), 3.0, "{m:?}");
    assert!(
        detail("height_error_min") > -0.1 && detail("height_error_max") < 0.1,
        "{m:?}"
    );
    assert!(detail("paddle_force_mean_error").abs() < 0.05, "{m:?}");
    assert!(detail("paddle_force_amplitude_error").abs() < 0.1, "{m:?}");
    assert!(detail("paddle_force_phase_error_deg").abs() < 15.0, "{m:?}");
}

/// At h/dx = 20 (the wave 3 spacings high; 39 s on 2 cores): measured −1.8% to +1.2%
/// (2026-12-07, 2-vCPU AMD EPYC, Zen 3).
#[test]
fn a_piston_makes_the_waves_biesel_gives() {
    assert_biesel_height(0.01);
}

/// At the scene's h/dx = 40: measured −1.8% to +1.1%, 254 s (2026-12-07, Zen 3).
#[test]
#[ignore = "about 5 minutes on 2 cores: run with --ignored"]
fn a_piston_makes_the_waves_biesel_gives_at_forty_particles_in_the_depth() {
    assert_biesel_height(0.005);
}
