//! `[[body]]`: rigid bodies in the fluid (docs/bodies.md, docs/scene-format.md).

use super::trajectory::Trajectory;
pub use crate::math::shape::Shape;

/// How a body moves.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyMotion {
    /// Moved by gravity, the fluid, its constant external force and the contact with the walls.
    Free,
    /// Held where it starts; the fluid's force on it is still measured.
    Fixed,
    /// Moved on a trajectory whatever the fluid does; the fluid's force on it is measured.
    Prescribed(Trajectory),
}

impl BodyMotion {
    pub const NAMES: [&'static str; 3] = ["free", "fixed", "prescribed"];

    /// Its name in the scene file and `isph plan`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Free => "free",
            Self::Fixed => "fixed",
            Self::Prescribed(_) => "prescribed",
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
    /// The time [s] a fixed or prescribed body is let go and moves freely from (None: never).
    pub release: Option<f64>,
    /// A constant external force on the body [N] (per metre of depth in 2D), besides gravity.
    pub force: Vec<f64>,
    /// The ratio of the speed off a wall to the speed into it in a contact (0: the body stops).
    pub restitution: f64,
    /// The Coulomb friction coefficient of its contacts (0: frictionless).
    pub friction: f64,
    /// The velocity of its centre of mass at t = 0 [m/s].
    pub velocity: Vec<f64>,
    /// Its angular velocity at t = 0 [rad/s]: 3 components in 3D, 1 (about z) in 2D.
    pub angular_velocity: Vec<f64>,
}
