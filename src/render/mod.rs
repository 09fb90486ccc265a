//! Pictures of a run without a viewer (`isph render`): PNGs of its frames, read back from
//! particles.h5.
//!
//! 2D: the particles as discs on axes in metres (`plot_2d`). 3D: the water's surface, shaded,
//! in its container seen from a fixed oblique camera (`view_3d`), or the particles as shaded
//! spheres where there is no surface. Both coloured by a field (`field`, `colormap`) with a
//! colour bar, and the time above (`overlay`, text by plotters in the embedded font of
//! `font`). Every picture of one call shares one colour scale and one camera (`survey`), so a
//! numbered sequence makes a steady video. The same run gives the same PNG bytes: drawing
//! follows particle and triangle order, and nothing depends on the thread count or the time
//! of day.

pub mod bounds;
pub mod camera;
pub mod colormap;
pub mod depth;
pub mod field;
pub mod font;
pub mod output;
pub mod overlay;
pub mod plot_2d;
pub mod png_file;
pub mod raster;
pub mod survey;
pub mod view_3d;

pub use field::ColorField;

use crate::io::frames::{self, Frame, FrameReader};
use crate::io::surface_files::{self, SurfaceReader};
use crate::io::OutputError;
use crate::surface::Mesh;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use survey::Survey;

/// Which frames to render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameChoice {
    /// Frame number k (0 is the initial state).
    One(usize),
    /// Every frame, as a numbered sequence.
    All,
    /// The newest frame.
    Last,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    pub frames: FrameChoice,
    pub color: ColorField,
    /// Width and height in pixels.
    pub size: (u32, u32),
    /// A .png file (one frame) or a directory (`frame_000012.png`, … inside it).
    pub output: PathBuf,
}

/// The smallest and largest side a picture may have: below 64 pixels the labels do not fit,
/// above 16384 a frame takes more than 800 MB of memory and most viewers refuse it.
pub const MIN_SIDE: u32 = 64;
pub const MAX_SIDE: u32 = 16384;

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(
        "{dir} holds no run to render: it has no {file} (give the output directory of `isph run`)"
    )]
    NoRun { dir: PathBuf, file: &'static str },
    #[error("cannot read {path}: {source}")]
    Read { path: PathBuf, source: OutputError },
    #[error("{path} holds no frames yet: a run writes its first frame when it starts; render it once that is done")]
    NoFrames { path: PathBuf },
    #[error(
        "frame {frame} does not exist in {path}: the run has {count} frames, numbered 0 to {last}"
    )]
    NoSuchFrame {
        path: PathBuf,
        frame: usize,
        count: usize,
        last: usize,
    },
    #[error("{path} holds a {dimensions}D run; only 2D and 3D runs can be rendered")]
    Dimensions { path: PathBuf, dimensions: usize },
    #[error("an image of {width}x{height} pixels cannot be rendered: each side must be from {MIN_SIDE} to {MAX_SIDE} pixels")]
    Size { width: u32, height: u32 },
    #[error("{path} names one .png file, but {count} frames are to be rendered: give a directory for the numbered sequence")]
    SequenceIntoFile { path: PathBuf, count: usize },
    #[error("{path} is a file, not a directory: the pictures cannot be written into it")]
    NotADirectory { path: PathBuf },
    #[error("{path} exists and is not a PNG picture: it is left alone; choose another output")]
    NotPng { path: PathBuf },
    #[error("cannot write {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot reconstruct the water surface of frame {frame} of {path}: {source}")]
    Surface {
        path: PathBuf,
        frame: usize,
        source: crate::surface::SurfaceError,
    },
    #[error("cannot draw frame {frame} of {path}: {message}")]
    Draw {
        path: PathBuf,
        frame: usize,
        message: String,
    },
}

/// "1920x1080" as (1920, 1080).
pub fn parse_size(text: &str) -> Option<(u32, u32)> {
    let (w, h) = text.split_once(['x', 'X'])?;
    Some((w.trim().parse().ok()?, h.trim().parse().ok()?))
}

/// Renders the frames `opts` asks for of the run in `run_dir`, returning the PNGs written in
/// frame order.
pub fn render_run(run_dir: &Path, opts: &RenderOptions) -> Result<Vec<PathBuf>, RenderError> {
    let (width, height) = opts.size;
    let side_ok = |s: u32| (MIN_SIDE..=MAX_SIDE).contains(&s);
    if !side_ok(width) || !side_ok(height) {
        return Err(RenderError::Size { width, height });
    }
    let run = Run::open(run_dir)?;
    let frames = chosen_frames(opts.frames, run.count, &run.path)?;
    let targets = output::targets(&opts.output, &frames)?;
    // The survey reads every frame once before any is drawn; one frame is read only once.
    let mut survey = Survey::new(run.dimensions, run.spacing, opts.color);
    let mut kept = Vec::new();
    for &k in &frames {
        let frame = run.frame(k)?;
        survey.add(&frame);
        if frames.len() == 1 {
            kept.push(frame);
        }
    }
    let jobs: Vec<(usize, &PathBuf)> = frames.iter().copied().zip(&targets).collect();
    // As many frames at a time as there are threads: read here (HDF5 from one thread only),
    // then drawn, encoded and written in parallel, each picture on its own.
    for chunk in jobs.chunks(rayon::current_num_threads().max(1)) {
        let inputs = chunk
            .iter()
            .map(|&(k, target)| {
                let frame = match kept.pop() {
                    Some(frame) => frame,
                    None => run.frame(k)?,
                };
                Ok((k, frame, run.stored_surface(k, &survey)?, target))
            })
            .collect::<Result<Vec<_>, RenderError>>()?;
        inputs
            .into_par_iter()
            .map(|(k, frame, stored, target)| {
                let image = picture(&frame, k, stored, &survey, opts.size, &run.path)?;
                write_png(&image, target)
            })
            .collect::<Result<Vec<()>, RenderError>>()?;
    }
    Ok(targets)
}

