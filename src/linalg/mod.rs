//! Dense linear algebra, in one place: everything the operator builds and the iterative
//! steppers need, written once.
//!
//! - Row-major `f64` arrays ([`Rows`], [`Mat`]) and `const fn` helpers on them: used by
//!   every operator build, evaluated either by the compiler (a `from_rows` constructor in a
//!   `static`, operators in flash) or at run time (`new`). IEEE `f64` arithmetic is the
//!   same in both places and nothing here is fused, so both give bit-identical operators.
//! - [`lu`]: LU with partial pivoting — operators are formed by factorization and solves
//!   (`G = M_eff⁻¹` is the solve with the identity, `GC`, `GK` solves with `C`, `K`), and a
//!   generic in-place solve for the per-step matrices of the nonlinear and time-varying
//!   steppers.
//! - [`tridiagonal`]: the `O(N)` Newton solve of a shear building (positive definite,
//!   else the caller pivots with [`lu`]).
//! - [`cholesky`], [`symmetric_eigen`]: the generalized eigenproblem of modal reduction.
//! - [`expm`]: the matrix exponential of the exact scheme.
//!
//! Cost: `O(N³)` flops and a few `N×N` `f64` temporaries on the stack (`8N²` bytes each)
//! per build — call them once, not per step (the in-place solve excepted).

#[cfg(target_arch = "x86_64")]
pub(crate) mod avx;
pub(crate) mod cholesky;
pub(crate) mod expm;
pub(crate) mod lu;
pub(crate) mod op_rows;
pub(crate) mod symmetric_eigen;
pub(crate) mod tridiagonal;

use nalgebra::SMatrix;

use crate::Real;

/// Run `f` (inlined loops over independent lanes, such as the spectrum bank's step over
/// its oscillators) at the host's vector width: on x86-64, compiled with AVX when the CPU
/// has it ([`avx::run`]: same bits, see its module docs); on every other target, as is.
/// The one dispatch point, so callers hold no `cfg` pairs. Cost: on x86-64 a relaxed load,
/// a branch and a call; elsewhere none.
#[inline(always)]
pub(crate) fn wide<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    return avx::run(f);
    #[cfg(not(target_arch = "x86_64"))]
    f()
}

/// [`wide`] for loops over lane arrays of `bytes` bytes ([`LaneStepper`]'s step): on
/// x86-64 also AVX-512 when the arrays fill a 512-bit register and the CPU has it
/// ([`avx::run_lanes`]: same bits). Cost: as [`wide`].
///
/// [`LaneStepper`]: crate::lanes::LaneStepper
#[inline(always)]
pub(crate) fn wide_lanes<R>(bytes: usize, f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    return avx::run_lanes(bytes, f);
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = bytes;
        f()
    }
}

/// A row-major `N×N` matrix of `f64` (`a[i][j]`: row `i`, column `j`), the form the
/// `const fn` constructors (`from_rows`) take.
///
/// **Row-major**; use [`models::matrix_of`](crate::models::matrix_of) to convert, not
/// `SMatrix::from`, which reads columns (a non-symmetric matrix would be silently
/// transposed). [`models::rows_of`](crate::models::rows_of) converts back.
pub type Rows<const N: usize> = [[f64; N]; N];

/// A row-major `R×C` matrix of `f64`.
pub(crate) type Mat<const R: usize, const C: usize> = [[f64; C]; R];

/// A row-major `f64` array as a `T` matrix, each entry rounded once: how the filters and
/// [`matrix_of`](crate::models::matrix_of) store what they were built from.
pub(crate) fn matrix_t<T: Real, const R: usize, const C: usize>(a: &Mat<R, C>) -> SMatrix<T, R, C> {
    SMatrix::from_fn(|i, j| T::from_f64_rounded(a[i][j]))
}

/// `(a + aᵀ)/2`: the Kalman-type filters' symmetrization of a covariance after an update.
pub(crate) fn sym<T: Real, const S: usize>(a: &SMatrix<T, S, S>) -> SMatrix<T, S, S> {
    (a + a.transpose()) * T::from_f64_rounded(0.5)
}

/// All entries finite.
pub(crate) const fn all_finite<const R: usize, const C: usize>(a: &Mat<R, C>) -> bool {
    all_finite_flat(a.as_flattened())
}

/// All entries finite ([`all_finite`] on a flat slice: the one loop both use).
pub(crate) const fn all_finite_flat(a: &[f64]) -> bool {
    let (mut i, len) = (0, a.len());
    while i < len {
        if !a[i].is_finite() {
            return false;
        }
        i += 1;
    }
    true
}

