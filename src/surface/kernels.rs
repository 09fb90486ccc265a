//! The paper's four density kernels, Eq. (28)–(31), each scaled by its D0 so that it integrates
//! to one over its support in 2D or 3D: the density lattice c(x) = Σ V_i D(|x − x_i|) is then 1
//! inside the fluid, and the surface at c = 0.5 lies where a flat surface lies, half a particle
//! spacing beyond its last particles.

use crate::scene::SurfaceKernel;
use std::f64::consts::PI;

/// erf(3): the share of a Gaussian's mass within 3 standard deviations of √2 each, which the
/// Gaussian kernel's cut at a r² = 9 keeps (Abramowitz & Stegun, Table 7.1).
const ERF_3: f64 = 0.999_977_909_503_001_4;

/// A kernel of radius b in `dimensions`, evaluated from the squared distance.
///
/// The rectangular kernel, Eq. (28), counts a particle wholly inside b or not at all; over
/// particles on a lattice its sum then steps as whole shells of them cross the sphere, and the
/// iso-surface of that staircase is a terrace (a disc of 20 spacings came out with its
/// perimeter 4–13% long, a ball had dozens of bubbles, swinging with b: docs/surface.md). A
/// particle is a volume dx^D, not a point: here it counts by the share of one spacing that
/// lies inside the sphere, a linear ramp from b − dx/2 to b + dx/2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kernel {
    pub shape: SurfaceKernel,
    /// The radius b [m].
    pub radius: f64,
    /// Where D falls to zero [m]: b, or b + dx/2 for the rectangular kernel's ramp.
    pub support: f64,
    /// The rectangular kernel's ramp width dx [m].
    ramp: f64,
    /// D0 of Eq. (28)–(31) (the constant `a` of the rectangular kernel).
    pub d0: f64,
    /// `a` of the Gaussian, Eq. (31): 9 / b², so that the cut at b falls at a r² = 9.
    pub a: f64,
}

impl Kernel {
    /// The kernel of radius `radius` for particles of `spacing`.
    pub fn new(shape: SurfaceKernel, radius: f64, spacing: f64, dimensions: usize) -> Self {
        let b = radius;
        let a = 9.0 / (b * b);
        let ramp = if shape == SurfaceKernel::Rectangular {
            spacing.min(b)
        } else {
            0.0
        };
        let d0 = match (shape, dimensions) {
            (SurfaceKernel::Rectangular, _) => 1.0 / ramped_ball(b, ramp, dimensions),
            (SurfaceKernel::Quadric, 2) => 54.0 / (13.0 * PI * b * b),
            (SurfaceKernel::Quadric, _) => 81.0 / (16.0 * PI * b.powi(3)),
            (SurfaceKernel::Quartic, 2) => 3.0 / (PI * b * b),
            (SurfaceKernel::Quartic, _) => 105.0 / (32.0 * PI * b.powi(3)),
            // (a/π)^{D/2} integrates to one over all space; divided by the share the cut at
            // a r² = 9 keeps (1 − e⁻⁹ in 2D, erf 3 − 6 e⁻⁹/√π in 3D).
            (SurfaceKernel::Gaussian, 2) => a / PI / (1.0 - (-9.0f64).exp()),
            (SurfaceKernel::Gaussian, _) => {
                (a / PI).powf(1.5) / (ERF_3 - 6.0 / PI.sqrt() * (-9.0f64).exp())
            }
        };
        Self {
            shape,
            radius,
            support: b + ramp / 2.0,
            ramp,
            d0,
            a,
        }
    }

    /// D at squared distance `r2`.
    #[inline]
    pub fn value(&self, r2: f64) -> f64 {
        if r2 >= self.support * self.support {
            return 0.0;
        }
        let b2 = self.radius * self.radius;
        match self.shape {
            SurfaceKernel::Rectangular => {
                // Eq. (28), the particle's share inside the sphere ramping over one spacing.
                let inner = self.radius - self.ramp / 2.0;
                if r2 <= inner * inner {
                    self.d0
                } else {
                    self.d0 * (self.support - r2.sqrt()) / self.ramp
                }
            }
            SurfaceKernel::Quadric => {
                // Eq. (29), its second branch in the continuous form that meets the first at
                // b/3 (the source prints it garbled).
                let q2 = r2 / b2;
                if q2 <= 1.0 / 9.0 {
                    self.d0 * (1.0 - 3.0 * q2)
                } else {
                    let t = 1.0 - q2.sqrt();
                    1.5 * self.d0 * t * t
                }
            }
            SurfaceKernel::Quartic => {
                let t = 1.0 - r2 / b2;
                self.d0 * t * t // Eq. (30)
            }
            SurfaceKernel::Gaussian => self.d0 * (-self.a * r2).exp(), // Eq. (31)
        }
    }
}

