//! LU factorization with partial (row) pivoting.
//!
//! [`Lu`] is the `const fn` `f64` factorization every constant operator is built with:
//! `G = M_eff⁻¹` is [`Lu::solve`] with the identity, `G C` and `G K` are solves with `C`
//! and `K` (no explicit inverse is multiplied). [`solve_in_place`] is the generic
//! (`f32`/`f64`) in-place solve of the per-step systems of the nonlinear and
//! time-varying steppers.
//!
//! **Singular to working precision**, judged row by row. Each row `i` has a scale `s_i`:
//! the size of the *terms* it was assembled from (for `M + (h/2) C + (h²/4) K`, the
//! largest `|M_ij| + (h/2)|C_ij| + (h²/4)|K_ij|` of the row), not of the assembled entries.
//! Pivots are chosen by scaled partial pivoting (largest `|a_rc| / s_r`), and a pivot with
//! `|a_rc| ≤ N·ε·s_r` rejects the matrix. So a sum that cancels to rounding noise is
//! singular however its noise is scaled, while an exactly invertible but badly scaled
//! matrix (`diag(1e16, 1)`) is not: scaling a row scales its terms alike.

use nalgebra::{SMatrix, SVector};

use super::{Mat, identity, max_abs_flat};
use crate::Real;

/// `P A = L U` of an `N×N` `f64` matrix, `L` unit lower triangular, both stored in `lu`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lu<const N: usize> {
    lu: Mat<N, N>,
    /// Row `i` of `P A` is row `perm[i]` of `A`.
    perm: [usize; N],
}

impl<const N: usize> Lu<N> {
    /// Factorize `a` with the row scales `scales` (the size of the terms each row was
    /// assembled from; [`row_scales`] for data). `None` when the matrix is singular to
    /// working precision (see the module docs), or a scale is zero or not finite. Inputs
    /// must be finite. Cost: `N³/3` multiply-adds.
    pub(crate) const fn new(a: &Mat<N, N>, scales: &[f64; N]) -> Option<Self> {
        let mut lu = *a;
        let mut s = *scales;
        let mut perm = [0usize; N];
        if factor(lu.as_flattened_mut(), N, &mut s, &mut perm) {
            Some(Self { lu, perm })
        } else {
            None
        }
    }

    /// `A⁻¹ B` for an `N×C` right-hand side (forward and back substitution, column by
    /// column; [`solve_flat`]). Cost: `N²·C` multiply-adds.
    pub(crate) const fn solve<const C: usize>(&self, b: &Mat<N, C>) -> Mat<N, C> {
        let mut x = [[0.0; C]; N];
        solve_flat(
            self.lu.as_flattened(),
            &self.perm,
            b.as_flattened(),
            C,
            x.as_flattened_mut(),
        );
        x
    }

    /// The factorization from the output of [`factor`] (`lu` and `perm` as it left them).
    pub(crate) const fn from_parts(lu: Mat<N, N>, perm: [usize; N]) -> Self {
        Self { lu, perm }
    }

    /// The factors and the permutation, flat (for the flat-slice solves).
    pub(crate) const fn parts(&self) -> (&[f64], &[usize]) {
        (self.lu.as_flattened(), &self.perm)
    }

    /// `A⁻¹` (the solve with the identity). Cost: `N³` multiply-adds.
    pub(crate) const fn inverse(&self) -> Mat<N, N> {
        self.solve(&identity())
    }
}

