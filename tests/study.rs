//! `isph study`: one study.csv row per point, the plot, no point run twice (resumed or claimed
//! by another process), and bad study files refused with the file and key named.

use crate::common::{isph_command, TempDir};
use isph::tools::study::claim;
use isph::tools::study::file::point_id;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::SystemTime;

/// Two coarse hydrostatic tanks for 0.2 s.
fn tiny_study(dir: &Path) -> PathBuf {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hydrostatic_2d.toml");
    let path = dir.join("tiny.toml");
    std::fs::write(
        &path,
        format!(
            "scene = \"{}\"\nmeasure = \"hydrostatic\"\nuntil = 0.2\n[grid]\n\"simulation.spacing\" = [0.05, 0.025]\n",
            scene.display()
        ),
    )
    .unwrap();
    path
}

fn study(path: &Path, out: &Path) -> Output {
    isph_command()
        .arg("study")
        .arg(path)
        .arg("--out")
        .arg(out)
        .args(["--threads", "1"])
        .output()
        .unwrap()
}

fn rows(out: &Path) -> Vec<Vec<String>> {
    std::fs::read_to_string(out.join("study.csv"))
        .unwrap()
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect()
}

fn modified(path: &Path) -> SystemTime {
    std::fs::metadata(path).unwrap().modified().unwrap()
}

#[test]
fn a_study_writes_one_row_per_point_and_resumes_without_rerunning() {
    let dir = TempDir::new("study");
    let (path, out) = (tiny_study(dir.path()), dir.path().join("out"));
    let o = study(&path, &out);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let rows = rows(&out);
    let header = &rows[0];
    let col = |name: &str| header.iter().position(|c| c == name).unwrap();
    assert_eq!(header[0], "id");
    assert_eq!(header[1], "simulation.spacing");
    assert_eq!(rows.len(), 3, "{rows:?}");
    for row in &rows[1..] {
        assert_eq!(row[col("status")], "ok", "{row:?}");
        for name in ["error", "wall_seconds", "ppe_iterations_mean"] {
            let v: f64 = row[col(name)].parse().unwrap();
            assert!(v.is_finite() && v > 0.0, "{name}: {row:?}");
        }
        let error: f64 = row[col("error")].parse().unwrap();
        assert!(error < 0.05, "{row:?}");
        assert!(row[col("steps")].parse::<u64>().unwrap() > 0);
        assert!(row[col("peak_bytes")].parse::<u64>().unwrap() > 1_000_000);
    }
    let svg = std::fs::read_to_string(out.join("study.svg")).unwrap();
    assert!(svg.contains("wall time [s]") && svg.contains("Pareto front"));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(
        table.contains("spacing=0.05") && table.contains('*'),
        "{table}"
    );

    let stats: Vec<(PathBuf, SystemTime)> = rows[1..]
        .iter()
        .map(|r| {
            let p = out.join("points").join(&r[0]).join("run/stats.csv");
            let t = modified(&p);
            (p, t)
        })
        .collect();
    let again = study(&path, &out);
    assert!(again.status.success());
    assert!(!String::from_utf8_lossy(&again.stderr).contains('…'));
    assert_eq!(self::rows(&out), rows);
    for (p, t) in stats {
        assert_eq!(modified(&p), t, "{} was rewritten", p.display());
    }
}

#[test]
fn a_claimed_point_is_left_alone_and_a_stale_claim_is_taken_over() {
    let dir = TempDir::new("study-claims");
    let (path, out) = (tiny_study(dir.path()), dir.path().join("out"));
    let id = |spacing: f64| {
        point_id(&[(
            "simulation.spacing".to_string(),
            toml::Value::Float(spacing),
        )])
    };
    let (held, stale) = (
        out.join("points").join(id(0.05)),
        out.join("points").join(id(0.025)),
    );
    std::fs::create_dir_all(&held).unwrap();
    std::fs::create_dir_all(&stale).unwrap();
    // This test process holds one point; a process that no longer exists held the other.
    let _claim = claim::claim(&held).unwrap().expect("the point is free");
    std::fs::write(stale.join(claim::FILE_NAME), "999999999 1").unwrap();
    let o = study(&path, &out);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("another isph study is running it"),
        "{stderr}"
    );
    let rows = rows(&out);
    assert_eq!(rows.len(), 2, "{rows:?}");
    assert_eq!(rows[1][0], id(0.025));
    assert!(!out.join("study.svg").exists());
    assert!(!stale.join(claim::FILE_NAME).exists());
    assert!(held.join(claim::FILE_NAME).exists());
}

