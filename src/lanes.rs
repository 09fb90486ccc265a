//! The SIMD vector every pair loop computes in: `LANES` f64 lanes of `wide`, as wide as the
//! CPU the build targets. `.cargo/config.toml` builds for the host (`target-cpu=native`), so a
//! build on an AVX-512 machine gets eight lanes in one zmm register and a build on an AVX2
//! machine four in one ymm register (eight there would be two ymm registers per operation, and
//! measured 15% slower than four: docs/performance.md).
//!
//! The width changes the order in which a row's pairs are summed, so runs on builds of
//! different widths agree to round-off, not bit for bit; one build gives the same bits at any
//! thread count.

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

pub use width::F64s;

/// Lanes per SIMD vector.
pub const LANES: usize = std::mem::size_of::<F64s>() / std::mem::size_of::<f64>();
