//! `surface.h5` + `surface.xdmf`: the reconstructed surface of each frame, and the same mesh as
//! binary PLY (and OBJ on request) under `surface/`, one file per frame.
//!
//! `surface.h5` holds one group per frame, named as the frame of `particles.h5` it was built
//! from (`/frame_000012`), with `position`, `normal` and `velocity` (V×3, f32) and `cells` (C×3
//! triangles in 3D, C×2 segments in 2D, vertex numbers from 0), and the frame's `time` as an
//! attribute. The XDMF index lists the frames at the particles' times, so ParaView shows the
//! surface and the particles of a run together.

use super::frames::{frame_index, group_name};
use super::{write_atomically, OutputError};
use crate::surface::Mesh;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub const FILE_NAME: &str = "surface.h5";
pub const INDEX_NAME: &str = "surface.xdmf";
/// The folder of the per-frame PLY and OBJ files.
pub const MESH_DIR: &str = "surface";

/// What the index needs to know of a written surface.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceInfo {
    pub frame: usize,
    pub time: f64,
    pub dimensions: usize,
    pub vertices: usize,
    pub cells: usize,
}

/// The mesh files (`surface/frame_NNNNNN.ply` or `.obj`) in `dir`, in name order.
pub fn mesh_files(dir: &Path) -> Vec<PathBuf> {
    mesh_files_from(dir, 0)
}

/// The mesh files of frames from `first` on.
fn mesh_files_from(dir: &Path, first: usize) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir.join(MESH_DIR)) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let ext = p.extension().and_then(|e| e.to_str());
            let frame = p.file_stem().and_then(|s| s.to_str()).and_then(frame_index);
            matches!(ext, Some("ply" | "obj")) && frame.is_some_and(|k| k >= first)
        })
        .collect();
    files.sort();
    files
}

/// Writes surfaces into a run's (or any) directory.
pub struct SurfaceWriter {
    file: hdf5::File,
    dir: PathBuf,
    path: PathBuf,
    written: Vec<SurfaceInfo>,
}

impl SurfaceWriter {
    /// A new surface.h5 in `dir`, replacing one there.
    pub fn create(dir: &Path) -> Result<Self, OutputError> {
        let path = dir.join(FILE_NAME);
        let file = hdf5::File::create(&path).map_err(|source| OutputError::Hdf5 {
            path: path.clone(),
            source,
        })?;
        Ok(Self {
            file,
            dir: dir.to_owned(),
            path,
            written: Vec::new(),
        })
    }

    /// The surface.h5 of `dir` opened to append to, its surfaces of frames from `first` on
    /// removed with their mesh files (written after the checkpoint a run resumes from), and the
    /// index rewritten.
    pub fn reopen(dir: &Path, first: usize) -> Result<Self, OutputError> {
        let path = dir.join(FILE_NAME);
        let hdf5_error = |source| OutputError::Hdf5 {
            path: path.clone(),
            source,
        };
        let file = hdf5::File::open_rw(&path).map_err(hdf5_error)?;
        let mut written = Vec::new();
        let mut names = file.member_names().map_err(hdf5_error)?;
        names.sort();
        for name in names {
            let Some(frame) = frame_index(&name) else {
                continue;
            };
            if frame >= first {
                file.unlink(&name).map_err(hdf5_error)?;
            } else {
                written.push(info_of(&file, &name, frame).map_err(hdf5_error)?);
            }
        }
        file.flush().map_err(hdf5_error)?;
        for mesh in mesh_files_from(dir, first) {
            std::fs::remove_file(&mesh)
                .map_err(|source| OutputError::Write { path: mesh, source })?;
        }
        let writer = Self {
            file,
            dir: dir.to_owned(),
            path,
            written,
        };
        writer.write_index()?;
        Ok(writer)
    }