/// Factorize the row-major `n×n` matrix `lu` in place (`P A = L U`, `L` unit lower
/// triangular, both stored in `lu`; `perm[i]`: the row of `A` that is row `i` of `P A`),
/// with the row scales `s` (permuted alongside): the one factorization behind [`Lu::new`]
/// and the run-time-sized operator build (`std`). `false` when the matrix is singular to
/// working precision (see the module docs) or a scale is zero or not finite; inputs must
/// be finite and the slices hold `n²`, `n`, `n` values (`false` if they do not).
/// Cost: `n³/3` multiply-adds.
pub(crate) const fn factor(lu: &mut [f64], n: usize, s: &mut [f64], perm: &mut [usize]) -> bool {
    if lu.len() != n * n || s.len() != n || perm.len() != n {
        return false;
    }
    let tiny = (n as f64) * f64::EPSILON;
    let mut i = 0;
    while i < n {
        if !(s[i].is_finite() && s[i] > 0.0) {
            return false;
        }
        perm[i] = i;
        i += 1;
    }
    let mut col = 0;
    while col < n {
        // Scaled partial pivoting: the largest |a_rc| / s_r at or below the diagonal.
        let mut piv = col;
        let mut best = lu[col * n + col].abs() / s[col];
        let mut r = col + 1;
        while r < n {
            let x = lu[r * n + col].abs() / s[r];
            if x > best {
                best = x;
                piv = r;
            }
            r += 1;
        }
        if best.is_nan() || best <= tiny {
            return false;
        }
        if piv != col {
            let (pn, cn) = (piv * n, col * n);
            let mut j = 0;
            while j < n {
                let t = lu[pn + j];
                lu[pn + j] = lu[cn + j];
                lu[cn + j] = t;
                j += 1;
            }
            let t = perm[piv];
            perm[piv] = perm[col];
            perm[col] = t;
            let t = s[piv];
            s[piv] = s[col];
            s[col] = t;
        }
        let d = lu[col * n + col];
        r = col + 1;
        while r < n {
            // Row offsets hoisted: the inner loop costs the compiler's evaluator no more
            // than indexing `[[f64; N]; N]` did (`Linear<f32, 63>` in a `static`).
            let (rn, cn) = (r * n, col * n);
            let f = lu[rn + col] / d;
            lu[rn + col] = f;
            if f != 0.0 {
                // lu[r][j] -= f·lu[col][j] for j > col, by running flat indices.
                let (mut a, mut b, end) = (rn + col + 1, cn + col + 1, rn + n);
                while a < end {
                    lu[a] -= f * lu[b];
                    a += 1;
                    b += 1;
                }
            }
            r += 1;
        }
        col += 1;
    }
    true
}

/// `x = A⁻¹ B` from the factors of [`factor`] (`lu`: `n×n` with `n = perm.len()`), `B`
/// and `x` row-major `n×c`: forward and back substitution, column by column. The one
/// solve behind [`Lu::solve`] and the run-time-sized build. Cost: `n²·c` multiply-adds.
pub(crate) const fn solve_flat(lu: &[f64], perm: &[usize], b: &[f64], c: usize, x: &mut [f64]) {
    // (`lu.len()` read once: in the compiler's evaluator each call is a step.)
    let (n, lu_len) = (perm.len(), lu.len());
    let mut col = 0;
    while col < c {
        // L y = P b (row offsets and column strides hoisted, see `factor`)
        let mut i = 0;
        while i < n {
            let mut s = b[perm[i] * c + col];
            // s −= lu[i][k]·x[k][col] for k < i, by running flat indices (`end` checked
            // once: the loop's `lu[l]` needs no bounds check, a traced call in the fuzz
            // build).
            let (mut l, end, mut xk) = (i * n, i * n + i, col);
            assert!(end <= lu_len);
            while l < end {
                s -= lu[l] * x[xk];
                xk += c;
                l += 1;
            }
            x[i * c + col] = s;
            i += 1;
        }
        // U x = y
        let mut i = n;
        while i > 0 {
            i -= 1;
            let li = i * n;
            let mut s = x[i * c + col];
            // s −= lu[i][k]·x[k][col] for k > i, by running flat indices.
            let (mut l, end, mut xk) = (li + i + 1, li + n, (i + 1) * c + col);
            assert!(end <= lu_len);
            while l < end {
                s -= lu[l] * x[xk];
                xk += c;
                l += 1;
            }
            x[i * c + col] = s / lu[li + i];
        }
        col += 1;
    }
}

/// The largest `|a_ij|` of each row: the row scales of a matrix that is data (not
/// assembled from terms).
pub(crate) const fn row_scales<const N: usize>(a: &Mat<N, N>) -> [f64; N] {
    let mut s = [0.0; N];
    row_scales_flat(a.as_flattened(), &mut s);
    s
}

/// [`row_scales`] of a row-major `n×n` matrix `a` into `s` (`n = s.len()`).
pub(crate) const fn row_scales_flat(a: &[f64], s: &mut [f64]) {
    let n = s.len();
    let (mut i, mut rest) = (0, a);
    while i < n {
        s[i] = match rest.split_at_checked(n) {
            Some((row, r)) => {
                rest = r;
                max_abs_flat(row)
            }
            None => 0.0,
        };
        i += 1;
    }
}

/// `κ₁` of the row-equilibrated matrix, `‖D⁻¹A‖₁ ‖A⁻¹D‖₁` with `D = diag(scales)`, from
/// `A` and its inverse: how close to singular the matrix is at the precision its rows
/// were assembled in (`1/κ` is the relative distance to a singular matrix). `O(N²)`.
pub(crate) const fn condition<const N: usize>(
    a: &Mat<N, N>,
    inv: &Mat<N, N>,
    scales: &[f64; N],
) -> f64 {
    condition_flat(a.as_flattened(), inv.as_flattened(), scales)
}

