//! Symmetric tridiagonal solves: `A = L D Lᵀ` without pivoting, `O(N)`, for the Newton
//! matrix of a shear building (`J = M + (h/2) C + (h²/4) K_t`, every term tridiagonal).
//!
//! Elimination without pivoting is backward stable when `A` is symmetric positive definite
//! (it is then Cholesky's factorization in another form, Higham, *Accuracy and Stability of
//! Numerical Algorithms*, §10.1 and §9.5). `A` is positive definite exactly when every
//! pivot `d_i` is positive; a pivot that is not positive, not finite or at most `N·ε·scale`
//! makes the solve decline (`false`), and the caller uses LU with partial pivoting
//! instead. So the structured solve is taken only where it is as accurate as the dense one.

use nalgebra::{SMatrix, SVector};

use crate::Real;

/// A symmetric tridiagonal `N×N` matrix: the stiffness, damping or mass of a chain of
/// degrees of freedom (a shear building, masses and springs in series).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SymTridiagonal<T, const N: usize> {
    /// The diagonal, `A_ii`.
    pub diagonal: SVector<T, N>,
    /// The off-diagonal: `off[i] = A_{i,i−1} = A_{i−1,i}` for `i ≥ 1`; `off[0]` is not
    /// read (keep it zero).
    pub off: SVector<T, N>,
}

impl<T: Real, const N: usize> SymTridiagonal<T, N> {
    /// `A x`, each row summed in column order (`A_{i,i−1} x_{i−1} + A_ii x_i +
    /// A_{i,i+1} x_{i+1}`): the same value as the dense product, whose other terms are
    /// exact zeros. Cost: `3N` multiplies, `2N` adds.
    pub fn mul(&self, x: &SVector<T, N>) -> SVector<T, N> {
        let mut y = [T::zero(); N];
        mul_flat(
            &self.diagonal.data.0[0],
            &self.off.data.0[0],
            &x.data.0[0],
            &mut y,
        );
        SVector::from(y)
    }

    /// The same matrix laid out densely (`N×N`, zero off the three diagonals). Cost: `N²`.
    pub fn to_matrix(&self) -> SMatrix<T, N, N> {
        SMatrix::from_fn(|row, col| match row.abs_diff(col) {
            0 => self.diagonal[row],
            1 => self.off[row.max(col)],
            _ => T::zero(),
        })
    }

    /// The zero matrix.
    pub(crate) fn zero() -> Self {
        Self {
            diagonal: SVector::zeros(),
            off: SVector::zeros(),
        }
    }

    /// Every entry read (the diagonal and `off[1..]`) is finite. Cost: `2N`.
    pub(crate) fn is_finite(&self) -> bool {
        self.diagonal.iter().all(|x| x.is_finite())
            && self.off.iter().skip(1).all(|x| x.is_finite())
    }
}

/// Solve `A x = b` in place (`b` becomes `x`) for a symmetric tridiagonal `A` by `L D Lᵀ`.
/// Returns `false` — with `b` unspecified — when a pivot is not finite or not above
/// `N·ε·scale` (`scale`: the size of the terms `A` was assembled from, as
/// [`lu::solve_in_place`](super::lu::solve_in_place)): `A` is then not positive definite to
/// working precision. Cost: `N` divisions, `6N` multiply-or-adds; no allocation, no panic.
#[inline]
pub(crate) fn solve_positive<T: Real, const N: usize>(
    a: &SymTridiagonal<T, N>,
    b: &mut SVector<T, N>,
    scale: T,
) -> bool {
    let mut inv = [T::zero(); N];
    solve_positive_flat(
        &a.diagonal.data.0[0],
        &a.off.data.0[0],
        &mut b.data.0[0],
        &mut inv,
        scale,
    )
}

/// `y = A x` for the symmetric tridiagonal `A` of diagonal `d` and off-diagonal `e`
/// (`e[0]` not read), `n = y.len()` rows, each summed in column order: the one product
/// behind [`SymTridiagonal::mul`] and the run-time-sized shear building (`std`). Every
/// slice holds `n` values. Cost: `3n` multiplies, `2n` adds.
#[inline(always)]
pub(crate) fn mul_flat<T: Real>(d: &[T], e: &[T], x: &[T], y: &mut [T]) {
    let n = y.len();
    for i in 0..n {
        let mut s = T::zero();
        if i > 0 {
            s = e[i] * x[i - 1];
        }
        s += d[i] * x[i];
        if i + 1 < n {
            s += e[i + 1] * x[i + 1];
        }
        y[i] = s;
    }
}