/// Largest `|a_ij|` (`0` for an empty matrix; NaN entries are skipped).
pub(crate) const fn max_abs<const R: usize, const C: usize>(a: &Mat<R, C>) -> f64 {
    max_abs_flat(a.as_flattened())
}

/// [`max_abs`] of a flat slice (the one loop both use).
pub(crate) const fn max_abs_flat(a: &[f64]) -> f64 {
    let mut s = 0.0f64;
    let (mut i, len) = (0, a.len());
    while i < len {
        if a[i].abs() > s {
            s = a[i].abs();
        }
        i += 1;
    }
    s
}

/// `a + s·b`.
pub(crate) const fn add_scaled<const R: usize, const C: usize>(
    a: &Mat<R, C>,
    s: f64,
    b: &Mat<R, C>,
) -> Mat<R, C> {
    let mut r = *a;
    add_scaled_flat(r.as_flattened_mut(), s, b.as_flattened());
    r
}

/// `dst = src` if the lengths agree (else nothing: a `copy_from_slice` with no panic).
pub(crate) const fn copy_flat(dst: &mut [f64], src: &[f64]) {
    // One `copy_from_slice` (a memcpy, also for the compiler's evaluator: a copy of the
    // operators of `Linear<f32, 63>` in a `static` stays within its step budget).
    if dst.len() == src.len() {
        dst.copy_from_slice(src);
    }
}

/// `r += s·b` entry by entry on flat slices of one length (the one loop [`add_scaled`]
/// and the run-time-sized build use).
pub(crate) const fn add_scaled_flat(r: &mut [f64], s: f64, b: &[f64]) {
    let (mut i, len) = (0, if r.len() < b.len() { r.len() } else { b.len() });
    while i < len {
        r[i] += s * b[i];
        i += 1;
    }
}

/// `s·a`.
pub(crate) const fn scaled<const R: usize, const C: usize>(s: f64, a: &Mat<R, C>) -> Mat<R, C> {
    add_scaled(&[[0.0; C]; R], s, a)
}

/// Matrix product `a·b` (`a` is `R×K`, `b` is `K×C`). `O(R·K·C)` flops.
pub(crate) const fn mul<const R: usize, const K: usize, const C: usize>(
    a: &Mat<R, K>,
    b: &Mat<K, C>,
) -> Mat<R, C> {
    let mut r = [[0.0; C]; R];
    let mut i = 0;
    while i < R {
        let mut j = 0;
        while j < C {
            let mut s = 0.0;
            let mut k = 0;
            while k < K {
                s += a[i][k] * b[k][j];
                k += 1;
            }
            r[i][j] = s;
            j += 1;
        }
        i += 1;
    }
    r
}

/// `aᵀ`.
pub(crate) const fn transpose<const R: usize, const C: usize>(a: &Mat<R, C>) -> Mat<C, R> {
    transpose_filled(a, 0.0)
}

/// `aᵀ` of any `Copy` entries, the result first filled with `fill` (a value of the type,
/// as a `const fn` cannot make a default one): the one transpose of [`transpose`] and of
/// [`matrix!`](crate::matrix)'s row-to-column copy. Cost: `R·C` copies.
pub(crate) const fn transpose_filled<T: Copy, const R: usize, const C: usize>(
    a: &[[T; C]; R],
    fill: T,
) -> [[T; R]; C] {
    let mut t = [[fill; R]; C];
    let mut i = 0;
    while i < R {
        let mut j = 0;
        while j < C {
            t[j][i] = a[i][j];
            j += 1;
        }
        i += 1;
    }
    t
}

/// The `N×N` identity.
pub(crate) const fn identity<const N: usize>() -> Mat<N, N> {
    let mut r = [[0.0; N]; N];
    let mut i = 0;
    while i < N {
        r[i][i] = 1.0;
        i += 1;
    }
    r
}

/// Write the row-major `n×n` identity into `r` (`n²` values, all overwritten): the
/// run-time-sized twin of [`identity`].
#[cfg(feature = "std")]
pub(crate) fn identity_flat(r: &mut [f64], n: usize) {
    for (i, x) in r.iter_mut().enumerate() {
        *x = if i % (n + 1) == 0 { 1.0 } else { 0.0 };
    }
}

