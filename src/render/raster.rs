//! The picture being drawn: an RGB buffer, rows top to bottom, that the particles and the
//! shaded surface are rasterised into before plotters draws axes and text over it.

use super::colormap::Rgb;

/// A pixel rectangle: x, y of the top-left corner, width and height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub x: i32,
    pub y: i32,
    pub w: i32,
    pub h: i32,
}

impl Rect {
    pub fn right(&self) -> i32 {
        self.x + self.w
    }

    pub fn bottom(&self) -> i32 {
        self.y + self.h
    }

    /// The pixel columns and rows from `x0..x1`, `y0..y1` (floats, any order) inside the
    /// rectangle, as half-open ranges.
    pub fn clip(
        &self,
        x0: f64,
        x1: f64,
        y0: f64,
        y1: f64,
    ) -> (std::ops::Range<i32>, std::ops::Range<i32>) {
        let span = |a: f64, b: f64, lo: i32, hi: i32| {
            let (a, b) = (a.min(b), a.max(b));
            let start = (a.floor().max(lo as f64)) as i32;
            let end = (b.ceil().min(hi as f64)) as i32;
            start..end.max(start)
        };
        (
            span(x0, x1, self.x, self.right()),
            span(y0, y1, self.y, self.bottom()),
        )
    }
}

/// An 8-bit RGB image, three bytes a pixel, the layout plotters' `BitMapBackend` and a PNG
/// encoder both take.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

impl Image {
    pub fn new(width: u32, height: u32, background: Rgb) -> Self {
        let rgb = background.repeat(width as usize * height as usize);
        Self { width, height, rgb }
    }

    pub fn rect(&self) -> Rect {
        Rect {
            x: 0,
            y: 0,
            w: self.width as i32,
            h: self.height as i32,
        }
    }

    fn offset(&self, x: i32, y: i32) -> usize {
        3 * (y as usize * self.width as usize + x as usize)
    }

    /// Sets a pixel that the caller has clipped to the image.
    pub fn set(&mut self, x: i32, y: i32, colour: Rgb) {
        let at = self.offset(x, y);
        self.rgb[at..at + 3].copy_from_slice(&colour);
    }

    pub fn get(&self, x: i32, y: i32) -> Rgb {
        let at = self.offset(x, y);
        [self.rgb[at], self.rgb[at + 1], self.rgb[at + 2]]
    }

    /// A filled disc of `diameter` pixels centred at (cx, cy) (pixel corners at integers),
    /// clipped to `clip`: the pixels whose centres lie inside it, or the pixel under the centre
    /// when the disc is too small to hold any centre, so that no particle vanishes.
    pub fn disc(&mut self, cx: f64, cy: f64, diameter: f64, colour: Rgb, clip: Rect) {
        let r = diameter / 2.0;
        let (xs, ys) = clip.clip(cx - r, cx + r, cy - r, cy + r);
        let mut any = false;
        for y in ys {
            let dy = y as f64 + 0.5 - cy;
            for x in xs.clone() {
                let dx = x as f64 + 0.5 - cx;
                if dx * dx + dy * dy <= r * r {
                    self.set(x, y, colour);
                    any = true;
                }
            }
        }
        let (x, y) = (cx.floor() as i32, cy.floor() as i32);
        if !any && x >= clip.x && x < clip.right() && y >= clip.y && y < clip.bottom() {
            self.set(x, y, colour);
        }
    }

    /// Fills `rect` (clipped to the image).
    pub fn fill(&mut self, rect: Rect, colour: Rgb) {
        let (xs, ys) = self.rect().clip(
            rect.x as f64,
            rect.right() as f64,
            rect.y as f64,
            rect.bottom() as f64,
        );
        for y in ys {
            for x in xs.clone() {
                self.set(x, y, colour);
            }
        }
    }
}
