//! `isph bench`: one CSV row per (size, threads) point with the documented columns; bad input is
//! refused before anything is measured.

use crate::common::{isph_command, TempDir};
use std::process::Output;

/// The CSV columns, in order (docs/performance.md describes each).
const COLUMNS: &[&str] = &[
    "requested_fluid",
    "threads",
    "kernel",
    "spacing_m",
    "fluid_particles",
    "particles",
    "warmup_steps",
    "timed_steps",
    "time_start_s",
    "time_end_s",
    "step_median_s",
    "step_min_s",
    "step_max_s",
    "us_per_fluid_particle_step",
    "cell_list_s",
    "free_surface_s",
    "kernel_correction_s",
    "eddy_viscosity_s",
    "predictor_s",
    "pressure_solve_s",
    "corrector_s",
    "wall_pressure_s",
    "density_correction_s",
    "surface_thickness_s",
    "shifting_s",
    "advection_s",
    "diagnostics_s",
    "other_s",
    "ppe_iterations_mean",
    "density_error",
    "apply_pairs",
    "pairs_per_fluid_particle",
    "apply_median_s",
    "apply_pairs_per_s",
    "peak_rss_bytes",
    "peak_bytes_per_particle",
    "parallel_efficiency",
];

fn bench(args: &[&str]) -> Output {
    isph_command().arg("bench").args(args).output().unwrap()
}

#[test]
fn bench_writes_one_csv_row_per_point() {
    let dir = TempDir::new("bench");
    let csv = dir.path().join("bench.csv");
    let o = bench(&[
        "--sizes",
        "1000",
        "--threads",
        "1",
        "--steps",
        "2",
        "--warmup",
        "1",
        "--kernel",
        "wendland_c2",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(!dir.path().join("bench.csv.partial").exists());
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header, COLUMNS);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 1, "{text}");
    let column = |name: &str| COLUMNS.iter().position(|c| *c == name).unwrap();
    assert_eq!(rows[0][column("kernel")], "wendland_c2");
    let value = |name: &str| -> f64 { rows[0][column(name)].parse().unwrap() };
    assert!(
        COLUMNS
            .iter()
            .filter(|&&c| c != "kernel")
            .all(|c| value(c).is_finite()),
        "{text}"
    );
    // 1000 wanted: the spacing 0.1/3 m, a block of 9 × 12 × 15 particles.
    assert_eq!(value("fluid_particles"), 1620.0);
    assert!(value("particles") > value("fluid_particles"));
    assert_eq!(value("threads"), 1.0);
    assert_eq!(value("timed_steps"), 2.0);
    assert_eq!(value("parallel_efficiency"), 1.0);
    for positive in [
        "step_median_s",
        "pressure_solve_s",
        "ppe_iterations_mean",
        "apply_pairs",
        "apply_pairs_per_s",
        "peak_rss_bytes",
    ] {
        assert!(value(positive) > 0.0, "{positive}: {text}");
    }
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("pressure solve"), "{table}");
    assert!(table.contains("wendland_c2 kernel at h/dx 1.8"), "{table}");
}

#[test]
fn bench_refuses_bad_sizes_threads_and_an_unwritable_csv() {
    let cases: &[(&[&str], &str)] = &[
        (&["--sizes", "1e4,many"], "invalid value 'many'"),
        (&["--sizes", "10"], "--sizes 10"),
        (&["--sizes", "2500.5"], "--sizes 2500.5"),
        (&["--sizes", "1000", "--threads", "0"], "--threads 0"),
        (&["--sizes", "1000", "--steps", "0"], "--steps"),
        (
            &["--sizes", "1000", "--kernel", "cubic"],
            "--kernel \"cubic\": not a kernel; give one of quintic, wendland_c2, wendland_c4",
        ),
        (
            &[
                "--sizes",
                "1000",
                "--csv",
                "/nonexistent-isph-dir/bench.csv",
            ],
            "cannot write the CSV file /nonexistent-isph-dir/bench.csv",
        ),
    ];
    for (args, expected) in cases {
        let o = bench(args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} accepted: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
        assert!(
            stderr.contains(expected),
            "{args:?}: `{expected}` missing from {stderr}"
        );
        assert!(
            !stderr.contains("[1/"),
            "{args:?} measured before refusing: {stderr}"
        );
    }
}

/// A bench that fails leaves a CSV file of that name as it was: the rows go to FILE.partial
/// until every point is measured.
#[test]
fn a_failed_bench_keeps_an_existing_csv() {
    let dir = TempDir::new("bench-keep");
    let csv = dir.path().join("bench.csv");
    std::fs::write(&csv, "an earlier bench\n").unwrap();
    let o = bench(&[
        "--sizes",
        "1e13",
        "--threads",
        "1",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), "an earlier bench\n");
}
