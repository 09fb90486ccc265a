//! `particles.h5`: one group per frame (`/frame_000000`, …) holding per-particle datasets in
//! id order, with the frame's `time` and `step` as attributes; the file's own attributes give
//! the run's `dimensions` and particle `spacing` (what `isph surface` and `isph render` need to
//! read a frame without the scene). Written from one thread only.

use super::OutputError;
use crate::particles::{Kind, Particles};
use crate::surface::Points;
use std::path::{Path, PathBuf};

pub const FILE_NAME: &str = "particles.h5";

/// What the XDMF index needs to know of a written frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameInfo {
    pub group: String,
    pub time: f64,
    pub step: u64,
    pub count: usize,
}

/// The group of frame number `index` (also the name of its surface, `io::surface_files`).
pub(crate) fn group_name(index: usize) -> String {
    format!("frame_{index:06}")
}

pub(crate) fn frame_index(group: &str) -> Option<usize> {
    group.strip_prefix("frame_")?.parse().ok()
}

/// The first `count` frames of the particles.h5 of `dir`, read without changing the file.
pub fn read_index(dir: &Path, count: usize) -> Result<Vec<FrameInfo>, OutputError> {
    let path = dir.join(FILE_NAME);
    let hdf5_error = |source| OutputError::Hdf5Read {
        path: path.clone(),
        source,
    };
    let file = hdf5::File::open(&path).map_err(hdf5_error)?;
    (0..count)
        .map(|index| {
            let group = group_name(index);
            let g = file.group(&group).map_err(|_| OutputError::Mismatch {
                path: path.clone(),
                what: format!(
                    "it lacks `{group}`, one of the {count} frames the checkpoint counts"
                ),
            })?;
            let info = || -> hdf5::Result<FrameInfo> {
                Ok(FrameInfo {
                    time: g.attr("time")?.read_scalar()?,
                    step: g.attr("step")?.read_scalar()?,
                    count: g.dataset("id")?.size(),
                    group: group.clone(),
                })
            };
            info().map_err(hdf5_error)
        })
        .collect()
}

pub struct FrameWriter {
    file: hdf5::File,
    path: PathBuf,
}

impl FrameWriter {
    /// A new particles.h5 in `dir` for a run of `dimensions` at particle `spacing`.
    pub fn create(dir: &Path, dimensions: usize, spacing: f64) -> Result<Self, OutputError> {
        let path = dir.join(FILE_NAME);
        let hdf5_error = |source| OutputError::Hdf5 {
            path: path.clone(),
            source,
        };
        let file = hdf5::File::create(&path).map_err(hdf5_error)?;
        let describe = || -> hdf5::Result<()> {
            file.new_attr::<u64>()
                .create("dimensions")?
                .write_scalar(&(dimensions as u64))?;
            file.new_attr::<f64>()
                .create("spacing")?
                .write_scalar(&spacing)
        };
        describe().map_err(hdf5_error)?;
        Ok(Self { file, path })
    }

    /// Opens the particles.h5 of `dir` to append to it, changing nothing yet.
    pub fn open(dir: &Path) -> Result<Self, OutputError> {
        let path = dir.join(FILE_NAME);
        let file = hdf5::File::open_rw(&path).map_err(|source| OutputError::Hdf5 {
            path: path.clone(),
            source,
        })?;
        Ok(Self { file, path })
    }

    /// Deletes the frames from number `first` on (written after the checkpoint being resumed);
    /// earlier ones are not touched.
    pub fn remove_frames_from(&self, first: usize) -> Result<(), OutputError> {
        let hdf5_error = |source| OutputError::Hdf5 {
            path: self.path.clone(),
            source,
        };
        for name in self.file.member_names().map_err(hdf5_error)? {
            if frame_index(&name).is_some_and(|k| k >= first) {
                self.file.unlink(&name).map_err(hdf5_error)?;
            }
        }
        self.file.flush().map_err(hdf5_error)
    }

    /// Makes the frames written so far durable (before a checkpoint that counts them).
    pub fn sync(&self) -> Result<(), OutputError> {
        let err = |source| OutputError::Write {
            path: self.path.clone(),
            source,
        };
        std::fs::File::open(&self.path)
            .map_err(err)?
            .sync_all()
            .map_err(err)
    }

