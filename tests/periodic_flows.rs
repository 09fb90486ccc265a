//! The two analytic flows of periodic boxes, each at two spacings: the Taylor–Green vortex's
//! decay and the start-up Poiseuille flow, measured by `isph::tools::validation` (the measures of
//! `isph study`), with the order of convergence fitted from the two spacings.

use crate::common::{run_scene, shipped_scene, TempDir};
use isph::tools::validation::{measure, Case, Measured};

/// Runs the shipped scene `name` at `spacing` to `until` and measures it against `case`.
fn measured(name: &str, case: Case, spacing: f64, until: f64) -> Measured {
    let mut scene = shipped_scene(name);
    scene.spacing = spacing;
    let dir = TempDir::new(&format!("{case}-{spacing}"));
    run_scene(&scene, dir.path(), until);
    measure(case, &scene, dir.path()).unwrap()
}

fn detail(m: &Measured, name: &str) -> f64 {
    m.details.iter().find(|(n, _)| n == name).unwrap().1
}

/// The order p of error ∝ dx^p from errors at dx and dx/2.
fn order(coarse: f64, fine: f64) -> f64 {
    (coarse / fine).log2()
}

/// Measured (release, t = 1 s): decay rate within 1.3% at dx = L/20 and 0.13% at L/40; velocity
/// L2 error 5.4% and 1.3%, order 2.0.
#[test]
fn taylor_green_decays_at_the_analytic_rate_and_converges() {
    let coarse = measured("taylor_green_2d.toml", Case::TaylorGreen, 0.05, 1.0);
    let fine = measured("taylor_green_2d.toml", Case::TaylorGreen, 0.025, 1.0);
    for m in [&coarse, &fine] {
        assert!(m.error < 0.05, "decay rate off by {}", m.error);
    }
    let (l2_coarse, l2_fine) = (
        detail(&coarse, "velocity_l2_error"),
        detail(&fine, "velocity_l2_error"),
    );
    assert!(l2_fine < 0.03, "velocity L2 error {l2_fine} at L/40");
    let p = order(l2_coarse, l2_fine);
    assert!(
        p > 1.0,
        "velocity L2 error {l2_coarse} → {l2_fine}: order {p}"
    );
}

/// Measured (release, t = 0.5 s): rms profile error 1.7% of u_max at L/10, 0.47% at L/20,
/// order 1.9.
#[test]
fn poiseuille_follows_the_start_up_series_and_converges() {
    let coarse = measured("poiseuille_2d.toml", Case::Poiseuille, 1.0e-4, 0.5);
    let fine = measured("poiseuille_2d.toml", Case::Poiseuille, 5.0e-5, 0.5);
    assert!(fine.error < 0.01, "profile error {} at L/20", fine.error);
    assert!(
        coarse.error < 0.03,
        "profile error {} at L/10",
        coarse.error
    );
    for m in [&coarse, &fine] {
        let cross = detail(m, "cross_velocity");
        assert!(cross < 1e-3, "velocity across the channel {cross} of u_max");
    }
    let p = order(coarse.error, fine.error);
    assert!(
        p > 1.0,
        "profile error {} → {}: order {p}",
        coarse.error,
        fine.error
    );
}

/// Along a periodic axis every position the frames hold lies in the period [min, max): the
/// particles that left it in a step's advection are wrapped at the end of that step, before
/// any frame is written. A dam break in a box periodic along x: the surge
/// runs out through x = max and comes back in at x = min.
#[test]
fn frames_hold_periodic_positions_inside_the_box() {
    let text = crate::common::water_block_scene(0.3).replace(
        "max = [0.4, 0.3]",
        "max = [0.4, 0.3]\nperiodic = [true, false]",
    );
    let scene = crate::common::scene_from_text(&text);
    let dir = TempDir::new("periodic-positions");
    let summary = run_scene(&scene, dir.path(), 0.3);
    let (lo, hi) = (scene.container.min[0], scene.container.max[0]);
    let outside = (0..summary.frames.len())
        .flat_map(|frame| crate::common::read_frame::<f64>(dir.path(), frame, "position"))
        .step_by(3)
        .filter(|x| *x < lo || *x >= hi)
        .count();
    assert_eq!(outside, 0, "positions outside [{lo}, {hi}) along x");
}