#[test]
fn bad_study_files_are_refused_with_the_file_and_key_named() {
    let dir = TempDir::new("study-bad");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hydrostatic_2d.toml");
    let scene = scene.display();
    let cases: &[(&str, String, &[&str])] = &[
        (
            "unknown key",
            format!("scene = \"{scene}\"\nmeasure = \"hydrostatic\"\nuntill = 1.0\n"),
            &["unknown field `untill`"],
        ),
        (
            "bad scene path",
            "scene = \"no-such-scene.toml\"\nmeasure = \"hydrostatic\"\n".into(),
            &["`scene`", "no-such-scene.toml"],
        ),
        (
            "unknown measure",
            format!("scene = \"{scene}\"\nmeasure = \"couette\"\n"),
            &["`measure`", "\"couette\" is no error measure"],
        ),
        (
            "measure that does not suit the scene",
            format!("scene = \"{scene}\"\nmeasure = \"taylor_green\"\n"),
            &["`measure`", "taylor_green", "initial_velocity"],
        ),
        (
            "grid key not in the scene",
            format!("scene = \"{scene}\"\nmeasure = \"hydrostatic\"\n[grid]\n\"simulation.spacings\" = [0.1]\n"),
            &["`grid.\"simulation.spacings\"`", "unknown field `spacings`"],
        ),
        (
            "grid key through a value",
            format!("scene = \"{scene}\"\nmeasure = \"hydrostatic\"\n[grid]\n\"simulation.spacing.x\" = [0.1]\n"),
            &["`grid.\"simulation.spacing.x\"`", "`simulation.spacing` is not a table"],
        ),
        (
            "bad value",
            format!("scene = \"{scene}\"\nmeasure = \"hydrostatic\"\n[grid]\n\"simulation.spacing\" = [-0.1]\n"),
            &["`grid.\"simulation.spacing\"`", "must be a positive number"],
        ),
        (
            "a grid of more points than a study runs",
            format!(
                "scene = \"{scene}\"\nmeasure = \"hydrostatic\"\n[grid]\n{}",
                (0..8)
                    .map(|k| format!("\"effects.key{k}\" = [{}]\n", vec!["1"; 30].join(", ")))
                    .collect::<String>()
            ),
            &["`grid`", "6.561e11 points", "more than the 10000"],
        ),
    ];
    for (what, text, expected) in cases {
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, text).unwrap();
        let out = dir.path().join("out");
        let o = study(&path, &out);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{what}: accepted");
        assert!(stderr.starts_with("error: "), "{what}: {stderr}");
        assert!(!stderr.contains("panicked"), "{what}: {stderr}");
        assert!(
            stderr.contains(&*path.to_string_lossy()),
            "{what}: {stderr}"
        );
        for e in *expected {
            assert!(stderr.contains(e), "{what}: `{e}` missing from {stderr}");
        }
        assert!(!out.exists(), "{what}: wrote {}", out.display());
    }
}

/// A grid value the scene refuses alone but accepts beside another key's value is taken: h/dx
/// 2.5 is out of the quintic's range (the scene's kernel) and inside the Wendland kernels'.
/// A point of the grid the scene refuses still refuses the study, naming the point.
#[test]
fn a_grid_value_valid_beside_another_key_is_taken() {
    use isph::tools::study::file::Study;
    let dir = TempDir::new("study-kernel-grid");
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/hydrostatic_2d.toml");
    let write = |grid: &str| {
        let path = dir.path().join("kernels.toml");
        let text = format!(
            "scene = \"{}\"\nmeasure = \"hydrostatic\"\n[grid]\n{grid}",
            scene.display()
        );
        std::fs::write(&path, text).unwrap();
        Study::load(&path)
    };
    let study = write("\"solver.kernel\" = [\"wendland_c2\"]\n\"solver.h_over_dx\" = [1.8, 2.5]\n")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(study.points.len(), 2);
    let e =
        write("\"solver.kernel\" = [\"quintic\", \"wendland_c2\"]\n\"solver.h_over_dx\" = [2.5]\n")
            .unwrap_err()
            .to_string();
    assert!(e.contains("the point") && e.contains("quintic"), "{e}");
    let e = write("\"solver.h_over_dx\" = [3.5]\n")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("grid.\"solver.h_over_dx\"") && e.contains("3.5"),
        "{e}"
    );
}