/// `√x` for finite `x ≥ 0`, in `const`: Newton's iteration from a bit-level first guess
/// (relative error ≤ 6 %), iterated until it stops changing (≤ 1 ulp from the correctly
/// rounded root; at most 64 iterations, 6 for normal numbers). `NaN` for `x < 0`.
pub(crate) const fn sqrt(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    if x < 0.0 {
        return f64::NAN;
    }
    let mut y = f64::from_bits((x.to_bits() >> 1) + 0x1FF8_0000_0000_0000);
    let mut i = 0;
    while i < 64 {
        let z = 0.5 * (y + x / y);
        if z == y {
            break;
        }
        y = z;
        i += 1;
    }
    y
}

/// A `nalgebra` matrix (column-major, any `T`) as row-major `f64` (exact).
pub(crate) fn rows_f64<T: Real, const R: usize, const C: usize>(a: &SMatrix<T, R, C>) -> Mat<R, C> {
    core::array::from_fn(|i| core::array::from_fn(|j| a[(i, j)].as_f64()))
}

/// Round a row-major `f64` matrix once to `T` (run time; see [`const_round!`] for `const`).
pub(crate) fn round_rows<T: Real, const R: usize, const C: usize>(a: &Mat<R, C>) -> [[T; C]; R] {
    a.map(|row| row.map(T::from_f64_rounded))
}

/// Round an `f64` vector once to `T`.
pub(crate) fn round_vec<T: Real, const N: usize>(a: &[f64; N]) -> [T; N] {
    a.map(T::from_f64_rounded)
}

/// `x` (computed in `f64`) fits the scalar type whose largest finite value is `max`:
/// finite and at most `max` in size, so it does not round to `∞`. Values within half an
/// ulp above `max` would still round to it, and are rejected too (harmless). The one
/// overflow test of every build (operators, kinematics, spectra, material laws).
pub(crate) const fn fits_value(x: f64, max: f64) -> bool {
    x.is_finite() && x.abs() <= max
}

/// Every value of `xs` [fits](fits_value) the scalar type whose largest finite value is
/// `max`.
pub(crate) const fn all_fit(xs: &[f64], max: f64) -> bool {
    let mut i = 0;
    while i < xs.len() {
        if !fits_value(xs[i], max) {
            return false;
        }
        i += 1;
    }
    true
}

/// Every entry of `a`, rounded to `T` (largest finite value `max`), is finite: an operator
/// that overflows when rounded (e.g. `1e39` to `f32`) is rejected rather than stored as `∞`.
pub(crate) const fn finite_as<const R: usize, const C: usize>(a: &Mat<R, C>, max: f64) -> bool {
    let mut i = 0;
    while i < R {
        if !all_fit(&a[i], max) {
            return false;
        }
        i += 1;
    }
    true
}

/// Round `f64` rows once to `f32` (round-to-nearest), in `const` contexts.
pub(crate) const fn rows_to_f32<const R: usize, const C: usize>(a: &Mat<R, C>) -> [[f32; C]; R] {
    let mut r = [[0.0; C]; R];
    let mut i = 0;
    while i < R {
        r[i] = vec_to_f32(&a[i]);
        i += 1;
    }
    r
}

/// Round an `f64` vector once to `f32` (round-to-nearest), in `const` contexts.
pub(crate) const fn vec_to_f32<const N: usize>(a: &[f64; N]) -> [f32; N] {
    let mut r = [0.0; N];
    let mut i = 0;
    while i < N {
        r[i] = a[i] as f32;
        i += 1;
    }
    r
}

/// `*a`, in `const` contexts (the `f64` arm of [`const_round!`]).
pub(crate) const fn copied<A: Copy>(a: &A) -> A {
    *a
}

/// `const_round!(f32, rows x)` / `const_round!(f64, vec x)`: an `f64` array (rows or a
/// vector) as the scalar type a `const` constructor is written for. `f64` is the identity,
/// `f32` rounds once — the same rounding as [`round_rows`] at run time.
macro_rules! const_round {
    (f64, rows $a:expr) => {
        $crate::linalg::copied(&$a)
    };
    (f64, vec $a:expr) => {
        $crate::linalg::copied(&$a)
    };
    (f32, rows $a:expr) => {
        $crate::linalg::rows_to_f32(&$a)
    };
    (f32, vec $a:expr) => {
        $crate::linalg::vec_to_f32(&$a)
    };
    (f64, kin $a:expr) => {
        $a.to_f64()
    };
    (f32, kin $a:expr) => {
        $a.to_f32()
    };
}
pub(crate) use const_round;

