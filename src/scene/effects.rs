//! The settings of the optional parts of the step (`[effects]`): the types the effects read,
//! parsed and checked with the rest of the scene.

/// The `[effects]` section: which optional parts of the step run, with their constants. Every
/// effect is on unless the scene turns it off, so a scene without the section runs the full
/// stabilised scheme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Effects {
    /// Particle shifting, Eq. (9)–(10) (None: off).
    pub shifting: Option<ShiftingSettings>,
    /// Smagorinsky large-eddy simulation, Eq. (3)–(4) (None: off, laminar viscosity only).
    pub les: Option<LesSettings>,
    /// Kernel gradient correction, Eq. (24)–(25) (false: every L_i is the identity).
    pub kernel_correction: bool,
}

impl Default for Effects {
    fn default() -> Self {
        Self {
            shifting: Some(ShiftingSettings::default()),
            les: Some(LesSettings::default()),
            kernel_correction: true,
        }
    }
}

/// The constants of shifting (the scene's `[effects.shifting]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShiftingSettings {
    /// A of D = A h U Δt.
    pub coefficient: f64,
    /// Largest shift per component and step, in particle spacings.
    pub max_shift: f64,
    /// R of the anti-clustering term.
    pub clustering_weight: f64,
}

impl Default for ShiftingSettings {
    fn default() -> Self {
        Self {
            coefficient: 2.0,
            max_shift: 0.1,
            clustering_weight: 0.2,
        }
    }
}

/// The constants of the turbulence model (the scene's `[effects.les]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LesSettings {
    /// Smagorinsky constant Cs of Eq. (3)–(4).
    pub cs: f64,
    /// Whether the particles touching a wall feel the log-law wall shear (`wall_shear`).
    pub wall_function: bool,
}

impl Default for LesSettings {
    /// Cs = 0.2, the paper's value (DualSPHysics uses 0.12), with the wall function.
    fn default() -> Self {
        Self {
            cs: 0.2,
            wall_function: true,
        }
    }
}
