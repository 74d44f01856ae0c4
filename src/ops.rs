//! Dense `f64` linear algebra in `const fn`, used to build the step operators.
//!
//! One implementation serves both paths: evaluated by the compiler for operators kept in
//! flash (`Linear::from_rows` in a `static`), and at run time by `Linear::new`. Both give
//! bit-identical operators, because IEEE `f64` arithmetic is the same in both places and
//! nothing here is fused.
//!
//! Matrices are row-major `[[f64; N]; N]`. Cost: O(N³) flops and a few `N×N` `f64`
//! temporaries on the stack (8·N² bytes each) — call it once, not per step.

use crate::Error;

/// Row-major `N×N` matrix of `f64`.
pub(crate) type Mat<const N: usize> = [[f64; N]; N];

/// All entries finite.
pub(crate) const fn all_finite<const N: usize>(a: &Mat<N>) -> bool {
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            if !a[i][j].is_finite() {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

/// `a + s·b`.
pub(crate) const fn add_scaled<const N: usize>(a: &Mat<N>, s: f64, b: &Mat<N>) -> Mat<N> {
    let mut r = *a;
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            r[i][j] += s * b[i][j];
            j += 1;
        }
        i += 1;
    }
    r
}

/// Matrix product `a·b`.
pub(crate) const fn mul<const N: usize>(a: &Mat<N>, b: &Mat<N>) -> Mat<N> {
    let mut r = [[0.0; N]; N];
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            let mut s = 0.0;
            let mut k = 0;
            while k < N {
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

/// Inverse by Gauss–Jordan elimination with partial (row) pivoting.
///
/// Returns `None` when a pivot falls to `N·ε·max|aᵢⱼ|` or below, i.e. when the matrix is
/// singular to working precision (this includes the zero matrix).
pub(crate) const fn inverse<const N: usize>(a: &Mat<N>) -> Option<Mat<N>> {
    let mut scale = 0.0f64;
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            let x = a[i][j].abs();
            if x > scale {
                scale = x;
            }
            j += 1;
        }
        i += 1;
    }
    let tiny = (N as f64) * f64::EPSILON * scale;
    let mut m = *a;
    let mut inv = [[0.0; N]; N];
    i = 0;
    while i < N {
        inv[i][i] = 1.0;
        i += 1;
    }
    let mut col = 0;
    while col < N {
        // Partial pivoting: largest entry of this column at or below the diagonal.
        let mut piv = col;
        let mut best = m[col][col].abs();
        let mut r = col + 1;
        while r < N {
            if m[r][col].abs() > best {
                best = m[r][col].abs();
                piv = r;
            }
            r += 1;
        }
        // Inputs are checked finite before this is called, so `best` is never NaN.
        if best <= tiny {
            return None;
        }
        if piv != col {
            let t = m[piv];
            m[piv] = m[col];
            m[col] = t;
            let t = inv[piv];
            inv[piv] = inv[col];
            inv[col] = t;
        }
        let d = m[col][col];
        let mut j = 0;
        while j < N {
            m[col][j] /= d;
            inv[col][j] /= d;
            j += 1;
        }
        r = 0;
        while r < N {
            if r != col {
                let f = m[r][col];
                if f != 0.0 {
                    j = 0;
                    while j < N {
                        m[r][j] -= f * m[col][j];
                        inv[r][j] -= f * inv[col][j];
                        j += 1;
                    }
                }
            }
            r += 1;
        }
        col += 1;
    }
    Some(inv)
}

/// The eliminated-form operators of the linear AEM step, in `f64`.
pub(crate) struct Operators<const N: usize> {
    /// `G = M_eff⁻¹`, `M_eff = M + (h/2) C + (h²/4) K`.
    pub g: Mat<N>,
    /// `G·C`.
    pub gc: Mat<N>,
    /// `G·K`.
    pub gk: Mat<N>,
    /// `(M⁻¹, M⁻¹C, M⁻¹K)` for the start-up acceleration (paper eq. 40); `None` if `M` is
    /// singular.
    pub start: Option<(Mat<N>, Mat<N>, Mat<N>)>,
}

