//! `isph surface RUN_DIR`: the water surface of a finished (or running) run's frames, written as
//! `surface.h5` + `surface.xdmf` and one PLY (and OBJ) file per frame (docs/surface.md).

use crate::io::frames::{self, FrameReader};
use crate::io::surface_files::{self, SurfaceWriter};
use crate::io::OutputError;
use crate::scene::SurfaceSettings;
use crate::surface::{self, SurfaceError};
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct SurfaceOptions {
    /// Which frames: `all`, `last`, or numbers and inclusive ranges, comma-separated
    /// (`0,10..20`); None: all.
    pub frames: Option<String>,
    pub settings: SurfaceSettings,
    /// Where the surface files go (default: the run's directory).
    pub out: Option<PathBuf>,
    /// Replace surface files already there.
    pub overwrite: bool,
}

/// What one frame's surface came to.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameSurface {
    pub frame: usize,
    pub dimensions: usize,
    pub time: f64,
    pub vertices: usize,
    pub cells: usize,
    /// The volume (3D) or area (2D) the surface encloses.
    pub enclosed: f64,
    /// The fluid particles' own volume (area), N dx^D, to compare with.
    pub fluid: f64,
    pub seconds: f64,
}

#[derive(Debug, thiserror::Error)]
pub enum SurfaceToolError {
    #[error(
        "{dir} is not a run's output directory: it holds no {}",
        frames::FILE_NAME
    )]
    NoRun { dir: PathBuf },
    #[error("{path} holds no frames yet")]
    NoFrames { path: PathBuf },
    #[error("--frames {spec}: {what}")]
    Frames { spec: String, what: String },
    #[error("{path} already exists; pass --overwrite to replace the surfaces there, or --out to write them elsewhere")]
    Exists { path: PathBuf },
    #[error("frame {frame} of {}: {source}", path.display())]
    Surface {
        frame: usize,
        path: PathBuf,
        source: SurfaceError,
    },
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// The frame numbers `spec` names among `count` frames, in increasing order, each once.
pub fn select_frames(spec: &str, count: usize) -> Result<Vec<usize>, String> {
    let last = count.checked_sub(1).ok_or("the run holds no frames")?;
    let number = |s: &str| -> Result<usize, String> {
        match s.trim() {
            "last" => Ok(last),
            t => t.parse::<usize>().map_err(|_| {
                format!("`{t}` is not a frame number (frames are numbered 0 to {last})")
            }),
        }
    };
    let mut frames = Vec::new();
    for part in spec.split(',') {
        let (first, end) = match part.trim() {
            "all" => (0, last),
            p => match p.split_once("..") {
                Some((a, b)) => (number(a)?, number(b)?),
                None => (number(p)?, number(p)?),
            },
        };
        if first > end {
            return Err(format!("the range {first}..{end} runs backwards"));
        }
        if end > last {
            return Err(format!(
                "frame {end} does not exist: the run holds frames 0 to {last}"
            ));
        }
        frames.extend(first..=end);
    }
    frames.sort_unstable();
    frames.dedup();
    Ok(frames)
}

/// What became of one chosen frame.
#[derive(Debug)]
pub enum FrameOutcome {
    Built(FrameSurface),
    /// No surface could be built (the first chosen frame's failure is an error instead).
    Skipped {
        frame: usize,
        reason: SurfaceError,
    },
}

/// Builds and writes the surface of each chosen frame of the run in `run_dir`; `on_frame` hears
/// of each as it is written, or skipped. Settings that cannot build the first chosen frame's
/// surface are an error, with nothing written; a later frame they cannot build (a drop flung
/// far, more cubes than allowed) is skipped, as a run skips it.
pub fn surface_run(
    run_dir: &Path,
    opts: &SurfaceOptions,
    mut on_frame: impl FnMut(&FrameOutcome),
) -> Result<Vec<FrameSurface>, SurfaceToolError> {
    if !run_dir.join(frames::FILE_NAME).is_file() {
        return Err(SurfaceToolError::NoRun {
            dir: run_dir.to_owned(),
        });
    }
    let reader = FrameReader::open(run_dir)?;
    let (dimensions, spacing) = reader.geometry()?;
    let times = reader.times()?;
    if times.is_empty() {
        return Err(SurfaceToolError::NoFrames {
            path: reader.path().to_owned(),
        });
    }
    let spec = opts.frames.as_deref().unwrap_or("all");
    let chosen = select_frames(spec, times.len()).map_err(|what| SurfaceToolError::Frames {
        spec: spec.to_owned(),
        what,
    })?;
    let out = opts.out.clone().unwrap_or_else(|| run_dir.to_owned());
    if !opts.overwrite {
        if let Some(path) = existing_surfaces(&out) {
            return Err(SurfaceToolError::Exists { path });
        }
    }
    let mut writer = None;
    let mut done = Vec::new();
    for frame in chosen {
        let started = Instant::now();
        let particles = reader.read(frame)?;
        let points = particles.fluid_points(dimensions, spacing);
        let mesh = match surface::reconstruct(&points, &opts.settings) {
            Ok(mesh) => mesh,
            Err(reason) if writer.is_some() => {
                on_frame(&FrameOutcome::Skipped { frame, reason });
                continue;
            }
            Err(source) => {
                return Err(SurfaceToolError::Surface {
                    frame,
                    path: reader.path().to_owned(),
                    source,
                })
            }
        };
        // The files are replaced only once the first surface has been built: settings that
        // cannot build one leave the old surfaces as they were.
        if writer.is_none() {
            writer = Some(create_output(&out)?);
        }
        let writer = writer.as_mut().expect("created above");
        writer.write(frame, particles.time, &mesh, opts.settings.obj)?;
        let result = FrameSurface {
            frame,
            dimensions,
            time: particles.time,
            vertices: mesh.vertex_count(),
            cells: mesh.cell_count(),
            enclosed: mesh.enclosed_measure(),
            fluid: points.position.len() as f64 * spacing.powi(dimensions as i32),
            seconds: started.elapsed().as_secs_f64(),
        };
        on_frame(&FrameOutcome::Built(result.clone()));
        done.push(result);
    }
    Ok(done)
}

/// A surface file already in `out`: its surface.h5, or a mesh file in its surface/ folder.
fn existing_surfaces(out: &Path) -> Option<PathBuf> {
    let h5 = out.join(surface_files::FILE_NAME);
    if h5.exists() {
        return Some(h5);
    }
    surface_files::mesh_files(out).into_iter().next()
}

/// A fresh surface.h5 in `out`, the mesh files of an earlier surface run removed (only those:
/// the surface/ folder may hold other files).
fn create_output(out: &Path) -> Result<SurfaceWriter, OutputError> {
    std::fs::create_dir_all(out).map_err(|source| OutputError::Write {
        path: out.to_owned(),
        source,
    })?;
    let writer = SurfaceWriter::create(out)?;
    for file in surface_files::mesh_files(out) {
        std::fs::remove_file(&file).map_err(|source| OutputError::Write { path: file, source })?;
    }
    Ok(writer)
}
