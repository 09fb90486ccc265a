//! The 3D camera: a fixed oblique direction (azimuth −60°, elevation 25°, z up, the way
//! gravity points in every 3D scene of isph), at a distance where a 30° lens holds the box's
//! bounding sphere, then zoomed and shifted so that the box's eight corners fill the viewport.
//! It depends on the box alone (`Survey::drawn_box`, over all the frames rendered), so every
//! frame of a rendering is seen from the same place.

use super::bounds::Bounds;
use super::raster::Rect;

const AZIMUTH_DEG: f64 = -60.0;
const ELEVATION_DEG: f64 = 25.0;
/// How much of the viewport's width or height the box takes.
const FILL: f64 = 0.94;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: [f64; 3],
    /// Unit vectors: right and up on the screen, forward into it.
    pub right: [f64; 3],
    pub up: [f64; 3],
    pub forward: [f64; 3],
    /// Pixels per unit of x/z.
    pub focal: f64,
    /// The pixel the optical axis goes through (after the shift that centres the box).
    pub centre: (f64, f64),
    /// The depth below which nothing is drawn (a hundredth of the distance to the box).
    pub near: f64,
}

/// A point on the screen: pixel x, y (corners at integers) and the depth along `forward`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projected {
    pub x: f64,
    pub y: f64,
    pub depth: f64,
}

impl Camera {
    /// The camera that shows `bounds` in `viewport`.
    pub fn fitted(bounds: &Bounds, viewport: Rect) -> Self {
        let (az, el) = (AZIMUTH_DEG.to_radians(), ELEVATION_DEG.to_radians());
        let towards_eye = [el.cos() * az.cos(), el.cos() * az.sin(), el.sin()];
        let forward = towards_eye.map(|c| -c);
        let right = normalise(cross(forward, [0.0, 0.0, 1.0]));
        let up = cross(right, forward);
        let radius = (0.5 * norm(bounds.extent())).max(1e-9);
        let distance = radius / 15f64.to_radians().sin();
        let target = bounds.centre();
        let eye = std::array::from_fn(|d| target[d] + distance * towards_eye[d]);
        let mut camera = Self {
            eye,
            right,
            up,
            forward,
            focal: 1.0,
            centre: (0.0, 0.0),
            near: 0.01 * distance,
        };
        // The corners' spread at unit focal length sets the zoom, their middle the shift.
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for corner in bounds.corners() {
            let p = camera.project(corner);
            for (d, v) in [p.x, -p.y].into_iter().enumerate() {
                lo[d] = lo[d].min(v);
                hi[d] = hi[d].max(v);
            }
        }
        let span = |d: usize| (hi[d] - lo[d]).max(1e-12);
        camera.focal = (FILL * viewport.w as f64 / span(0)).min(FILL * viewport.h as f64 / span(1));
        camera.centre = (
            viewport.x as f64 + 0.5 * viewport.w as f64 - camera.focal * 0.5 * (lo[0] + hi[0]),
            viewport.y as f64 + 0.5 * viewport.h as f64 + camera.focal * 0.5 * (lo[1] + hi[1]),
        );
        camera
    }

    /// Where `p` lands on the screen; `depth` ≤ 0 for a point behind the eye.
    pub fn project(&self, p: [f64; 3]) -> Projected {
        let v = sub(p, self.eye);
        let depth = dot(v, self.forward);
        Projected {
            x: self.centre.0 + self.focal * dot(v, self.right) / depth,
            y: self.centre.1 - self.focal * dot(v, self.up) / depth,
            depth,
        }
    }
}

pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

pub fn normalise(a: [f64; 3]) -> [f64; 3] {
    let n = norm(a);
    if n > 0.0 {
        a.map(|c| c / n)
    } else {
        a
    }
}
