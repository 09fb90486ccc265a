//! `bodies.csv`: one row per body at every frame, `time,body,name,x,y,z,qw,qx,qy,qz,vx,vy,vz,
//! wx,wy,wz,fx,fy,fz,tx,ty,tz`: the centre of mass, the orientation quaternion, the velocity of
//! the centre, the angular velocity, and the fluid's force and torque on the body over the last
//! step (pressure and viscosity; not gravity, the body's external force nor the contacts'
//! impulses). In 2D z, qx, qy, wx, wy, fz, tx and ty are zero.

use super::csv::{end_of_row, CsvWriter, CutAt};
use super::OutputError;
use crate::bodies::Bodies;
use std::path::Path;

pub const FILE_NAME: &str = "bodies.csv";

pub const HEADER: &str = "time,body,name,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,fx,fy,fz,tx,ty,tz";

pub struct BodiesWriter(CsvWriter);

impl BodiesWriter {
    pub fn create(dir: &Path) -> Result<Self, OutputError> {
        CsvWriter::create(dir.join(FILE_NAME), HEADER).map(Self)
    }

    /// Continues the bodies.csv of `dir` after its first `length` bytes (`end_of_frames`).
    pub fn append_at(dir: &Path, length: u64) -> Result<Self, OutputError> {
        CsvWriter::append_at(dir.join(FILE_NAME), length).map(Self)
    }

    /// The rows of a frame at `time`: one per body (numbers printed so that they read back to
    /// the same bits).
    pub fn rows(&mut self, time: f64, bodies: &Bodies) -> Result<(), OutputError> {
        for (b, body) in bodies.bodies.iter().enumerate() {
            let s = &body.state;
            let w = body.angular_velocity();
            let mut line = format!("{time:e},{b},{}", body.name);
            for v in s
                .centre
                .iter()
                .chain(&s.orientation.0)
                .chain(&s.velocity)
                .chain(&w)
                .chain(&s.force)
                .chain(&s.torque)
            {
                line += &format!(",{v:e}");
            }
            self.0.line(format_args!("{line}"))?;
        }
        Ok(())
    }

    pub fn flush(&mut self) -> Result<(), OutputError> {
        self.0.flush()
    }

    /// Flushes and fsyncs (before a checkpoint that counts on the rows).
    pub fn sync(&mut self) -> Result<(), OutputError> {
        self.0.sync()
    }
}

/// Length in bytes of the bodies.csv of `dir` up to the rows of its first `frames` frames of
/// `bodies` bodies each. Refuses a file with another header or fewer rows.
pub fn end_of_frames(dir: &Path, frames: usize, bodies: usize) -> Result<u64, OutputError> {
    let what = format!("the checkpoint's {frames} frames of {bodies} bodies");
    let at = CutAt::Rows {
        count: frames * bodies,
        what: &what,
    };
    end_of_row(&dir.join(FILE_NAME), HEADER, at)
}

/// The column of fx among a row's numbers x … tz (`read`).
pub const FX: usize = 13;

/// The bodies.csv of `dir`: its rows as (time, body, numbers x … tz).
pub fn read(dir: &Path) -> Result<Vec<(f64, usize, Vec<f64>)>, OutputError> {
    let path = dir.join(FILE_NAME);
    let text = std::fs::read_to_string(&path).map_err(|source| OutputError::Read {
        path: path.clone(),
        source,
    })?;
    text.lines()
        .skip(1)
        .enumerate()
        .map(|(k, line)| {
            let fields: Vec<&str> = line.split(',').collect();
            let numbers: Option<Vec<f64>> = fields
                .iter()
                .enumerate()
                .filter(|(c, _)| *c != 1 && *c != 2)
                .map(|(_, v)| v.parse().ok())
                .collect();
            match (numbers, fields.get(1).and_then(|b| b.parse().ok())) {
                (Some(n), Some(b)) if n.len() == 20 => Ok((n[0], b, n[1..].to_vec())),
                _ => Err(OutputError::Malformed {
                    path: path.clone(),
                    what: format!("row {} is not a row of {HEADER}", k + 1),
                }),
            }
        })
        .collect()
}