/// [`condition`] of row-major `n×n` `a` and `inv` (`n = scales.len()`): the one loop both
/// sizes use.
pub(crate) const fn condition_flat(a: &[f64], inv: &[f64], scales: &[f64]) -> f64 {
    let n = scales.len();
    let (mut na, mut ni) = (0.0f64, 0.0f64);
    let mut j = 0;
    while j < n {
        let (mut ca, mut ci) = (0.0, 0.0);
        let mut i = 0;
        while i < n {
            ca += a[i * n + j].abs() / scales[i];
            ci += inv[i * n + j].abs() * scales[j];
            i += 1;
        }
        if ca > na {
            na = ca;
        }
        if ci > ni {
            ni = ci;
        }
        j += 1;
    }
    na * ni
}

/// Solve `A x = b` in place (`b` becomes `x`) by Gaussian elimination with partial
/// pivoting; `a` is overwritten. Returns `false` — with `b` unspecified — when a pivot is
/// not finite or at most `N·ε·scale` (`scale`: the size of the terms `A` was assembled
/// from), i.e. `A` is singular to working precision. Cost: `N³/3 + N²` multiply-adds; no
/// allocation, no panic.
pub(crate) fn solve_in_place<T: Real, const N: usize>(
    a: &mut SMatrix<T, N, N>,
    b: &mut SVector<T, N>,
    scale: T,
) -> bool {
    solve_in_place_scaled(a, b, &SVector::repeat(scale))
}

/// [`solve_in_place`] with a scale per row (scaled partial pivoting, as [`Lu::new`]): the
/// pivot of row `r` must exceed `N·ε·scales[r]`, the size of the terms the row was
/// assembled from. Cost: `N³/3 + N²` multiply-adds; no allocation, no panic.
pub(crate) fn solve_in_place_scaled<T: Real, const N: usize>(
    a: &mut SMatrix<T, N, N>,
    b: &mut SVector<T, N>,
    scales: &SVector<T, N>,
) -> bool {
    let tiny = T::from_f64_rounded(N as f64) * T::default_epsilon();
    // Column-major storage, `a[c][r]` = A(r, c); plain array indexing with loop-bounded
    // indices, which the compiler proves in bounds (no panic path in the binary).
    let a = &mut a.data.0;
    let x = &mut b.data.0[0];
    let mut s = scales.data.0[0];
    for col in 0..N {
        let mut piv = col;
        let mut best = a[col][col].abs() / s[col];
        for r in col + 1..N {
            let e = a[col][r].abs() / s[r];
            if e > best {
                best = e;
                piv = r;
            }
        }
        // A NaN or infinite pivot (or scale) is rejected too.
        if !best.is_finite() || best <= tiny {
            return false;
        }
        if piv != col {
            for column in a.iter_mut() {
                column.swap(piv, col);
            }
            x.swap(piv, col);
            s.swap(piv, col);
        }
        let d = a[col][col];
        for r in col + 1..N {
            let f = a[col][r] / d;
            if f != T::zero() {
                for k in col + 1..N {
                    let p = a[k][col];
                    a[k][r] -= f * p;
                }
                let xc = x[col];
                x[r] -= f * xc;
            }
        }
    }
    for col in (0..N).rev() {
        let mut t = x[col];
        for k in col + 1..N {
            t -= a[k][col] * x[k];
        }
        x[col] = t / a[col][col];
    }
    true
}

