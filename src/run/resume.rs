//! What `isph resume` checks before a run continues, and how the output directory is cut back to
//! the checkpoint. Every check comes before the first change to a file, so a refused resume
//! leaves the directory byte for byte as it was.

use crate::io::bodies_csv::{self, BodiesWriter};
use crate::io::checkpoint::{Checkpoint, CheckpointError, RunState};
use crate::io::checkpoint_folder::{self, DIR_NAME};
use crate::io::frames::{self, FrameWriter};
use crate::io::probes::{self, ProbesWriter};
use crate::io::stats::{self, StatsWriter};
use crate::io::surface_files::{self, SurfaceWriter};
use crate::io::{xdmf, OutputError};
use crate::particles::{Kind, Particles};
use crate::run::output::Output;
use crate::run::stop::StopSignal;
use crate::scene::{Scene, SceneError};
use std::path::{Path, PathBuf};

#[derive(Clone, Debug)]
pub struct ResumeOptions {
    /// Simulated time to stop at (default: the scene's `end_time`).
    pub until: Option<f64>,
    /// Continue even if the scene has changed since the checkpoint was written.
    pub force: bool,
    /// The scene file to use instead of the one the checkpoint names.
    pub scene: Option<PathBuf>,
    /// No progress display.
    pub quiet: bool,
    pub stop: StopSignal,
}

#[derive(Debug, thiserror::Error)]
pub enum ResumeError {
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(transparent)]
    Coverage(#[from] SceneError),
    #[error("cannot read the checkpoints in {dir}: {source}")]
    Folder {
        dir: PathBuf,
        source: std::io::Error,
    },
    #[error("{dir} holds no checkpoint (files {DIR_NAME}/step_*.ckpt of a run's output directory); a run writes one at its end, on SIGINT/SIGTERM and as `[checkpoint]` in the scene asks")]
    NoCheckpoint { dir: PathBuf },
    #[error("{dir} holds no valid checkpoint: {}", reasons.join("; "))]
    NoValidCheckpoint { dir: PathBuf, reasons: Vec<String> },
    #[error("{reason}. It is newer than {older}, which a resume of {dir} would continue from and would delete it: resume with an isph that reads it, or move it out of {dir} to continue from the older one")]
    NewerUnreadable {
        dir: PathBuf,
        older: PathBuf,
        reason: String,
    },
    #[error("{path} is not in the `{DIR_NAME}` folder of a run's output directory, so the run it continues cannot be found; move it back to OUT/{DIR_NAME}/")]
    OutsideRun { path: PathBuf },
    #[error("cannot load the scene of checkpoint {checkpoint}: {source}{}", if *given { "" } else { "; pass --scene FILE if the scene has moved" })]
    Scene {
        checkpoint: PathBuf,
        source: SceneError,
        /// The scene was given with --scene.
        given: bool,
    },
    #[error("{scene} has changed since {checkpoint} was written (the scene's hash is {now:#018x}, the checkpoint's {then:#018x}): a continuation would not be the run that was checkpointed. Restore the scene, or pass --force to continue with the scene as it is now")]
    SceneChanged {
        checkpoint: PathBuf,
        scene: PathBuf,
        now: u64,
        then: u64,
    },
    #[error("{checkpoint} holds a {then}D run but the scene {scene} is {now}D; no --force can continue it")]
    Dimensions {
        checkpoint: PathBuf,
        scene: PathBuf,
        now: usize,
        then: usize,
    },
    #[error("{scene} makes other particles than {checkpoint} holds ({what}): its spacing, fluid blocks, container, obstacles or bodies have changed since, and no --force can continue a run into other particles. Restore the scene, or start a new run")]
    ParticlesChanged {
        checkpoint: PathBuf,
        scene: PathBuf,
        what: String,
    },
    #[error("{checkpoint} is already at t = {time:?} s, not before the stop time {end:?} s; pass --until with a later time (or raise `end_time` in the scene)")]
    NothingToDo {
        checkpoint: PathBuf,
        time: f64,
        end: f64,
    },
}

/// The checkpoint `isph resume` continues from, and the newer ones it had to pass over.
pub struct Located {
    pub checkpoint: Checkpoint,
    pub skipped: Vec<CheckpointError>,
}

