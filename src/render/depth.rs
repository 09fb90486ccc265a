//! The 3D rasteriser: triangles, sphere splats and lines into an image with a depth buffer,
//! lit by one fixed light. Everything is drawn in the order it is given and a pixel is taken
//! only by something strictly nearer, so the picture does not depend on anything but the input.

use super::camera::{dot, normalise, Camera, Projected};
use super::colormap::Rgb;
use super::raster::{Image, Rect};

/// Light from above, front right of the camera (azimuth −30°, elevation 55°).
const LIGHT: [f64; 3] = [0.496_731_8, -0.286_788_2, 0.819_152_0];
const AMBIENT: f64 = 0.38;
const DIFFUSE: f64 = 0.62;
/// A small Blinn–Phong highlight, so that water looks wet and the shape reads.
const SPECULAR: f64 = 0.22;
const SHININESS: i32 = 40;

/// A vertex handed to `triangle`: where it is and what it looks like.
#[derive(Clone, Copy, Debug)]
pub struct Vertex {
    pub position: [f64; 3],
    /// Unit normal (either side faces the light: the shading is two-sided).
    pub normal: [f64; 3],
    pub colour: Rgb,
}

pub struct DepthImage<'a> {
    pub image: &'a mut Image,
    pub camera: Camera,
    /// Where drawing is allowed (the viewport).
    pub clip: Rect,
    /// 1/depth of what each pixel shows; 0 where nothing is drawn yet.
    inverse_depth: Vec<f32>,
}

impl<'a> DepthImage<'a> {
    pub fn new(image: &'a mut Image, camera: Camera, clip: Rect) -> Self {
        let n = image.width as usize * image.height as usize;
        Self {
            image,
            camera,
            clip,
            inverse_depth: vec![0.0; n],
        }
    }

    /// Takes pixel (x, y) for something at 1/depth `inverse` if it is nearer than what the
    /// pixel shows.
    fn claim(&mut self, x: i32, y: i32, inverse: f64) -> bool {
        let at = y as usize * self.image.width as usize + x as usize;
        let inverse = inverse as f32;
        if inverse > self.inverse_depth[at] {
            self.inverse_depth[at] = inverse;
            true
        } else {
            false
        }
    }

    /// The colour of a surface of `base` colour with normal `n` under the light.
    pub fn lit(&self, base: Rgb, n: [f64; 3]) -> Rgb {
        let view = self.camera.forward.map(|c| -c);
        // Two-sided: the side facing the camera is lit.
        let n = if dot(n, view) < 0.0 { n.map(|c| -c) } else { n };
        let diffuse = dot(n, LIGHT).max(0.0);
        let half = normalise([LIGHT[0] + view[0], LIGHT[1] + view[1], LIGHT[2] + view[2]]);
        let highlight = SPECULAR * dot(n, half).max(0.0).powi(SHININESS);
        base.map(|c| {
            let v = c as f64 * (AMBIENT + DIFFUSE * diffuse) + 255.0 * highlight;
            v.round().clamp(0.0, 255.0) as u8
        })
    }

    /// A triangle, normals and colours interpolated perspective-correctly, shaded per pixel.
    pub fn triangle(&mut self, v: [Vertex; 3]) {
        let p = v.map(|v| self.camera.project(v.position));
        if p.iter().any(|p| p.depth <= self.camera.near) {
            return;
        }
        let area = edge(&p[0], &p[1], p[2].x, p[2].y);
        if area == 0.0 || !area.is_finite() {
            return;
        }
        let (xs, ys) = self.clip.clip(
            p[0].x.min(p[1].x).min(p[2].x),
            p[0].x.max(p[1].x).max(p[2].x),
            p[0].y.min(p[1].y).min(p[2].y),
            p[0].y.max(p[1].y).max(p[2].y),
        );
        for y in ys {
            let py = y as f64 + 0.5;
            for x in xs.clone() {
                let px = x as f64 + 0.5;
                // Barycentric weights, of the same sign as `area` inside.
                let b = [
                    edge(&p[1], &p[2], px, py) / area,
                    edge(&p[2], &p[0], px, py) / area,
                    edge(&p[0], &p[1], px, py) / area,
                ];
                if b.iter().any(|&b| b < 0.0) {
                    continue;
                }
                let w = [0, 1, 2].map(|k| b[k] / p[k].depth);
                let inverse = w[0] + w[1] + w[2];
                if !self.claim(x, y, inverse) {
                    continue;
                }
                let mix =
                    |f: &dyn Fn(usize) -> f64| (w[0] * f(0) + w[1] * f(1) + w[2] * f(2)) / inverse;
                let n = normalise(std::array::from_fn(|d| mix(&|k| v[k].normal[d])));
                let base = std::array::from_fn(|c| mix(&|k| v[k].colour[c] as f64).round() as u8);
                let colour = self.lit(base, n);
                self.image.set(x, y, colour);
            }
        }
    }

