//! Boxes: the box around the particles that fixes the 2D axes and the 3D camera, and the
//! container's inner box, read back from its wall particles.

/// An axis-aligned box; empty (min > max) until a point is added.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Default for Bounds {
    fn default() -> Self {
        Self {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        }
    }
}

impl Bounds {
    pub fn of<'a>(points: impl IntoIterator<Item = &'a [f64; 3]>) -> Self {
        let mut b = Self::default();
        points.into_iter().for_each(|p| b.include(p));
        b
    }

    pub fn include(&mut self, p: &[f64; 3]) {
        for d in 0..3 {
            // A NaN position (a failed run's last frame) is left out rather than spoiling the box.
            if p[d].is_finite() {
                self.min[d] = self.min[d].min(p[d]);
                self.max[d] = self.max[d].max(p[d]);
            }
        }
    }

    pub fn merge(&mut self, other: &Bounds) {
        self.include(&other.min);
        self.include(&other.max);
    }

    pub fn is_empty(&self) -> bool {
        (0..3).any(|d| self.min[d] > self.max[d])
    }

    pub fn grown(&self, by: f64) -> Self {
        Self {
            min: self.min.map(|x| x - by),
            max: self.max.map(|x| x + by),
        }
    }

    pub fn centre(&self) -> [f64; 3] {
        std::array::from_fn(|d| 0.5 * (self.min[d] + self.max[d]))
    }

    pub fn extent(&self) -> [f64; 3] {
        std::array::from_fn(|d| self.max[d] - self.min[d])
    }

    /// The eight corners, corner k taking max on axis d when bit d of k is set.
    pub fn corners(&self) -> [[f64; 3]; 8] {
        std::array::from_fn(|k| {
            std::array::from_fn(|d| {
                if k >> d & 1 == 1 {
                    self.max[d]
                } else {
                    self.min[d]
                }
            })
        })
    }
}

/// The inside of the container whose wall particles are `walls`, on a lattice of `spacing`:
/// on each side, the wall layers are the lattice planes, from the outside in, that walls fill
/// completely (a floor's plane is full, the plane above it has the water's hole), and the inner
/// face lies half a spacing past the last of them. A side without a full plane (an open top, a
/// periodic axis) keeps the walls' own extent.
pub fn container(walls: &[[f64; 3]], spacing: f64, dimensions: usize) -> Option<Bounds> {
    let outer = Bounds::of(walls);
    if outer.is_empty() {
        return None;
    }
    let planes: Vec<usize> = (0..dimensions)
        .map(|d| ((outer.max[d] - outer.min[d]) / spacing).round() as usize + 1)
        .collect();
    let mut inner = outer;
    for d in 0..dimensions {
        let full: usize = (0..dimensions)
            .filter(|&e| e != d)
            .map(|e| planes[e])
            .product();
        let mut count = vec![0usize; planes[d]];
        for p in walls {
            let k = ((p[d] - outer.min[d]) / spacing).round() as usize;
            count[k.min(planes[d] - 1)] += 1;
        }
        let low = count.iter().take_while(|&&c| c >= full).count();
        let high = count.iter().rev().take_while(|&&c| c >= full).count();
        if low + high >= planes[d] {
            continue;
        }
        if low > 0 {
            inner.min[d] = outer.min[d] + (low as f64 - 0.5) * spacing;
        }
        if high > 0 {
            inner.max[d] = outer.max[d] - (high as f64 - 0.5) * spacing;
        }
    }
    Some(inner)
}
