//! Two fluids of different density in a violent flow: the paper's two-fluid dam break
//! (`scenes/two_fluid_dam_break_2d.toml`) ends with the lighter fluid on top.

use crate::common::{read_frame, run_scene, shipped_scene, TempDir};

#[test]
fn after_a_two_fluid_dam_break_the_lighter_fluid_ends_on_top() {
    // The paper's ratios ρX/ρY = 0.8, 1.2 and 1.5, at four times the scene's spacing. Settled in
    // layers, the two 0.25 m × 0.4 m columns make two layers 0.1 m deep: the lighter's mean
    // height is then 0.1 m above the heavier's. After 4 s the tank still sloshes and the
    // fluids are still parting; at least half of that must be there.
    for density in [800.0, 1200.0, 1500.0] {
        let dir = TempDir::new("two-fluid-dam-break");
        let mut scene = shipped_scene("two_fluid_dam_break_2d.toml");
        scene.spacing = 0.02;
        scene.output_interval = 0.5;
        scene.fluids[0].density = density;
        let summary = run_scene(&scene, dir.path(), 4.0);
        let last = summary.frames.len() - 1;
        let fluid: Vec<i32> = read_frame(dir.path(), last, "fluid");
        let pos: Vec<f64> = read_frame(dir.path(), last, "position");
        let mean_height = |f: i32| {
            let ys: Vec<f64> = (0..fluid.len())
                .filter(|&i| fluid[i] == f)
                .map(|i| pos[3 * i + 1])
                .collect();
            ys.iter().sum::<f64>() / ys.len() as f64
        };
        let (x, y) = (mean_height(0), mean_height(1));
        let above = if density < 1000.0 { x - y } else { y - x };
        eprintln!(
            "ρX/ρY = {}: the lighter's mean height {above} m above the heavier's",
            density / 1000.0
        );
        assert!(
            above > 0.05,
            "ρX/ρY = {}: mean heights X {x} m, Y {y} m",
            density / 1000.0
        );
    }
}
