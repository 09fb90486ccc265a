//! Same binary + same scene ⇒ the same bits, whatever the thread count.

use crate::common::{read_frame, run_scene, shipped_scene, TempDir};
use isph::scene::{Probe, ProbeField, Scene};

/// Runs `scene` to `until` on 1 and on 2 threads and compares the first `frames` frames bit
/// for bit, and probes.csv byte for byte.
fn assert_thread_count_independent(name: &str, scene: &Scene, until: f64, frames: usize) {
    let dirs = [
        TempDir::new(&format!("det-{name}-1")),
        TempDir::new(&format!("det-{name}-2")),
    ];
    for (threads, dir) in [1, 2].into_iter().zip(&dirs) {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| run_scene(scene, dir.path(), until));
    }
    for frame in 0..=frames {
        for field in ["position", "velocity", "pressure", "density"] {
            let a: Vec<f64> = read_frame(dirs[0].path(), frame, field);
            let b: Vec<f64> = read_frame(dirs[1].path(), frame, field);
            let same =
                a.len() == b.len() && a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(
                same,
                "{name}: frame {frame} `{field}` differs between 1 and 2 threads"
            );
        }
    }
    let bodies = |dir: &TempDir| std::fs::read(dir.path().join("bodies.csv")).ok();
    assert_eq!(
        bodies(&dirs[0]).is_some(),
        !scene.bodies.is_empty(),
        "{name}: bodies.csv is written exactly when the scene has bodies"
    );
    assert!(
        bodies(&dirs[0]) == bodies(&dirs[1]),
        "{name}: bodies.csv differs between 1 and 2 threads"
    );
    let probes = |dir: &TempDir| std::fs::read(dir.path().join("probes.csv")).ok();
    assert_eq!(
        probes(&dirs[0]).is_some(),
        !scene.probes.is_empty(),
        "{name}: probes.csv is written exactly when the scene has probes"
    );
    assert_eq!(
        probes(&dirs[0]),
        probes(&dirs[1]),
        "{name}: probes.csv differs between 1 and 2 threads"
    );
}

/// A pressure probe on the back wall's face under the column and a velocity probe at its foot,
/// where the water starts to run.
fn dam_break_probes() -> Vec<Probe> {
    let probe = |name: &str, point: Vec<f64>, field| Probe {
        name: name.into(),
        point,
        field,
    };
    vec![
        probe("wall", vec![0.0, 0.02], ProbeField::Pressure),
        probe("u", vec![0.05, 0.02], ProbeField::Velocity),
    ]
}

#[test]
fn one_and_two_threads_write_bit_identical_frames() {
    let mut scene = shipped_scene("dam_break_2d.toml");
    scene.spacing *= 2.0;
    scene.output_interval = 0.01;
    scene.probes = dam_break_probes();
    assert_thread_count_independent("dam-break", &scene, 0.03, 3);
}

/// Bodies, free, prescribed and resting, in a rolling tank: their sums run in the sorted order
/// on one thread.
#[test]
fn free_and_prescribed_bodies_in_a_rolling_tank_are_bit_identical_on_one_and_two_threads() {
    let mut scene = shipped_scene("floating_box_2d.toml");
    scene.spacing = 0.02;
    scene.output_interval = 0.05;
    let mut sinker = scene.bodies[0].clone();
    sinker.name = "sinker".into();
    sinker.shape = isph::scene::Shape::Ball {
        center: vec![0.2, 0.15],
        radius: 0.06,
    };
    sinker.mass = isph::scene::BodyMass::Density(1500.0);
    scene.bodies.push(sinker.clone());
    // A paddle on a sinusoid, in a tank that rolls.
    let mut paddle = sinker;
    paddle.name = "paddle".into();
    paddle.shape = isph::scene::Shape::Box {
        min: vec![0.82, 0.2],
        max: vec![0.88, 0.4],
    };
    let roll = |amplitude: [f64; 3], degrees: f64, period: f64, pivot: [f64; 3]| {
        isph::scene::trajectory::Trajectory {
            pivot,
            axis: [0.0, 0.0, 1.0],
            path: isph::scene::trajectory::Path::Sinusoid {
                amplitude,
                angle: degrees.to_radians(),
                period,
            },
        }
    };
    paddle.motion =
        isph::scene::BodyMotion::Prescribed(roll([0.02, 0.0, 0.0], 5.0, 0.5, [0.85, 0.3, 0.0]));
    scene.bodies.push(paddle.clone());
    // A heavy box resting on the floor, held still while its contacts hold it.
    let mut rester = paddle;
    rester.name = "rester".into();
    rester.shape = isph::scene::Shape::Box {
        min: vec![0.6, 0.0],
        max: vec![0.68, 0.08],
    };
    rester.motion = isph::scene::BodyMotion::Free;
    rester.mass = isph::scene::BodyMass::Density(1500.0);
    rester.friction = 0.5;
    scene.bodies.push(rester);
    scene.container_motion = Some(roll([0.0; 3], 3.0, 1.0, [0.5, 0.0, 0.0]));
    assert_thread_count_independent("bodies", &scene, 0.2, 4);
}

/// A periodic, confined flow: the wrapped neighbour search, the reference pressure and the
/// zero-mean shift are thread-count independent too.
#[test]
fn a_periodic_flow_is_bit_identical_on_one_and_two_threads() {
    let mut scene = shipped_scene("taylor_green_2d.toml");
    scene.spacing = 0.04;
    scene.output_interval = 0.05;
    assert_thread_count_independent("taylor-green", &scene, 0.15, 3);
}

/// In 3D, with a body falling into the water and a pressure probe under it: the 3D pair loops,
/// the body's sums in three dimensions and the probe's are thread-count independent too.
#[test]
fn a_body_falling_into_3d_water_is_bit_identical_on_one_and_two_threads() {
    let mut scene = shipped_scene("falling_body_3d.toml");
    scene.spacing = 0.03;
    scene.output_interval = 0.05;
    scene.probes = vec![Probe {
        name: "floor".into(),
        point: vec![0.3, 0.3, 0.0],
        field: ProbeField::Pressure,
    }];
    assert_thread_count_independent("falling-body-3d", &scene, 0.2, 4);
}
