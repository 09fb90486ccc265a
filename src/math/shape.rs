//! The shapes of rigid bodies, as signed distance functions: negative inside, zero on the
//! surface, the distance to it outside. The inside test fills a body's particles; the distance
//! outside keeps fluid half a spacing off it at the start.

use super::aabb::Aabb;
use super::mesh::TriangleMesh;

/// A body's shape where it starts, in world coordinates.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// An axis-aligned box [min, max].
    Box { min: Vec<f64>, max: Vec<f64> },
    /// A circle (2D) or a sphere (3D).
    Ball { center: Vec<f64>, radius: f64 },
    /// A 3D cylinder along coordinate axis `axis` (0 x, 1 y, 2 z), `length` long, centred on
    /// `center`.
    Cylinder {
        center: Vec<f64>,
        radius: f64,
        axis: usize,
        length: f64,
    },
    /// A closed triangle mesh (3D), inside by its winding number (`mesh`).
    Mesh(TriangleMesh),
    /// The union of its parts (none a union): inside where any part is.
    Union(Vec<Shape>),
}

impl Shape {
    /// The shape's name in a scene (`shape = "…"`), in `dims` dimensions.
    pub fn name(&self, dims: usize) -> &'static str {
        match self {
            Shape::Box { .. } => "box",
            Shape::Ball { .. } if dims == 2 => "circle",
            Shape::Ball { .. } => "sphere",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Mesh(_) => "mesh",
            Shape::Union(_) => "union",
        }
    }

    /// Signed distance from x to the surface: negative inside. A union's is the least of its
    /// parts': exact outside it, where the fluid's and the bodies' contacts ask; inside, where
    /// parts overlap, it may overstate how near the surface is, never the sign.
    pub fn signed_distance(&self, x: &[f64]) -> f64 {
        match self {
            Shape::Box { min, max } => {
                let mut q = [0.0; 3];
                for d in 0..x.len() {
                    q[d] = (x[d] - 0.5 * (min[d] + max[d])).abs() - 0.5 * (max[d] - min[d]);
                }
                slab_distance(&q[..x.len()])
            }
            Shape::Ball { center, radius } => distance(x, center) - radius,
            Shape::Cylinder {
                center,
                radius,
                axis,
                length,
            } => {
                let radial = (0..x.len())
                    .filter(|d| d != axis)
                    .map(|d| (x[d] - center[d]).powi(2))
                    .sum::<f64>()
                    .sqrt()
                    - radius;
                let along = (x[*axis] - center[*axis]).abs() - 0.5 * length;
                slab_distance(&[radial, along])
            }
            Shape::Mesh(mesh) => mesh.signed_distance(x),
            Shape::Union(parts) => parts
                .iter()
                .map(|part| part.signed_distance(x))
                .fold(f64::INFINITY, f64::min),
        }
    }

    /// Whether x lies inside.
    pub fn contains(&self, x: &[f64]) -> bool {
        match self {
            // The winding number alone: no distance to find.
            Shape::Mesh(mesh) => mesh.contains(x),
            Shape::Union(parts) => parts.iter().any(|part| part.contains(x)),
            _ => self.signed_distance(x) < 0.0,
        }
    }

    /// The smallest axis-aligned box around the shape.
    pub fn bounds(&self) -> Aabb {
        match self {
            Shape::Box { min, max } => Aabb {
                min: min.clone(),
                max: max.clone(),
            },
            Shape::Ball { center, radius } => Aabb {
                min: center.iter().map(|c| c - radius).collect(),
                max: center.iter().map(|c| c + radius).collect(),
            },
            Shape::Cylinder {
                center,
                radius,
                axis,
                length,
            } => {
                let half = |d: usize| if d == *axis { 0.5 * length } else { *radius };
                Aabb {
                    min: (0..center.len()).map(|d| center[d] - half(d)).collect(),
                    max: (0..center.len()).map(|d| center[d] + half(d)).collect(),
                }
            }
            Shape::Mesh(mesh) => mesh.bounds().clone(),
            // A union has at least two parts (`validate`).
            Shape::Union(parts) => parts
                .iter()
                .map(Shape::bounds)
                .reduce(|a, b| a.union(&b))
                .expect("a union has parts"),
        }
    }
}

/// The signed distance to the intersection of slabs, from the signed distances `q` to each
/// (negative inside): the Euclidean distance over the slabs outside, the nearest face inside.
/// A box is the slabs of its axes; a cylinder its radial and axial slabs.
fn slab_distance(q: &[f64]) -> f64 {
    let outside = q.iter().map(|q| q.max(0.0).powi(2)).sum::<f64>().sqrt();
    let inside = q.iter().copied().fold(f64::NEG_INFINITY, f64::max).min(0.0);
    outside + inside
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        .sqrt()
}
