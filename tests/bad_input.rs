//! Bad input: one clear paragraph naming the file and key (and line), exit code ≠ 0, no panic,
//! and nothing already written is touched.

use crate::common::{isph_command, water_block_scene, TempDir};
use std::path::{Path, PathBuf};
use std::process::Output;

/// A valid scene: one 10 × 10 block of water, run for a single frame.
fn good() -> String {
    water_block_scene(0.01)
}

fn isph(args: &[&str]) -> Output {
    isph_command().args(args).output().unwrap()
}

/// `scene` text written to `dir`/scene.toml: (that file, the output directory `dir`/out).
fn scene_in(dir: &Path, scene: &str) -> (PathBuf, PathBuf) {
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    (path, dir.join("out"))
}

/// Runs `isph run` on `scene` text and returns (exit code, stderr).
fn run_text(dir: &Path, scene: &str, extra: &[&str]) -> (i32, String) {
    let (path, out) = scene_in(dir, scene);
    let mut args = vec![
        "run",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "-q",
    ];
    args.extend_from_slice(extra);
    let o = isph(&args);
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn assert_refused(code: i32, stderr: &str, expected: &[&str]) {
    assert_ne!(code, 0, "accepted; stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    for e in expected {
        assert!(stderr.contains(e), "`{e}` missing from: {stderr}");
    }
}

#[test]
fn each_bad_scene_is_refused_with_its_key_and_line() {
    let dir = TempDir::new("bad-input");
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "spacing = 0.02",
            "spacing = -0.02",
            &["simulation.spacing", "scene.toml:3", "positive"],
        ),
        (
            // A number prints in the shortest form that reads back, not in 300 digits.
            "spacing = 0.02",
            "spacing = -1e-300",
            &["simulation.spacing", "= -1e-300 must be a positive number"],
        ),
        (
            "output_interval = 0.01",
            "output_interval = 1e-12",
            &["simulation.output_interval", "scene.toml:5", "frames"],
        ),
        (
            "spacing = 0.02",
            "spacing = 1e-9",
            &[
                "simulation.spacing",
                "scene.toml:3",
                "particles",
                "more than",
            ],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [1e6, 0.3]",
            &["simulation.spacing", "GiB of memory this machine has"],
        ),
        (
            // A small block in a vast empty container: the container's lattice, not the
            // particles, would fill the memory.
            "max = [0.4, 0.3]",
            "max = [1200.0, 1200.0]",
            &["simulation.spacing", "lattice points", "GiB of memory this machine has"],
        ),
        (
            // A body's lattice points are counted before they are made.
            "max = [0.4, 0.3]",
            "max = [1200.0, 1200.0]\n\n[[body]]\nshape = \"box\"\nmin = [1.0, 1.0]\nmax = [1199.0, 1199.0]\ndensity = 500.0\nmotion = \"free\"",
            &["body[0].shape", "scene.toml:23", "GiB of memory this machine has"],
        ),
        (
            "dimensions = 2",
            "dimensions = 4",
            &["simulation.dimensions", "scene.toml:2", "2 or 3"],
        ),
        (
            "dimensions = 2",
            "dimensions = 2\nname = \"../../elsewhere\"",
            &["simulation.name", "scene.toml:3", "plain directory name"],
        ),
        (
            "dimensions = 2",
            "dimensions = 2\nname = \"\"",
            &["simulation.name", "scene.toml:3", "plain directory name"],
        ),
        (
            "gravity = [0.0, -9.81]",
            "gravity = [0.0, -9.81, 0.0]",
            &["simulation.gravity", ":6", "3 components"],
        ),
        (
            "max = [0.2, 0.2]",
            "max = [0.2, 0.5]",
            &["fluid_block[0]", "not inside the container"],
        ),
        (
            "fluid = \"water\"",
            "fluid = \"oil\"",
            &[
                "fluid_block[0].fluid",
                "scene.toml:14",
                "\"oil\"",
                "\"water\"",
            ],
        ),
        (
            "viscosity = 1.0e-6",
            "viscosity = 1.0e-6\ncolour = 3",
            &["unknown field `colour`", "line 12"],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\nperiodic = [true]",
            &["container.periodic", "scene.toml:21", "1 flags"],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.41, 0.3]\nperiodic = [true, false]",
            &["container.periodic", "axis 0", "whole number of spacings"],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\n\n[initial_velocity]\nfield = \"taylor_green\"\namplitude = 1.0",
            &[
                "initial_velocity.field",
                "scene.toml:23",
                "periodic in both axes",
            ],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\n\n[initial_velocity]\nfield = \"vortex\"\namplitude = 1.0",
            &["initial_velocity.field", "\"vortex\"", "taylor_green"],
        ),
        (
            "end_time = 0.01",
            "end_time = [0.01",
            &["line 5", "TOML parse error", "expected `]`"],
        ),
        (
            "gravity = [0.0, -9.81]",
            "",
            &["line 1", "missing field `gravity`", "in the section `[simulation]`"],
        ),
        (
            "density = 1000.0",
            "",
            &["line 8", "missing field `density`", "in the section `[[fluid]]`"],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\n\n[walls]\nghost_pressure = \"sticky\"",
            &[
                "line 23",
                "unknown variant `sticky`",
                "hydrostatic",
                "mirror",
            ],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\n\n[[probe]]\npoint = [0.5, 0.1]\nfield = \"pressure\"",
            &["probe[0].point", "scene.toml:23", "not inside the container"],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\n\n[[probe]]\npoint = [0.1, 0.1]\nfield = \"vorticity\"",
            &["probe[0].field", "scene.toml:24", "\"vorticity\"", "\"pressure\", \"velocity\""],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\n\n[[probe]]\nname = \"A\"\npoint = [0.1, 0.1]\nfield = \"pressure\"\n\n[[probe]]\nname = \"A\"\npoint = [0.2, 0.1]\nfield = \"pressure\"",
            &["probe[1].name", "scene.toml:28", "column `A`"],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\n\n[[probe]]\npoint = [0.1, 0.1, 0.1]\nfield = \"velocity\"",
            &["probe[0].point", "scene.toml:23", "has 3 components"],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\n\n[[probe]]\nname = \"a,b\"\npoint = [0.1, 0.1]\nfield = \"pressure\"",
            &["probe[0].name", "scene.toml:23", "plain column name"],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\n\n[solver]\nkernel = \"cubic\"",
            &[
                "solver.kernel",
                "scene.toml:23",
                "\"cubic\" is not a kernel",
                "quintic, wendland_c2, wendland_c4",
            ],
        ),
        (
            "max = [0.4, 0.3]",
            "max = [0.4, 0.3]\n\n[solver]\nkernel = \"wendland_c2\"\nh_over_dx = 3.5",
            &[
                "solver.h_over_dx",
                "scene.toml:24",
                "[1.0, 3.0] with the wendland_c2 kernel",
            ],
        ),
    ];
    for (from, to, expected) in cases {
        let (code, stderr) = run_text(dir.path(), &good().replace(from, to), &[]);
        assert_refused(code, &stderr, expected);
        assert!(stderr.contains("scene.toml"), "file not named: {stderr}");
    }
}

