//! Checkpoint and restart: a continued run is bit-identical to one never stopped, in 2D and 3D;
//! a damaged checkpoint or a changed scene is refused with every file left as it was; SIGTERM
//! stops a run with a checkpoint it resumes from.

use crate::common::{isph_command, tank, TempDir};
use isph::io::checkpoint::Checkpoint;
use isph::io::checkpoint_folder;
use isph::particles::{ArrayMut, Kind, Particles};
use isph::run::resume::{self, ResumeOptions};
use isph::run::{self, RunError, RunOptions, StopSignal};
use isph::scene::Scene;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::Ordering;

/// A shipped scene made coarse and short, writing checkpoints every `every` simulated seconds.
fn scene_file(
    dir: &Path,
    shipped: &str,
    edits: &[(&str, &str)],
    every: f64,
    keep: usize,
) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(shipped);
    let mut text = std::fs::read_to_string(path).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "`{from}` not in {shipped}");
        text = text.replace(from, to);
    }
    text += &format!("\n[checkpoint]\ninterval = {every}\nkeep = {keep}\n");
    let file = dir.join(shipped);
    std::fs::write(&file, text).unwrap();
    file
}

/// 2D dam break at 2 dx: 40 steps to 16 output intervals, with a pressure probe on the back
/// wall's face under the column and a velocity probe in the surge's path.
fn dam_break_2d(dir: &Path) -> PathBuf {
    let edits = [
        ("spacing = 0.00142875", "spacing = 0.00381"),
        ("output_interval = 0.01", "output_interval = 0.005"),
    ];
    let file = scene_file(dir, "dam_break_2d.toml", &edits, 0.01, 3);
    let probes = "\n[[probe]]\nname = \"back\"\npoint = [0.0, 0.005]\nfield = \"pressure\"\n\n[[probe]]\npoint = [0.1, 0.005]\nfield = \"velocity\"\n";
    let text = std::fs::read_to_string(&file).unwrap() + probes;
    std::fs::write(&file, text).unwrap();
    file
}

fn run_options(out: &Path, until: f64) -> RunOptions {
    RunOptions {
        out: out.to_owned(),
        until: Some(until),
        overwrite: false,
        quiet: true,
        stop: StopSignal::default(),
    }
}

fn resume_options(until: f64) -> ResumeOptions {
    ResumeOptions {
        until: Some(until),
        force: false,
        scene: None,
        quiet: true,
        stop: StopSignal::default(),
    }
}

/// Resumes the newest valid checkpoint of `target` (a file or a directory) until `until`.
fn resume_until(target: &Path, until: f64) -> run::RunSummary {
    let located = resume::locate(target).unwrap_or_else(|e| panic!("{e}"));
    run::resume(&located.checkpoint, &resume_options(until)).unwrap_or_else(|e| panic!("{e}"))
}

/// Every file under `dir` with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files.extend(snapshot(&path));
        } else {
            files.insert(path.clone(), std::fs::read(&path).unwrap());
        }
    }
    files
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let target = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_dir(&path, &target);
        } else {
            std::fs::copy(&path, &target).unwrap();
        }
    }
}

/// Every dataset and attribute of every frame of two runs' particles.h5, compared bit for bit.
fn assert_same_frames(a: &Path, b: &Path, what: &str) {
    let open = |dir: &Path| hdf5::File::open(dir.join("particles.h5")).unwrap();
    let (fa, fb) = (open(a), open(b));
    let (mut names_a, mut names_b) = (fa.member_names().unwrap(), fb.member_names().unwrap());
    names_a.sort();
    names_b.sort();
    assert_eq!(names_a, names_b, "{what}: the frames differ");
    for frame in &names_a {
        let (ga, gb) = (fa.group(frame).unwrap(), fb.group(frame).unwrap());
        for attr in ["time", "step"] {
            let x: f64 = ga.attr(attr).unwrap().read_scalar::<f64>().unwrap();
            let y: f64 = gb.attr(attr).unwrap().read_scalar::<f64>().unwrap();
            assert_eq!(x.to_bits(), y.to_bits(), "{what}: {frame} `{attr}` differs");
        }
        for name in ["position", "velocity", "pressure", "density"] {
            let x = ga.dataset(name).unwrap().read_raw::<f64>().unwrap();
            let y = gb.dataset(name).unwrap().read_raw::<f64>().unwrap();
            let same =
                x.len() == y.len() && x.iter().zip(&y).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(same, "{what}: {frame} `{name}` differs");
        }
        for name in ["kind", "fluid", "free_surface", "body", "id"] {
            let x = ga.dataset(name).unwrap().read_raw::<i64>().unwrap();
            let y = gb.dataset(name).unwrap().read_raw::<i64>().unwrap();
            assert_eq!(x, y, "{what}: {frame} `{name}` differs");
        }
    }
}