/// A checkpoint file as given; or, for a run's output directory or its checkpoints folder, the
/// newest checkpoint in it that passes every check.
pub fn locate(target: &Path) -> Result<Located, ResumeError> {
    if !target.is_dir() {
        return Ok(Located {
            checkpoint: Checkpoint::open(target)?,
            skipped: Vec::new(),
        });
    }
    let dir = if target.file_name().is_some_and(|n| n == DIR_NAME) {
        target.to_owned()
    } else {
        checkpoint_folder::folder(target)
    };
    let newest = checkpoint_folder::newest_valid(&dir).map_err(|source| ResumeError::Folder {
        dir: dir.clone(),
        source,
    })?;
    match newest.valid {
        Some(checkpoint) => {
            // A damaged checkpoint is skipped (and deleted with the run's future); one this isph
            // cannot read but another could is a good run's state, and is kept.
            if let Some(e) = newest.rejected.iter().find(|e| !e.is_damage()) {
                return Err(ResumeError::NewerUnreadable {
                    dir: target.to_owned(),
                    older: checkpoint.path().to_owned(),
                    reason: e.to_string(),
                });
            }
            Ok(Located {
                checkpoint,
                skipped: newest.rejected,
            })
        }
        None if newest.rejected.is_empty() => Err(ResumeError::NoCheckpoint {
            dir: target.to_owned(),
        }),
        None => Err(ResumeError::NoValidCheckpoint {
            dir: target.to_owned(),
            reasons: newest.rejected.iter().map(|e| e.to_string()).collect(),
        }),
    }
}

/// A continued run, ready to step: the scene, and its output cut back to the checkpoint and
/// open for appending.
pub(crate) struct Continuation {
    pub scene: Scene,
    pub output: Output,
}

/// A checkpoint that `check` found can be continued, and what the cut-back will do; no file has
/// changed yet.
pub(crate) struct Checked {
    pub scene: Scene,
    out: PathBuf,
    step: u64,
    time: f64,
    frames: Vec<frames::FrameInfo>,
    stats_length: u64,
    probes_file: ProbesFile,
    bodies_length: Option<u64>,
}

/// Checks that `checkpoint` can be continued: its scene unchanged unless `force`, its run's
/// frames and rows all there, a stop time after it. Changes no file.
pub(crate) fn check(checkpoint: &Checkpoint, opts: &ResumeOptions) -> Result<Checked, ResumeError> {
    let state = &checkpoint.state;
    let path = checkpoint.path().to_owned();
    let out = output_dir(&path)?;
    let scene = load_scene(checkpoint, opts)?;
    let end = opts.until.unwrap_or(scene.end_time);
    scene.check_stop_time(end)?;
    if end <= state.time {
        return Err(ResumeError::NothingToDo {
            checkpoint: path,
            time: state.time,
            end,
        });
    }
    let frames = frames::read_index(&out, state.frames_written as usize)?;
    if let Some(last) = frames.last().filter(|f| f.time > state.time) {
        return Err(OutputError::Mismatch {
            path: out.join(frames::FILE_NAME),
            what: format!(
                "its frame {} at t = {} s lies after the checkpoint's t = {} s",
                last.group, last.time, state.time
            ),
        }
        .into());
    }
    let stats_length = stats::end_of_step(&out, state.step)?;
    let probes_file = probes_file(&out, &scene, state)?;
    let bodies_length = if scene.bodies.is_empty() {
        None
    } else {
        let frames = state.frames_written as usize;
        Some(bodies_csv::end_of_frames(&out, frames, scene.bodies.len())?)
    };
    Ok(Checked {
        scene,
        out,
        step: state.step,
        time: state.time,
        frames,
        stats_length,
        probes_file,
        bodies_length,
    })
}

