//! `[[body]]`: rigid bodies in the fluid (docs/bodies.md, docs/scene-format.md).

pub use crate::math::shape::Shape;

/// How a body moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyMotion {
    /// Moved by gravity, the fluid, its constant external force and the contact with the walls.
    Free,
    /// Held where it starts; the fluid's force on it is still measured.
    Fixed,
}

impl BodyMotion {
    pub const NAMES: [&'static str; 2] = ["free", "fixed"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "free" => Some(Self::Free),
            "fixed" => Some(Self::Fixed),
            _ => None,
        }
    }
}

/// How a body's mass is given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BodyMass {
    /// Its density [kg/m³].
    Density(f64),
    /// Its total mass [kg] (per metre of depth in 2D), spread evenly over its particles.
    Total(f64),
}

/// One body of a validated scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// Unique among the scene's bodies; its name in `bodies.csv`.
    pub name: String,
    pub shape: Shape,
    pub mass: BodyMass,
    pub motion: BodyMotion,
    /// A constant external force on the body [N] (per metre of depth in 2D), besides gravity.
    pub force: Vec<f64>,
    /// The ratio of the speed off a wall to the speed into it in a contact (0: the body stops).
    pub restitution: f64,
    /// The velocity of its centre of mass at t = 0 [m/s].
    pub velocity: Vec<f64>,
    /// Its angular velocity at t = 0 [rad/s]: 3 components in 3D, 1 (about z) in 2D.
    pub angular_velocity: Vec<f64>,
}
