//! Same binary + same scene ⇒ the same bits, whatever the thread count.

use crate::common::{read_frame, run_scene, shipped_scene, TempDir};

#[test]
fn one_and_two_threads_write_bit_identical_frames() {
    let mut scene = shipped_scene("dam_break_2d.toml");
    scene.spacing *= 2.0;
    scene.output_interval = 0.01;
    let dirs = [TempDir::new("det-1"), TempDir::new("det-2")];
    for (threads, dir) in [1, 2].into_iter().zip(&dirs) {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| run_scene(&scene, dir.path(), 0.03));
    }
    for frame in 0..=3 {
        for name in ["position", "velocity", "pressure", "density"] {
            let a: Vec<f64> = read_frame(dirs[0].path(), frame, name);
            let b: Vec<f64> = read_frame(dirs[1].path(), frame, name);
            let same =
                a.len() == b.len() && a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(
                same,
                "frame {frame} `{name}` differs between 1 and 2 threads"
            );
        }
    }
}