/// stats.csv of two runs, equal in every column but the wall-clock time.
fn assert_same_stats(a: &Path, b: &Path, what: &str) {
    let rows = |dir: &Path| -> Vec<Vec<String>> {
        let text = std::fs::read_to_string(dir.join("stats.csv")).unwrap();
        let wall = text
            .lines()
            .next()
            .unwrap()
            .split(',')
            .position(|c| c == "wall_seconds")
            .unwrap();
        text.lines()
            .map(|l| {
                let mut cells: Vec<String> = l.split(',').map(str::to_owned).collect();
                cells.remove(wall);
                cells
            })
            .collect()
    };
    assert_eq!(rows(a), rows(b), "{what}: stats.csv differs");
}

/// The state of a run's newest checkpoint: step, time and every particle array in memory order.
fn final_state<const D: usize>(out: &Path) -> (u64, u64, Particles<D>) {
    let all = checkpoint_folder::list(&checkpoint_folder::folder(out)).unwrap();
    let checkpoint = Checkpoint::open(&all.last().unwrap().1).unwrap();
    let mut p = Particles::<D>::default();
    checkpoint.restore(&mut p).unwrap();
    (checkpoint.state.step, checkpoint.state.time.to_bits(), p)
}

fn assert_same_final_state<const D: usize>(a: &Path, b: &Path, what: &str) {
    let (step_a, time_a, mut pa) = final_state::<D>(a);
    let (step_b, time_b, mut pb) = final_state::<D>(b);
    assert_eq!(
        (step_a, time_a),
        (step_b, time_b),
        "{what}: the final step or time differs"
    );
    for ((name, x), (_, y)) in pa.arrays_mut().into_iter().zip(pb.arrays_mut()) {
        let same = match (x, y) {
            (ArrayMut::F64(x), ArrayMut::F64(y)) => {
                x.len() == y.len()
                    && x.iter()
                        .zip(y.iter())
                        .all(|(x, y)| x.to_bits() == y.to_bits())
            }
            (ArrayMut::U64(x), ArrayMut::U64(y)) => x == y,
            (ArrayMut::U16(x), ArrayMut::U16(y)) => x == y,
            (ArrayMut::U8(x), ArrayMut::U8(y)) => x == y,
            (ArrayMut::Kind(x), ArrayMut::Kind(y)) => x == y,
            _ => false,
        };
        assert!(same, "{what}: the final `{name}` differs");
    }
}

/// probes.csv of two runs (when the first has one), byte for byte.
fn assert_same_probes(a: &Path, b: &Path, what: &str) {
    let read = |dir: &Path| std::fs::read(dir.join("probes.csv")).ok();
    let (x, y) = (read(a), read(b));
    assert_eq!(
        x.is_some(),
        y.is_some(),
        "{what}: probes.csv in one run only"
    );
    assert!(x == y, "{what}: probes.csv differs");
}

/// bodies.csv byte for byte: the bodies' state at every frame.
fn assert_same_bodies(a: &Path, b: &Path, what: &str) {
    let read = |dir: &Path| std::fs::read(dir.join("bodies.csv")).ok();
    assert!(read(a) == read(b), "{what}: bodies.csv differs");
}

fn assert_same_run<const D: usize>(whole: &Path, other: &Path, what: &str) {
    assert_same_frames(whole, other, what);
    assert_same_stats(whole, other, what);
    assert_same_probes(whole, other, what);
    assert_same_bodies(whole, other, what);
    assert_same_final_state::<D>(whole, other, what);
}