    /// A sphere of `radius` around `centre`, shaded as a ball; at least the pixel under its
    /// centre when it is smaller than a pixel.
    pub fn sphere(&mut self, centre: [f64; 3], radius: f64, colour: Rgb) {
        let c = self.camera.project(centre);
        if c.depth <= self.camera.near || !(c.x.is_finite() && c.y.is_finite()) {
            return;
        }
        let r = self.camera.focal * radius / c.depth;
        let (xs, ys) = self.clip.clip(c.x - r, c.x + r, c.y - r, c.y + r);
        let mut any = false;
        for y in ys {
            let b = (y as f64 + 0.5 - c.y) / r;
            for x in xs.clone() {
                let a = (x as f64 + 0.5 - c.x) / r;
                let q = a * a + b * b;
                if q > 1.0 {
                    continue;
                }
                any = true;
                let towards = (1.0 - q).sqrt();
                if self.claim(x, y, 1.0 / (c.depth - towards * radius)) {
                    let cam = &self.camera;
                    let n = std::array::from_fn(|d| {
                        a * cam.right[d] - b * cam.up[d] - towards * cam.forward[d]
                    });
                    let lit = self.lit(colour, n);
                    self.image.set(x, y, lit);
                }
            }
        }
        let (x, y) = (c.x.floor() as i32, c.y.floor() as i32);
        let inside =
            x >= self.clip.x && x < self.clip.right() && y >= self.clip.y && y < self.clip.bottom();
        if !any && inside && self.claim(x, y, 1.0 / c.depth) {
            let lit = self.lit(colour, self.camera.forward.map(|c| -c));
            self.image.set(x, y, lit);
        }
    }

    /// A line `width` pixels wide from `a` to `b`: `colour` where nothing nearer covers it,
    /// and `hidden` (mixed into what covers it by `hidden_weight`) where something does, so
    /// that the container's far edges show faintly through the water.
    pub fn line(
        &mut self,
        a: [f64; 3],
        b: [f64; 3],
        width: i32,
        colour: Rgb,
        hidden: Rgb,
        hidden_weight: f64,
    ) {
        let (pa, pb) = (self.camera.project(a), self.camera.project(b));
        if pa.depth <= self.camera.near || pb.depth <= self.camera.near {
            return;
        }
        let steps = ((pb.x - pa.x).abs().max((pb.y - pa.y).abs()) * 2.0)
            .ceil()
            .max(1.0) as usize;
        let half = width as f64 / 2.0;
        // The pixels the line covers, each once with its nearest depth, so that the hidden
        // parts are mixed in once however many samples touch a pixel.
        let mut pixels: Vec<(i32, i32, f64)> = Vec::new();
        for s in 0..=steps {
            let t = s as f64 / steps as f64;
            let (x, y) = (pa.x + t * (pb.x - pa.x), pa.y + t * (pb.y - pa.y));
            // 1/depth is linear on the screen.
            let inverse = (1.0 - t) / pa.depth + t / pb.depth;
            let (xs, ys) = self.clip.clip(x - half, x + half, y - half, y + half);
            for py in ys {
                pixels.extend(xs.clone().map(|px| (py, px, inverse)));
            }
        }
        pixels.sort_by(|a, b| (a.0, a.1).cmp(&(b.0, b.1)).then(b.2.total_cmp(&a.2)));
        pixels.dedup_by_key(|p| (p.0, p.1));
        for (py, px, inverse) in pixels {
            let at = py as usize * self.image.width as usize + px as usize;
            // A hair of slack, so that an edge is not hidden by the face it bounds.
            let visible = inverse as f32 >= self.inverse_depth[at] * (1.0 - 2e-3);
            let shown = if visible {
                colour
            } else {
                let under = self.image.get(px, py);
                std::array::from_fn(|c| {
                    let (u, h) = (under[c] as f64, hidden[c] as f64);
                    (u + hidden_weight * (h - u)).round() as u8
                })
            };
            self.image.set(px, py, shown);
        }
    }
}

/// Twice the signed area of the triangle (a, b, (x, y)).
fn edge(a: &Projected, b: &Projected, x: f64, y: f64) -> f64 {
    (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x)
}