/// [`solve_in_place_scaled`] on slices: `a` the `n×n` matrix column by column (`a[c·n + r]`
/// = A(r, c), overwritten), `b` the right-hand side of `n = b.len()` values (becomes `x`),
/// `s` the row scales (permuted alongside): the one elimination of the const-generic steps
/// and the run-time-sized shear building (`std`). `false` — with `b` unspecified — when a
/// pivot is not finite or at most `n·ε·s[r]`, or a slice has the wrong length. Cost:
/// `n³/3 + n²` multiply-adds; no allocation. The same elimination, in the same order, as
/// [`solve_in_place_scaled`] on its arrays (`tests/runtime_size.rs` checks the bits on the
/// dense path); the const-generic step keeps the array version: through this one the
/// Cortex-M4F `hysteretic_3` step took 3524 instructions against 3323 (`scripts/qemu.sh`).
#[cfg(feature = "std")]
pub(crate) fn solve_in_place_flat<T: Real>(a: &mut [T], x: &mut [T], s: &mut [T]) -> bool {
    let n = x.len();
    if a.len() != n * n || s.len() != n {
        return false;
    }
    let tiny = T::from_f64_rounded(n as f64) * T::default_epsilon();
    for col in 0..n {
        let mut piv = col;
        let mut best = a[col * n + col].abs() / s[col];
        for r in col + 1..n {
            let e = a[col * n + r].abs() / s[r];
            if e > best {
                best = e;
                piv = r;
            }
        }
        // A NaN or infinite pivot (or scale) is rejected too.
        if !best.is_finite() || best <= tiny {
            return false;
        }
        if piv != col {
            for column in a.chunks_exact_mut(n) {
                column.swap(piv, col);
            }
            x.swap(piv, col);
            s.swap(piv, col);
        }
        let (head, tail) = a.split_at_mut((col + 1) * n);
        let pivot = &head[col * n..];
        let d = pivot[col];
        for r in col + 1..n {
            let f = pivot[r] / d;
            if f != T::zero() {
                for column in tail.chunks_exact_mut(n) {
                    let p = column[col];
                    column[r] -= f * p;
                }
                let xc = x[col];
                x[r] -= f * xc;
            }
        }
    }
    for col in (0..n).rev() {
        let mut t = x[col];
        for k in col + 1..n {
            t -= a[k * n + col] * x[k];
        }
        x[col] = t / a[col * n + col];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::mul;

    #[test]
    fn inverse_of_known_matrix() {
        let a = [[4.0, 3.0], [6.0, 3.0]];
        let inv = Lu::new(&a, &row_scales(&a)).unwrap().inverse();
        let expect = [[-0.5, 0.5], [1.0, -2.0 / 3.0]];
        for i in 0..2 {
            for j in 0..2 {
                assert!(
                    (inv[i][j] - expect[i][j]).abs() <= 2.0 * f64::EPSILON,
                    "{inv:?}"
                );
            }
        }
    }

    #[test]
    fn solve_needs_pivoting_and_detects_singularity() {
        // Zero leading entry: needs a row swap.
        let a = [[0.0, 1.0, 2.0], [1.0, 0.0, 3.0], [4.0, -3.0, 8.0]];
        let inv = Lu::new(&a, &row_scales(&a)).unwrap().inverse();
        let id = mul(&a, &inv);
        for i in 0..3 {
            for j in 0..3 {
                let e = if i == j { 1.0 } else { 0.0 };
                // Residual of a backward-stable solve: a few ε·‖A‖·‖A⁻¹‖ (here ‖A‖‖A⁻¹‖ ≈ 60).
                assert!((id[i][j] - e).abs() < 60.0 * 8.0 * f64::EPSILON, "{id:?}");
            }
        }
        // Rank 2: third row is the sum of the first two.
        let s = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [5.0, 7.0, 9.0]];
        assert!(Lu::new(&s, &row_scales(&s)).is_none());
        assert!(Lu::new(&[[0.0; 2]; 2], &[0.0; 2]).is_none());
        // Cancellation judged against the terms: 1 + (−1 + 1e-17) is zero to rounding.
        assert!(Lu::new(&[[1e-17]], &[1.0]).is_none());
        assert!(Lu::new(&[[1e-17]], &[1e-17]).is_some());
        // Badly scaled but exactly invertible: not singular, and solved exactly.
        let d = [[1e16, 0.0], [0.0, 1.0]];
        let lu = Lu::new(&d, &row_scales(&d)).unwrap();
        assert_eq!(lu.inverse(), [[1e-16, 0.0], [0.0, 1.0]]);
        assert_eq!(condition(&d, &lu.inverse(), &row_scales(&d)), 1.0);
    }

    #[test]
    fn const_and_generic_solves_agree() {
        let a = [[2.0, 0.3, 0.1], [0.3, 1.0, -0.2], [0.1, -0.2, 3.0]];
        let b = [[1.0], [2.0], [3.0]];
        let x = Lu::new(&a, &row_scales(&a)).unwrap().solve(&b);
        let mut am = SMatrix::<f64, 3, 3>::from_fn(|i, j| a[i][j]);
        let mut bv = SVector::<f64, 3>::new(1.0, 2.0, 3.0);
        assert!(solve_in_place(&mut am, &mut bv, 3.0));
        for i in 0..3 {
            assert!((x[i][0] - bv[i]).abs() <= 4.0 * f64::EPSILON * x[i][0].abs());
        }
    }
}