#[test]
fn a_continued_2d_run_is_bit_identical_to_one_never_stopped() {
    let dir = TempDir::new("ckpt-2d");
    let scene = Scene::load(&dam_break_2d(dir.path())).unwrap();
    let (half, end) = (8.0 * scene.output_interval, 16.0 * scene.output_interval);
    let whole = dir.path().join("whole");
    run::run(&scene, &run_options(&whole, end)).unwrap();
    // `keep = 3` of the checkpoints written every 0.01 s and at the end.
    assert_eq!(
        checkpoint_folder::list(&checkpoint_folder::folder(&whole))
            .unwrap()
            .len(),
        3
    );

    // Stopped at T/2, continued to T.
    let split = dir.path().join("split");
    run::run(&scene, &run_options(&split, half)).unwrap();
    let summary = resume_until(&split, end);
    assert!(summary.steps > 10, "only {} steps after T/2", summary.steps);
    assert_same_run::<2>(&whole, &split, "stopped at T/2");

    // Stopped at T/2 and continued to a sliver past it: the sliver takes the divergence the
    // particles carry out over the last step's Δt, which the checkpoint holds (`dt`).
    let sliver = half + 1e-5;
    let through = dir.path().join("through");
    run::run(&scene, &run_options(&through, sliver)).unwrap();
    let resumed = dir.path().join("resumed");
    run::run(&scene, &run_options(&resumed, half)).unwrap();
    assert_eq!(resume_until(&resumed, sliver).steps, 1);
    assert_same_run::<2>(&through, &resumed, "continued to a sliver past T/2");

    // Stopped by a signal after its first step (between two frames), continued to T.
    let signalled = dir.path().join("signalled");
    let opts = run_options(&signalled, end);
    opts.stop.store(15, Ordering::Relaxed);
    match run::run(&scene, &opts) {
        Err(RunError::Interrupted { saved, .. }) => assert_eq!(saved.step, 1),
        other => panic!("not interrupted: {other:?}"),
    }
    resume_until(&signalled, end);
    assert_same_run::<2>(&whole, &signalled, "stopped by a signal");

    // A run that went on to T, resumed from an older checkpoint: the frames, rows and
    // checkpoints after that checkpoint are replaced.
    let rewound = dir.path().join("rewound");
    copy_dir(&whole, &rewound);
    let (oldest_step, oldest) = checkpoint_folder::list(&checkpoint_folder::folder(&rewound))
        .unwrap()
        .remove(0);
    let before: Vec<f64> = crate::common::stats_column(&rewound, "step");
    assert!(before.len() as u64 > oldest_step);
    resume_until(&oldest, end);
    assert_same_run::<2>(&whole, &rewound, "rewound to an older checkpoint");
}

/// Runs `scene` to `end` at once and to `half` then resumed to `end`: the two runs agree bit
/// for bit.
fn assert_split_run_is_identical<const D: usize>(dir: &Path, scene: &Scene, half: f64, end: f64) {
    let whole = dir.join("whole");
    run::run(scene, &run_options(&whole, end)).unwrap();
    let split = dir.join("split");
    run::run(scene, &run_options(&split, half)).unwrap();
    let summary = resume_until(&split.join("checkpoints"), end);
    assert!(summary.steps > 5, "only {} steps after T/2", summary.steps);
    assert_same_run::<D>(&whole, &split, "stopped at T/2");
}

#[test]
fn a_continued_3d_run_is_bit_identical_to_one_never_stopped() {
    let dir = TempDir::new("ckpt-3d");
    let edits = [("spacing = 0.02", "spacing = 0.04")];
    let file = scene_file(dir.path(), "dam_break_3d.toml", &edits, 0.04, 2);
    let scene = Scene::load(&file).unwrap();
    let every = scene.output_interval;
    assert_split_run_is_identical::<3>(dir.path(), &scene, 3.0 * every, 6.0 * every);
}