    /// Appends the surface of particle frame `frame` at `time`, rewrites the index, and writes
    /// its PLY file (and OBJ file if `obj`).
    pub fn write(
        &mut self,
        frame: usize,
        time: f64,
        mesh: &Mesh,
        obj: bool,
    ) -> Result<SurfaceInfo, OutputError> {
        write_group(&self.file, &group_name(frame), time, mesh).map_err(|source| {
            OutputError::Hdf5 {
                path: self.path.clone(),
                source,
            }
        })?;
        let info = SurfaceInfo {
            frame,
            time,
            dimensions: mesh.dimensions,
            vertices: mesh.vertex_count(),
            cells: mesh.cell_count(),
        };
        self.written.push(info.clone());
        self.write_index()?;
        let meshes = self.dir.join(MESH_DIR);
        std::fs::create_dir_all(&meshes).map_err(|source| OutputError::Write {
            path: meshes.clone(),
            source,
        })?;
        write_ply(
            &meshes.join(format!("{}.ply", group_name(frame))),
            mesh,
            time,
        )?;
        if obj {
            write_obj(
                &meshes.join(format!("{}.obj", group_name(frame))),
                mesh,
                time,
            )?;
        }
        Ok(info)
    }

    fn write_index(&self) -> Result<(), OutputError> {
        write_atomically(
            &self.dir.join(INDEX_NAME),
            index_document(&self.written).as_bytes(),
        )
    }
}

fn info_of(file: &hdf5::File, name: &str, frame: usize) -> hdf5::Result<SurfaceInfo> {
    let g = file.group(name)?;
    let cells = g.dataset("cells")?.shape();
    Ok(SurfaceInfo {
        frame,
        time: g.attr("time")?.read_scalar()?,
        dimensions: cells.get(1).copied().unwrap_or(3),
        vertices: g.dataset("position")?.shape()[0],
        cells: cells[0],
    })
}

fn write_group(file: &hdf5::File, name: &str, time: f64, mesh: &Mesh) -> hdf5::Result<()> {
    if file.link_exists(name) {
        file.unlink(name)?;
    }
    let g = file.create_group(name)?;
    let v = mesh.vertex_count();
    for (field, data) in [
        ("position", &mesh.positions),
        ("normal", &mesh.normals),
        ("velocity", &mesh.velocity),
    ] {
        g.new_dataset::<f32>()
            .shape((v, 3))
            .create(field)?
            .write_raw(data.as_flattened())?;
    }
    g.new_dataset::<u32>()
        .shape((mesh.cell_count(), mesh.vertices_per_cell()))
        .create("cells")?
        .write_raw(&mesh.cells)?;
    g.new_attr::<f64>().create("time")?.write_scalar(&time)?;
    file.flush()
}

/// The XDMF text indexing `surfaces` (frames without a surface are left out: a grid of no
/// cells is not one every reader takes).
pub fn index_document(surfaces: &[SurfaceInfo]) -> String {
    let mut x = String::from(
        "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"2.0\">\n <Domain>\n  <Grid Name=\"surface\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
    );
    for s in surfaces.iter().filter(|s| s.cells > 0) {
        let g = group_name(s.frame);
        let (topology, per) = if s.dimensions == 3 {
            ("Triangle", 3)
        } else {
            ("Polyline", 2)
        };
        let item = |name: &str, columns: usize, number: &str| {
            format!(
                "<DataItem Dimensions=\"{} {columns}\" NumberType=\"{number}\" Precision=\"4\" Format=\"HDF\">{FILE_NAME}:/{g}/{name}</DataItem>",
                if name == "cells" { s.cells } else { s.vertices }
            )
        };
        let _ = writeln!(x, "   <Grid Name=\"{g}\" GridType=\"Uniform\">");
        let _ = writeln!(x, "    <Time Value=\"{:e}\"/>", s.time);
        let _ = writeln!(
            x,
            "    <Topology TopologyType=\"{topology}\" NumberOfElements=\"{}\" NodesPerElement=\"{per}\">{}</Topology>",
            s.cells,
            item("cells", per, "UInt")
        );
        let _ = writeln!(
            x,
            "    <Geometry GeometryType=\"XYZ\">{}</Geometry>",
            item("position", 3, "Float")
        );
        for name in ["normal", "velocity"] {
            let _ = writeln!(
                x,
                "    <Attribute Name=\"{name}\" AttributeType=\"Vector\" Center=\"Node\">{}</Attribute>",
                item(name, 3, "Float")
            );
        }
        x.push_str("   </Grid>\n");
    }
    x.push_str("  </Grid>\n </Domain>\n</Xdmf>\n");
    x
}

