//! The output opens in real readers: VTK's XDMF reader (through pyvista) and h5py.

use crate::common::{command, run_scene, shipped_scene, TempDir};

#[test]
fn pyvista_and_h5py_read_the_run_as_a_time_series() {
    let mut scene = shipped_scene("hydrostatic_2d.toml");
    scene.output_interval = 0.02;
    let dir = TempDir::new("readers");
    let summary = run_scene(&scene, dir.path(), 0.06);
    let tool = concat!(env!("CARGO_MANIFEST_DIR"), "/tools/inspect_run.py");
    let out = command("python3")
        .arg(tool)
        .arg(dir.path())
        .output()
        .expect("python3 runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "inspect_run.py failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let n = summary.frames[0].count;
    for f in &summary.frames {
        let line = format!("t = {:.6} s", f.time);
        assert!(stdout.contains(&line), "frame at {line} missing:\n{stdout}");
    }
    assert!(
        stdout.contains(&format!("{} frames", summary.frames.len())),
        "{stdout}"
    );
    assert!(stdout.contains(&format!("{n} particles")), "{stdout}");
}