/// A run's particles.h5 and surface.h5, opened for reading.
struct Run {
    path: PathBuf,
    reader: FrameReader,
    surfaces: Option<SurfaceReader>,
    count: usize,
    dimensions: usize,
    spacing: f64,
}

impl Run {
    fn open(dir: &Path) -> Result<Self, RenderError> {
        let path = dir.join(frames::FILE_NAME);
        if !path.is_file() {
            return Err(RenderError::NoRun {
                dir: dir.to_owned(),
                file: frames::FILE_NAME,
            });
        }
        let read_error = |source| RenderError::Read {
            path: path.clone(),
            source,
        };
        let reader = FrameReader::open(dir).map_err(read_error)?;
        let count = reader.times().map_err(read_error)?.len();
        let (dimensions, spacing) = reader.geometry().map_err(read_error)?;
        if !(2..=3).contains(&dimensions) {
            return Err(RenderError::Dimensions { path, dimensions });
        }
        let surfaces = SurfaceReader::open(dir).map_err(|source| RenderError::Read {
            path: dir.join(surface_files::FILE_NAME),
            source,
        })?;
        Ok(Self {
            path,
            reader,
            surfaces,
            count,
            dimensions,
            spacing,
        })
    }

    fn frame(&self, k: usize) -> Result<Frame, RenderError> {
        self.reader.read(k).map_err(|source| RenderError::Read {
            path: self.path.clone(),
            source,
        })
    }

    /// The surface of frame `k` that surface.h5 holds (written by `isph surface` or by the run),
    /// if the picture shows a surface and there is one.
    fn stored_surface(&self, k: usize, survey: &Survey) -> Result<Option<Mesh>, RenderError> {
        let Some(reader) = &self.surfaces else {
            return Ok(None);
        };
        if survey.dimensions != 3 || !view_3d::shows_surface(survey) {
            return Ok(None);
        }
        let stored = reader.read(k).map_err(|source| RenderError::Read {
            path: self.path.with_file_name(surface_files::FILE_NAME),
            source,
        })?;
        Ok(stored.filter(|m| m.dimensions == 3))
    }
}

/// The frame numbers `choice` names among `count` frames.
fn chosen_frames(
    choice: FrameChoice,
    count: usize,
    path: &Path,
) -> Result<Vec<usize>, RenderError> {
    if count == 0 {
        return Err(RenderError::NoFrames {
            path: path.to_owned(),
        });
    }
    match choice {
        FrameChoice::All => Ok((0..count).collect()),
        FrameChoice::Last => Ok(vec![count - 1]),
        FrameChoice::One(frame) if frame < count => Ok(vec![frame]),
        FrameChoice::One(frame) => Err(RenderError::NoSuchFrame {
            path: path.to_owned(),
            frame,
            count,
            last: count - 1,
        }),
    }
}

/// The picture of frame number `k`; in 3D with the `stored` surface, or else one reconstructed
/// from its particles (none when the picture shows particles).
fn picture(
    frame: &Frame,
    k: usize,
    stored: Option<Mesh>,
    survey: &Survey,
    size: (u32, u32),
    path: &Path,
) -> Result<raster::Image, RenderError> {
    let drawn = if survey.dimensions == 2 {
        plot_2d::draw(frame, survey, size)
    } else {
        let mesh = match stored {
            Some(mesh) => mesh,
            None if view_3d::shows_surface(survey) => {
                view_3d::reconstruct(frame, survey).map_err(|source| RenderError::Surface {
                    path: path.to_owned(),
                    frame: k,
                    source,
                })?
            }
            None => Mesh {
                dimensions: 3,
                ..Mesh::default()
            },
        };
        view_3d::draw(frame, &mesh, survey, size)
    };
    drawn.map_err(|message| RenderError::Draw {
        path: path.to_owned(),
        frame: k,
        message,
    })
}

fn write_png(image: &raster::Image, target: &Path) -> Result<(), RenderError> {
    let write_error = |source| RenderError::Write {
        path: target.to_owned(),
        source,
    };
    let bytes =
        png_file::encode(image).map_err(|e| write_error(std::io::Error::other(e.to_string())))?;
    crate::io::replace_file(target, &bytes).map_err(write_error)
}
