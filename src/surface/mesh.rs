//! A reconstructed water surface: triangles in 3D, line segments in 2D, with a normal and a
//! velocity at each vertex. Vertices are shared by every cell that touches them, so the mesh
//! is connected; where the fluid is closed, the mesh is closed and its cells wind outward.

/// A surface mesh. Coordinates are single precision, as mesh files and viewers take them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// 2 (segments) or 3 (triangles).
    pub dimensions: usize,
    /// (x, y, z) of each vertex; z = 0 in 2D.
    pub positions: Vec<[f32; 3]>,
    /// Outward unit normal at each vertex (away from the fluid).
    pub normals: Vec<[f32; 3]>,
    /// The fluid's velocity at each vertex (kernel-weighted mean of the particles').
    pub velocity: Vec<[f32; 3]>,
    /// Vertex indices, `dimensions` per cell: triangles wound counter-clockwise seen from
    /// outside in 3D; segments with the fluid on their left in 2D.
    pub cells: Vec<u32>,
}

impl Mesh {
    /// Vertices per cell: 3 (triangle) in 3D, 2 (segment) in 2D.
    pub fn vertices_per_cell(&self) -> usize {
        self.dimensions
    }

    pub fn cell_count(&self) -> usize {
        self.cells.len() / self.dimensions.max(1)
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    fn cell(&self, c: usize) -> impl Iterator<Item = [f64; 3]> + '_ {
        let n = self.dimensions;
        self.cells[c * n..(c + 1) * n]
            .iter()
            .map(|&v| self.positions[v as usize].map(f64::from))
    }

    /// The volume the mesh encloses in 3D (the divergence theorem over the triangles), the
    /// area in 2D (the shoelace sum over the segments); positive for an outward mesh.
    pub fn enclosed_measure(&self) -> f64 {
        (0..self.cell_count())
            .map(|c| {
                let v: Vec<[f64; 3]> = self.cell(c).collect();
                if self.dimensions == 3 {
                    dot(v[0], cross(v[1], v[2])) / 6.0
                } else {
                    // Fluid on the left of each segment: a counter-clockwise boundary.
                    (v[0][0] * v[1][1] - v[1][0] * v[0][1]) / 2.0
                }
            })
            .sum::<f64>()
            + 0.0 // an empty sum is −0
    }

    /// The area of the surface in 3D, the length of the iso-line in 2D.
    pub fn boundary_measure(&self) -> f64 {
        (0..self.cell_count())
            .map(|c| {
                let v: Vec<[f64; 3]> = self.cell(c).collect();
                if self.dimensions == 3 {
                    norm(cross(sub(v[1], v[0]), sub(v[2], v[0]))) / 2.0
                } else {
                    norm(sub(v[1], v[0]))
                }
            })
            .sum()
    }
}

pub(crate) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