/// `|a_ij − a_ji| ≤ rel · max|a|` for every pair (not a finiteness check: callers check
/// that first). Cost: `N²/2` comparisons.
pub(crate) const fn is_symmetric<const N: usize>(a: &Mat<N, N>, rel: f64) -> bool {
    let tol = rel * max_abs(a);
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < i {
            if (a[i][j] - a[j][i]).abs() > tol {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

/// Whether `a`, computed from `source`, fits the scalar type whose largest finite value
/// is `max` (`f64::MAX` or `f32::MAX`), in one pass over `a`:
/// [`Error::OperatorOverflow`](crate::Error::OperatorOverflow) if an entry is not finite or
/// exceeds `max`; [`Error::OperatorUnderflow`](crate::Error::OperatorUnderflow) if `a` is
/// zero while `source` is not (`source` is read only then), or if its largest entry is
/// subnormal in that type. Normwise, an operator whose largest entry is normal keeps its
/// precision: the absolute error of its subnormal entries is below `ε` times that entry.
pub(crate) const fn fits<const R: usize, const C: usize, const R2: usize, const C2: usize>(
    a: &Mat<R, C>,
    source: &Mat<R2, C2>,
    max: f64,
) -> Result<(), crate::Error> {
    fits_flat(a.as_flattened(), source.as_flattened(), max)
}

/// [`fits`] on flat slices (any shapes): the one check both use.
pub(crate) const fn fits_flat(a: &[f64], source: &[f64], max: f64) -> Result<(), crate::Error> {
    let mut m = 0.0f64;
    let (mut i, len) = (0, a.len());
    while i < len {
        if !fits_value(a[i], max) {
            return Err(crate::Error::OperatorOverflow);
        }
        let x = a[i].abs();
        if x > m {
            m = x;
        }
        i += 1;
    }
    let min_normal = if max > f32::MAX as f64 {
        f64::MIN_POSITIVE
    } else {
        f32::MIN_POSITIVE as f64
    };
    if (m == 0.0 && max_abs_flat(source) != 0.0) || (m != 0.0 && m < min_normal) {
        return Err(crate::Error::OperatorUnderflow);
    }
    Ok(())
}

/// [`fits`] judged on `a` alone, for operators with no one source matrix to tell an
/// operator flushed to zero from one that is zero (the exact scheme's exponential blocks,
/// the modal operators): overflow, or a largest entry that is subnormal in the type.
pub(crate) const fn fits_alone<const R: usize, const C: usize>(
    a: &Mat<R, C>,
    max: f64,
) -> Result<(), crate::Error> {
    fits(a, a, max)
}

/// The verdict of several [`fits`] checks: an overflow if any, else an underflow if any
/// (the same verdict whatever the order of the checks).
pub(crate) const fn first_error<const L: usize>(
    fit: [Result<(), crate::Error>; L],
) -> Option<crate::Error> {
    let mut under = None;
    let mut i = 0;
    while i < L {
        match fit[i] {
            Err(crate::Error::OperatorUnderflow) => under = Some(crate::Error::OperatorUnderflow),
            Err(e) => return Some(e),
            Ok(()) => {}
        }
        i += 1;
    }
    under
}

/// Copy the `R2×C2` block `src` into `dst` at row `r0`, column `c0` (entries outside
/// `dst` are skipped).
pub(crate) const fn put<const R1: usize, const C1: usize, const R2: usize, const C2: usize>(
    dst: &mut Mat<R1, C1>,
    src: &Mat<R2, C2>,
    r0: usize,
    c0: usize,
) {
    let mut i = 0;
    while i < R2 {
        let mut j = 0;
        while j < C2 {
            if r0 + i < R1 && c0 + j < C1 {
                dst[r0 + i][c0 + j] = src[i][j];
            }
            j += 1;
        }
        i += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `const` square root is within 1 ulp of the correctly rounded one (libm's
    /// `sqrt` is correctly rounded) over 40 decades and at the edges.
    #[test]
    fn const_sqrt_within_one_ulp() {
        let mut x = 1e-300f64;
        let mut worst = 0u64;
        while x < 1e300 {
            for f in [1.0, 1.37, 2.0, 3.99, 7.3] {
                let v = x * f;
                let (a, b) = (sqrt(v).to_bits(), nalgebra::ComplexField::sqrt(v).to_bits());
                worst = worst.max(a.abs_diff(b));
            }
            x *= 1.0e10;
        }
        assert!(worst <= 1, "{worst} ulp");
        assert_eq!(sqrt(0.0), 0.0);
        assert_eq!(sqrt(4.0), 2.0);
        assert!(sqrt(-1.0).is_nan());
        assert_eq!(sqrt(f64::INFINITY), f64::INFINITY);
        // Subnormal input still converges.
        let t = 4.9e-324f64;
        assert!((sqrt(t) - 2.2227587494850775e-162).abs() <= 1e-177);
    }
}
