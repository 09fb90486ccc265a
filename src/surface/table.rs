//! The case tables of marching squares (16 cases) and marching cubes (256 cases), built from
//! one rule rather than typed in: on every square face, the iso-line runs from where the
//! boundary leaves the inside (c > iso) to where it last entered it, so each run of inside
//! corners is cut off by one segment. On a face with two diagonal inside corners (the ambiguous
//! case) that separates them. Two cubes sharing a face see the same four corners and so cut it
//! by the same segments, traversed in opposite directions: the surfaces of neighbouring cubes
//! meet edge to edge and the mesh has no cracks, the defect of tables built from the 15
//! patterns by complement symmetry.
//!
//! A cube's segments on its six faces chain into loops around its inside corners; each loop
//! is cut into triangles by diagonals through the cube (never along a face), wound so that
//! their normal points out of the fluid.
//!
//! Corners are numbered by their offset bits (corner k sits at (k & 1, k >> 1 & 1, k >> 2 & 1));
//! an edge is its axis and the corner it starts from, numbered axis by axis.

/// The cells of each case: `cases[k]` for the corners set in `k` inside, each cell `D` edge
/// numbers (a segment in 2D, a triangle in 3D).
pub struct Table<const D: usize> {
    pub cases: Vec<Vec<[u8; D]>>,
    /// Each edge's start corner and axis.
    pub edges: Vec<(usize, usize)>,
}

/// The edges of the unit square (D = 2) or cube (D = 3): (start corner, axis), axis by axis.
fn edges(dimensions: usize) -> Vec<(usize, usize)> {
    (0..dimensions)
        .flat_map(|axis| {
            (0..1usize << dimensions)
                .filter(move |c| c & (1 << axis) == 0)
                .map(move |c| (c, axis))
        })
        .collect()
}

/// The number of the edge joining corners `p` and `q` (which differ in one bit).
fn edge_between(edges: &[(usize, usize)], p: usize, q: usize) -> u8 {
    let axis = (p ^ q).trailing_zeros() as usize;
    let start = p.min(q);
    edges
        .iter()
        .position(|&e| e == (start, axis))
        .expect("p and q are neighbours") as u8
}

/// The iso-segments of a face whose corners `ring` are listed counter-clockwise as seen from
/// outside: (from edge, to edge) with the inside on the left.
fn face_segments(ring: [usize; 4], inside: usize, edges: &[(usize, usize)]) -> Vec<(u8, u8)> {
    let is_in = |k: usize| inside & (1 << ring[k % 4]) != 0;
    let edge = |k: usize| edge_between(edges, ring[k % 4], ring[(k + 1) % 4]);
    let mut segments = Vec::new();
    for k in 0..4 {
        // A run of inside corners ends at corner k: the boundary leaves through edge k.
        if is_in(k) && !is_in(k + 1) {
            let mut first = k;
            while is_in(first + 3) {
                first = (first + 3) % 4;
            }
            // It entered through the edge before the run's first corner.
            segments.push((edge(k), edge(first + 3)));
        }
    }
    segments
}

impl Table<2> {
    /// Marching squares: the square's corners counter-clockwise seen from +z, so every segment
    /// has the fluid on its left.
    pub fn squares() -> Self {
        let edges = edges(2);
        let cases = (0..16)
            .map(|inside| {
                face_segments([0, 1, 3, 2], inside, &edges)
                    .into_iter()
                    .map(|(a, b)| [a, b])
                    .collect()
            })
            .collect();
        Self { cases, edges }
    }
}

impl Table<3> {
    /// Marching cubes.
    pub fn cubes() -> Self {
        let edges = edges(3);
        let cases = (0..256)
            .map(|inside| cube_triangles(inside, &edges))
            .collect();
        Self { cases, edges }
    }
}

/// Whether two edges of the cube lie on one face: a segment between their crossings would lie
/// in that face, where the neighbouring cube has its own cut.
fn on_one_face(edges: &[(usize, usize)], a: u8, b: u8) -> bool {
    let ((ca, axa), (cb, axb)) = (edges[a as usize], edges[b as usize]);
    (0..3).any(|axis| axis != axa && axis != axb && (ca >> axis & 1) == (cb >> axis & 1))
}

/// Triangles covering the polygon `lp` (in its winding) whose every diagonal crosses the cube's
/// inside: a fan from one corner could lay a triangle flat in a face that the loop visits
/// twice (an ambiguous face), on top of the neighbouring cube's surface. The first such
/// diagonal in index order is cut, recursively.
fn triangulate(lp: &[u8], edges: &[(usize, usize)]) -> Option<Vec<[u8; 3]>> {
    let n = lp.len();
    if n == 3 {
        return Some(vec![[lp[0], lp[1], lp[2]]]);
    }
    for i in 0..n {
        for j in i + 2..n {
            if (i == 0 && j == n - 1) || on_one_face(edges, lp[i], lp[j]) {
                continue;
            }
            let first: Vec<u8> = lp[i..=j].to_vec();
            let second: Vec<u8> = lp[j..].iter().chain(&lp[..=i]).copied().collect();
            if let (Some(mut a), Some(b)) =
                (triangulate(&first, edges), triangulate(&second, edges))
            {
                a.extend(b);
                return Some(a);
            }
        }
    }
    None
}

/// The six faces of the cube, corners counter-clockwise seen from outside.
fn cube_faces() -> Vec<[usize; 4]> {
    let mut faces = Vec::new();
    for axis in 0..3 {
        let (u, v) = (1 << ((axis + 1) % 3), 1 << ((axis + 2) % 3));
        for side in [0, 1 << axis] {
            // (u, v, axis) is right-handed: u → u+v → v turns counter-clockwise seen from +axis.
            let ring = [side, side | u, side | u | v, side | v];
            faces.push(if side == 0 {
                [ring[0], ring[3], ring[2], ring[1]]
            } else {
                ring
            });
        }
    }
    faces
}

fn cube_triangles(inside: usize, edges: &[(usize, usize)]) -> Vec<[u8; 3]> {
    // Every crossed edge starts exactly one segment (on one of its two faces it is left, on
    // the other entered), so following the segments gives closed loops.
    let mut next = [u8::MAX; 12];
    for face in cube_faces() {
        for (from, to) in face_segments(face, inside, edges) {
            next[from as usize] = to;
        }
    }
    let mut triangles = Vec::new();
    let mut seen = [false; 12];
    for start in 0..12 {
        if next[start] == u8::MAX || seen[start] {
            continue;
        }
        let mut lp = vec![start as u8];
        seen[start] = true;
        let mut e = next[start];
        while e as usize != start {
            seen[e as usize] = true;
            lp.push(e);
            e = next[e as usize];
        }
        // The loop runs counter-clockwise around the inside seen from outside the cube, i.e.
        // from the fluid's side: its triangles are wound the other way, so normals leave the
        // fluid.
        let lp: Vec<u8> = lp.into_iter().rev().collect();
        triangles
            .extend(triangulate(&lp, edges).expect("every loop of a cube has a triangulation"));
    }
    triangles
}
