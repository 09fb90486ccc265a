//! The files of a run's output directory, open for appending.

use crate::io::bodies_csv::BodiesWriter;
use crate::io::frames::{FrameInfo, FrameWriter};
use crate::io::probes::ProbesWriter;
use crate::io::stats::StatsWriter;
use crate::io::surface_files::SurfaceWriter;
use crate::particles::Particles;
use crate::scene::SurfaceSettings;
use crate::surface::Points;
use std::path::PathBuf;

/// The output directory of a run, its files open for appending, and the frames already in them.
pub(crate) struct Output {
    pub dir: PathBuf,
    pub frames_out: FrameWriter,
    pub stats: StatsWriter,
    pub frames: Vec<FrameInfo>,
    /// `[output.surface]`: surface.h5 and the meshes, with their settings.
    pub surfaces: Option<(SurfaceWriter, SurfaceSettings)>,
    /// `[[probe]]`: probes.csv (None: the scene has no probe).
    pub probes: Option<ProbesWriter>,
    /// `[[body]]`: bodies.csv (None: the scene has no body).
    pub bodies: Option<BodiesWriter>,
}

/// The fluid particles of `p` standing at `pos`, in id order, as a frame lists them: the
/// surface built during a run is the one `isph surface` builds from its frame.
pub(crate) fn fluid_points<const D: usize>(
    p: &Particles<D>,
    pos: &[Vec<f64>; D],
    spacing: f64,
) -> Points {
    let fluid: Vec<usize> = p
        .index_by_id()
        .into_iter()
        .map(|i| i as usize)
        .filter(|&i| p.is_fluid(i))
        .collect();
    let triple = |c: &[Vec<f64>; D], i: usize| -> [f64; 3] {
        std::array::from_fn(|d| if d < D { c[d][i] } else { 0.0 })
    };
    Points {
        dimensions: D,
        spacing,
        position: fluid.iter().map(|&i| triple(pos, i)).collect(),
        velocity: fluid.iter().map(|&i| triple(&p.vel, i)).collect(),
    }
}
