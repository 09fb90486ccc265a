//! `OUT/checkpoints/`: one file per checkpoint, named by its step, written so that a process
//! killed at any instant leaves every earlier checkpoint intact, and pruned to the newest K.

use super::checkpoint::{self, Checkpoint, CheckpointError, RunState};
use crate::particles::Particles;
use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};

/// The folder of a run's checkpoints, inside its output directory.
pub const DIR_NAME: &str = "checkpoints";
const EXTENSION: &str = "ckpt";
/// Suffix of a checkpoint still being written (never read; removed by the next save).
const PARTIAL: &str = ".tmp";

pub fn folder(out: &Path) -> PathBuf {
    out.join(DIR_NAME)
}

fn file_name(step: u64) -> String {
    format!("step_{step:012}.{EXTENSION}")
}

fn step_of(name: &str) -> Option<u64> {
    name.strip_prefix("step_")?
        .strip_suffix(&format!(".{EXTENSION}"))?
        .parse()
        .ok()
}

/// The checkpoints in `dir` as (step, path), oldest first; none if `dir` does not exist.
pub fn list(dir: &Path) -> io::Result<Vec<(u64, PathBuf)>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e),
    };
    let mut found = Vec::new();
    for entry in entries {
        let entry = entry?;
        if let Some(step) = entry.file_name().to_str().and_then(step_of) {
            found.push((step, entry.path()));
        }
    }
    found.sort();
    Ok(found)
}

/// Makes the directory entries of `dir` durable (a rename or creation in it survives a crash).
fn sync_dir(dir: &Path) -> io::Result<()> {
    File::open(dir)?.sync_all()
}

/// Writes a checkpoint of `state` and `p` into `dir` durably and returns its path: the file is
/// written under a temporary name in the same folder, fsynced, renamed into place and the folder
/// fsynced; only then are the checkpoints beyond the newest `keep` deleted.
pub fn save<const D: usize>(
    dir: &Path,
    state: &RunState,
    p: &mut Particles<D>,
    bodies: &[f64],
    keep: usize,
) -> Result<PathBuf, CheckpointError> {
    let path = dir.join(file_name(state.step));
    let write_error = |source| CheckpointError::Write {
        path: path.clone(),
        source,
    };
    if !dir.exists() {
        std::fs::create_dir_all(dir).map_err(write_error)?;
        if let Some(parent) = dir.parent() {
            sync_dir(parent).map_err(write_error)?;
        }
    }
    let tmp = dir.join(format!(".{}{PARTIAL}", file_name(state.step)));
    if let Err(e) = write_synced(&tmp, state, p, bodies) {
        // Do not leave a partial file taking the room (a full disk is the likely cause).
        let _ = std::fs::remove_file(&tmp);
        return Err(write_error(e));
    }
    std::fs::rename(&tmp, &path).map_err(write_error)?;
    sync_dir(dir).map_err(write_error)?;
    prune(dir, keep).map_err(write_error)?;
    Ok(path)
}

fn write_synced<const D: usize>(
    path: &Path,
    state: &RunState,
    p: &mut Particles<D>,
    bodies: &[f64],
) -> io::Result<()> {
    let mut file = File::create(path)?;
    checkpoint::write(&mut file, state, p, bodies)?;
    file.sync_all()
}

/// Deletes all but the newest `keep` checkpoints, and what killed writers left half-written.
fn prune(dir: &Path, keep: usize) -> io::Result<()> {
    let all = list(dir)?;
    for (_, old) in &all[..all.len().saturating_sub(keep)] {
        std::fs::remove_file(old)?;
    }
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with('.') && name.ends_with(&format!(".{EXTENSION}{PARTIAL}")) {
            std::fs::remove_file(entry.path())?;
        }
    }
    Ok(())
}

/// Deletes the checkpoints after `step`: the future of a run that is resumed from `step`.
pub fn remove_after(dir: &Path, step: u64) -> io::Result<()> {
    for (s, path) in list(dir)? {
        if s > step {
            std::fs::remove_file(path)?;
        }
    }
    Ok(())
}

/// What `newest_valid` found.
pub struct Newest {
    /// The newest checkpoint that opens and passes every check.
    pub valid: Option<Checkpoint>,
    /// Why each newer one was rejected, newest first.
    pub rejected: Vec<CheckpointError>,
}

/// The newest valid checkpoint in `dir`, and why the newer ones are not.
pub fn newest_valid(dir: &Path) -> io::Result<Newest> {
    let mut rejected = Vec::new();
    for (_, path) in list(dir)?.into_iter().rev() {
        match Checkpoint::open(&path) {
            Ok(c) => {
                return Ok(Newest {
                    valid: Some(c),
                    rejected,
                })
            }
            Err(e) => rejected.push(e),
        }
    }
    Ok(Newest {
        valid: None,
        rejected,
    })
}
