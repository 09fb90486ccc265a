//! Triangle meshes from OBJ and STL files (ASCII or binary STL), for `shape = "mesh"`.

use crate::math::mesh::TriangleMesh;
use std::path::Path;

/// The mesh of the OBJ or STL file at `path` (by its extension). On error: what is wrong, with
/// the line where there is one.
pub fn read(path: &Path) -> Result<TriangleMesh, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read it: {e}"))?;
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    let mesh = match extension.as_str() {
        "obj" => obj(&String::from_utf8_lossy(&bytes))?,
        "stl" if bytes.starts_with(b"solid") && std::str::from_utf8(&bytes).is_ok() => {
            ascii_stl(&String::from_utf8_lossy(&bytes))?
        }
        "stl" => binary_stl(&bytes)?,
        _ => return Err("is neither .obj nor .stl".into()),
    };
    if mesh.triangle_count() == 0 {
        return Err("holds no triangle".into());
    }
    Ok(mesh)
}

/// OBJ: `v x y z` vertices and `f` faces (1-based or negative indices, `i/t/n` forms), each
/// polygon fanned into triangles; other lines ignored.
fn obj(text: &str) -> Result<TriangleMesh, String> {
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    for (k, line) in text.lines().enumerate() {
        let bad = |what: &str| format!("line {}: {what}", k + 1);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let xyz: Result<Vec<f64>, _> = words.take(3).map(str::parse).collect();
                match xyz {
                    Ok(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => {
                        vertices.push([v[0], v[1], v[2]])
                    }
                    _ => return Err(bad("a vertex needs three finite numbers")),
                }
            }
            Some("f") => {
                let corners: Result<Vec<usize>, String> = words
                    .map(|w| {
                        let index: i64 = w
                            .split('/')
                            .next()
                            .and_then(|i| i.parse().ok())
                            .ok_or_else(|| bad(&format!("`{w}` is not a vertex index")))?;
                        let n = vertices.len() as i64;
                        let i = if index < 0 { n + index } else { index - 1 };
                        if (0..n).contains(&i) {
                            Ok(i as usize)
                        } else {
                            Err(bad(&format!("vertex {index} is not defined before it")))
                        }
                    })
                    .collect();
                let corners = corners?;
                if corners.len() < 3 {
                    return Err(bad("a face needs at least three vertices"));
                }
                for k in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[k], corners[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok(TriangleMesh::new(vertices, triangles))
}

/// ASCII STL: `vertex x y z` lines, three per facet.
fn ascii_stl(text: &str) -> Result<TriangleMesh, String> {
    let mut vertices = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() == Some("vertex") {
            let xyz: Result<Vec<f64>, _> = words.take(3).map(str::parse).collect();
            match xyz {
                Ok(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => {
                    vertices.push([v[0], v[1], v[2]])
                }
                _ => {
                    return Err(format!(
                        "line {}: a vertex needs three finite numbers",
                        k + 1
                    ))
                }
            }
        }
    }
    if vertices.len() % 3 != 0 {
        return Err("its vertices are not a whole number of facets of three".into());
    }
    Ok(welded(vertices))
}

/// Binary STL: an 80-byte header, a u32 count, then per facet a normal and three vertices as
/// f32 and a u16.
fn binary_stl(bytes: &[u8]) -> Result<TriangleMesh, String> {
    let count = bytes
        .get(80..84)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
        .ok_or("is too short for a binary STL header")?;
    if bytes.len() < 84 + 50 * count {
        return Err(format!(
            "says it holds {count} facets but is {} bytes long, not {}",
            bytes.len(),
            84 + 50 * count
        ));
    }
    let f = |at: usize| {
        f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as f64
    };
    let vertices: Vec<[f64; 3]> = (0..count)
        .flat_map(|t| (0..3).map(move |v| 84 + 50 * t + 12 + 12 * v))
        .map(|at| [f(at), f(at + 4), f(at + 8)])
        .collect();
    if let Some(k) = vertices
        .iter()
        .position(|v| !v.iter().all(|x| x.is_finite()))
    {
        return Err(format!(
            "facet {}: a vertex needs three finite numbers, not {:?}",
            k / 3 + 1,
            vertices[k]
        ));
    }
    Ok(welded(vertices))
}

/// Triangles of consecutive vertex triples, equal vertices merged (an STL repeats each
/// vertex in every facet that shares it, and the closedness test needs shared vertices).
fn welded(corners: Vec<[f64; 3]>) -> TriangleMesh {
    let mut index = std::collections::HashMap::new();
    let mut vertices = Vec::new();
    let ids: Vec<usize> = corners
        .iter()
        .map(|v| {
            *index.entry(v.map(f64::to_bits)).or_insert_with(|| {
                vertices.push(*v);
                vertices.len() - 1
            })
        })
        .collect();
    let triangles = ids.chunks(3).map(|t| [t[0], t[1], t[2]]).collect();
    TriangleMesh::new(vertices, triangles)
}
