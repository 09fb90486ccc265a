//! `particles.xdmf`: an XDMF 2 temporal collection over the frames of `particles.h5`, so that
//! ParaView and pyvista (VTK's XDMF reader) open the run as a time series with no plugin.

use super::frames::{FrameInfo, FILE_NAME as H5};
use super::OutputError;
use std::fmt::Write as _;
use std::path::Path;

pub const FILE_NAME: &str = "particles.xdmf";

/// (name, attribute type, number type, precision, components) of each per-particle dataset.
const FIELDS: [(&str, &str, &str, u8, u8); 8] = [
    ("velocity", "Vector", "Float", 8, 3),
    ("pressure", "Scalar", "Float", 8, 1),
    ("density", "Scalar", "Float", 8, 1),
    ("kind", "Scalar", "Int", 4, 1),
    ("fluid", "Scalar", "Int", 4, 1),
    ("free_surface", "Scalar", "Int", 4, 1),
    ("body", "Scalar", "Int", 4, 1),
    ("id", "Scalar", "Int", 8, 1),
];

fn data_item(n: usize, components: u8, number: &str, precision: u8, path: &str) -> String {
    let dims = if components == 1 {
        n.to_string()
    } else {
        format!("{n} {components}")
    };
    format!(
        "<DataItem Dimensions=\"{dims}\" NumberType=\"{number}\" Precision=\"{precision}\" Format=\"HDF\">{H5}:{path}</DataItem>"
    )
}

/// The XDMF text indexing `frames`.
pub fn document(frames: &[FrameInfo]) -> String {
    let mut x = String::from(
        "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"2.0\">\n <Domain>\n  <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
    );
    for f in frames {
        let (n, g) = (f.count, &f.group);
        let _ = writeln!(x, "   <Grid Name=\"{g}\" GridType=\"Uniform\">");
        let _ = writeln!(x, "    <Time Value=\"{:e}\"/>", f.time);
        let _ = writeln!(x, "    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{n}\" NodesPerElement=\"1\"/>");
        let _ = writeln!(
            x,
            "    <Geometry GeometryType=\"XYZ\">{}</Geometry>",
            data_item(n, 3, "Float", 8, &format!("/{g}/position"))
        );
        for (name, kind, number, precision, components) in FIELDS {
            let item = data_item(n, components, number, precision, &format!("/{g}/{name}"));
            let _ = writeln!(x, "    <Attribute Name=\"{name}\" AttributeType=\"{kind}\" Center=\"Node\">{item}</Attribute>");
        }
        x.push_str("   </Grid>\n");
    }
    x.push_str("  </Grid>\n </Domain>\n</Xdmf>\n");
    x
}

/// Rewrites the index atomically (temporary file, then rename), so a reader never sees half of it.
pub fn write(dir: &Path, frames: &[FrameInfo]) -> Result<(), OutputError> {
    super::write_atomically(&dir.join(FILE_NAME), document(frames).as_bytes())
}
