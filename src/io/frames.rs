//! `particles.h5`: one group per frame (`/frame_000000`, …) holding per-particle datasets in
//! id order, with the frame's `time` and `step` as attributes. Written from one thread only.

use super::OutputError;
use crate::particles::{Particles, NO_FLUID};
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

pub struct FrameWriter {
    file: hdf5::File,
    path: PathBuf,
}

impl FrameWriter {
    pub fn create(dir: &Path) -> Result<Self, OutputError> {
        let path = dir.join(FILE_NAME);
        let file = hdf5::File::create(&path).map_err(|source| OutputError::Hdf5 {
            path: path.clone(),
            source,
        })?;
        Ok(Self { file, path })
    }

    /// Appends frame number `index` and flushes the file.
    pub fn write<const D: usize>(
        &mut self,
        index: usize,
        p: &Particles<D>,
        time: f64,
        step: u64,
    ) -> Result<FrameInfo, OutputError> {
        let group = format!("frame_{index:06}");
        self.write_group(&group, p, time, step)
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
            .write_raw(&vector(&p.pos))?;
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
            if p.fluid[i] == NO_FLUID {
                -1
            } else {
                p.fluid[i] as i32
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
            .write_raw(&ints(&|_| -1))?;
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