/// [`solve_positive`] on slices (`n = b.len()`; `d`, `e` and the work space `inv`, which
/// receives `1/d_i` of the factorization, hold `n` values each): the one `L D Lᵀ` solve
/// of the const-generic and the run-time-sized (`std`) Newton iterations. Returns `false`
/// — with `b` unspecified — as [`solve_positive`]. Cost: `n` divisions, `6n`
/// multiply-or-adds; no allocation.
#[inline(always)]
pub(crate) fn solve_positive_flat<T: Real>(
    d: &[T],
    e: &[T],
    b: &mut [T],
    inv: &mut [T],
    scale: T,
) -> bool {
    let n = b.len();
    let tiny = T::from_f64_rounded(n as f64) * T::default_epsilon() * scale;
    let x = b;
    let mut prev = T::zero(); // 1 / d_{i−1}
    for i in 0..n {
        let l = e[i] * prev; // l_i = e_i / d_{i−1}; e_0 is not read (prev = 0)
        let di = if i == 0 { d[0] } else { d[i] - l * e[i] };
        // A NaN pivot fails `di > tiny` too.
        let accepted = di > tiny && di.is_finite();
        if !accepted {
            return false;
        }
        if i > 0 {
            x[i] -= l * x[i - 1];
        }
        prev = T::one() / di;
        inv[i] = prev;
    }
    for i in (0..n).rev() {
        let upper = if i + 1 < n {
            e[i + 1] * x[i + 1]
        } else {
            T::zero()
        };
        x[i] = (x[i] - upper) * inv[i];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::lu::solve_in_place;

    /// A positive definite shear-building-like matrix: the solve agrees with pivoted LU to
    /// a few `κ ε` (here `κ(A) < 10`, so well under `1e-14`), and `A x` gives `b` back.
    #[test]
    fn solves_like_lu_on_positive_definite() {
        const N: usize = 7;
        let a = SymTridiagonal::<f64, N> {
            diagonal: SVector::from_fn(|i, _| 4.0 + 0.25 * i as f64),
            off: SVector::from_fn(|i, _| if i == 0 { 0.0 } else { -1.0 - 0.1 * i as f64 }),
        };
        let b = SVector::<f64, N>::from_fn(|i, _| (i as f64 * 0.7).sin());
        let mut x = b;
        assert!(solve_positive(&a, &mut x, 5.0));
        let (mut lu, mut y) = (a.to_matrix(), b);
        assert!(solve_in_place(&mut lu, &mut y, 5.0));
        let err = (x - y).amax() / y.amax();
        assert!(err < 1e-14, "tridiagonal vs LU: {err:e}");
        let back = (a.to_matrix() * x - b).amax();
        assert!(back < 1e-14, "residual {back:e}");
    }

    /// Indefinite, singular and NaN matrices are declined (the caller then pivots).
    #[test]
    fn declines_what_is_not_positive_definite() {
        let indefinite = SymTridiagonal::<f64, 2> {
            diagonal: SVector::from([1.0, 1.0]),
            off: SVector::from([0.0, 2.0]),
        };
        let singular = SymTridiagonal::<f64, 2> {
            diagonal: SVector::from([1.0, 1.0]),
            off: SVector::from([0.0, 1.0]),
        };
        let nan = SymTridiagonal::<f64, 2> {
            diagonal: SVector::from([f64::NAN, 1.0]),
            off: SVector::from([0.0, 0.0]),
        };
        for a in [indefinite, singular, nan] {
            let mut x = SVector::from([1.0, 1.0]);
            assert!(!solve_positive(&a, &mut x, 2.0), "{a:?}");
        }
        // A 1×1 and a diagonal matrix (no coupling) are solved exactly.
        let one = SymTridiagonal::<f64, 1> {
            diagonal: SVector::from([4.0]),
            off: SVector::from([0.0]),
        };
        let mut x = SVector::from([2.0]);
        assert!(solve_positive(&one, &mut x, 4.0) && x[0] == 0.5);
    }
}