/// Cuts the run of a `check`ed checkpoint back to it: the checkpoints, frames and stats.csv,
/// probes.csv and bodies.csv rows after it are deleted, particles.xdmf is rewritten.
pub(crate) fn cut_back(checked: Checked) -> Result<Continuation, ResumeError> {
    let Checked {
        scene,
        out,
        step,
        time,
        frames,
        stats_length,
        probes_file,
        bodies_length,
    } = checked;
    // particles.h5 is opened for writing first, so that if another program holds it, nothing
    // has changed yet.
    let frames_out = FrameWriter::open(&out)?;
    let folder = checkpoint_folder::folder(&out);
    checkpoint_folder::remove_after(&folder, step).map_err(|source| OutputError::Write {
        path: folder.clone(),
        source,
    })?;
    let stats = StatsWriter::append_at(&out, stats_length)?;
    frames_out.remove_frames_from(frames.len())?;
    xdmf::write(&out, &frames)?;
    let surfaces = match scene.surface {
        Some(settings) => Some((surfaces_from(&out, frames.len())?, settings)),
        None => None,
    };
    let probes = continue_probes(&out, &scene, step, time, probes_file)?;
    let bodies = bodies_length
        .map(|length| BodiesWriter::append_at(&out, length))
        .transpose()?;
    Ok(Continuation {
        scene,
        output: Output {
            dir: out,
            frames_out,
            stats,
            frames,
            surfaces,
            probes,
            bodies,
        },
    })
}

/// Checks that `restored`, the particles of `checkpoint`, are those the scene at `scene_path`
/// makes (`fresh`, at t = 0): as many, each id of the same kind and
/// fluid or body, the walls where they were. `--force` continues a run whose settings changed,
/// never one whose particles did (a body's offsets and a fluid's lattice come from the scene).
pub(crate) fn check_particles<const D: usize>(
    checkpoint: &Checkpoint,
    scene_path: &Path,
    fresh: &Particles<D>,
    restored: &Particles<D>,
) -> Result<(), ResumeError> {
    let changed = |what: String| ResumeError::ParticlesChanged {
        checkpoint: checkpoint.path().to_owned(),
        scene: scene_path.to_owned(),
        what,
    };
    if fresh.len() != restored.len() {
        return Err(changed(format!(
            "{} particles against {}",
            fresh.len(),
            restored.len()
        )));
    }
    let kind_name = |k: Kind| match k {
        Kind::Fluid => "fluid",
        Kind::Wall => "wall",
        Kind::Body => "body",
    };
    let index = fresh.index_by_id();
    for k in 0..restored.len() {
        let (id, i) = (restored.id[k], index[restored.id[k] as usize] as usize);
        let (then, now) = (restored.kind[k], fresh.kind[i]);
        if then != now {
            return Err(changed(format!(
                "particle {id} is a {} particle in the scene, a {} particle in the checkpoint",
                kind_name(now),
                kind_name(then)
            )));
        }
        if restored.fluid[k] != fresh.fluid[i] {
            return Err(changed(format!(
                "{} particle {id} belongs to {} {} in the scene, {} in the checkpoint",
                kind_name(now),
                if now == Kind::Body { "body" } else { "fluid" },
                fresh.fluid[i],
                restored.fluid[k]
            )));
        }
        if now == Kind::Wall && (0..D).any(|d| restored.pos[d][k] != fresh.pos[d][i]) {
            return Err(changed(format!(
                "wall particle {id} is at {:?} in the scene, {:?} in the checkpoint",
                fresh.position(i),
                restored.position(k)
            )));
        }
    }
    Ok(())
}

/// What becomes of a run's probes.csv on resume.
enum ProbesFile {
    /// It holds the scene's probes: cut back to this length (the checkpoint's row) and continued.
    Continue(u64),
    /// There is none, or it holds other probes than the scene's (probes may change between a
    /// stop and a resume: they do not enter the scene's hash); then it is kept under another
    /// name (`set_aside`) and a scene with probes starts a new one at the checkpoint.
    Start { set_aside: bool },
}

/// Decides `ProbesFile`, before any file changes: a probes.csv with the scene's header must hold
/// the checkpoint's row, as stats.csv must.
fn probes_file(out: &Path, scene: &Scene, state: &RunState) -> Result<ProbesFile, OutputError> {
    let path = out.join(probes::FILE_NAME);
    if !path.exists() {
        return Ok(ProbesFile::Start { set_aside: false });
    }
    let text = std::fs::read_to_string(&path).map_err(|source| OutputError::Read {
        path: path.clone(),
        source,
    })?;
    let same_probes = !scene.probes.is_empty()
        && text.lines().next() == Some(probes::header(&scene.probes).as_str());
    if !same_probes {
        return Ok(ProbesFile::Start { set_aside: true });
    }
    probes::end_of_time(out, &scene.probes, state.step, state.time).map(ProbesFile::Continue)
}

