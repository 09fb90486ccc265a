//! Surfaces of runs, from the command line: `[output.surface]` during a run and across a
//! resume, `isph surface` afterwards, the same bytes on one and two threads, pyvista reading
//! the XDMF index, and bad input refused with nothing overwritten.

use crate::common::{command, isph_command, water_block_scene_3d, TempDir};
use isph::io::surface_files::SurfaceReader;
use std::path::{Path, PathBuf};

/// A 3D block of water 8 × 6 × 10 spacings collapsing in a box, frames every 0.02 s to
/// `end_time`, checkpoints every 0.02 s, with `extra` appended (an `[output.surface]` section).
fn column_3d(end_time: f64, extra: &str) -> String {
    let extra = format!("\n[checkpoint]\ninterval = 0.02\n{extra}");
    water_block_scene_3d([0.16, 0.12, 0.2], [0.4, 0.12, 0.3], end_time, 0.02, &extra)
}

fn isph(args: &[&str]) -> std::process::Output {
    let o = isph_command().args(args).output().unwrap();
    assert!(
        !String::from_utf8_lossy(&o.stderr).contains("panicked"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

fn ok(args: &[&str]) -> String {
    let o = isph(args);
    assert!(
        o.status.success(),
        "isph {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Runs `scene` text into `dir`/out, with `extra` arguments.
fn run(dir: &Path, scene: &str, extra: &[&str]) -> PathBuf {
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let out = dir.join("out");
    let mut args = vec![
        "run",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "-q",
        "--overwrite",
    ];
    args.extend_from_slice(extra);
    ok(&args);
    out
}

fn frames_of(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir.join("surface"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    files
}

#[test]
fn a_run_with_output_surface_writes_a_closed_mesh_per_frame_that_pyvista_reads() {
    let dir = TempDir::new("surface-run");
    let out = run(
        dir.path(),
        &column_3d(0.06, "[output.surface]\nobj = true\n"),
        &[],
    );
    let reader = SurfaceReader::open(&out)
        .unwrap()
        .expect("surface.h5 written");
    for frame in 0..4 {
        let mesh = reader
            .read(frame)
            .unwrap()
            .expect("a surface at every frame");
        assert!(
            mesh.cell_count() > 100,
            "frame {frame}: {} triangles",
            mesh.cell_count()
        );
        // The water's volume, 0.16 × 0.12 × 0.2 m³, less what a kernel of 3 spacings rounds
        // off the edges and corners of a block 6 spacings thick (17% at the start).
        let volume = mesh.enclosed_measure() / 3.84e-3;
        assert!(
            volume > 0.75 && volume < 1.0,
            "frame {frame}: encloses {volume} of the water"
        );
    }
    let names: Vec<String> = frames_of(&out)
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "frame_000000.obj",
            "frame_000000.ply",
            "frame_000001.obj",
            "frame_000001.ply",
            "frame_000002.obj",
            "frame_000002.ply",
            "frame_000003.obj",
            "frame_000003.ply"
        ]
    );
    let tool = concat!(env!("CARGO_MANIFEST_DIR"), "/tools/inspect_surface.py");
    let o = command("python3")
        .args([tool, out.to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "inspect_surface.py:\n{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("4 surfaces"), "{stdout}");
}

#[test]
fn isph_surface_writes_the_same_bytes_on_one_and_two_threads_and_as_the_run_did() {
    let dir = TempDir::new("surface-threads");
    let out = run(dir.path(), &column_3d(0.04, "[output.surface]\n"), &[]);
    let (one, two) = (dir.path().join("one"), dir.path().join("two"));
    for (threads, target) in [("1", &one), ("2", &two)] {
        let printed = ok(&[
            "surface",
            out.to_str().unwrap(),
            "--threads",
            threads,
            "--out",
            target.to_str().unwrap(),
        ]);
        assert!(printed.contains("frame 2 (t = 0.04 s)"), "{printed}");
    }
    let ply = |d: &Path| {
        frames_of(d)
            .iter()
            .map(|p| std::fs::read(p).unwrap())
            .collect::<Vec<_>>()
    };
    assert_eq!(ply(&one).len(), 3);
    assert_eq!(
        ply(&one),
        ply(&two),
        "PLY files differ between 1 and 2 threads"
    );
    assert_eq!(
        ply(&one),
        ply(&out),
        "isph surface differs from the run's own surfaces"
    );
    let meshes = |d: &Path| {
        let r = SurfaceReader::open(d).unwrap().unwrap();
        (0..3)
            .map(|k| r.read(k).unwrap().unwrap())
            .collect::<Vec<_>>()
    };
    assert_eq!(meshes(&one), meshes(&two));
}

#[test]
fn a_resumed_run_writes_the_surfaces_of_a_straight_run() {
    let dir = TempDir::new("surface-resume");
    let straight = run(dir.path(), &column_3d(0.06, "[output.surface]\n"), &[]);
    let split_dir = TempDir::new("surface-resume-split");
    let split = run(
        split_dir.path(),
        &column_3d(0.06, "[output.surface]\n"),
        &["--until", "0.02"],
    );
    ok(&["resume", split.to_str().unwrap(), "-q"]);
    let read = |d: &Path| std::fs::read(d.join("surface/frame_000003.ply")).unwrap();
    assert_eq!(read(&straight), read(&split));
    let r = SurfaceReader::open(&split).unwrap().unwrap();
    assert!(r.read(3).unwrap().is_some() && r.read(4).unwrap().is_none());
}

#[test]
fn bad_surface_requests_are_refused_and_nothing_is_overwritten() {
    let dir = TempDir::new("surface-bad");
    let out = run(dir.path(), &column_3d(0.02, ""), &[]);
    let o = out.to_str().unwrap();
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    // A run that has written its particles.h5 but no frame yet.
    let no_frames = dir.path().join("no-frames");
    std::fs::create_dir_all(&no_frames).unwrap();
    drop(isph::io::frames::FrameWriter::create(&no_frames, 3, 0.02).unwrap());
    let png = dir.path().join("x.png");
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["surface", empty.to_str().unwrap()],
            &["not a run's output directory", "particles.h5"],
        ),
        (
            &["surface", no_frames.to_str().unwrap()],
            &["particles.h5 holds no frames yet"],
        ),
        (
            &["surface", o, "--frames", "7"],
            &["--frames 7", "frame 7 does not exist", "0 to 1"],
        ),
        (&["surface", o, "--frames", "1..0"], &["runs backwards"]),
        (
            &["surface", o, "--cube-size", "0"],
            &["--cube-size", "positive"],
        ),
        (
            &["surface", o, "--cube-size", "0.0001"],
            &["frame 0", "cubes", "limit of 1e9"],
        ),
        (
            &["surface", o, "--kernel", "cubic"],
            &["--kernel", "cubic", "quartic"],
        ),
        (&["surface", o, "--iso", "1.5"], &["--iso", "(0, 1)"]),
        (
            &["render", o, "--frame", "9", "-o", png.to_str().unwrap()],
            &["9"],
        ),
    ];
    for (args, expected) in cases {
        let r = isph(args);
        let stderr = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success(), "{args:?} accepted");
        assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
        for e in *expected {
            assert!(stderr.contains(e), "{args:?}: `{e}` missing from {stderr}");
        }
        assert!(!out.join("surface.h5").exists(), "{args:?} wrote a surface");
    }
    // --out into a folder whose surface/ holds other files: they stay.
    let elsewhere = dir.path().join("elsewhere");
    std::fs::create_dir_all(elsewhere.join("surface")).unwrap();
    std::fs::write(elsewhere.join("surface/notes.txt"), "mine").unwrap();
    ok(&["surface", o, "--out", elsewhere.to_str().unwrap()]);
    ok(&[
        "surface",
        o,
        "--out",
        elsewhere.to_str().unwrap(),
        "--overwrite",
        "--frames",
        "1",
    ]);
    assert_eq!(
        std::fs::read_to_string(elsewhere.join("surface/notes.txt")).unwrap(),
        "mine"
    );
    assert!(
        !elsewhere.join("surface/frame_000000.ply").exists()
            && elsewhere.join("surface/frame_000001.ply").exists()
    );
    // A surface already there is kept unless --overwrite.
    ok(&["surface", o, "--frames", "0"]);
    let before = std::fs::read(out.join("surface.h5")).unwrap();
    let r = isph(&["surface", o]);
    assert!(!r.status.success() && String::from_utf8_lossy(&r.stderr).contains("--overwrite"));
    assert_eq!(std::fs::read(out.join("surface.h5")).unwrap(), before);
    // And a scene's bad [output.surface] names its key and line.
    let path = dir.path().join("bad.toml");
    std::fs::write(
        &path,
        column_3d(0.02, "[output.surface]\nkernel = \"cubic\"\n"),
    )
    .unwrap();
    let r = isph(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        dir.path().join("bad").to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(
        !r.status.success()
            && stderr.contains("output.surface.kernel")
            && stderr.contains("bad.toml:25"),
        "{stderr}"
    );
}

#[test]
fn the_surface_and_a_picture_of_a_run_still_going_can_be_made() {
    let dir = TempDir::new("surface-live");
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, column_3d(10.0, "")).unwrap();
    let out = dir.path().join("out");
    let mut running = isph_command()
        .args([
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "-q",
            "--threads",
            "1",
        ])
        .spawn()
        .unwrap();
    // The run holds particles.h5 open for writing, with HDF5's lock, until it ends.
    let started = std::time::Instant::now();
    let made = loop {
        let o = isph(&[
            "surface",
            out.to_str().unwrap(),
            "--frames",
            "1",
            "--out",
            dir.path().join("s").to_str().unwrap(),
            "--overwrite",
        ]);
        if o.status.success() || started.elapsed().as_secs() > 120 {
            break o;
        }
        std::thread::sleep(std::time::Duration::from_millis(200));
    };
    let png = dir.path().join("live.png");
    let picture = isph(&[
        "render",
        out.to_str().unwrap(),
        "--frame",
        "1",
        "-o",
        png.to_str().unwrap(),
        "--size",
        "320x200",
    ]);
    let still_running = running.try_wait().unwrap().is_none();
    running.kill().unwrap();
    running.wait().unwrap();
    assert!(still_running, "the run ended before the test could read it");
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    assert!(
        picture.status.success(),
        "{}",
        String::from_utf8_lossy(&picture.stderr)
    );
}
