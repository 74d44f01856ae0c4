//! The scalar types the kernel runs in: `f32` and `f64`.

use nalgebra::RealField;

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// A floating-point scalar the kernel can step in: implemented for `f32` and `f64` only.
///
/// Operators are always computed in `f64` and rounded once to `Self`, so an `f32`
/// kernel built at run time is bit-identical to one built by the compiler.
pub trait Real: RealField + Copy + sealed::Sealed {
    /// Widen to `f64` (exact for both types).
    fn as_f64(self) -> f64;
    /// Round an `f64` to `Self` (round-to-nearest; exact for `f64`).
    fn from_f64_rounded(x: f64) -> Self;
}

impl Real for f32 {
    #[inline(always)]
    fn as_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn from_f64_rounded(x: f64) -> Self {
        x as f32
    }
}

impl Real for f64 {
    #[inline(always)]
    fn as_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn from_f64_rounded(x: f64) -> Self {
        x
    }
}
