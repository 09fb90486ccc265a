//! Study files: a scene, an error measure, an optional end time and a grid of settings whose
//! Cartesian product are the study's points. Unknown keys are errors; every error names the
//! study file and the key. Each point's scene is built and validated here, before any runs.

use super::StudyError;
use crate::scene::{overrides, Scene};
use crate::tools::validation::Case;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StudyFile {
    scene: PathBuf,
    measure: String,
    until: Option<f64>,
    #[serde(default)]
    grid: BTreeMap<String, Vec<toml::Value>>,
}

/// Points a study holds at most: a grid beyond it is a typo, not a study (each point is a run).
const MAX_POINTS: usize = 10_000;

/// One combination of the grid's values.
#[derive(Clone, Debug)]
pub struct Point {
    /// Short and stable: a hash of the settings.
    pub id: String,
    /// (dotted scene key, value), in the grid's key order.
    pub settings: Vec<(String, toml::Value)>,
    /// The scene text with the settings written in.
    pub scene_text: String,
}

/// A loaded and checked study.
#[derive(Clone, Debug)]
pub struct Study {
    pub path: PathBuf,
    pub scene_path: PathBuf,
    pub case: Case,
    pub until: Option<f64>,
    /// The grid's keys, sorted.
    pub keys: Vec<String>,
    pub points: Vec<Point>,
}

impl Study {
    pub fn load(path: &Path) -> Result<Self, StudyError> {
        let text = std::fs::read_to_string(path).map_err(|source| StudyError::Read {
            path: path.to_owned(),
            source,
        })?;
        let file: StudyFile = toml::from_str(&text).map_err(|e| StudyError::Syntax {
            path: path.to_owned(),
            message: crate::scene::syntax_message(&text, &e),
        })?;
        let invalid = |key: &str, message: String| StudyError::Invalid {
            path: path.to_owned(),
            key: key.to_owned(),
            message,
        };
        let case: Case =
            file.measure
                .parse()
                .map_err(|e: crate::tools::validation::UnknownCase| {
                    invalid("measure", e.to_string())
                })?;
        if let Some(t) = file.until {
            if !(t.is_finite() && t > 0.0) {
                return Err(invalid(
                    "until",
                    format!("= {t:?} must be a positive number of seconds"),
                ));
            }
        }
        let scene_path = path.parent().unwrap_or(Path::new(".")).join(&file.scene);
        let scene_text = std::fs::read_to_string(&scene_path).map_err(|e| {
            invalid(
                "scene",
                format!(
                    "= \"{}\": cannot read {}: {e}",
                    file.scene.display(),
                    scene_path.display()
                ),
            )
        })?;
        Scene::parse(&scene_text, &scene_path)
            .map_err(|e| invalid("scene", format!("does not load: {e}")))?;
        let count: f64 = file.grid.values().map(|v| v.len() as f64).product();
        if count > MAX_POINTS as f64 {
            return Err(invalid(
                "grid",
                format!(
                    "holds {count:.3e} points ({}), more than the {MAX_POINTS} a study runs: split it into studies over fewer keys or values",
                    file.grid
                        .iter()
                        .map(|(k, v)| format!("{} of \"{k}\"", v.len()))
                        .collect::<Vec<_>>()
                        .join(" × ")
                ),
            ));
        }
        let grid = product(&file.grid);
        for (key, values) in &file.grid {
            check_values(key, values).map_err(|m| invalid(&format!("grid.\"{key}\""), m))?;
            for value in values {
                let setting = (key.clone(), value.clone());
                if let Err(m) = scene_with(&scene_text, &scene_path, std::slice::from_ref(&setting))
                {
                    // A value the scene refuses alone may hold beside another key's value (an
                    // h/dx in a Wendland kernel's range but not the quintic's): it is refused
                    // only if no point of the grid that holds it loads.
                    let loads_somewhere = grid
                        .iter()
                        .filter(|p| p.contains(&setting))
                        .any(|p| scene_with(&scene_text, &scene_path, p).is_ok());
                    if !loads_somewhere {
                        let key = format!("grid.\"{key}\"");
                        return Err(invalid(&key, format!("= {value}: {m}")));
                    }
                }
            }
        }
        let keys: Vec<String> = file.grid.keys().cloned().collect();
        let mut points = Vec::new();
        for settings in grid {
            let (text, scene) = scene_with(&scene_text, &scene_path, &settings)
                .map_err(|m| invalid("grid", format!("the point {}: {m}", label(&settings))))?;
            // A scene the measure cannot judge is refused before any point runs.
            crate::tools::validation::check(case, &scene)
                .map_err(|e| invalid("measure", format!("the point {}: {e}", label(&settings))))?;
            points.push(Point {
                id: point_id(&settings),
                settings,
                scene_text: text,
            });
        }
        Ok(Self {
            path: path.to_owned(),
            scene_path,
            case,
            until: file.until,
            keys,
            points,
        })
    }
}