#[test]
fn a_continued_run_with_bodies_in_a_rolling_tank_is_bit_identical_to_one_never_stopped() {
    let dir = TempDir::new("ckpt-bodies");
    // The tank rolls, a paddle moves on a sinusoid beside the floating box until it is let go
    // at 0.25 s (between two frames, after the stop: the continued run lands on it too), and a
    // heavy box rests on the floor.
    let edits = [
        ("spacing = 0.005 ", "spacing = 0.02 "),
        (
            "max = [1.0, 0.6]\n",
            "max = [1.0, 0.6]\n\n[container.trajectory]\npivot = [0.5, 0.0]\nperiod = 1.0\nangle = 3.0\n",
        ),
        (
            "density = 500.0                 # [kg/m^3]: s = 0.5",
            "density = 500.0\n\n[[body]]\nname = \"paddle\"\nshape = \"box\"\nmin = [0.06, 0.2]\nmax = [0.1, 0.4]\ndensity = 1000.0\nmotion = \"prescribed\"\nrelease = 0.25\n\n[body.trajectory]\nperiod = 0.5\namplitude = [0.02, 0.0]\nangle = 5.0\n\n[[body]]\nname = \"rester\"\nshape = \"box\"\nmin = [0.8, 0.0]\nmax = [0.88, 0.08]\ndensity = 1500.0\nfriction = 0.5\n",
        ),
    ];
    let file = scene_file(dir.path(), "floating_box_2d.toml", &edits, 0.1, 2);
    let scene = Scene::load(&file).unwrap();
    // Stopped while the box heaves and the heavy one rests: their states come from the
    // checkpoint, not the scene.
    assert_split_run_is_identical::<2>(dir.path(), &scene, 0.2, 0.4);
    let rows = std::fs::read_to_string(dir.path().join("split/bodies.csv")).unwrap();
    let at_stop = rows
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
        .find(|c| c[1] == "2" && (c[0].parse::<f64>().unwrap() - 0.2).abs() < 1e-9)
        .unwrap_or_else(|| panic!("no row of the resting box at 0.2 s in {rows}"));
    let velocity: Vec<f64> = at_stop[10..13].iter().map(|v| v.parse().unwrap()).collect();
    assert_eq!(
        velocity, [0.0; 3],
        "the heavy box does not rest at the stop: {at_stop:?}"
    );
}

#[test]
fn a_continued_periodic_run_is_bit_identical_to_one_never_stopped() {
    let dir = TempDir::new("ckpt-periodic");
    let edits = [("spacing = 0.02 ", "spacing = 0.04 ")];
    let file = scene_file(dir.path(), "taylor_green_2d.toml", &edits, 0.1, 2);
    let scene = Scene::load(&file).unwrap();
    // Stopped at 0.15 as a user types it, the frame the whole run schedules at 3 × 0.05 =
    // 0.15000000000000002 (`run::on_frame`).
    assert_split_run_is_identical::<2>(dir.path(), &scene, 0.15, 0.4);
}

#[test]
fn a_forced_resume_with_another_output_interval_writes_frames_on_the_new_one() {
    // Stopped at 0.02 s with frames every 0.005 s (frame 4 written, 5 due next), resumed with
    // frames every 0.002 s and every 0.0075 s: the checkpoint's frame count of the old interval
    // put the next frame at 5 × 0.002 = 0.01 s, behind the run, and the first step ran
    // backwards; or at 5 × 0.0075 = 0.0375 s, leaving out the frame at 0.0225 s.
    let dir = TempDir::new("ckpt-interval");
    let base = base_run(dir.path());
    let scene = std::fs::read_to_string(dir.path().join("dam_break_2d.toml")).unwrap();
    for (interval, expected) in [
        (0.002, vec![0.022, 0.024, 0.026, 0.028, 0.03]),
        (0.0075, vec![0.0225, 0.03]),
    ] {
        let run = dir.path().join(format!("every_{interval}"));
        copy_dir(&base, &run);
        let file = dir.path().join(format!("every_{interval}.toml"));
        let edited = scene.replace(
            "output_interval = 0.005",
            &format!("output_interval = {interval}"),
        );
        std::fs::write(&file, edited).unwrap();
        let options = ResumeOptions {
            force: true,
            scene: Some(file),
            ..resume_options(0.03)
        };
        let located = resume::locate(&run).unwrap();
        let summary = run::resume(&located.checkpoint, &options).unwrap_or_else(|e| panic!("{e}"));
        let after: Vec<f64> = summary
            .frames
            .iter()
            .map(|f| f.time)
            .filter(|&t| t > 0.02 + 1e-9)
            .collect();
        assert_eq!(
            after.len(),
            expected.len(),
            "every {interval} s: frames at {after:?}"
        );
        for (t, e) in after.iter().zip(&expected) {
            assert!(
                (t - e).abs() < 1e-9,
                "every {interval} s: frames at {after:?}"
            );
        }
        let steps = crate::common::stats_column(&run, "dt");
        assert!(
            steps.iter().all(|&dt| dt > 0.0),
            "every {interval} s: {steps:?}"
        );
    }
}