    /// Appends frame number `index`, the particles of `p` standing at `pos`, and flushes the
    /// file.
    pub fn write<const D: usize>(
        &mut self,
        index: usize,
        p: &Particles<D>,
        pos: &[Vec<f64>; D],
        time: f64,
        step: u64,
    ) -> Result<FrameInfo, OutputError> {
        let group = group_name(index);
        self.write_group(&group, p, pos, time, step)
            .map_err(|source| OutputError::Hdf5 {
                path: self.path.clone(),
                source,
            })?;
        Ok(FrameInfo {
            group,
            time,
            step,
            count: p.len(),
        })
    }

    fn write_group<const D: usize>(
        &self,
        name: &str,
        p: &Particles<D>,
        pos: &[Vec<f64>; D],
        time: f64,
        step: u64,
    ) -> hdf5::Result<()> {
        let n = p.len();
        let by_id = p.index_by_id();
        let g = self.file.create_group(name)?;
        let vector = |c: &[Vec<f64>; D]| -> Vec<f64> {
            by_id
                .iter()
                .flat_map(|&i| (0..3).map(move |d| if d < D { c[d][i as usize] } else { 0.0 }))
                .collect()
        };
        let scalar = |a: &[f64]| -> Vec<f64> { by_id.iter().map(|&i| a[i as usize]).collect() };
        g.new_dataset::<f64>()
            .shape((n, 3))
            .create("position")?
            .write_raw(&vector(pos))?;
        g.new_dataset::<f64>()
            .shape((n, 3))
            .create("velocity")?
            .write_raw(&vector(&p.vel))?;
        g.new_dataset::<f64>()
            .shape(n)
            .create("pressure")?
            .write_raw(&scalar(&p.pressure))?;
        g.new_dataset::<f64>()
            .shape(n)
            .create("density")?
            .write_raw(&scalar(&p.density))?;
        let ints = |f: &dyn Fn(usize) -> i32| -> Vec<i32> {
            by_id.iter().map(|&i| f(i as usize)).collect()
        };
        g.new_dataset::<i32>()
            .shape(n)
            .create("kind")?
            .write_raw(&ints(&|i| p.kind[i] as i32))?;
        let fluid = |i: usize| {
            if p.kind[i] != Kind::Fluid {
                -1
            } else {
                p.fluid[i] as i32
            }
        };
        let body = |i: usize| {
            if p.kind[i] == Kind::Body {
                p.fluid[i] as i32
            } else {
                -1
            }
        };
        g.new_dataset::<i32>()
            .shape(n)
            .create("fluid")?
            .write_raw(&ints(&fluid))?;
        g.new_dataset::<i32>()
            .shape(n)
            .create("free_surface")?
            .write_raw(&ints(&|i| p.free_surface[i] as i32))?;
        g.new_dataset::<i32>()
            .shape(n)
            .create("body")?
            .write_raw(&ints(&body))?;
        let ids: Vec<i64> = (0..n as i64).collect();
        g.new_dataset::<i64>()
            .shape(n)
            .create("id")?
            .write_raw(&ids)?;
        g.new_attr::<f64>().create("time")?.write_scalar(&time)?;
        g.new_attr::<u64>().create("step")?.write_scalar(&step)?;
        self.file.flush()
    }
}

/// One frame read back from particles.h5, rows in id order.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub time: f64,
    /// (x, y, z) of each particle; z = 0 in 2D.
    pub position: Vec<[f64; 3]>,
    pub velocity: Vec<[f64; 3]>,
    pub pressure: Vec<f64>,
    pub density: Vec<f64>,
    /// 0 fluid, 1 wall, 2 body (`particles::Kind` codes).
    pub kind: Vec<i32>,
    /// Index into the scene's fluids; -1 for walls and bodies.
    pub fluid: Vec<i32>,
    /// The PPE role of each fluid particle: 0 interior, 1 free surface, 2 spray
    /// (`ppe::Role::code`); 0 for walls.
    pub free_surface: Vec<i32>,
}

