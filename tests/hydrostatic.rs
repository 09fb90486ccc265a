//! Hydrostatic tank (2D): the pressure against ρ g (H − y) after 1 s, and water that stays still.

use crate::common::{read_frame, run_scene, shipped_scene, stats_column, TempDir};

#[test]
fn still_water_has_hydrostatic_pressure_and_no_penetration() {
    let scene = shipped_scene("hydrostatic_2d.toml");
    let dir = TempDir::new("hydrostatic");
    let summary = run_scene(&scene, dir.path(), 1.0);
    let last = summary.frames.len() - 1;
    let (rho, g) = (scene.fluids[0].density, -scene.gravity[1]);
    let depth = scene.blocks[0].region.max[1];
    let pos: Vec<f64> = read_frame(dir.path(), last, "position");
    let pressure: Vec<f64> = read_frame(dir.path(), last, "pressure");
    let kind: Vec<i32> = read_frame(dir.path(), last, "kind");
    let first_kind: Vec<i32> = read_frame(dir.path(), 0, "kind");
    let (mut sum, mut n) = (0.0, 0);
    for i in 0..kind.len() {
        let y = pos[3 * i + 1];
        if kind[i] == 0 && depth - y > 0.15 * depth {
            sum += (pressure[i] - rho * g * (depth - y)).powi(2);
            n += 1;
        }
    }
    let rms = (sum / n as f64).sqrt() / (rho * g * depth);
    assert!(rms < 0.03, "rms pressure error {rms} of ρgH");
    assert_eq!(
        kind.iter().filter(|&&k| k == 0).count(),
        first_kind.iter().filter(|&&k| k == 0).count()
    );
    assert!(stats_column(dir.path(), "penetrations")
        .iter()
        .all(|&p| p == 0.0));
}
