//! The files of a run's output directory, open for appending.

use crate::io::frames::{FrameInfo, FrameWriter};
use crate::io::stats::StatsWriter;
use std::path::PathBuf;

/// The output directory of a run, its files open for appending, and the frames already in them.
pub(crate) struct Output {
    pub dir: PathBuf,
    pub frames_out: FrameWriter,
    pub stats: StatsWriter,
    pub frames: Vec<FrameInfo>,
}
