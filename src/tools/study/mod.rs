//! `isph study STUDY.toml`: accuracy against cost over a grid of settings (docs/study-format.md).
//!
//! Each point of the grid is the study's scene with the point's settings written in (`scene::overrides`),
//! run by a child `isph run` (so its wall time and peak memory are its own, see
//! [`crate::tools::child`]), measured by [`crate::tools::validation::measure`] and recorded as one
//! row of `OUT/study.csv` (`table`). A point with a row is never run again, and `claim` keeps two
//! processes on the same OUT from running the same point. Once every point has its row,
//! `OUT/study.svg` plots error against wall time with the Pareto front (`plot`).

pub mod claim;
pub mod file;
pub mod plot;
pub mod table;

use crate::io::stats::read_column;
use crate::scene::Scene;
use crate::tools::child::{self, RunReport};
use crate::tools::validation::{self, Measured};
use file::{label, Point, Study};
use plot::Outcome;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error("cannot read {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Syntax { path: PathBuf, message: String },
    #[error("{path}: `{key}` {message}")]
    Invalid {
        path: PathBuf,
        key: String,
        message: String,
    },
    #[error("cannot write {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Table { path: PathBuf, message: String },
    #[error("cannot draw {path}: {message}")]
    Plot { path: PathBuf, message: String },
}

/// Where a study writes and how its runs are started.
#[derive(Clone, Debug)]
pub struct StudyOptions {
    /// Output directory [default: out/study-<study file stem>].
    pub out: Option<PathBuf>,
    /// Passed on to each `isph run`.
    pub threads: Option<usize>,
}

/// What `run` leaves: every point's outcome in the study's order, and whether all are done
/// (the plot is written only then).
#[derive(Clone, Debug)]
pub struct Summary {
    pub out: PathBuf,
    pub outcomes: Vec<Outcome>,
    pub complete: bool,
}

impl Summary {
    pub fn csv(&self) -> PathBuf {
        self.out.join(table::FILE_NAME)
    }

    pub fn svg(&self) -> PathBuf {
        self.out.join(plot::FILE_NAME)
    }
}

/// The study's default output directory: out/study-<stem>.
pub fn default_out(study: &Path) -> PathBuf {
    let stem = study
        .file_stem()
        .map_or("study".into(), |s| s.to_string_lossy().into_owned());
    PathBuf::from("out").join(format!("study-{stem}"))
}

/// Runs every point of the study in `path` that has no row yet and no other process on it,
/// with `exe` (this program) as the child; `log` gets a line before and after each point.
pub fn run(
    path: &Path,
    opts: &StudyOptions,
    exe: &Path,
    mut log: impl FnMut(String),
) -> Result<Summary, StudyError> {
    let study = Study::load(path)?;
    let out = opts.out.clone().unwrap_or_else(|| default_out(path));
    let csv = out.join(table::FILE_NAME);
    create_dir(&out.join("points"))?;
    table::ensure(&csv, &columns(&study))?;
    let total = study.points.len();
    for (k, point) in study.points.iter().enumerate() {
        let what = format!(
            "[{}/{total}] {} ({})",
            k + 1,
            point.id,
            label(&point.settings)
        );
        if done(&csv)?.contains_key(&point.id) {
            continue;
        }
        let dir = out.join("points").join(&point.id);
        create_dir(&dir)?;
        let Some(_claim) = claim::claim(&dir).map_err(|source| StudyError::Write {
            path: dir.join(claim::FILE_NAME),
            source,
        })?
        else {
            log(format!("{what}: another isph study is running it"));
            continue;
        };
        if done(&csv)?.contains_key(&point.id) {
            continue;
        }
        log(format!("{what} …"));
        let row = run_point(&study, point, &dir, opts, exe)?;
        log(format!("{what}: {}", row.last().map_or("", String::as_str)));
        table::append(&csv, &row)?;
    }
    let rows = done(&csv)?;
    let varying = varying_settings(&study.points);
    let outcomes: Vec<Outcome> = study
        .points
        .iter()
        .filter_map(|p| rows.get(&p.id).map(|row| outcome(p, row, &varying)))
        .collect();
    let complete = outcomes.len() == total;
    let summary = Summary {
        out,
        outcomes,
        complete,
    };
    if complete {
        let title = format!("{}: {} against wall time", study.path.display(), study.case);
        plot::write_svg(&summary.svg(), &title, &summary.outcomes)?;
    }
    Ok(summary)
}

fn create_dir(dir: &Path) -> Result<(), StudyError> {
    std::fs::create_dir_all(dir).map_err(|source| StudyError::Write {
        path: dir.to_owned(),
        source,
    })
}

/// study.csv's columns: point id, each grid key, the error and the case's details, the cost,
/// the status.
fn columns(study: &Study) -> Vec<String> {
    let mut c = vec!["id".to_string()];
    c.extend(study.keys.iter().cloned());
    c.push("error".into());
    c.extend(study.case.detail_names().iter().map(|d| d.to_string()));
    c.extend(
        [
            "wall_seconds",
            "steps",
            "ppe_iterations_mean",
            "peak_bytes",
            "status",
        ]
        .map(String::from),
    );
    c
}