/// ∫ f over the plane (2D) or space (3D), f = 1 within b − w/2 falling linearly to 0 at
/// b + w/2.
fn ramped_ball(b: f64, w: f64, dimensions: usize) -> f64 {
    let (c1, c2) = (b - w / 2.0, b + w / 2.0);
    if dimensions == 2 {
        // π c1² + 2π ∫ (c2 − r)/w r dr over [c1, c2].
        let shell = if w > 0.0 {
            (c2 * (c2 * c2 - c1 * c1) / 2.0 - (c2.powi(3) - c1.powi(3)) / 3.0) / w
        } else {
            0.0
        };
        PI * c1 * c1 + 2.0 * PI * shell
    } else {
        // 4π c1³/3 + 4π ∫ (c2 − r)/w r² dr over [c1, c2].
        let shell = if w > 0.0 {
            (c2 * (c2.powi(3) - c1.powi(3)) / 3.0 - (c2.powi(4) - c1.powi(4)) / 4.0) / w
        } else {
            0.0
        };
        4.0 * PI * c1.powi(3) / 3.0 + 4.0 * PI * shell
    }
}

/// A kernel as the lattice sums evaluate it: V D(r) from the squared distance, in single
/// precision and without branches, so that a row of lattice points is summed in SIMD lanes.
/// Each point's sum still runs over the particles in one order: the bits do not depend on the
/// lanes or the threads.
pub trait Profile: Copy + Send + Sync {
    fn at(&self, r2: f32) -> f32;
    /// Where the profile is zero from, squared.
    fn support2(&self) -> f32;
}

/// Eq. (30) times V: V D0 max(1 − r²/b², 0)².
#[derive(Clone, Copy)]
pub struct Quartic {
    scale: f32,
    inv_b2: f32,
}

/// Eq. (31) times V, cut at b.
#[derive(Clone, Copy)]
pub struct Gaussian {
    scale: f32,
    a: f32,
    b2: f32,
}

/// Eq. (29) times V, in its continuous form.
#[derive(Clone, Copy)]
pub struct Quadric {
    scale: f32,
    inv_b2: f32,
}

/// Eq. (28) times V with the particle's share inside the sphere ramping over one spacing.
#[derive(Clone, Copy)]
pub struct Rectangular {
    scale: f32,
    support: f32,
    inv_ramp: f32,
}

impl Profile for Quartic {
    #[inline(always)]
    fn at(&self, r2: f32) -> f32 {
        // A select, not f32::max, whose NaN rule costs two more vector instructions.
        let t = 1.0 - r2 * self.inv_b2;
        let t = if t > 0.0 { t } else { 0.0 };
        self.scale * t * t
    }
    fn support2(&self) -> f32 {
        1.0 / self.inv_b2
    }
}

impl Profile for Gaussian {
    #[inline(always)]
    fn at(&self, r2: f32) -> f32 {
        let w = self.scale * (-self.a * r2).exp();
        if r2 < self.b2 {
            w
        } else {
            0.0
        }
    }
    fn support2(&self) -> f32 {
        self.b2
    }
}

impl Profile for Quadric {
    #[inline(always)]
    fn at(&self, r2: f32) -> f32 {
        let q2 = r2 * self.inv_b2;
        let t = (1.0 - q2.sqrt()).max(0.0);
        let w = if q2 <= 1.0 / 9.0 {
            1.0 - 3.0 * q2
        } else {
            1.5 * t * t
        };
        self.scale * w
    }
    fn support2(&self) -> f32 {
        1.0 / self.inv_b2
    }
}

impl Profile for Rectangular {
    #[inline(always)]
    fn at(&self, r2: f32) -> f32 {
        self.scale * ((self.support - r2.sqrt()) * self.inv_ramp).clamp(0.0, 1.0)
    }
    fn support2(&self) -> f32 {
        self.support * self.support
    }
}

impl Kernel {
    /// The kernel's profile scaled by the particle volume V, for `visit` to sum with.
    pub fn with_profile<R>(&self, volume: f64, visit: impl ProfileVisitor<Output = R>) -> R {
        let scale = (volume * self.d0) as f32;
        let inv_b2 = (1.0 / (self.radius * self.radius)) as f32;
        match self.shape {
            SurfaceKernel::Quartic => visit.visit(Quartic { scale, inv_b2 }),
            SurfaceKernel::Quadric => visit.visit(Quadric { scale, inv_b2 }),
            SurfaceKernel::Gaussian => visit.visit(Gaussian {
                scale,
                a: self.a as f32,
                b2: (self.radius * self.radius) as f32,
            }),
            SurfaceKernel::Rectangular => visit.visit(Rectangular {
                scale,
                support: self.support as f32,
                inv_ramp: (1.0 / self.ramp) as f32,
            }),
        }
    }
}

/// Code run with a concrete profile (a generic closure, which Rust has no syntax for).
pub trait ProfileVisitor {
    type Output;
    fn visit<P: Profile>(self, profile: P) -> Self::Output;
}
