//! Cholesky factorization `M = L Lᵀ` and the triangular solves with `L`, in `const fn`.

use super::Rows;

/// Cholesky factor `L` (lower, row-major) of a symmetric `m`; `None` unless every pivot
/// exceeds `N ε max|m|` (positive definite and not singular to working precision).
pub(crate) const fn cholesky<const N: usize>(m: &Rows<N>) -> Option<Rows<N>> {
    let mut l = [[0.0; N]; N];
    if crate::observer::cholesky_flat(m.as_flattened(), N, l.as_flattened_mut()) {
        Some(l)
    } else {
        None
    }
}

/// `L⁻¹ B` for lower-triangular `L` with a nonzero diagonal (forward substitution).
pub(crate) const fn lower_solve<const N: usize>(l: &Rows<N>, b: &Rows<N>) -> Rows<N> {
    let mut x = [[0.0; N]; N];
    let mut c = 0;
    while c < N {
        let mut i = 0;
        while i < N {
            let mut s = b[i][c];
            let mut k = 0;
            while k < i {
                s -= l[i][k] * x[k][c];
                k += 1;
            }
            x[i][c] = s / l[i][i];
            i += 1;
        }
        c += 1;
    }
    x
}

/// `L⁻ᵀ B` for lower-triangular `L` with a nonzero diagonal (back substitution).
pub(crate) const fn lower_transpose_solve<const N: usize>(l: &Rows<N>, b: &Rows<N>) -> Rows<N> {
    let mut x = [[0.0; N]; N];
    let mut c = 0;
    while c < N {
        let mut i = N;
        while i > 0 {
            i -= 1;
            let mut s = b[i][c];
            let mut k = i + 1;
            while k < N {
                s -= l[k][i] * x[k][c];
                k += 1;
            }
            x[i][c] = s / l[i][i];
        }
        c += 1;
    }
    x
}
