//! The SIMD vector every pair loop computes in: `LANES` f64 lanes of `wide`, as wide as the
//! CPU the build targets. `.cargo/config.toml` builds for the host (`target-cpu=native`), so a
//! build on an AVX-512 machine gets eight lanes in one zmm register and a build on an AVX2
//! machine four in one ymm register (eight there would be two ymm registers per operation,
//! slower than four: docs/performance.md, "Build").
//!
//! The width does not change the results: the pair loops sum into a `Sum`, which adds a
//! chunk's lanes four at a time in index order, so builds of either width give the same bits
//! (with FMA, which every AVX-512 CPU has), and one build the same bits at any thread count.

#[cfg(target_feature = "avx512f")]
mod width {
    /// Eight f64 lanes: one AVX-512 register.
    pub type F64s = wide::f64x8;
}

#[cfg(not(target_feature = "avx512f"))]
mod width {
    /// Four f64 lanes: one AVX2 register.
    pub type F64s = wide::f64x4;
}

use wide::f64x4;
pub use width::F64s;

/// Lanes per SIMD vector.
pub const LANES: usize = std::mem::size_of::<F64s>() / std::mem::size_of::<f64>();

/// A running sum over the pair loop in four f64 lanes, into which each chunk's `LANES` lanes
/// are added four at a time in index order: a build of eight lanes then adds every pair term
/// in the same order, with the same roundings, as a build of four, and the two give the same
/// bits (the wide lanes only evaluate the pair terms, two chunks of four at once).
#[derive(Clone, Copy, Debug, Default)]
pub struct Sum(f64x4);

impl Sum {
    pub const ZERO: Self = Sum(f64x4::ZERO);

    /// The sum plus `a b`, fused lane by lane.
    #[inline(always)]
    pub fn mul_add(self, a: F64s, b: F64s) -> Self {
        let (a, b) = (quarters(a), quarters(b));
        Sum((0..LANES / 4).fold(self.0, |s, q| a[q].mul_add(b[q], s)))
    }

    /// The sum of the lanes.
    #[inline(always)]
    pub fn total(self) -> f64 {
        self.0.reduce_add()
    }
}

impl std::ops::Add<F64s> for Sum {
    type Output = Sum;

    #[inline(always)]
    fn add(self, x: F64s) -> Sum {
        Sum(quarters(x).into_iter().fold(self.0, |s, x| s + x))
    }
}

impl std::ops::AddAssign<F64s> for Sum {
    #[inline(always)]
    fn add_assign(&mut self, x: F64s) {
        *self = *self + x;
    }
}

/// The lanes of `x` in groups of four, in index order (the halves of a zmm register, or the
/// ymm register itself).
#[inline(always)]
fn quarters(x: F64s) -> [f64x4; LANES / 4] {
    bytemuck::cast(x)
}
