//! Where the PNGs go: one file the user names, or `frame_000012.png` files in a directory, and
//! never over anything but a PNG.

use super::png_file;
use super::RenderError;
use std::path::{Path, PathBuf};

/// The name of frame `index`'s picture in an output directory: zero-padded to six digits like
/// the frames of particles.h5, so that a directory listing and ffmpeg's `%06d` take them in
/// order.
pub fn file_name(index: usize) -> String {
    format!("frame_{index:06}.png")
}

fn is_png_name(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
}

/// The file of each frame in `frames`, the directories they go in created: `output` itself
/// when it names a .png file and one frame is rendered, else files named by `file_name` in the
/// directory `output`. A path that exists and is not a PNG is refused, so that a slip of `-o`
/// never replaces a run's data.
pub fn targets(output: &Path, frames: &[usize]) -> Result<Vec<PathBuf>, RenderError> {
    let single_file = is_png_name(output) && !output.is_dir();
    if single_file && frames.len() != 1 {
        return Err(RenderError::SequenceIntoFile {
            path: output.to_owned(),
            count: frames.len(),
        });
    }
    let dir = if single_file {
        match output.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
            _ => PathBuf::from("."),
        }
    } else {
        output.to_owned()
    };
    if dir.exists() && !dir.is_dir() {
        return Err(RenderError::NotADirectory { path: dir });
    }
    std::fs::create_dir_all(&dir).map_err(|source| RenderError::Write {
        path: dir.clone(),
        source,
    })?;
    let paths: Vec<PathBuf> = if single_file {
        vec![output.to_owned()]
    } else {
        frames.iter().map(|&k| dir.join(file_name(k))).collect()
    };
    for path in &paths {
        if path.is_dir() || (path.exists() && !png_file::is_png(path)) {
            return Err(RenderError::NotPng { path: path.clone() });
        }
    }
    Ok(paths)
}