/// A grid key's list: not empty, no value twice, no tables.
fn check_values(key: &str, values: &[toml::Value]) -> Result<(), String> {
    if values.is_empty() {
        return Err("is an empty list: give the values to try".into());
    }
    if key.split('.').any(str::is_empty) {
        return Err("is not a dotted key into the scene, e.g. \"simulation.spacing\"".into());
    }
    for (k, v) in values.iter().enumerate() {
        if v.is_table() {
            return Err(format!("lists a table ({v}): give values"));
        }
        if values[..k].contains(v) {
            return Err(format!("lists {v} twice"));
        }
    }
    Ok(())
}

/// The scene text with `settings` written in, checked by loading it.
fn scene_with(
    text: &str,
    scene_path: &Path,
    settings: &[(String, toml::Value)],
) -> Result<(String, Scene), String> {
    let new = overrides::apply(text, settings).map_err(|e| e.to_string())?;
    let scene =
        Scene::parse(&new, scene_path).map_err(|e| format!("the scene does not accept it: {e}"))?;
    Ok((new, scene))
}

/// Every combination of the grid's values, the last key varying fastest.
fn product(grid: &BTreeMap<String, Vec<toml::Value>>) -> Vec<Vec<(String, toml::Value)>> {
    grid.iter().fold(vec![Vec::new()], |points, (key, values)| {
        points
            .iter()
            .flat_map(|p| {
                values.iter().map(move |v| {
                    let mut p = p.clone();
                    p.push((key.clone(), v.clone()));
                    p
                })
            })
            .collect()
    })
}

/// 12 hex digits of the XXH3-64 of the settings as `key = value` lines: the same settings give
/// the same id in every run of the study.
pub fn point_id(settings: &[(String, toml::Value)]) -> String {
    let mut sorted: Vec<String> = settings
        .iter()
        .map(|(k, v)| format!("{k} = {v}\n"))
        .collect();
    sorted.sort();
    let hash = xxhash_rust::xxh3::xxh3_64(sorted.concat().as_bytes());
    format!("{hash:016x}")[..12].to_owned()
}

/// The settings as `key=value` with each key's last part, e.g. `spacing=0.02 tolerance=0.0001`.
pub fn label(settings: &[(String, toml::Value)]) -> String {
    let parts: Vec<String> = settings
        .iter()
        .map(|(k, v)| format!("{}={v}", short_key(k, settings)))
        .collect();
    if parts.is_empty() {
        "the scene as it is".into()
    } else {
        parts.join(" ")
    }
}

/// The last part of `key`, or the whole key when another key ends the same way.
fn short_key<'a>(key: &'a str, settings: &[(String, toml::Value)]) -> &'a str {
    let last = |k: &'a str| k.rsplit('.').next().unwrap_or(k);
    let shared = settings
        .iter()
        .filter(|(k, _)| k.rsplit('.').next() == Some(last(key)))
        .count();
    if shared > 1 {
        key
    } else {
        last(key)
    }
}