/// Carries out `file`: the probes.csv the continued run appends to, if the scene has probes.
fn continue_probes(
    out: &Path,
    scene: &Scene,
    step: u64,
    time: f64,
    file: ProbesFile,
) -> Result<Option<ProbesWriter>, OutputError> {
    match file {
        ProbesFile::Continue(length) => ProbesWriter::append_at(out, length).map(Some),
        ProbesFile::Start { set_aside } => {
            if set_aside {
                let path = out.join(probes::FILE_NAME);
                let aside = free_name(out, &format!("probes_replaced_at_step_{step}"), "csv");
                std::fs::rename(&path, &aside).map_err(|source| OutputError::Write {
                    path: aside.clone(),
                    source,
                })?;
                eprintln!(
                    "warning: the scene's probes differ from those of {}: it is kept as {}, and probes.csv starts anew at t = {time} s",
                    path.display(),
                    aside.display(),
                );
            }
            if scene.probes.is_empty() {
                return Ok(None);
            }
            ProbesWriter::create(out, &scene.probes).map(Some)
        }
    }
}

/// `dir`/`stem`.`extension`, or the first of `stem`_2, `stem`_3, … not taken: a file set
/// aside never replaces one set aside before (probes changed twice at one step).
fn free_name(dir: &Path, stem: &str, extension: &str) -> PathBuf {
    (1..)
        .map(|k| match k {
            1 => dir.join(format!("{stem}.{extension}")),
            k => dir.join(format!("{stem}_{k}.{extension}")),
        })
        .find(|path| !path.exists())
        .expect("some name is free")
}

/// The run's surface.h5 cut back to its first `frames` frames; a new one if it has none, or if
/// it cannot be read (killed in the middle of a write): surfaces are derived from the frames, and
/// `isph surface` rebuilds the lost ones.
fn surfaces_from(out: &Path, frames: usize) -> Result<SurfaceWriter, OutputError> {
    if !out.join(surface_files::FILE_NAME).exists() {
        return SurfaceWriter::create(out);
    }
    SurfaceWriter::reopen(out, frames).or_else(|e| {
        eprintln!("warning: {e}; the run's surfaces start anew (`isph surface` rebuilds those of earlier frames)");
        SurfaceWriter::create(out)
    })
}

/// OUT for a checkpoint at OUT/checkpoints/step_….ckpt.
fn output_dir(checkpoint: &Path) -> Result<PathBuf, ResumeError> {
    let absolute = std::path::absolute(checkpoint).unwrap_or_else(|_| checkpoint.to_owned());
    let folder = absolute
        .parent()
        .filter(|f| f.file_name().is_some_and(|n| n == DIR_NAME));
    folder
        .and_then(Path::parent)
        .map(Path::to_owned)
        .ok_or_else(|| ResumeError::OutsideRun {
            path: checkpoint.to_owned(),
        })
}

/// The scene the checkpoint names (or `--scene`), refused if it no longer describes the same
/// run: another dimension always, another content hash unless `--force`.
fn load_scene(checkpoint: &Checkpoint, opts: &ResumeOptions) -> Result<Scene, ResumeError> {
    let path = opts
        .scene
        .clone()
        .unwrap_or_else(|| checkpoint.state.scene_path.clone());
    let scene = Scene::load(&path).map_err(|source| ResumeError::Scene {
        checkpoint: checkpoint.path().to_owned(),
        source,
        given: opts.scene.is_some(),
    })?;
    if scene.dimensions != checkpoint.dimensions() {
        return Err(ResumeError::Dimensions {
            checkpoint: checkpoint.path().to_owned(),
            scene: path,
            now: scene.dimensions,
            then: checkpoint.dimensions(),
        });
    }
    let (now, then) = (scene.content_hash(), checkpoint.state.scene_hash);
    if now != then && !opts.force {
        return Err(ResumeError::SceneChanged {
            checkpoint: checkpoint.path().to_owned(),
            scene: path,
            now,
            then,
        });
    }
    Ok(scene)
}
