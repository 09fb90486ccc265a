//! What every picture of one rendering shares, gathered from all the frames it renders before
//! the first is drawn: the top of the colour scale, the fluids and bodies present, the box
//! that fixes the axes and the camera, and the container. A video made of `--all` thus keeps
//! one colour scale and one camera from its first frame to its last.

use super::bounds::{self, Bounds};
use super::field::{ColorField, Colouring, BODY, FLUID, WALL};
use crate::io::frames::Frame;

#[derive(Clone, Debug, PartialEq)]
pub struct Survey {
    pub dimensions: usize,
    pub spacing: f64,
    /// Every particle of every frame surveyed: what the 2D axes show.
    pub bounds: Bounds,
    /// Every fluid and body particle of every frame surveyed.
    pub moving: Bounds,
    /// The container's inner box (from the first frame's walls), if it has walls.
    pub container: Option<Bounds>,
    pub colouring: Colouring,
    /// The largest per-frame top of the scale so far, before rounding up.
    largest: f64,
}

impl Survey {
    pub fn new(dimensions: usize, spacing: f64, field: ColorField) -> Self {
        Self {
            dimensions,
            spacing,
            bounds: Bounds::default(),
            moving: Bounds::default(),
            container: None,
            colouring: Colouring {
                field,
                max: 1.0,
                fluids: Vec::new(),
                bodies: false,
            },
            largest: 0.0,
        }
    }

    /// Takes `frame` into account.
    pub fn add(&mut self, frame: &Frame) {
        self.bounds.merge(&Bounds::of(&frame.position));
        if self.container.is_none() {
            let walls: Vec<[f64; 3]> = (0..frame.kind.len())
                .filter(|&i| frame.kind[i] == WALL)
                .map(|i| frame.position[i])
                .collect();
            self.container = bounds::container(&walls, self.spacing, self.dimensions);
        }
        let c = &mut self.colouring;
        let mut values = Vec::new();
        for i in 0..frame.kind.len() {
            match frame.kind[i] {
                FLUID => {
                    self.moving.include(&frame.position[i]);
                    values.push(c.field.value(frame, i));
                    if let Err(at) = c.fluids.binary_search(&frame.fluid[i]) {
                        c.fluids.insert(at, frame.fluid[i]);
                    }
                }
                BODY => {
                    self.moving.include(&frame.position[i]);
                    c.bodies = true;
                }
                _ => {}
            }
        }
        self.largest = self.largest.max(top_of_scale(values));
        // Rounded up so that the bar's ticks come out round.
        c.max = super::field::nice_ceiling(self.largest);
    }

    /// What the 3D camera frames: everything the picture draws, the container's inner box and
    /// the water and bodies in it (the wall particles, not drawn, would only add a border of
    /// their thickness).
    pub fn drawn_box(&self) -> Bounds {
        let mut b = self.moving;
        if let Some(container) = &self.container {
            b.merge(container);
        }
        if b.is_empty() {
            self.bounds
        } else {
            b
        }
    }
}

/// The share of a frame's fluid particles at or below the top of the colour scale. The rest
/// take the top colour: an impact puts a few particles at several times the pressure of the
/// water around them for a step, and a scale up to them would show everything else in its
/// bottom third.
pub const SCALE_QUANTILE: f64 = 0.995;

/// The `SCALE_QUANTILE` quantile of `values` (NaN left out; 0 for none).
fn top_of_scale(mut values: Vec<f64>) -> f64 {
    values.retain(|v| !v.is_nan());
    if values.is_empty() {
        return 0.0;
    }
    let k = (SCALE_QUANTILE * (values.len() - 1) as f64).round() as usize;
    *values.select_nth_unstable_by(k, f64::total_cmp).1
}