impl Frame {
    /// The frame's fluid particles (kind 0), for a surface: a run of `dimensions` at `spacing`.
    pub fn fluid_points(&self, dimensions: usize, spacing: f64) -> Points {
        let fluid: Vec<usize> = (0..self.kind.len())
            .filter(|&i| self.kind[i] == 0)
            .collect();
        Points {
            dimensions,
            spacing,
            position: fluid.iter().map(|&i| self.position[i]).collect(),
            velocity: fluid.iter().map(|&i| self.velocity[i]).collect(),
        }
    }
}

/// Reads the frames of a finished (or running) run's particles.h5.
pub struct FrameReader {
    file: hdf5::File,
    path: PathBuf,
}

impl FrameReader {
    /// Opens the particles.h5 of `dir` for reading, also while a run is appending to it.
    pub fn open(dir: &Path) -> Result<Self, OutputError> {
        let path = dir.join(FILE_NAME);
        let file = super::open_for_reading(&path)?;
        Ok(Self { file, path })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    fn error(&self, source: hdf5::Error) -> OutputError {
        OutputError::Hdf5Read {
            path: self.path.clone(),
            source,
        }
    }

    /// The run's `dimensions` and particle `spacing`, from the file's attributes.
    pub fn geometry(&self) -> Result<(usize, f64), OutputError> {
        let read = || -> hdf5::Result<(usize, f64)> {
            let dimensions: u64 = self.file.attr("dimensions")?.read_scalar()?;
            Ok((
                dimensions as usize,
                self.file.attr("spacing")?.read_scalar()?,
            ))
        };
        let (dimensions, spacing) = read().map_err(|_| OutputError::Malformed {
            path: self.path.clone(),
            what: "it lacks the `dimensions` and `spacing` attributes of the file (written by an isph older than its surface reconstruction): run the scene again".into(),
        })?;
        let sensible = (2..=3).contains(&dimensions) && spacing > 0.0 && spacing.is_finite();
        if !sensible {
            return Err(OutputError::Malformed {
                path: self.path.clone(),
                what: format!("its attributes say {dimensions} dimensions at a spacing of {spacing} m: not a run of isph"),
            });
        }
        Ok((dimensions, spacing))
    }

    /// The time of every frame, in frame order.
    pub fn times(&self) -> Result<Vec<f64>, OutputError> {
        let names = self.file.member_names().map_err(|e| self.error(e))?;
        let count = names.iter().filter(|n| frame_index(n).is_some()).count();
        (0..count)
            .map(|k| {
                let read = || self.file.group(&group_name(k))?.attr("time")?.read_scalar();
                read().map_err(|e| self.error(e))
            })
            .collect()
    }

    /// Frame number `index`.
    pub fn read(&self, index: usize) -> Result<Frame, OutputError> {
        let read = || -> hdf5::Result<Frame> {
            let g = self.file.group(&group_name(index))?;
            let triples = |name: &str| -> hdf5::Result<Vec<[f64; 3]>> {
                let flat = g.dataset(name)?.read_raw::<f64>()?;
                Ok(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
            };
            Ok(Frame {
                time: g.attr("time")?.read_scalar()?,
                position: triples("position")?,
                velocity: triples("velocity")?,
                pressure: g.dataset("pressure")?.read_raw()?,
                density: g.dataset("density")?.read_raw()?,
                kind: g.dataset("kind")?.read_raw()?,
                fluid: g.dataset("fluid")?.read_raw()?,
                free_surface: g.dataset("free_surface")?.read_raw()?,
            })
        };
        let frame = read().map_err(|e| self.error(e))?;
        let n = frame.kind.len();
        let lengths = [
            ("position", frame.position.len()),
            ("velocity", frame.velocity.len()),
            ("pressure", frame.pressure.len()),
            ("density", frame.density.len()),
            ("fluid", frame.fluid.len()),
            ("free_surface", frame.free_surface.len()),
        ];
        if let Some((name, len)) = lengths.into_iter().find(|&(_, len)| len != n) {
            return Err(OutputError::Malformed {
                path: self.path.clone(),
                what: format!(
                    "frame {index} holds {n} particles in `kind` but {len} in `{name}`: not a frame isph wrote, or one cut short"
                ),
            });
        }
        Ok(frame)
    }
}
