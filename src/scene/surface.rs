//! The settings of surface reconstruction (a scene's `[output.surface]`, or the options of
//! `isph surface`): the types the `surface` module reads.

/// One of the paper's four density kernels, Eq. (28)–(31).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceKernel {
    /// Eq. (28): constant inside the radius.
    Rectangular,
    /// Eq. (29): a parabola inside b/3, a squared ramp beyond, continuous at b/3.
    Quadric,
    /// Eq. (30): D0 (1 − (r/b)²)².
    Quartic,
    /// Eq. (31): D0 exp(−a r²), cut where a r² = 9.
    Gaussian,
}

impl SurfaceKernel {
    pub const NAMES: [&'static str; 4] = ["rectangular", "quadric", "quartic", "gaussian"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "rectangular" => Some(Self::Rectangular),
            "quadric" => Some(Self::Quadric),
            "quartic" => Some(Self::Quartic),
            "gaussian" => Some(Self::Gaussian),
            _ => None,
        }
    }

    /// The kernel radius b, in particle spacings, unless one is given: the radius at which the
    /// surface of a ball of 20 spacings' radius, its particles on a lattice, is smooth (normals
    /// within 2.7° of the radius on the mean) and within 1.2% of the ball's volume
    /// (docs/surface.md, "Kernels"). A narrower kernel shows each particle as a bump; a wider
    /// one rounds corners and thins curved bodies more. The Gaussian's a = 9/b² makes it the
    /// narrowest for its radius.
    pub fn default_radius(self) -> f64 {
        match self {
            Self::Rectangular => 2.5,
            Self::Quartic => 3.0,
            Self::Quadric => 3.5,
            Self::Gaussian => 5.0,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Rectangular => "rectangular",
            Self::Quadric => "quadric",
            Self::Quartic => "quartic",
            Self::Gaussian => "gaussian",
        }
    }
}

/// How the lattice's cube edge is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CubeRule {
    /// The paper's rule (§3.4): the particles' bounding box divided into at most this many
    /// cubes.
    MaxCubes(u64),
    /// An edge given in particle spacings.
    Size(f64),
}

/// Surface reconstruction settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSettings {
    pub kernel: SurfaceKernel,
    /// Kernel radius b, in particle spacings.
    pub radius: f64,
    pub cubes: CubeRule,
    /// The iso-value of the normalised density (1 inside the fluid) that is the surface.
    pub iso: f64,
    /// Also write each frame's mesh as a Wavefront OBJ file.
    pub obj: bool,
}

impl Default for SurfaceSettings {
    /// The quartic kernel at its default radius, cubes of half a spacing, the surface at half
    /// the fluid's density (where a flat surface lies half a spacing beyond its last particles).
    fn default() -> Self {
        Self {
            kernel: SurfaceKernel::Quartic,
            radius: SurfaceKernel::Quartic.default_radius(),
            cubes: CubeRule::Size(0.5),
            iso: 0.5,
            obj: false,
        }
    }
}

/// Surface settings as a scene or the command line gives them, every part optional.
#[derive(Clone, Debug, Default)]
pub struct SurfaceRequest {
    pub kernel: Option<String>,
    pub radius: Option<f64>,
    pub cube_size: Option<f64>,
    pub max_cubes: Option<i64>,
    pub iso: Option<f64>,
    pub obj: Option<bool>,
}

impl SurfaceRequest {
    /// The settings asked for, or the key at fault (`kernel`, `radius`, `cube_size`,
    /// `max_cubes`, `iso`) and what is wrong with it.
    pub fn settings(&self) -> Result<SurfaceSettings, (&'static str, String)> {
        let kernel = match &self.kernel {
            None => SurfaceKernel::Quartic,
            Some(name) => SurfaceKernel::from_name(name).ok_or_else(|| {
                (
                    "kernel",
                    format!(
                        "= \"{name}\" is not a kernel: one of {}",
                        SurfaceKernel::NAMES.join(", ")
                    ),
                )
            })?,
        };
        let radius = self.radius.unwrap_or(kernel.default_radius());
        if !(0.5..=20.0).contains(&radius) {
            return Err((
                "radius",
                format!("= {radius:?} must lie in [0.5, 20] particle spacings"),
            ));
        }
        let cubes = match (self.cube_size, self.max_cubes) {
            (Some(_), Some(_)) => {
                return Err((
                    "cube_size",
                    "and max_cubes both choose the cube size: give one".into(),
                ))
            }
            (Some(size), None) if !(size.is_finite() && size > 0.0) => {
                return Err((
                    "cube_size",
                    format!("= {size:?} must be a positive number of particle spacings"),
                ))
            }
            (Some(size), None) => CubeRule::Size(size),
            (None, Some(n)) if n < 1 => {
                return Err(("max_cubes", format!("= {n} must be at least 1")))
            }
            (None, Some(n)) => CubeRule::MaxCubes(n as u64),
            (None, None) => SurfaceSettings::default().cubes,
        };
        let iso = self.iso.unwrap_or(0.5);
        if !(iso > 0.0 && iso < 1.0) {
            return Err(("iso", format!("= {iso:?} must lie in (0, 1): the density is 1 inside the fluid and 0 far from it")));
        }
        Ok(SurfaceSettings {
            kernel,
            radius,
            cubes,
            iso,
            obj: self.obj.unwrap_or(false),
        })
    }
}
