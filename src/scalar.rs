//! The scalar types the kernel runs in: `f32` and `f64`.

use nalgebra::{RealField, SVector};

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
    /// The largest finite value of `Self`, as `f64` (operators above it are rejected with
    /// [`Error::OperatorOverflow`](crate::Error::OperatorOverflow) instead of rounding to
    /// `∞`).
    const MAX: f64;
}

/// The input check of every start-up function: `u0`, `v0` and the load at `t = 0` (`p0`,
/// or `w0` of an input map) are finite. (A chained iterator: on Cortex-M it compiles
/// smaller than a loop over slices.)
pub(crate) fn initial_inputs_finite<T: Real, const N: usize, const I: usize>(
    u0: &SVector<T, N>,
    v0: &SVector<T, N>,
    p0: &SVector<T, I>,
) -> bool {
    u0.iter()
        .chain(v0.iter())
        .chain(p0.iter())
        .all(|x| x.is_finite())
}

impl Real for f32 {
    const MAX: f64 = f32::MAX as f64;
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
    const MAX: f64 = f64::MAX;
    #[inline(always)]
    fn as_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn from_f64_rounded(x: f64) -> Self {
        x
    }
}