fn isph(args: &[&str]) -> Output {
    isph_command().args(args).output().unwrap()
}

fn assert_refused(o: &Output, expected: &[&str]) {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_ne!(o.status.code(), Some(0), "accepted; stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    for e in expected {
        assert!(stderr.contains(e), "`{e}` missing from: {stderr}");
    }
}

/// A short 2D run in `dir/base` whose checkpoints every run of the refusal test starts from.
fn base_run(dir: &Path) -> PathBuf {
    let edits = [
        ("spacing = 0.00142875", "spacing = 0.00762"),
        ("output_interval = 0.01", "output_interval = 0.005"),
    ];
    let scene = scene_file(dir, "dam_break_2d.toml", &edits, 0.005, 3);
    let out = dir.join("base");
    run_until(&scene, &out, "0.02");
    out
}

/// `isph run SCENE --out OUT --until UNTIL`, which must succeed.
fn run_until(scene: &Path, out: &Path, until: &str) {
    let o = isph(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--until",
        until,
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn newest_checkpoint(out: &Path) -> PathBuf {
    let all = checkpoint_folder::list(&checkpoint_folder::folder(out)).unwrap();
    all.last().unwrap().1.clone()
}

/// Rewrites the newest checkpoint of the 2D run in `out` with its particles changed by
/// `change` (the folder keeping `keep`); returns its path and the checkpoint as it was.
fn rewrite_newest_checkpoint(
    out: &Path,
    keep: usize,
    change: impl FnOnce(&mut Particles<2>),
) -> (PathBuf, Checkpoint) {
    let newest = newest_checkpoint(out);
    let checkpoint = Checkpoint::open(&newest).unwrap();
    let mut p = Particles::<2>::default();
    checkpoint.restore(&mut p).unwrap();
    change(&mut p);
    let folder = checkpoint_folder::folder(out);
    checkpoint_folder::save(&folder, &checkpoint.state, &mut p, &[], keep).unwrap();
    (newest, checkpoint)
}

/// Damages the newest checkpoint of a copy of `base` and resumes it: refused with `expected`
/// in the message, and no file of the run changed.
fn assert_damage_refused(
    base: &Path,
    copy: &Path,
    damage: impl Fn(&mut Vec<u8>),
    expected: &[&str],
) {
    copy_dir(base, copy);
    let newest = newest_checkpoint(copy);
    let mut bytes = std::fs::read(&newest).unwrap();
    damage(&mut bytes);
    std::fs::write(&newest, bytes).unwrap();
    let before = snapshot(copy);
    let o = isph(&["resume", newest.to_str().unwrap(), "--until", "0.04", "-q"]);
    assert_refused(&o, expected);
    assert!(
        snapshot(copy) == before,
        "a refused resume changed the run's files"
    );
}

#[test]
fn damaged_checkpoints_and_changed_scenes_are_refused_and_nothing_changes() {
    let dir = TempDir::new("ckpt-refusals");
    let base = base_run(dir.path());
    let case = |name: &str| dir.path().join(name);

    assert_damage_refused(
        &base,
        &case("truncated"),
        |b| b.truncate(b.len() - 100),
        &["is truncated", "holds"],
    );
    assert_damage_refused(
        &base,
        &case("checksum"),
        |b| {
            let k = b.len() / 2;
            b[k] ^= 1;
        },
        &["checksum", "damaged"],
    );
    assert_damage_refused(
        &base,
        &case("magic"),
        |b| b[..8].copy_from_slice(b"HDF5\0\0\0\0"),
        &["not an isph checkpoint"],
    );
    assert_damage_refused(
        &base,
        &case("version"),
        |b| b[8..12].copy_from_slice(&99u32.to_ne_bytes()),
        &["format version 99", "newer"],
    );

    // The scene changed: refused, unless --force.
    let changed = case("changed");
    copy_dir(&base, &changed);
    let scene = dir.path().join("dam_break_2d.toml");
    let original = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(
        &scene,
        original.replace("viscosity = 1.0e-6", "viscosity = 2.0e-6"),
    )
    .unwrap();
    let before = snapshot(&changed);
    let o = isph(&["resume", changed.to_str().unwrap(), "--until", "0.04", "-q"]);
    assert_refused(&o, &["has changed", "--force", "dam_break_2d.toml"]);
    assert!(
        snapshot(&changed) == before,
        "a refused resume changed the run's files"
    );
    let o = isph(&[
        "resume",
        changed.to_str().unwrap(),
        "--until",
        "0.04",
        "-q",
        "--force",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Comments and the end time do not count as a change.
    std::fs::write(
        &scene,
        format!(
            "# a comment\n{}",
            original.replace("end_time = 1.0", "end_time = 2.0")
        ),
    )
    .unwrap();
    let o = isph(&["resume", base.to_str().unwrap(), "--until", "0.03", "-q"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn a_forced_resume_into_a_scene_that_makes_other_particles_is_refused_and_nothing_changes() {
    // `--force` continues a run whose settings changed; a body of another size, another
    // spacing or a body less make other particles than the checkpoint holds (a body's offsets
    // come from the scene's lattice), and are refused before the cut-back touches a file: an
    // older checkpoint's later checkpoints, frames and rows stay.
    let dir = TempDir::new("ckpt-other-particles");
    let scene = dir.path().join("bodies.toml");
    let bodies = "[[body]]\nshape = \"circle\"\ncenter = [0.1, 0.3]\nradius = 0.05\ndensity = 500.0\n\n[[body]]\nshape = \"circle\"\ncenter = [0.3, 0.3]\nradius = 0.05\ndensity = 500.0\n\n[checkpoint]\ninterval = 0.01\nkeep = 5\n";
    let text = &tank(2, 0.02, [0.4, 0.4, 0.0], 0.2, 0.01, bodies);
    std::fs::write(&scene, text).unwrap();
    let out = dir.path().join("out");
    run_until(&scene, &out, "0.04");
    let oldest = checkpoint_folder::list(&checkpoint_folder::folder(&out)).unwrap()[0]
        .1
        .clone();
    let refused = |changed: &str, target: &Path| {
        std::fs::write(&scene, changed).unwrap();
        let before = snapshot(&out);
        let o = isph(&[
            "resume",
            target.to_str().unwrap(),
            "--until",
            "0.06",
            "--force",
            "-q",
        ]);
        assert_refused(&o, &["makes other particles", "bodies.toml", "no --force"]);
        assert!(
            snapshot(&out) == before,
            "a refused resume changed the run's files"
        );
    };
    refused(&text.replacen("radius = 0.05", "radius = 0.03", 1), &out);
    refused(&text.replace("spacing = 0.02", "spacing = 0.025"), &out);
    let one_body = text.replacen(
        "[[body]]\nshape = \"circle\"\ncenter = [0.3, 0.3]\nradius = 0.05\ndensity = 500.0\n\n",
        "",
        1,
    );
    assert_ne!(&one_body, text);
    refused(&one_body, &oldest);
    // The scene put back: the run continues.
    std::fs::write(&scene, text).unwrap();
    let o = isph(&["resume", oldest.to_str().unwrap(), "--until", "0.06", "-q"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn a_directory_resumes_from_its_newest_valid_checkpoint() {
    let dir = TempDir::new("ckpt-newest");
    let base = base_run(dir.path());
    let all = checkpoint_folder::list(&checkpoint_folder::folder(&base)).unwrap();
    assert!(all.len() >= 2);
    let (newest, older) = (&all[all.len() - 1].1, &all[all.len() - 2]);
    std::fs::OpenOptions::new()
        .write(true)
        .open(newest)
        .unwrap()
        .set_len(1000)
        .unwrap();
    let o = isph(&["resume", base.to_str().unwrap(), "--until", "0.03", "-q"]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("skipped") && stderr.contains("truncated"),
        "{stderr}"
    );
    assert!(
        stdout.contains(&format!(
            "resumed {} at step {}",
            older.1.display(),
            older.0
        )),
        "{stdout}"
    );

    // With every checkpoint damaged, nothing is resumed and nothing changes.
    for (_, path) in checkpoint_folder::list(&checkpoint_folder::folder(&base)).unwrap() {
        std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .unwrap()
            .set_len(50)
            .unwrap();
    }
    let before = snapshot(&base);
    let o = isph(&["resume", base.to_str().unwrap(), "--until", "0.04", "-q"]);
    assert_refused(&o, &["no valid checkpoint", "truncated"]);
    assert!(
        snapshot(&base) == before,
        "a refused resume changed the run's files"
    );
}

/// A newer checkpoint this isph cannot read but another could (here of a newer format) is a
/// good run's state: a directory's resume refuses to continue from an older one, which would
/// delete it, and changes nothing.
#[test]
fn a_directory_resume_keeps_a_newer_checkpoint_of_a_newer_format() {
    let dir = TempDir::new("ckpt-newer-format");
    let base = base_run(dir.path());
    let newest = newest_checkpoint(&base);
    let mut bytes = std::fs::read(&newest).unwrap();
    bytes[8..12].copy_from_slice(&99u32.to_ne_bytes());
    std::fs::write(&newest, bytes).unwrap();
    let before = snapshot(&base);
    let o = isph(&["resume", base.to_str().unwrap(), "--until", "0.04", "-q"]);
    assert_refused(&o, &["format version 99", "newer than", "move it out of"]);
    assert!(
        snapshot(&base) == before,
        "a refused resume changed the run's files"
    );
}

#[test]
fn sigterm_stops_a_run_with_a_checkpoint_it_resumes_from() {
    let dir = TempDir::new("ckpt-sigterm");
    let scene = dam_break_2d(dir.path());
    let out = dir.path().join("out");
    let child = isph_command()
        .args([
            "run",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "-q",
        ])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait for the run to be under way: its first periodic checkpoint (t = 0.01 s).
    let started = std::time::Instant::now();
    while checkpoint_folder::list(&checkpoint_folder::folder(&out)).map_or(true, |l| l.is_empty()) {
        assert!(started.elapsed().as_secs() < 60, "no checkpoint after 60 s");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // SAFETY: a signal to the child this test started and has not yet waited for.
    let sent = unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
    assert_eq!(sent, 0, "kill failed");
    let o = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(128 + 15), "{stderr}");
    assert!(
        stderr.contains("stopped by SIGTERM") && stderr.contains("isph resume"),
        "{stderr}"
    );
    let steps = crate::common::stats_column(&out, "step");
    let newest = newest_checkpoint(&out);
    let state = &Checkpoint::open(&newest).unwrap().state;
    assert_eq!(
        state.step as f64,
        *steps.last().unwrap(),
        "the checkpoint is not at the last step"
    );
    let o = isph(&[
        "resume",
        out.to_str().unwrap(),
        "--until",
        &(state.time + 0.005).to_string(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A flow without gravity that blows up stops on a collapsed time step, measured against the
/// viscous step: the Taylor–Green vortex at L/20 (viscous step 0.045 s) with one particle of its
/// checkpoint set moving at 10⁴ m/s, whose CFL step (2e-6 s) is below a thousandth of it. With
/// the body-force step as the only reference, such a run crept on at steps of 1e-8 s and less.
#[test]
fn a_gravity_free_flow_that_blows_up_stops_on_a_collapsed_time_step() {
    let dir = TempDir::new("ckpt-collapse");
    let edits = [("spacing = 0.02", "spacing = 0.05")];
    let file = scene_file(dir.path(), "taylor_green_2d.toml", &edits, 0.1, 2);
    let scene = Scene::load(&file).unwrap();
    let out = dir.path().join("out");
    run::run(&scene, &run_options(&out, 0.1)).unwrap();
    rewrite_newest_checkpoint(&out, 2, |p| p.vel[0][0] = 1.0e4);

    let located = resume::locate(&out).unwrap();
    let e = run::resume(&located.checkpoint, &resume_options(0.1001)).unwrap_err();
    let message = e.to_string();
    assert!(
        matches!(e, RunError::Numerical { .. }) && message.contains("time step collapsed"),
        "{message}"
    );
}

#[test]
fn a_numerical_failure_names_the_newest_checkpoint() {
    let dir = TempDir::new("ckpt-failure");
    let scene = Scene::load(&dam_break_2d(dir.path())).unwrap();
    let out = dir.path().join("out");
    run::run(&scene, &run_options(&out, 2.0 * scene.output_interval)).unwrap();
    // The newest checkpoint, rewritten with a fluid particle far outside the domain: the next
    // step finds it there.
    let (newest, checkpoint) = rewrite_newest_checkpoint(&out, 3, |p| {
        let fluid = p.kind.iter().position(|&k| k == Kind::Fluid).unwrap();
        p.pos[0][fluid] = 1.0e3;
    });
    let rows = crate::common::stats_column(&out, "step").len();

    let located = resume::locate(&out).unwrap();
    let e = run::resume(&located.checkpoint, &resume_options(0.1)).unwrap_err();
    let message = e.to_string();
    match e {
        RunError::Numerical {
            last_checkpoint, ..
        } => {
            let saved = last_checkpoint.expect("no checkpoint named");
            assert_eq!((saved.step, &saved.path), (checkpoint.state.step, &newest));
        }
        other => panic!("not a numerical failure: {other}"),
    }
    assert!(
        message.contains("left the domain") && message.contains("isph resume"),
        "{message}"
    );
    assert_eq!(
        crate::common::stats_column(&out, "step").len(),
        rows,
        "rows written after the failure"
    );
    assert_eq!(
        newest_checkpoint(&out),
        newest,
        "a checkpoint was written after the failure"
    );
}

#[test]
fn bad_checkpoint_sections_are_refused_with_key_and_line() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hydrostatic_2d.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let lines = text.lines().count();
    let cases: &[(&str, &[&str])] = &[
        ("interval = -0.5", &["checkpoint.interval", "positive"]),
        (
            "wall_interval = 0.0",
            &["checkpoint.wall_interval", "positive"],
        ),
        ("keep = 0", &["checkpoint.keep", "at least 1"]),
        ("every = 3", &["unknown field `every`"]),
    ];
    for (section, expected) in cases {
        let bad = format!("{text}\n[checkpoint]\n{section}\n");
        let e = Scene::parse(&bad, &path).unwrap_err().to_string();
        assert!(
            e.contains(&format!(":{}", lines + 3)) || e.contains(&format!("line {}", lines + 3)),
            "no line in: {e}"
        );
        for x in *expected {
            assert!(e.contains(x), "`{x}` missing from: {e}");
        }
    }
}

/// Probes are not part of the scene's hash: a run resumed with other probes keeps the old
/// probes.csv under another name and starts a new one at the checkpoint.
#[test]
fn a_run_resumed_with_other_probes_keeps_the_old_readings_aside() {
    let dir = TempDir::new("ckpt-probes");
    let file = dam_break_2d(dir.path());
    let scene = Scene::load(&file).unwrap();
    let (half, end) = (8.0 * scene.output_interval, 16.0 * scene.output_interval);
    let out = dir.path().join("run");
    run::run(&scene, &run_options(&out, half)).unwrap();
    let before = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let text = std::fs::read_to_string(&file).unwrap();
    std::fs::write(&file, text.replace("name = \"back\"", "name = \"rear\"")).unwrap();
    let step = final_state::<2>(&out).0;
    // A file set aside at this step before (the probes changed twice) is not replaced.
    let earlier = out.join(format!("probes_replaced_at_step_{step}.csv"));
    std::fs::write(&earlier, "set aside before\n").unwrap();
    let summary = resume_until(&out, end);
    assert_eq!(
        std::fs::read_to_string(earlier).unwrap(),
        "set aside before\n"
    );
    let aside = out.join(format!("probes_replaced_at_step_{step}_2.csv"));
    assert_eq!(std::fs::read_to_string(aside).unwrap(), before);
    let (columns, rows) = isph::io::probes::read(&out).unwrap();
    assert_eq!(columns, ["time", "rear", "probe_2_x", "probe_2_y"]);
    assert_eq!(
        rows.len() as u64,
        summary.steps,
        "rows from the checkpoint on"
    );
}