/// Check `M, C, K, h` and build the operators (paper eqs. 19–23 in eliminated form).
pub(crate) const fn operators<const N: usize>(
    m: &Mat<N>,
    c: &Mat<N>,
    k: &Mat<N>,
    h: f64,
) -> Result<Operators<N>, Error> {
    if !(all_finite(m) && all_finite(c) && all_finite(k)) {
        return Err(Error::NonFiniteInput);
    }
    if !(h.is_finite() && h > 0.0) {
        return Err(Error::InvalidTimeStep);
    }
    let meff = add_scaled(&add_scaled(m, 0.5 * h, c), 0.25 * h * h, k);
    let g = match inverse(&meff) {
        Some(g) => g,
        None => return Err(Error::SingularEffectiveMatrix),
    };
    let start = match inverse(m) {
        Some(mi) => Some((mi, mul(&mi, c), mul(&mi, k))),
        None => None,
    };
    Ok(Operators {
        gc: mul(&g, c),
        gk: mul(&g, k),
        g,
        start,
    })
}

/// Rectangular product `a·b` (`a` is `R×K`, `b` is `K×C`, both row-major): for the
/// input operators `G·B` and `M⁻¹B` (issue 6). `O(R·K·C)` flops.
pub(crate) const fn mul_rect<const R: usize, const K: usize, const C: usize>(
    a: &[[f64; K]; R],
    b: &[[f64; C]; K],
) -> [[f64; C]; R] {
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

/// All entries of a rectangular row-major matrix finite.
pub(crate) const fn all_finite_rect<const R: usize, const C: usize>(a: &[[f64; C]; R]) -> bool {
    let mut i = 0;
    while i < R {
        let mut j = 0;
        while j < C {
            if !a[i][j].is_finite() {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

/// Round `f64` rows once to `f32` (round-to-nearest), in `const` contexts.
pub(crate) const fn rows_to_f32<const R: usize, const C: usize>(
    a: &[[f64; C]; R],
) -> [[f32; C]; R] {
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

/// `const_round!(f32, rows)` / `const_round!(f64, rows)`: an `f64` array (vector or
/// rows, `vec`/`rows` selects) as the scalar type the `const` constructors are written
/// for. `f64` is the identity, `f32` rounds once.
macro_rules! const_round {
    (f64, rows $a:expr) => {
        $crate::ops::copied(&$a)
    };
    (f64, vec $a:expr) => {
        $crate::ops::copied(&$a)
    };
    (f32, rows $a:expr) => {
        $crate::ops::rows_to_f32(&$a)
    };
    (f32, vec $a:expr) => {
        $crate::ops::vec_to_f32(&$a)
    };
}
pub(crate) use const_round;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_of_known_matrix() {
        let a = [[4.0, 3.0], [6.0, 3.0]];
        let inv = inverse(&a).unwrap();
        let expect = [[-0.5, 0.5], [1.0, -2.0 / 3.0]];
        for i in 0..2 {
            for j in 0..2 {
                assert!((inv[i][j] - expect[i][j]).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn inverse_needs_pivoting_and_detects_singularity() {
        // Zero leading entry: needs a row swap.
        let a = [[0.0, 1.0, 2.0], [1.0, 0.0, 3.0], [4.0, -3.0, 8.0]];
        let inv = inverse(&a).unwrap();
        let id = mul(&a, &inv);
        for i in 0..3 {
            for j in 0..3 {
                let e = if i == j { 1.0 } else { 0.0 };
                assert!((id[i][j] - e).abs() < 1e-14, "{id:?}");
            }
        }
        // Rank 2: third row is the sum of the first two.
        let s = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [5.0, 7.0, 9.0]];
        assert!(inverse(&s).is_none());
        assert!(inverse(&[[0.0; 2]; 2]).is_none());
    }
}
