//! What a picture's colours mean: the field a particle (or a surface vertex) is coloured by,
//! and the legend that says so.

use super::colormap::{self, Rgb};
use crate::io::frames::Frame;

/// Particle kind codes of particles.h5 (`particles::Kind`, and 2 for rigid bodies).
pub const FLUID: i32 = 0;
pub const WALL: i32 = 1;
pub const BODY: i32 = 2;

/// The quantity a picture is coloured by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorField {
    /// Fluid pressure, viridis from 0 to the largest.
    Pressure,
    /// Fluid speed |u|, viridis from 0 to the largest.
    Speed,
    /// Which fluid a particle belongs to, one colour each.
    Fluid,
    /// Rigid bodies in colour against pale water.
    Body,
}

impl ColorField {
    pub const NAMES: [&'static str; 4] = ["pressure", "speed", "fluid", "body"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "pressure" => Some(Self::Pressure),
            "speed" => Some(Self::Speed),
            "fluid" => Some(Self::Fluid),
            "body" => Some(Self::Body),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Pressure => "pressure",
            Self::Speed => "speed",
            Self::Fluid => "fluid",
            Self::Body => "body",
        }
    }

    /// The field's value at particle `i` in SI units (0 for categorical fields).
    pub fn value(self, frame: &Frame, i: usize) -> f64 {
        match self {
            Self::Pressure => frame.pressure[i],
            Self::Speed => norm(frame.velocity[i]),
            Self::Fluid | Self::Body => 0.0,
        }
    }
}

pub fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// The legend drawn beside a picture.
#[derive(Clone, Debug, PartialEq)]
pub enum Legend {
    /// A colour bar from 0 to `max`, shown in `unit` (the SI value times `factor`).
    Bar {
        name: &'static str,
        unit: &'static str,
        factor: f64,
        max: f64,
    },
    /// One swatch per category.
    Swatches(Vec<(String, Rgb)>),
}

impl Legend {
    /// "pressure [kPa]".
    pub fn title(&self) -> String {
        match self {
            Self::Bar { name, unit, .. } => format!("{name} [{unit}]"),
            Self::Swatches(_) => String::new(),
        }
    }
}

/// How particles and surface vertices get their colours in one rendering.
#[derive(Clone, Debug, PartialEq)]
pub struct Colouring {
    pub field: ColorField,
    /// The top of the colour scale, SI units: the scale runs 0..max.
    pub max: f64,
    /// The fluid indices present (sorted), for `ColorField::Fluid`.
    pub fluids: Vec<i32>,
    /// Whether any rigid-body particle is present.
    pub bodies: bool,
}

impl Colouring {
    /// The colour of a scalar value `v` (SI units).
    pub fn scalar(&self, v: f64) -> Rgb {
        colormap::viridis(v / self.max)
    }

    /// The colour of fluid number `index`.
    pub fn fluid(&self, index: i32) -> Rgb {
        let slot = self.fluids.iter().position(|&f| f == index).unwrap_or(0);
        colormap::category(slot)
    }

    /// The colour of particle `i`: walls grey, bodies dark grey unless the picture is of bodies.
    pub fn particle(&self, frame: &Frame, i: usize) -> Rgb {
        match (frame.kind[i], self.field) {
            (WALL, _) => colormap::WALL,
            // The reader gives no body index yet: every body takes the first category.
            (BODY, ColorField::Body) => colormap::category(0),
            (BODY, _) => colormap::BODY,
            (_, ColorField::Fluid) => self.fluid(frame.fluid[i]),
            (_, ColorField::Body) => colormap::WATER,
            (_, field) => self.scalar(field.value(frame, i)),
        }
    }

    pub fn legend(&self) -> Legend {
        match self.field {
            ColorField::Pressure if self.max >= 1e4 => Legend::Bar {
                name: "pressure",
                unit: "kPa",
                factor: 1e-3,
                max: self.max,
            },
            ColorField::Pressure => Legend::Bar {
                name: "pressure",
                unit: "Pa",
                factor: 1.0,
                max: self.max,
            },
            ColorField::Speed => Legend::Bar {
                name: "speed",
                unit: "m/s",
                factor: 1.0,
                max: self.max,
            },
            ColorField::Fluid => Legend::Swatches(
                self.fluids
                    .iter()
                    .map(|&f| (format!("fluid {f}"), self.fluid(f)))
                    .collect(),
            ),
            ColorField::Body => {
                let mut swatches = vec![("water".to_owned(), colormap::WATER)];
                if self.bodies {
                    swatches.push(("bodies".to_owned(), colormap::category(0)));
                }
                Legend::Swatches(swatches)
            }
        }
    }
}

/// The smallest of 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 times a power of ten at or above `x`:
/// the top of a colour scale whose ticks come out round. 1 for a scale with nothing on it.
pub fn nice_ceiling(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    let decade = 10f64.powf(x.log10().floor());
    [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        // A hair of tolerance so that 1200 (stored as 1199.9999…) stays 1200.
        .find(|&top| top >= x * (1.0 - 1e-12))
        .unwrap_or(10.0 * decade)
}
