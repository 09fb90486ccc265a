//! Run output: HDF5 frames with their XDMF index, the per-step `stats.csv`, checkpoints, and
//! the output directory itself (never overwritten by accident).

pub mod bodies_csv;
pub mod checkpoint;
pub mod checkpoint_folder;
pub mod csv;
pub mod frames;
pub mod probes;
pub mod stats;
pub mod surface_files;
pub mod xdmf;

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("output directory {dir} cannot be used: {source}")]
    Directory {
        dir: PathBuf,
        source: std::io::Error,
    },
    #[error("output directory {dir} already holds a run ({file}); pass --overwrite to replace it, `isph resume` to continue it, or choose another --out")]
    HoldsRun { dir: PathBuf, file: String },
    #[error("cannot write {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot write {path}: {source}")]
    Hdf5 { path: PathBuf, source: hdf5::Error },
    #[error("cannot read {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot read {path}: {source}")]
    Hdf5Read { path: PathBuf, source: hdf5::Error },
    #[error("{path} does not belong with the checkpoint: {what}")]
    Mismatch { path: PathBuf, what: String },
    #[error("{path}: {what}")]
    Malformed { path: PathBuf, what: String },
}

/// Opens an HDF5 file of a run for reading, also while the run is appending to it: the run
/// holds HDF5's file lock, so a reader takes none (it sees what was flushed so far).
pub fn open_for_reading(path: &Path) -> Result<hdf5::File, OutputError> {
    hdf5::File::with_options()
        .with_fapl(|p| p.file_locking(false))
        .open(path)
        .map_err(|source| OutputError::Hdf5Read {
            path: path.to_owned(),
            source,
        })
}

/// Writes `bytes` to `path` through a hidden temporary file beside it and a rename, so that a
/// reader (ParaView, a viewer, ffmpeg) never sees half of the file; the temporary file is
/// removed if the write fails. Not fsynced: these files can be written again from the frames.
pub fn replace_file(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let private = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    match std::fs::write(&private, bytes).and_then(|()| std::fs::rename(&private, path)) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(&private);
            Err(e)
        }
    }
}

/// `replace_file`, its error naming the file.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    replace_file(path, bytes).map_err(|source| OutputError::Write {
        path: path.to_owned(),
        source,
    })
}

/// Files that make a directory an isph run.
pub const RUN_FILES: [&str; 3] = [frames::FILE_NAME, xdmf::FILE_NAME, stats::FILE_NAME];

/// Creates `dir` if needed and checks it can hold a new run: it must be writable, and must
/// not already hold one unless `overwrite` (then the old run's files and checkpoints are removed,
/// so that `isph resume` cannot pick up a checkpoint of the old run).
pub fn prepare_output_dir(dir: &Path, overwrite: bool) -> Result<(), OutputError> {
    let dir_error = |source| OutputError::Directory {
        dir: dir.to_owned(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(dir_error)?;
    // Surfaces, probes and bodies.csv belong to the run they were taken from: a new run replaces them only
    // when told.
    let others = [
        surface_files::FILE_NAME,
        surface_files::INDEX_NAME,
        probes::FILE_NAME,
        bodies_csv::FILE_NAME,
    ];
    for file in RUN_FILES.into_iter().chain(others) {
        if dir.join(file).exists() {
            if !overwrite {
                return Err(OutputError::HoldsRun {
                    dir: dir.to_owned(),
                    file: file.to_owned(),
                });
            }
            std::fs::remove_file(dir.join(file)).map_err(dir_error)?;
        }
    }
    if overwrite {
        for mesh in surface_files::mesh_files(dir) {
            std::fs::remove_file(mesh).map_err(dir_error)?;
        }
    }
    let checkpoints = checkpoint_folder::folder(dir);
    if checkpoints.exists() {
        if !overwrite {
            return Err(OutputError::HoldsRun {
                dir: dir.to_owned(),
                file: checkpoint_folder::DIR_NAME.to_owned(),
            });
        }
        std::fs::remove_dir_all(&checkpoints).map_err(dir_error)?;
    }
    // Probe that files can be created here before any simulation work starts.
    let probe = dir.join(".isph-write-test");
    std::fs::write(&probe, b"").map_err(dir_error)?;
    std::fs::remove_file(&probe).map_err(dir_error)
}
