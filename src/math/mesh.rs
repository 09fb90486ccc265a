//! A closed triangle mesh as a shape: inside by the generalised winding number (Jacobson et
//! al. 2013), w(p) = Σ Ω_t(p)/(4π) over the triangles t, Ω_t the solid angle t subtends at p
//! (Van Oosterom & Strackee 1983). w is 1 inside a closed, consistently wound mesh and 0
//! outside, and degrades gracefully where it is not (a small hole, a flipped face): p is inside
//! where |w| > ½. The distance to the surface is to the nearest triangle.

use super::aabb::Aabb;
use super::rotation::cross;
use super::vector::{dot, norm};

/// A triangle mesh in 3D.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
    bounds: Aabb,
}

impl TriangleMesh {
    /// The mesh of `triangles`, each three indices into `vertices` (all valid).
    pub fn new(vertices: Vec<[f64; 3]>, triangles: Vec<[usize; 3]>) -> Self {
        let mut min = vec![f64::INFINITY; 3];
        let mut max = vec![f64::NEG_INFINITY; 3];
        for v in &vertices {
            for d in 0..3 {
                min[d] = min[d].min(v[d]);
                max[d] = max[d].max(v[d]);
            }
        }
        Self {
            vertices,
            triangles,
            bounds: Aabb { min, max },
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The generalised winding number at p.
    pub fn winding_number(&self, p: &[f64]) -> f64 {
        let solid: f64 = self
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| sub(self.vertices[v], p));
                let (la, lb, lc) = (norm(a), norm(b), norm(c));
                let numerator = dot(a, cross(b, c));
                let denominator = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
                2.0 * numerator.atan2(denominator)
            })
            .sum();
        solid / (4.0 * std::f64::consts::PI)
    }

    /// Whether p is inside: |w(p)| > ½.
    pub fn contains(&self, p: &[f64]) -> bool {
        // Outside the bounds first: the winding number visits every triangle.
        self.bounds.contains(p) && self.winding_number(p).abs() > 0.5
    }

    /// Distance from p to the nearest point of the mesh's surface.
    pub fn distance(&self, p: &[f64]) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.vertices[v]);
                norm(sub(closest_on_triangle([p[0], p[1], p[2]], a, b, c), p))
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The signed distance: negative inside.
    pub fn signed_distance(&self, p: &[f64]) -> f64 {
        let d = self.distance(p);
        if self.contains(p) {
            -d
        } else {
            d
        }
    }

    /// The enclosed volume Σ a·(b × c)/6 (positive for outward-wound faces).
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.vertices[v]);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    /// The smallest axis-aligned box around the vertices.
    pub fn bounds(&self) -> &Aabb {
        &self.bounds
    }

    /// The edges not shared by exactly two triangles: none for a closed mesh.
    pub fn open_edges(&self) -> usize {
        let mut edges = std::collections::BTreeMap::new();
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
            }
        }
        edges.values().filter(|&&n| n != 2).count()
    }

    /// The same mesh moved by `offset`.
    pub fn moved(self, offset: &[f64]) -> Self {
        let vertices = self
            .vertices
            .iter()
            .map(|v| std::array::from_fn(|d| v[d] + offset[d]))
            .collect();
        Self::new(vertices, self.triangles)
    }
}

/// The point of triangle abc nearest to p (Ericson, Real-Time Collision Detection, 5.1.5).
fn closest_on_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let (ab, ac, ap) = (sub(b, &a), sub(c, &a), sub(p, &a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, &b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return along(a, ab, d1 / (d1 - d3));
    }
    let cp = sub(p, &c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return along(a, ac, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return along(b, sub(c, &b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denominator = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denominator, vc * denominator);
    std::array::from_fn(|d| a[d] + ab[d] * v + ac[d] * w)
}

fn along(a: [f64; 3], edge: [f64; 3], t: f64) -> [f64; 3] {
    std::array::from_fn(|d| a[d] + t * edge[d])
}

fn sub(a: [f64; 3], b: &[f64]) -> [f64; 3] {
    std::array::from_fn(|d| a[d] - b[d])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube [0, 1]³, faces wound outwards.
    fn cube() -> TriangleMesh {
        let vertices = (0..8)
            .map(|k| [(k & 1) as f64, ((k >> 1) & 1) as f64, ((k >> 2) & 1) as f64])
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        TriangleMesh::new(vertices, triangles)
    }

    #[test]
    fn the_winding_number_of_a_cube_is_one_inside_and_zero_outside() {
        let c = cube();
        assert!((c.winding_number(&[0.3, 0.6, 0.2]) - 1.0).abs() < 1e-12);
        assert!(c.winding_number(&[1.3, 0.6, 0.2]).abs() < 1e-12);
        assert!((c.volume() - 1.0).abs() < 1e-15);
        assert_eq!(c.open_edges(), 0);
    }

    #[test]
    fn the_distance_to_a_cube_is_to_its_nearest_face_edge_or_corner() {
        let c = cube();
        assert!((c.signed_distance(&[0.5, 0.5, 0.9]) + 0.1).abs() < 1e-12);
        assert!((c.signed_distance(&[0.5, 1.5, 0.5]) - 0.5).abs() < 1e-12);
        assert!((c.signed_distance(&[2.0, 2.0, 2.0]) - 3f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn a_cube_with_a_face_missing_is_open_and_still_mostly_inside() {
        let full = cube();
        let c = TriangleMesh::new(full.vertices, full.triangles[..10].to_vec());
        assert_eq!(c.open_edges(), 4);
        // The centre sees the missing face under 1/6 of the sphere: w = 5/6, still inside.
        assert!((c.winding_number(&[0.5, 0.5, 0.5]) - 5.0 / 6.0).abs() < 1e-12);
    }
}
