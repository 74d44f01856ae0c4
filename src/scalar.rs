//! The scalar types the kernel runs in: `f32` and `f64`.

use nalgebra::{RealField, SVector};

pub(crate) mod sealed {
    /// Seals [`Real`](super::Real), and carries what only the crate calls.
    pub trait Sealed: Copy {
        /// `⌊x·2^bits + ½⌋` of a finite `x ≥ 0` as an integer (the fixed-point term of a
        /// [`Window`](crate::detection::Window)), saturating at `u64::MAX` (`+∞`, huge
        /// `x`); `0` for `x < ½·2^−bits`; `None` for NaN. `bits ≤ 24`. Both types give
        /// the value `f64` arithmetic gives (exact: `x·2^bits + ½` is exact in `f64` for
        /// an `f32` `x`); `f32` computes it in `f32` (on a Cortex-M4F, hardware float
        /// instead of the `f64` library routines).
        fn fixed_round(self, bits: u32) -> Option<u64>;
    }
    impl Sealed for f32 {
        #[inline(always)]
        fn fixed_round(self, bits: u32) -> Option<u64> {
            if self.is_nan() {
                return None;
            }
            // Exact: a power-of-two scaling (no overflow below 2^(128−24)).
            let x = self * (1u32 << bits) as f32;
            if x < 16_777_216.0 {
                // 0 ≤ x < 2²⁴ (a negative saturates to 0, as in `f64`): the integer part
                // and the fraction are exact, so this is ⌊x + ½⌋ exactly.
                let t = x as u32;
                let frac = x - t as f32;
                Some(t as u64 + u64::from(frac >= 0.5))
            } else {
                // x ≥ 2²⁴ is an integer in f32 already (or +∞: saturates).
                Some(x as u64)
            }
        }
    }
    impl Sealed for f64 {
        #[inline(always)]
        fn fixed_round(self, bits: u32) -> Option<u64> {
            if self.is_nan() {
                return None;
            }
            // `as` saturates (a negative to 0, above 2⁶⁴ to `u64::MAX`).
            Some((self * (1u64 << bits) as f64 + 0.5) as u64)
        }
    }
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
