//! Error measures of a finished run against a reference solution or experiment, computed from
//! the run's `particles.h5`, `stats.csv` and `probes.csv`: what `isph study` plots against wall time and what
//! the validation tests assert. One file per case.

pub mod cylinder_array;
pub mod dam_break;
pub mod density;
pub mod hydrostatic;
pub mod lobovsky;
pub mod poiseuille;
pub mod taylor_green;
pub mod wave_flume;

use crate::io::frames::{Frame, FrameReader};
use crate::io::OutputError;
use crate::particles::Kind;
use crate::scene::{Block, Scene};
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// A reference the error of a run is measured against.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Case {
    /// Still water: the pressure against ρ0 |g| (H − y) (`hydrostatic.rs`).
    Hydrostatic,
    /// Collapsing 2:1 column: the surge front against Martin & Moyce (1952) (`dam_break.rs`).
    DamBreakFront,
    /// Start-up flow between plates against the analytic series (`poiseuille.rs`).
    Poiseuille,
    /// The decaying Taylor–Green vortex (`taylor_green.rs`).
    TaylorGreen,
    /// Wall pressures of a dam break against Lobovsky et al. (2014) (`lobovsky.rs`).
    LobovskyPressure,
    /// Stokes flow through a square array of cylinders against Sangani & Acrivos (1982)
    /// (`cylinder_array.rs`).
    CylinderArray,
    /// Regular waves from a piston wave maker against Biesel's transfer function
    /// (`wave_flume.rs`).
    WaveFlume,
    /// Any flow: its density against ρ0 over every step (`density.rs`).
    Density,
}

impl Case {
    pub const ALL: [Case; 8] = [
        Case::Hydrostatic,
        Case::DamBreakFront,
        Case::Poiseuille,
        Case::TaylorGreen,
        Case::LobovskyPressure,
        Case::CylinderArray,
        Case::WaveFlume,
        Case::Density,
    ];

    /// The name a study file gives (`measure = "…"`).
    pub fn name(self) -> &'static str {
        match self {
            Case::Hydrostatic => "hydrostatic",
            Case::DamBreakFront => "dam_break_front",
            Case::Poiseuille => "poiseuille",
            Case::TaylorGreen => "taylor_green",
            Case::LobovskyPressure => "lobovsky_pressure",
            Case::CylinderArray => "cylinder_array",
            Case::WaveFlume => "wave_flume",
            Case::Density => "density",
        }
    }

    /// The names of the details `measure` returns for this case, in their order.
    pub fn detail_names(self) -> &'static [&'static str] {
        match self {
            Case::Hydrostatic => &hydrostatic::DETAILS,
            Case::DamBreakFront => &dam_break::DETAILS,
            Case::Poiseuille => &poiseuille::DETAILS,
            Case::TaylorGreen => &taylor_green::DETAILS,
            Case::LobovskyPressure => &lobovsky::DETAILS,
            Case::CylinderArray => &cylinder_array::DETAILS,
            Case::WaveFlume => &wave_flume::DETAILS,
            Case::Density => &density::DETAILS,
        }
    }
}

impl std::fmt::Display for Case {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is no `Case`.
#[derive(Debug, thiserror::Error)]
#[error("\"{name}\" is no error measure; known: {}", Case::ALL.map(|c| format!("\"{c}\"")).join(", "))]
pub struct UnknownCase {
    pub name: String,
}

impl FromStr for Case {
    type Err = UnknownCase;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        Case::ALL
            .into_iter()
            .find(|c| c.name() == name)
            .ok_or_else(|| UnknownCase { name: name.into() })
    }
}

/// What `measure` found.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// The headline relative error of the case.
    pub error: f64,
    /// Named extras, in the order of `Case::detail_names`.
    pub details: Vec<(String, f64)>,
}