/// The rows of study.csv by point id.
fn done(csv: &Path) -> Result<HashMap<String, HashMap<String, String>>, StudyError> {
    Ok(table::rows(csv)?
        .into_iter()
        .filter_map(|row| Some((row.get("id")?.clone(), row)))
        .collect())
}

/// What a point's run gave; a failure is recorded, not returned.
struct PointResult {
    seconds: Option<f64>,
    steps: Option<usize>,
    ppe_iterations: Option<f64>,
    peak_bytes: Option<u64>,
    measured: Option<Measured>,
    status: String,
}

/// Writes the point's scene, runs it and measures it: its study.csv row. Only a failure to
/// write the point's own scene file is an error; a failed run or measure is the row's status.
fn run_point(
    study: &Study,
    point: &Point,
    dir: &Path,
    opts: &StudyOptions,
    exe: &Path,
) -> Result<Vec<String>, StudyError> {
    let scene_path = dir.join("scene.toml");
    std::fs::write(&scene_path, &point.scene_text).map_err(|source| StudyError::Write {
        path: scene_path.clone(),
        source,
    })?;
    let result = measure_run(study, &scene_path, &dir.join("run"), opts, exe);
    let text = |v: Option<String>| v.unwrap_or_default();
    let mut row = vec![point.id.clone()];
    row.extend(point.settings.iter().map(|(_, v)| v.to_string()));
    row.push(text(
        result.measured.as_ref().map(|m| format!("{:e}", m.error)),
    ));
    for name in study.case.detail_names() {
        let value = result
            .measured
            .as_ref()
            .and_then(|m| m.details.iter().find(|(n, _)| n == name))
            .map(|(_, v)| format!("{v:e}"));
        row.push(text(value));
    }
    row.extend([
        text(result.seconds.map(|s| format!("{s:.3}"))),
        text(result.steps.map(|s| s.to_string())),
        text(result.ppe_iterations.map(|p| p.to_string())),
        text(result.peak_bytes.map(|b| b.to_string())),
        result.status,
    ]);
    Ok(row)
}

/// Runs the point's scene in a child `isph run` and measures what it wrote.
fn measure_run(
    study: &Study,
    scene_path: &Path,
    run_dir: &Path,
    opts: &StudyOptions,
    exe: &Path,
) -> PointResult {
    let mut result = PointResult {
        seconds: None,
        steps: None,
        ppe_iterations: None,
        peak_bytes: None,
        measured: None,
        status: String::new(),
    };
    let mut command = Command::new(exe);
    command
        .arg("run")
        .arg(scene_path)
        .arg("--out")
        .arg(run_dir)
        .args(["--quiet", "--overwrite", "--report"]);
    if let Some(t) = study.until {
        command.args(["--until", &t.to_string()]);
    }
    if let Some(n) = opts.threads {
        command.args(["--threads", &n.to_string()]);
    }
    let clock = Instant::now();
    let report = child::run::<RunReport>(&mut command);
    result.seconds = Some(clock.elapsed().as_secs_f64());
    match report {
        Ok(r) => result.peak_bytes = Some(r.peak_rss_bytes),
        Err(e) => {
            result.status = format!("failed: the run {e}");
            return result;
        }
    }
    match read_column(run_dir, "ppe_iterations") {
        Ok(ppe) => {
            result.steps = Some(ppe.len());
            result.ppe_iterations = Some(ppe.iter().sum::<f64>() / ppe.len().max(1) as f64);
        }
        Err(e) => {
            result.status = format!("failed: {e}");
            return result;
        }
    }
    let measured = Scene::load(scene_path)
        .map_err(|e| e.to_string())
        .and_then(|scene| {
            validation::measure(study.case, &scene, run_dir).map_err(|e| e.to_string())
        });
    match measured {
        Ok(m) => {
            result.measured = Some(m);
            result.status = "ok".into();
        }
        Err(e) => result.status = format!("failed: {e}"),
    }
    result
}

/// The grid keys that take more than one value over the points: what tells points apart.
fn varying_settings(points: &[Point]) -> Vec<String> {
    let Some(first) = points.first() else {
        return Vec::new();
    };
    first
        .settings
        .iter()
        .filter(|(key, value)| {
            points
                .iter()
                .any(|p| p.settings.iter().any(|(k, v)| k == key && v != value))
        })
        .map(|(key, _)| key.clone())
        .collect()
}

/// A point's row of study.csv as an `Outcome`, labelled by its `varying` settings.
fn outcome(point: &Point, row: &HashMap<String, String>, varying: &[String]) -> Outcome {
    let number = |name: &str| row.get(name).and_then(|v| v.parse::<f64>().ok());
    let settings: Vec<_> = point
        .settings
        .iter()
        .filter(|(k, _)| varying.contains(k))
        .cloned()
        .collect();
    Outcome {
        id: point.id.clone(),
        label: label(&settings),
        error: number("error"),
        seconds: number("wall_seconds"),
        steps: number("steps"),
        ppe_iterations: number("ppe_iterations_mean"),
        peak_bytes: number("peak_bytes"),
        status: row.get("status").cloned().unwrap_or_default(),
    }
}