#[test]
fn a_missing_file_is_refused() {
    let o = isph(&["run", "/nonexistent/scene.toml", "-q"]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_refused(
        o.status.code().unwrap_or(-1),
        &stderr,
        &["/nonexistent/scene.toml", "cannot read"],
    );
}

#[test]
fn an_unwritable_output_directory_is_refused() {
    let dir = TempDir::new("unwritable");
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, good()).unwrap();
    let out = file.join("out");
    let o = isph(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "-q",
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_refused(
        o.status.code().unwrap_or(-1),
        &stderr,
        &["output directory", "cannot be used"],
    );
}

#[test]
fn an_existing_run_is_never_overwritten_by_accident() {
    let dir = TempDir::new("existing-run");
    let (code, stderr) = run_text(dir.path(), &good(), &[]);
    assert_eq!(code, 0, "{stderr}");
    let h5 = dir.path().join("out/particles.h5");
    let before = std::fs::read(&h5).unwrap();
    let (code, stderr) = run_text(dir.path(), &good(), &[]);
    assert_refused(code, &stderr, &["already holds a run", "--overwrite"]);
    assert_eq!(
        std::fs::read(&h5).unwrap(),
        before,
        "the earlier run was modified"
    );
    let (code, stderr) = run_text(dir.path(), &good(), &["--overwrite"]);
    assert_eq!(code, 0, "{stderr}");
    // A folder holding only another run's bodies.csv is not written into either.
    let other = TempDir::new("existing-bodies");
    std::fs::create_dir(other.path().join("out")).unwrap();
    let bodies = other.path().join("out/bodies.csv");
    std::fs::write(&bodies, "time,body\n").unwrap();
    let (code, stderr) = run_text(other.path(), &good(), &[]);
    assert_refused(code, &stderr, &["bodies.csv", "--overwrite"]);
    assert_eq!(std::fs::read_to_string(&bodies).unwrap(), "time,body\n");
}

/// A TOML syntax error is one line: where it is and what is wrong, not the source line echoed
/// with a caret under it.
#[test]
fn a_toml_syntax_error_is_one_line() {
    let dir = TempDir::new("toml-one-line");
    let long = format!("{}\ncolour = \"{}", good(), "x".repeat(10_000));
    let (code, stderr) = run_text(dir.path(), &long, &[]);
    assert_refused(code, &stderr, &["TOML parse error at line 22"]);
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert!(stderr.len() < 500, "{} bytes of error", stderr.len());
}

/// `isph plan x | head -1`, `isph run x | true`: a reader of stdout that has gone away is not
/// an error, nor a panic ("failed printing to stdout: Broken pipe").
#[test]
fn a_closed_stdout_is_not_an_error() {
    let dir = TempDir::new("closed-stdout");
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, good()).unwrap();
    let out = dir.path().join("out");
    let (scene, out) = (scene.to_str().unwrap(), out.to_str().unwrap());
    for args in [vec!["plan", scene], vec!["run", scene, "--out", out, "-q"]] {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let o = isph_command().args(&args).stdout(writer).output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "isph {args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "isph {args:?}: {stderr}");
    }
    assert!(
        dir.path()
            .join("out/checkpoints")
            .read_dir()
            .unwrap()
            .count()
            > 0
    );
}

