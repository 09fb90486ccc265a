//! Dam breaks: the 2D surge front against Martin & Moyce (1952) and a 3D run.

use crate::common::{read_frame, run_scene, shipped_scene, stats_column, TempDir};

/// Martin & Moyce (1952), n² = 2, a = 2.25 in: (T = t √(2g/a), Z = x/a), as tabulated in
/// PySPH's `db_exp_data.py` from their Figure 3.
const MARTIN_MOYCE: [(f64, f64); 6] = [
    (0.832, 1.217),
    (1.219, 1.474),
    (1.997, 2.292),
    (2.547, 2.995),
    (3.345, 4.134),
    (4.034, 4.944),
];

#[test]
#[ignore = "known failure: the front leads Martin & Moyce by 12.7% mean relative error (bound 10%): a near-constant time lead of ~13 ms, converged in dx and dt (see the issue note)"]
fn surge_front_follows_martin_and_moyce() {
    let mut scene = shipped_scene("dam_break_2d.toml");
    let a = scene.blocks[0].region.max[0];
    let g = -scene.gravity[1];
    let t_scale = (2.0 * g / a).sqrt();
    scene.output_interval = 0.1 / t_scale;
    let dir = TempDir::new("dam-break");
    let summary = run_scene(&scene, dir.path(), 4.1 / t_scale);
    let mut errors = Vec::new();
    for (t_ref, z_ref) in MARTIN_MOYCE {
        let frame = summary
            .frames
            .iter()
            .position(|f| (f.time * t_scale - t_ref).abs() < 0.051)
            .unwrap();
        let pos: Vec<f64> = read_frame(dir.path(), frame, "position");
        let kind: Vec<i32> = read_frame(dir.path(), frame, "kind");
        let front = (0..kind.len())
            .filter(|&i| kind[i] == 0)
            .map(|i| pos[3 * i])
            .fold(0.0, f64::max);
        errors.push(((front / a) - z_ref).abs() / z_ref);
    }
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    assert!(
        mean < 0.10,
        "mean relative surge-front error {mean}: {errors:?}"
    );
    assert!(stats_column(dir.path(), "penetrations")
        .iter()
        .all(|&p| p == 0.0));
    let density = stats_column(dir.path(), "density_error");
    assert!(density.iter().sum::<f64>() / (density.len() as f64) < 0.01);
}

#[test]
fn dam_break_3d_runs_half_a_second() {
    let mut scene = shipped_scene("dam_break_3d.toml");
    scene.spacing *= 2.0;
    let dir = TempDir::new("dam-break-3d");
    run_scene(&scene, dir.path(), 0.5);
    assert!(stats_column(dir.path(), "penetrations")
        .iter()
        .all(|&p| p == 0.0));
}
