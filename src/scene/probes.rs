//! `[[probe]]`: points at which a run records a field every step into `probes.csv`.

/// The field a probe records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProbeField {
    /// The pressure P [Pa]: one column.
    Pressure,
    /// The velocity [m/s]: one column per component.
    Velocity,
    /// A wave gauge: the height [m] of the free surface on the vertical line through the point
    /// (its last coordinate is the height and is not read): one column.
    Elevation,
}

impl ProbeField {
    pub const NAMES: [&'static str; 3] = ["pressure", "velocity", "elevation"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "pressure" => Some(Self::Pressure),
            "velocity" => Some(Self::Velocity),
            "elevation" => Some(Self::Elevation),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Pressure => "pressure",
            Self::Velocity => "velocity",
            Self::Elevation => "elevation",
        }
    }
}

/// One probe of a validated scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    /// Unique among the scene's probes; the column name in `probes.csv`.
    pub name: String,
    /// Where the field is read [m], one component per dimension, inside the container.
    pub point: Vec<f64>,
    pub field: ProbeField,
}

impl Probe {
    /// The probe's columns in `probes.csv`: its name for a pressure, `name_x`, `name_y`
    /// (, `name_z`) for a velocity.
    pub fn columns(&self) -> Vec<String> {
        match self.field {
            ProbeField::Pressure | ProbeField::Elevation => vec![self.name.clone()],
            ProbeField::Velocity => ["x", "y", "z"][..self.point.len()]
                .iter()
                .map(|axis| format!("{}_{axis}", self.name))
                .collect(),
        }
    }
}