impl Measured {
    fn new(error: f64, names: &[&str], values: &[f64]) -> Self {
        let details = names
            .iter()
            .zip(values)
            .map(|(n, &v)| (n.to_string(), v))
            .collect();
        Self { error, details }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ValidationError {
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error("{case}: the scene {}: {message}", path.display())]
    Scene {
        case: Case,
        path: PathBuf,
        message: String,
    },
    #[error("{case}: the run in {}: {message}", dir.display())]
    Run {
        case: Case,
        dir: PathBuf,
        message: String,
    },
}

/// The error of the finished run of `scene` in `run_dir` against `case`.
pub fn measure(case: Case, scene: &Scene, run_dir: &Path) -> Result<Measured, ValidationError> {
    made_from(case, scene, run_dir)?;
    match case {
        Case::Hydrostatic => hydrostatic::measure(scene, run_dir),
        Case::DamBreakFront => dam_break::measure(scene, run_dir),
        Case::Poiseuille => poiseuille::measure(scene, run_dir),
        Case::TaylorGreen => taylor_green::measure(scene, run_dir),
        Case::LobovskyPressure => lobovsky::measure(scene, run_dir),
        Case::CylinderArray => cylinder_array::measure(scene, run_dir),
        Case::WaveFlume => wave_flume::measure(scene, run_dir),
        Case::Density => density::measure(run_dir),
    }
}

/// Refuses a run whose newest checkpoint (a run always ends with one) was written for another
/// scene: the same scene hash as `isph resume` checks (name, end time and checkpoint settings
/// may differ). A directory without a readable checkpoint is measured as it is.
fn made_from(case: Case, scene: &Scene, run_dir: &Path) -> Result<(), ValidationError> {
    let folder = crate::io::checkpoint_folder::folder(run_dir);
    let Ok(newest) = crate::io::checkpoint_folder::newest_valid(&folder) else {
        return Ok(());
    };
    match newest.valid {
        Some(c) if c.state.scene_hash != scene.content_hash() => Err(ValidationError::Run {
            case,
            dir: run_dir.to_owned(),
            message: format!(
                "was made from another scene than {} (its checkpoint {} holds a different scene hash): measure it with the scene it was run from",
                scene.path.display(),
                c.path().display()
            ),
        }),
        _ => Ok(()),
    }
}

/// Whether `scene` suits `case`: what `measure` checks of the scene before it reads a run.
pub fn check(case: Case, scene: &Scene) -> Result<(), ValidationError> {
    match case {
        Case::Hydrostatic => vertical(case, scene).and(first_block(case, scene).map(|_| ())),
        Case::DamBreakFront => dam_break::Column::new(scene).map(|_| ()),
        Case::Poiseuille => poiseuille::Channel::of(scene).map(|_| ()),
        Case::TaylorGreen => taylor_green::Vortex::of(scene).map(|_| ()),
        Case::LobovskyPressure => lobovsky::Tank::new(scene).map(|_| ()),
        Case::CylinderArray => cylinder_array::Cell::of(scene).map(|_| ()),
        Case::WaveFlume => wave_flume::Flume::of(scene).map(|_| ()),
        Case::Density => Ok(()),
    }
}

/// The error of a scene that `case` cannot be measured on, saying why.
fn unsuitable(case: Case, scene: &Scene, message: impl Into<String>) -> ValidationError {
    ValidationError::Scene {
        case,
        path: scene.path.clone(),
        message: message.into(),
    }
}

/// The first fluid block, the water column or box the case's reference is for: a box, not a
/// mesh (whose region is only the box around it).
fn first_block(case: Case, scene: &Scene) -> Result<&Block, ValidationError> {
    let block = &scene.blocks[0];
    match block.mesh {
        None => Ok(block),
        Some(_) => Err(unsuitable(
            case,
            scene,
            "the first fluid block is a mesh: the reference is for a box of water given by its `min` and `max`",
        )),
    }
}

/// The axis gravity points down along (it must be along one axis only) and |g|.
fn vertical(case: Case, scene: &Scene) -> Result<(usize, f64), ValidationError> {
    let along: Vec<usize> = (0..scene.gravity.len())
        .filter(|&d| scene.gravity[d] != 0.0)
        .collect();
    match along[..] {
        [v] if scene.gravity[v] < 0.0 => Ok((v, -scene.gravity[v])),
        _ => Err(unsuitable(
            case,
            scene,
            format!(
                "gravity {:?} must point down one axis (e.g. [0.0, -9.81])",
                scene.gravity
            ),
        )),
    }
}

/// `vertical` for a dam break, whose surge runs along x: gravity must not point along it.
fn surge_vertical(case: Case, scene: &Scene) -> Result<(usize, f64), ValidationError> {
    let (v, g) = vertical(case, scene)?;
    if v == 0 {
        return Err(unsuitable(
            case,
            scene,
            "gravity points along x, the axis the surge runs along",
        ));
    }
    Ok((v, g))
}

/// A run's probes.csv, read for `case`: each probe's column as a curve of (t, value).
struct ProbeCurves {
    case: Case,
    dir: PathBuf,
    columns: Vec<String>,
    rows: Vec<Vec<f64>>,
}

impl ProbeCurves {
    fn read(case: Case, run_dir: &Path) -> Result<Self, ValidationError> {
        let (columns, rows) = crate::io::probes::read(run_dir)?;
        Ok(Self {
            case,
            dir: run_dir.to_owned(),
            columns,
            rows,
        })
    }

    /// The column `name` against time; an error names the column the file lacks.
    fn curve(&self, name: &str) -> Result<Vec<(f64, f64)>, ValidationError> {
        let col = self
            .columns
            .iter()
            .position(|c| c == name)
            .ok_or_else(|| self.error(format!("its probes.csv has no column {name}")))?;
        Ok(self.rows.iter().map(|r| (r[0], r[col])).collect())
    }

    /// The time of the last row (0 without rows).
    fn end(&self) -> f64 {
        self.rows.last().map_or(0.0, |r| r[0])
    }

    /// What is wrong with the run, for `case`.
    fn error(&self, message: String) -> ValidationError {
        ValidationError::Run {
            case: self.case,
            dir: self.dir.clone(),
            message,
        }
    }
}

/// The last frame of the run in `run_dir`.
fn last_frame(case: Case, run_dir: &Path) -> Result<Frame, ValidationError> {
    let reader = FrameReader::open(run_dir)?;
    let count = reader.times()?.len();
    if count == 0 {
        return Err(no_frames(case, run_dir));
    }
    Ok(reader.read(count - 1)?)
}

fn no_frames(case: Case, run_dir: &Path) -> ValidationError {
    ValidationError::Run {
        case,
        dir: run_dir.to_owned(),
        message: "its particles.h5 holds no frame".into(),
    }
}

/// The rows of `frame` that are fluid particles.
fn fluid(frame: &Frame) -> impl Iterator<Item = usize> + '_ {
    (0..frame.kind.len()).filter(|&i| frame.kind[i] == Kind::Fluid as i32)
}