/// A block one spacing wide holds one particle per axis, whatever the rounding of its corners
/// (0.3 − 0.28 = 0.01999… is not narrower than the spacing 0.02).
#[test]
fn a_block_one_spacing_wide_is_accepted() {
    let text = good()
        .replace(
            "min = [0.0, 0.0]\nmax = [0.2, 0.2]",
            "min = [0.28, 0.1]\nmax = [0.3, 0.12]",
        )
        .replace("spacing = 0.02", "spacing = 0.02\nname = \"one\"");
    let scene = crate::common::scene_from_text(&text);
    let plan = isph::tools::plan::Plan::new(&scene).unwrap_or_else(|e| panic!("{e}"));
    assert!(plan.to_string().contains("particles: 1 fluid"), "{plan}");
}

#[test]
fn a_run_of_more_than_ten_million_steps_is_warned_of_with_the_limit_that_sets_the_step() {
    use std::io::{BufRead, BufReader};
    let dir = TempDir::new("long-run");
    // ν = 1e6 m²/s: Δt = 0.125 h²/ν = 7.2e-11 s (h = 0.024 m), 9.7e9 steps to 0.7 s.
    let text = good().replace("viscosity = 1.0e-6", "viscosity = 1.0e6");
    let (path, out) = scene_in(dir.path(), &text);
    let mut child = isph_command()
        .args([
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "-q",
        ])
        .args(["--until", "0.7"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // The warning comes before the first step; the run itself is not waited for.
    let mut first = String::new();
    BufReader::new(child.stderr.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        first.starts_with("warning: the first time step is"),
        "{first}"
    );
    assert!(first.contains("the viscous condition"), "{first}");
    assert!(
        first.contains("reaching t = 0.7 s takes about 9.7e9 steps"),
        "{first}"
    );
    // A run of ordinary length is not warned of.
    let (code, stderr) = run_text(dir.path(), &good(), &["--until", "0.01", "--overwrite"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("warning"), "{stderr}");
}

#[test]
fn the_progress_line_shows_the_end_time_as_written() {
    let dir = TempDir::new("progress-end");
    // Frames every 0.1 s: the run ends on the third, scheduled at 3 × 0.1 = 0.30000000000000004.
    let text = good().replace("output_interval = 0.01", "output_interval = 0.1");
    let (path, out) = scene_in(dir.path(), &text);
    let o = isph(&[
        "run",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--until",
        "0.3",
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    // Not a terminal: plain lines, the first after the first step.
    let line = stderr
        .lines()
        .find(|l| l.starts_with("t = "))
        .unwrap_or_else(|| panic!("{stderr}"));
    assert!(line.contains("/0.3 s |"), "{line}");
    assert!(!stderr.contains("0.30000000000000004"), "{stderr}");
}

#[test]
fn each_bad_body_is_refused_with_its_key() {
    let dir = TempDir::new("bad-bodies");
    let body = |text: &str| format!("{}\n[[body]]\n{text}\n", good());
    let cases: &[(&str, &[&str])] = &[
        ("shape = \"box\"\nmin = [0.3, 0.1]\nmax = [0.5, 0.2]\ndensity = 500.0", &["body[0].shape", "not inside the container"]),
        ("shape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\ndensity = 500.0\n[[body]]\nshape = \"circle\"\ncenter = [0.15, 0.1]\nradius = 0.05\ndensity = 500.0", &["body[1].shape", "overlaps body[0]"]),
        ("shape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\ndensity = -1.0", &["body[0].density", "positive"]),
        ("shape = \"cone\"\ncenter = [0.1, 0.1]\nradius = 0.05\ndensity = 500.0", &["body[0].shape", "\"cone\" is not a shape", "\"circle\""]),
        ("shape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\ndensity = 500.0\nmotion = \"wobbly\"", &["body[0].motion", "\"free\""]),
        ("shape = \"circle\"\ncenter = [0.1, 0.1]\ndensity = 500.0", &["body[0].radius", "missing"]),
        ("shape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\nmin = [0.0, 0.0]\ndensity = 500.0", &["body[0].min", "not a key of a circle"]),
        ("shape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05", &["body[0]", "neither `density`"]),
        ("shape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\ndensity = 500.0\nfriction = -0.1", &["body[0].friction", "≥ 0"]),
        ("shape = \"union\"\ndensity = 500.0", &["body[0].part", "has 0", "two shapes or more"]),
        ("shape = \"union\"\ncenter = [0.1, 0.1]\ndensity = 500.0\n[[body.part]]\nshape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\n[[body.part]]\nshape = \"circle\"\ncenter = [0.15, 0.1]\nradius = 0.05", &["body[0].center", "not a key of a union"]),
        ("shape = \"union\"\ndensity = 500.0\n[[body.part]]\nshape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\n[[body.part]]\nshape = \"union\"", &["body[0].part[1].shape", "\"union\" is not a shape a union's part takes"]),
        ("shape = \"union\"\ndensity = 500.0\n[[body.part]]\nshape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\n[[body.part]]\nshape = \"box\"\nmin = [0.1, 0.1]", &["body[0].part[1].max", "missing"]),
        ("shape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\ndensity = 500.0\n[[body.part]]\nshape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05", &["body[0].part", "is for a union"]),
        ("shape = \"union\"\ndensity = 500.0\n[[body.part]]\nshape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\n[[body.part]]\nshape = \"circle\"\ncenter = [0.2, 0.2]\nradius = 0.005", &["body[0].part[1].shape", "no lattice point", "adds nothing"]),
    ];
    for (text, expected) in cases {
        let (code, stderr) = run_text(dir.path(), &body(text), &[]);
        assert_refused(code, &stderr, expected);
    }
}

#[test]
fn a_body_that_could_cross_a_period_is_refused() {
    // A held body stays where the box holds it; a free one, or one let go, could cross the
    // period, and a body's particles are not wrapped.
    let dir = TempDir::new("bad-periodic-bodies");
    let periodic = good().replace(
        "max = [0.4, 0.3]\n",
        "max = [0.4, 0.3]\nperiodic = [true, false]\n",
    );
    let body = |text: &str| {
        format!("{periodic}\n[[body]]\nshape = \"circle\"\ncenter = [0.3, 0.15]\nradius = 0.03\ndensity = 500.0\n{text}\n")
    };
    for text in ["", "motion = \"fixed\"\nrelease = 0.005"] {
        let (code, stderr) = run_text(dir.path(), &body(text), &[]);
        assert_refused(
            code,
            &stderr,
            &["body[0].motion", "periodic container", "held"],
        );
    }
    let (code, stderr) = run_text(dir.path(), &body("motion = \"fixed\""), &[]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn each_bad_trajectory_is_refused_with_its_key() {
    let dir = TempDir::new("bad-trajectories");
    std::fs::write(
        dir.path().join("backwards.csv"),
        "time,x,y,angle\n0.0,0,0,0\n0.5,0,0,1\n0.4,0,0,2\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("short.csv"),
        "time,x,y,angle\n0.0,0,0,0\n0.001,0,0,1\n",
    )
    .unwrap();
    let circle =
        "[[body]]\nshape = \"circle\"\ncenter = [0.1, 0.1]\nradius = 0.05\ndensity = 500.0";
    let cases: &[(String, &[&str])] = &[
        (format!("{circle}\nmotion = \"prescribed\""), &["body[0]", "no [body.trajectory]"]),
        (format!("{circle}\n[body.trajectory]\nperiod = 1.0\nangle = 5.0"), &["body[0].trajectory", "prescribed body"]),
        (format!("{circle}\nmotion = \"prescribed\"\n[body.trajectory]\nperiod = 1.0\ntable = \"short.csv\""), &["body[0].trajectory.table", "both given"]),
        (format!("{circle}\nmotion = \"prescribed\"\n[body.trajectory]\ntable = \"backwards.csv\""), &["body[0].trajectory.table", "line 4", "times must increase"]),
        (format!("{circle}\nmotion = \"prescribed\"\n[body.trajectory]\ntable = \"short.csv\""), &["body[0].trajectory.table", "before `simulation.end_time`"]),
        (format!("{circle}\nmotion = \"prescribed\"\n[body.trajectory]\ntable = \"missing.csv\""), &["body[0].trajectory.table", "cannot read"]),
        (format!("{circle}\nmotion = \"prescribed\"\n[body.trajectory]\nperiod = 1.0"), &["body[0].trajectory", "gives no motion"]),
        (format!("{circle}\nmotion = \"prescribed\"\n[body.trajectory]\nperiod = 1e-300\namplitude = [0.01, 0.0]"), &["body[0].trajectory.period", "overflow"]),
        (format!("{circle}\nrelease = 1.0"), &["body[0].release", "fixed or prescribed"]),
        (format!("{circle}\nmotion = \"prescribed\"\n[body.trajectory]\nperiod = 0.04\namplitude = [0.3, 0.0]"), &["body[0].trajectory", "out of the container", "walls do not yield"]),
        (format!("[[obstacle]]\nmin = [0.25, 0.05]\nmax = [0.3, 0.15]\n\n{circle}\nmotion = \"prescribed\"\n[body.trajectory]\nperiod = 0.04\namplitude = [0.2, 0.0]"), &["body[0].trajectory", "into obstacle[0]", "does not yield"]),
        ("[container.trajectory]\nperiod = -1.0\nangle = 4.0".to_string(), &["container.trajectory.period", "positive"]),
        ("[container.trajectory]\nperiod = 1.0".to_string(), &["container.trajectory", "gives no motion", "stands still"]),
        ("[container.trajectory]\nperiod = 1.0\nangle = 4.0\naxis = [0.0, 0.0, 1.0]".to_string(), &["container.trajectory.axis", "for 3D"]),
    ];
    for (text, expected) in cases {
        let (code, stderr) = run_text(dir.path(), &format!("{}\n{text}\n", good()), &[]);
        assert_refused(code, &stderr, expected);
    }
}

#[test]
fn a_stop_time_past_the_end_of_a_motion_table_is_refused_before_anything_is_written() {
    // After its last row a table holds its last pose, at rest: `--until` past it, on a run or a
    // resume, would stop the prescribed motion dead. The table covers `end_time` (0.01 s).
    let dir = TempDir::new("table-until");
    std::fs::write(
        dir.path().join("moves.csv"),
        "time,x,y,angle\n0.0,0,0,0\n0.01,0.001,0,0\n",
    )
    .unwrap();
    let body = "[[body]]\nshape = \"circle\"\ncenter = [0.05, 0.15]\nradius = 0.02\ndensity = 500.0\nmotion = \"prescribed\"\n[body.trajectory]\ntable = \"moves.csv\"";
    let scene = format!("{}\n{body}\n", good());
    let expected = [
        "body[0].trajectory.table",
        "moves.csv",
        "ends at 0.01 s",
        "0.02",
    ];
    let (code, stderr) = run_text(dir.path(), &scene, &["--until", "0.02"]);
    assert_refused(code, &stderr, &expected);
    assert!(
        !dir.path().join("out").exists(),
        "the refused run wrote {}",
        dir.path().join("out").display()
    );
    let (code, stderr) = run_text(dir.path(), &scene, &[]);
    assert_eq!(code, 0, "{stderr}");
    let out = dir.path().join("out");
    let before: Vec<_> = std::fs::read_dir(out.join("checkpoints"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    let o = isph(&["resume", out.to_str().unwrap(), "--until", "0.02", "-q"]);
    assert_refused(
        o.status.code().unwrap_or(-1),
        &String::from_utf8_lossy(&o.stderr),
        &expected,
    );
    let after: Vec<_> = std::fs::read_dir(out.join("checkpoints"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(before, after);
}

#[test]
fn each_bad_mesh_is_refused_with_its_key() {
    let dir = TempDir::new("bad-meshes");
    // A cube with its top face missing: open.
    std::fs::write(
        dir.path().join("open.obj"),
        "v 0.1 0.1 0.1\nv 0.2 0.1 0.1\nv 0.1 0.2 0.1\nv 0.2 0.2 0.1\nv 0.1 0.1 0.2\nv 0.2 0.1 0.2\nv 0.1 0.2 0.2\nv 0.2 0.2 0.2\nf 1 3 4 2\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("bad.obj"), "v 0.1 0.1\nf 1 2 3\n").unwrap();
    // A binary STL of one facet whose second vertex has a NaN coordinate.
    let mut stl = vec![0u8; 80];
    stl.extend(1u32.to_le_bytes());
    for x in [
        0.0f32,
        0.0,
        1.0,
        0.1,
        0.1,
        0.1,
        0.2,
        f32::NAN,
        0.1,
        0.1,
        0.2,
        0.1,
    ] {
        stl.extend(x.to_le_bytes());
    }
    stl.extend(0u16.to_le_bytes());
    std::fs::write(dir.path().join("nan.stl"), stl).unwrap();
    let scene = |body: &str| {
        crate::common::water_block_scene_3d([0.2, 0.2, 0.1], [0.4, 0.4, 0.4], 0.01, 0.01, body)
    };
    let cases: &[(&str, &[&str])] = &[
        ("[[body]]\nshape = \"mesh\"\nmesh = \"missing.obj\"\ndensity = 500.0", &["body[0].mesh", "cannot read"]),
        ("[[body]]\nshape = \"mesh\"\nmesh = \"open.obj\"\ndensity = 500.0", &["body[0].mesh", "not closed", "4 of its edges"]),
        ("[[body]]\nshape = \"mesh\"\nmesh = \"bad.obj\"\ndensity = 500.0", &["body[0].mesh", "line 1", "three finite numbers"]),
        ("[[body]]\nshape = \"mesh\"\nmesh = \"nan.stl\"\ndensity = 500.0", &["body[0].mesh", "facet 1", "three finite numbers"]),
        ("[[body]]\nshape = \"box\"\nmin = [0.1, 0.1, 0.2]\nmax = [0.2, 0.2, 0.3]\noffset = [0.0, 0.0, 0.0]\ndensity = 500.0", &["body[0].offset", "moves a mesh"]),
        ("[[fluid_block]]\nfluid = \"water\"\nmin = [0.0, 0.0, 0.2]\nmax = [0.1, 0.1, 0.3]\nmesh = \"open.obj\"", &["fluid_block[1]", "not both"]),
    ];
    for (text, expected) in cases {
        let (code, stderr) = run_text(dir.path(), &scene(text), &[]);
        assert_refused(code, &stderr, expected);
    }
}

/// A periodic axis exactly three kernel supports long, 3 × 3h = n dx: the scene's check asks
/// for more than three supports by more than rounding, so each such scene is refused with its
/// key or builds, never a panic in the cell list (n = 10 … 40 spacings across, for the quintic and a Wendland kernel; an h/dx
/// outside the kernel's range is refused by `solver.h_over_dx`).
#[test]
fn a_periodic_axis_three_supports_long_is_refused_or_built() {
    for n in 10..=40 {
        for (kernel, support_in_h) in [("quintic", 3.0), ("wendland_c2", 2.0)] {
            let h_over_dx = n as f64 / (3.0 * support_in_h);
            let length = n as f64 * 0.1;
            let text = format!(
                "[simulation]\ndimensions = 2\nspacing = 0.1\nend_time = 0.1\n\
                 output_interval = 0.05\ngravity = [0.0, 0.0]\n\n\
                 [[fluid]]\nname = \"water\"\ndensity = 1000.0\nviscosity = 1e-3\n\n\
                 [[fluid_block]]\nfluid = \"water\"\nmin = [0.0, 0.0]\nmax = [{length:?}, {length:?}]\n\n\
                 [container]\nmin = [0.0, 0.0]\nmax = [{length:?}, {length:?}]\n\
                 periodic = [true, true]\n\n\
                 [solver]\nkernel = \"{kernel}\"\nh_over_dx = {h_over_dx:?}\n"
            );
            match isph::Scene::parse(&text, Path::new("scene.toml")) {
                Ok(scene) => {
                    isph::Simulation::<2>::new(&scene).unwrap();
                }
                Err(e) => assert!(
                    e.to_string().contains("container.periodic")
                        || e.to_string().contains("solver.h_over_dx"),
                    "n = {n}, {kernel}: {e}"
                ),
            }
        }
    }
}

/// A particles.h5 whose datasets disagree in length (edited, or cut short) is refused by the
/// readers with the file, the frame and the dataset named, not a panic.
#[test]
fn a_frame_with_datasets_of_unequal_length_is_refused() {
    let dir = TempDir::new("bad-frame");
    let (path, out) = scene_in(dir.path(), &good());
    let (path, out_s) = (path.to_str().unwrap(), out.to_str().unwrap());
    assert!(isph(&["run", path, "--out", out_s, "-q"]).status.success());
    {
        let file = hdf5::File::open_rw(out.join("particles.h5")).unwrap();
        let frame = file.group("frame_000001").unwrap();
        frame.unlink("pressure").unwrap();
        frame
            .new_dataset_builder()
            .with_data(&[0.0f64; 3])
            .create("pressure")
            .unwrap();
    }
    let png = dir.path().join("frame.png");
    for args in [
        vec!["render", out_s, "-o", png.to_str().unwrap()],
        vec!["surface", out_s, "--frames", "last"],
    ] {
        let o = isph(&args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_refused(
            o.status.code().unwrap_or(-1),
            &stderr,
            &["particles.h5", "frame 1", "but 3 in `pressure`"],
        );
    }
}

/// A stop time beyond `end_time` (`--until`) is held to what `end_time` is: the frames it
/// would write, and a prescribed body's path up to it (here a box swung along x that stays in
/// the tank for the scene's 0.01 s and hits the right wall at t = 0.25 s).
#[test]
fn a_stop_time_beyond_end_time_is_validated_as_end_time() {
    let dir = TempDir::new("bad-until");
    let (code, stderr) = run_text(dir.path(), &good(), &["--until", "1e4"]);
    assert_refused(
        code,
        &stderr,
        &["simulation.output_interval", "frames", "--until"],
    );
    let swung = format!(
        "{}\n[[body]]\nshape = \"box\"\nmin = [0.25, 0.22]\nmax = [0.29, 0.26]\ndensity = 1000.0\n\
         motion = \"prescribed\"\n\n[body.trajectory]\nperiod = 1.0\namplitude = [0.12, 0.0]\n",
        good()
    );
    let (code, stderr) = run_text(dir.path(), &swung, &["--until", "0.5"]);
    assert_refused(
        code,
        &stderr,
        &["body[0].trajectory", "out of the container", "--until"],
    );
    assert!(!dir.path().join("out").exists());
    let (code, stderr) = run_text(dir.path(), &swung, &["--until", "0.02"]);
    assert_eq!(code, 0, "{stderr}");
}
