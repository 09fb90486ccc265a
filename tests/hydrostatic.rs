//! Hydrostatic tank (2D): the pressure against ρ g (H − y) after 1 s, and water that stays still.

use crate::common::{read_frame, run_scene, shipped_scene, stats_column, TempDir};
use isph::validation::{measure, Case};

#[test]
fn still_water_has_hydrostatic_pressure_and_no_penetration() {
    let scene = shipped_scene("hydrostatic_2d.toml");
    let dir = TempDir::new("hydrostatic");
    let summary = run_scene(&scene, dir.path(), 1.0);
    let last = summary.frames.len() - 1;
    let m = measure(Case::Hydrostatic, &scene, dir.path()).unwrap_or_else(|e| panic!("{e}"));
    // Measured: 2–5e-5 of ρgH at tolerance 1e-6 (docs/accuracy.md), bottom pressure likewise.
    assert!(m.error < 0.005, "rms pressure error {} of ρgH", m.error);
    let bottom = m.details[0].1;
    assert!(bottom.abs() < 0.005, "bottom pressure error {bottom}");
    let kind: Vec<i32> = read_frame(dir.path(), last, "kind");
    let first_kind: Vec<i32> = read_frame(dir.path(), 0, "kind");
    assert_eq!(
        kind.iter().filter(|&&k| k == 0).count(),
        first_kind.iter().filter(|&&k| k == 0).count()
    );
    assert!(stats_column(dir.path(), "penetrations")
        .iter()
        .all(|&p| p == 0.0));
}