/// Reads the surfaces of a run's surface.h5.
pub struct SurfaceReader {
    file: hdf5::File,
    path: PathBuf,
}

impl SurfaceReader {
    /// The surface.h5 of `dir`, or None if the run has none.
    pub fn open(dir: &Path) -> Result<Option<Self>, OutputError> {
        let path = dir.join(FILE_NAME);
        if !path.exists() {
            return Ok(None);
        }
        // A run may be writing it.
        let file = super::open_for_reading(&path)?;
        Ok(Some(Self { file, path }))
    }

    /// The surface of particle frame `frame`, if one was written.
    pub fn read(&self, frame: usize) -> Result<Option<Mesh>, OutputError> {
        let name = group_name(frame);
        if !self.file.link_exists(&name) {
            return Ok(None);
        }
        let read = || -> hdf5::Result<Mesh> {
            let g = self.file.group(&name)?;
            let triples = |field: &str| -> hdf5::Result<Vec<[f32; 3]>> {
                let flat = g.dataset(field)?.read_raw::<f32>()?;
                Ok(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
            };
            let cells = g.dataset("cells")?;
            Ok(Mesh {
                dimensions: cells.shape().get(1).copied().unwrap_or(3),
                positions: triples("position")?,
                normals: triples("normal")?,
                velocity: triples("velocity")?,
                cells: cells.read_raw()?,
            })
        };
        read().map(Some).map_err(|source| OutputError::Hdf5Read {
            path: self.path.clone(),
            source,
        })
    }
}

/// A binary little-endian PLY file: vertices with float coordinates, normals and velocity, and
/// triangles (3D, `face`) or segments (2D, `edge`).
pub fn write_ply(path: &Path, mesh: &Mesh, time: f64) -> Result<(), OutputError> {
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment isph surface at t = {time} s\nelement vertex {}\n",
        mesh.vertex_count()
    );
    for p in ["x", "y", "z", "nx", "ny", "nz", "vx", "vy", "vz"] {
        let _ = writeln!(header, "property float {p}");
    }
    if mesh.dimensions == 3 {
        let _ = writeln!(
            header,
            "element face {}\nproperty list uchar int vertex_indices",
            mesh.cell_count()
        );
    } else {
        let _ = writeln!(
            header,
            "element edge {}\nproperty int vertex1\nproperty int vertex2",
            mesh.cell_count()
        );
    }
    header.push_str("end_header\n");
    let mut bytes = header.into_bytes();
    for v in 0..mesh.vertex_count() {
        for c in mesh.positions[v]
            .iter()
            .chain(&mesh.normals[v])
            .chain(&mesh.velocity[v])
        {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for cell in mesh.cells.chunks_exact(mesh.vertices_per_cell()) {
        if mesh.dimensions == 3 {
            bytes.push(3);
        }
        for &v in cell {
            bytes.extend_from_slice(&(v as i32).to_le_bytes());
        }
    }
    write_atomically(path, &bytes)
}

/// A Wavefront OBJ file: `v`, `vn` and `f a//a b//b c//c` (3D) or `l a b` (2D), numbered from 1.
pub fn write_obj(path: &Path, mesh: &Mesh, time: f64) -> Result<(), OutputError> {
    let mut text = format!("# isph surface at t = {time} s\n");
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        let _ = writeln!(
            text,
            "v {} {} {}\nvn {} {} {}",
            p[0], p[1], p[2], n[0], n[1], n[2]
        );
    }
    for cell in mesh.cells.chunks_exact(mesh.vertices_per_cell()) {
        if mesh.dimensions == 3 {
            let [a, b, c] = [cell[0] + 1, cell[1] + 1, cell[2] + 1];
            let _ = writeln!(text, "f {a}//{a} {b}//{b} {c}//{c}");
        } else {
            let _ = writeln!(text, "l {} {}", cell[0] + 1, cell[1] + 1);
        }
    }
    write_atomically(path, text.as_bytes())
}
