//! Axis-aligned boxes: the container, fluid blocks and obstacles of a scene.

/// An axis-aligned box [min, max].
#[derive(Debug, Clone, PartialEq)]
pub struct Aabb {
    pub min: Vec<f64>,
    pub max: Vec<f64>,
}

impl Aabb {
    /// True when x lies strictly inside the box.
    pub fn contains(&self, x: &[f64]) -> bool {
        self.contains_within(x, 0.0)
    }

    /// True when x lies strictly inside the box grown by `margin` on every side.
    pub fn contains_within(&self, x: &[f64], margin: f64) -> bool {
        x.iter()
            .zip(&self.min)
            .zip(&self.max)
            .all(|((x, lo), hi)| *x > lo - margin && *x < hi + margin)
    }

    /// Lattice points of `spacing` the box holds, at most, with `layers(d)` more on each side
    /// along axis d: counted, not made.
    pub fn lattice_points_bound(&self, spacing: f64, layers: impl Fn(usize) -> f64) -> f64 {
        (0..self.min.len())
            .map(|d| ((self.max[d] - self.min[d]) / spacing).ceil() + 1.0 + 2.0 * layers(d))
            .product()
    }

    /// True when the box lies inside `outer` (faces may touch).
    pub fn within(&self, outer: &Aabb) -> bool {
        (0..self.min.len()).all(|d| self.min[d] >= outer.min[d] && self.max[d] <= outer.max[d])
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self
                .min
                .iter()
                .zip(&other.min)
                .map(|(a, b)| a.min(*b))
                .collect(),
            max: self
                .max
                .iter()
                .zip(&other.max)
                .map(|(a, b)| a.max(*b))
                .collect(),
        }
    }
}
