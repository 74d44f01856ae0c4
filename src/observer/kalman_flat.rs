//! The Kalman filter's step on flat column-major slices of the filter's scalar type: the
//! one arithmetic of the const-generic [`Kalman`](super::Kalman) (which calls it with its
//! `SMatrix` storage, `as_slice`), the dual and joint filters' innovation and gain
//! ([`innovation_t`](super::kalman_core::innovation_t), [`gain_t`](super::kalman_core::gain_t),
//! [`predict_t`](super::kalman_core::predict_t)) and the run-time-sized `DynKalman`.
//!
//! Every function reproduces the operation order of the `nalgebra` 0.35 code the filters
//! were first written with, so the const-generic filters' numbers did not move by one bit
//! (`tests/kalman_step_pin.rs`):
//!
//! * products of statically sized matrices (`gemm`, blas_uninit.rs): column by column,
//!   `c_ij = a_i0 b_0j`, then `c_ij = a_ip b_pj + c_ij` for `p = 1, 2, …` (no fused
//!   multiply-add; an empty inner dimension gives zeros);
//! * `Cholesky::new` (cholesky.rs): column `j` of the lower triangle updated by
//!   `l_ij = (−l_jk) l_ik + l_ij` for `k < j`, `i ≥ j`, then `l_jj = √l_jj` (refused when
//!   `l_jj` is zero, negative or NaN) and `l_ij = l_ij / l_jj`;
//! * `Cholesky::solve` (solve.rs): forward `b_i = b_i / l_ii`, `b_r = (−b_i) l_ri + b_r`,
//!   column by column; backward `b_i = (b_i − Σ_{r>i} l_ri b_r) / l_ii` with the sum of
//!   `dot` on dynamic views (eight accumulators over blocks of 8, then the tail);
//! * the symmetrization `(A + Aᵀ) · ½`, element-wise sums and differences in the order
//!   the filters wrote them.

use crate::{Error, Real};

/// A matrix in a flat slice with strides: entry `(i, j)` at `d[i·rs + j·cs]` (column-major
/// `rows×cols`: `rs = 1`, `cs = rows`; its transpose: `rs = rows`, `cs = 1`).
#[derive(Clone, Copy)]
pub(crate) struct View<'a, T> {
    d: &'a [T],
    rs: usize,
    cs: usize,
}

impl<'a, T: Copy> View<'a, T> {
    /// The column-major `rows×·` matrix in `d`.
    #[inline(always)]
    pub(crate) fn cm(d: &'a [T], rows: usize) -> Self {
        Self { d, rs: 1, cs: rows }
    }

    /// The transpose of the column-major `rows×·` matrix in `d`.
    #[inline(always)]
    pub(crate) fn tr(d: &'a [T], rows: usize) -> Self {
        Self { d, rs: rows, cs: 1 }
    }

    #[inline(always)]
    fn at(&self, i: usize, j: usize) -> T {
        self.d[i * self.rs + j * self.cs]
    }
}

/// `out = a b` (`m×n`, column-major; `a` is `m×k`, `b` is `k×n`) in `nalgebra`'s order
/// for static sizes ([module docs](self)). Cost: `m·k·n` multiply-adds.
#[inline(always)]
pub(crate) fn gemm<T: Real>(out: &mut [T], a: View<'_, T>, b: View<'_, T>, [m, k, n]: [usize; 3]) {
    if m == 0 {
        return;
    }
    for (j, col) in out.chunks_exact_mut(m).take(n).enumerate() {
        if k == 0 {
            col.fill(T::zero());
            continue;
        }
        let b0 = b.at(0, j);
        for (i, c) in col.iter_mut().enumerate() {
            *c = a.at(i, 0) * b0;
        }
        for p in 1..k {
            let bp = b.at(p, j);
            for (i, c) in col.iter_mut().enumerate() {
                *c = a.at(i, p) * bp + *c;
            }
        }
    }
}

/// `a = (a + aᵀ) · ½` in place (`n×n`). Cost: `n²` flops.
#[inline(always)]
pub(crate) fn sym_flat<T: Real>(a: &mut [T], n: usize) {
    let half = T::from_f64_rounded(0.5);
    for j in 0..n {
        for i in 0..=j {
            let m = (a[i + j * n] + a[j + i * n]) * half;
            a[i + j * n] = m;
            a[j + i * n] = m;
        }
    }
}

/// `a = a + b` element-wise.
#[inline(always)]
fn add_into<T: Real>(a: &mut [T], b: &[T]) {
    a.iter_mut().zip(b).for_each(|(x, y)| *x += *y);
}

/// `a = a − b` element-wise.
#[inline(always)]
fn sub_into<T: Real>(a: &mut [T], b: &[T]) {
    a.iter_mut().zip(b).for_each(|(x, y)| *x -= *y);
}

/// `Cholesky::new` in place on the column-major `n×n` `m` (lower triangle read and
/// written; the strict upper triangle left as it was): `false` when a pivot is zero,
/// negative or NaN (the matrix is not positive definite to working precision).
/// Cost: `n³/6` multiply-adds and `n` square roots.
#[inline(always)]
pub(crate) fn cholesky_cm<T: Real>(m: &mut [T], n: usize) -> bool {
    for j in 0..n {
        for k in 0..j {
            let factor = -m[j + k * n];
            for i in j..n {
                m[i + j * n] = factor * m[i + k * n] + m[i + j * n];
            }
        }
        let diag = m[j + j * n];
        if diag.is_zero() {
            return false;
        }
        let Some(denom) = diag.try_sqrt() else {
            return false;
        };
        m[j + j * n] = denom;
        for i in j + 1..n {
            m[i + j * n] /= denom;
        }
    }
    true
}

/// `nalgebra`'s `dot` on dynamic views: eight accumulators over blocks of 8, then the tail.
#[inline(always)]
fn dot_unrolled<T: Real>(a: &[T], b: &[T]) -> T {
    let len = a.len().min(b.len());
    let mut res = T::zero();
    let mut acc = [T::zero(); 8];
    let mut i = 0;
    while len - i >= 8 {
        for (q, s) in acc.iter_mut().enumerate() {
            *s += a[i + q] * b[i + q];
        }
        i += 8;
    }
    res += acc[0] + acc[4];
    res += acc[1] + acc[5];
    res += acc[2] + acc[6];
    res += acc[3] + acc[7];
    for k in i..len {
        res += a[k] * b[k];
    }
    res
}

/// `Cholesky::solve`: `b = (L Lᵀ)⁻¹ b` in place, `l` the factor of [`cholesky_cm`]
/// (`n×n`), `b` column-major `n×cols`. Cost: `n²·cols` multiply-adds.
#[inline(always)]
pub(crate) fn cholesky_solve_cm<T: Real>(l: &[T], b: &mut [T], n: usize, cols: usize) {
    if n == 0 {
        return;
    }
    for col in b.chunks_exact_mut(n).take(cols) {
        for i in 0..n {
            let coeff = col[i] / l[i + i * n];
            col[i] = coeff;
            for r in i + 1..n {
                col[r] = -coeff * l[r + i * n] + col[r];
            }
        }
    }
    for col in b.chunks_exact_mut(n).take(cols) {
        for i in (0..n).rev() {
            let dot = dot_unrolled(&l[i + 1 + i * n..(i + 1) * n], &col[i + 1..]);
            col[i] = (col[i] - dot) / l[i + i * n];
        }
    }
}

/// `P⁻ = sym(Φ P Φᵀ + Q)` into `pm` (`S×S`; `tmp`: `S×S`). Cost: `2S³` multiply-adds.
#[inline(always)]
pub(crate) fn predict_cov<T: Real>(pm: &mut [T], [phi, p, q]: [&[T]; 3], tmp: &mut [T], s: usize) {
    gemm(tmp, View::cm(phi, s), View::cm(p, s), [s, s, s]);
    gemm(pm, View::cm(tmp, s), View::tr(phi, s), [s, s, s]);
    add_into(pm, q);
    sym_flat(pm, s);
}

/// The innovation's parts: `Xᵀ = H P⁻ (+ Nᵀ)` into `xt` (`O×S`) and
/// `Σ = sym(H P⁻ Hᵀ + R (+ H N + Nᵀ Hᵀ))` into `si` (`O×O`; `tmp`: `O×O`, used with `n`).
/// Cost: `S²·O + S·O²` multiply-adds (`S·O²` more with `n`).
#[inline(always)]
pub(crate) fn innovation_flat<T: Real>(
    [xt, si, tmp]: [&mut [T]; 3],
    [pm, h, r]: [&[T]; 3],
    n: Option<&[T]>,
    [s, o]: [usize; 2],
) {
    gemm(xt, View::cm(h, o), View::cm(pm, s), [o, s, s]);
    gemm(si, View::cm(xt, o), View::tr(h, o), [o, s, o]);
    add_into(si, r);
    if let Some(n) = n {
        gemm(tmp, View::cm(h, o), View::cm(n, s), [o, s, o]);
        add_into(si, tmp);
        for j in 0..o {
            for i in 0..o {
                si[i + j * o] += tmp[j + i * o];
            }
        }
        for j in 0..s {
            for i in 0..o {
                xt[i + j * o] += n[j + i * s];
            }
        }
    }
    sym_flat(si, o);
}

/// The a-posteriori covariance in Joseph form into `p` (`S×S`) from `P⁻` (`pm`), the gain's
/// transpose `Kᵀ` (`kt`, `O×S`), `H`, `R` and the cross covariance `n`:
/// `sym((I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ (− C − Cᵀ))`, `C = (I − K H) N Kᵀ`. Work space:
/// `ikh`, `tmp` (`S×S`), `so` (`S×O`). Cost: about `2S³ + 2S²·O + S·O²` multiply-adds.
#[inline(always)]
pub(crate) fn joseph_flat<T: Real>(
    [p, ikh, tmp, so]: [&mut [T]; 4],
    [pm, kt, h, r]: [&[T]; 4],
    n: Option<&[T]>,
    [s, o]: [usize; 2],
) {
    let k = View::tr(kt, o);
    gemm(ikh, k, View::cm(h, o), [s, o, s]);
    for j in 0..s {
        for i in 0..s {
            let one = if i == j { T::one() } else { T::zero() };
            ikh[i + j * s] = one - ikh[i + j * s];
        }
    }
    gemm(tmp, View::cm(ikh, s), View::cm(pm, s), [s, s, s]);
    gemm(p, View::cm(tmp, s), View::tr(ikh, s), [s, s, s]);
    gemm(so, k, View::cm(r, o), [s, o, o]);
    gemm(tmp, View::cm(so, s), View::cm(kt, o), [s, o, s]);
    add_into(p, tmp);
    if let Some(n) = n {
        gemm(so, View::cm(ikh, s), View::cm(n, s), [s, s, o]);
        gemm(tmp, View::cm(so, s), View::cm(kt, o), [s, o, s]);
        sub_into(p, tmp);
        for j in 0..s {
            for i in 0..s {
                p[i + j * s] -= tmp[j + i * s];
            }
        }
    }
    sym_flat(p, s);
}

/// The model of a Kalman step, column-major slices of `T`: `Φ` (`S×S`), `Γ₀`, `Γ₁`
/// (`S×I`), `H` (`O×S`), `D` (`O×I`), `Q` (`S×S`), `R` (`O×O`), the cross covariance `N`
/// (`S×O`) or `None`, and `[S, I, O]`.
pub(crate) struct KalmanModel<'a, T> {
    pub(crate) phi: &'a [T],
    pub(crate) gamma: [&'a [T]; 2],
    pub(crate) h: &'a [T],
    pub(crate) d: &'a [T],
    pub(crate) q: &'a [T],
    pub(crate) r: &'a [T],
    pub(crate) cross: Option<&'a [T]>,
    pub(crate) dims: [usize; 3],
}

/// The work space of [`kalman_step_flat`]: `pm` (`P⁻`), `ikh`, `ss` (`S×S`), `so` (`S×O`),
/// `xt` (`O×S`: `Xᵀ`, then `Kᵀ`), `si` (`Σ`, `O×O`, returned), `oo` (`O×O`), `xp` (`x̂⁻`,
/// `S`), `vs` (`S`), `innov` (`ν`, `O`, returned), `vo` (`O`).
pub(crate) struct KalmanWork<'a, T> {
    pub(crate) pm: &'a mut [T],
    pub(crate) ikh: &'a mut [T],
    pub(crate) ss: &'a mut [T],
    pub(crate) so: &'a mut [T],
    pub(crate) xt: &'a mut [T],
    pub(crate) si: &'a mut [T],
    pub(crate) oo: &'a mut [T],
    pub(crate) xp: &'a mut [T],
    pub(crate) vs: &'a mut [T],
    pub(crate) innov: &'a mut [T],
    pub(crate) vo: &'a mut [T],
}

/// One Kalman step: from `prev = (x̂, P, w_{n−1})`, the input `w` and the measurement `y`
/// (a non-finite entry: missing, predict only), the new `(x̂, P)` into `out`; the
/// innovation and its covariance are left in `wk.innov`, `wk.si`. Returns whether `y`
/// was present. Finiteness of the result and the counters are the caller's.
///
/// Errors: [`Error::InvalidCovariance`] (`Σ` not positive definite), `out` then unwritten.
/// Cost: about `3S³ + 3S²·O + 2S·O² + O³/6` multiply-adds.
#[inline(always)]
pub(crate) fn kalman_step_flat<T: Real>(
    m: &KalmanModel<'_, T>,
    wk: &mut KalmanWork<'_, T>,
    (x, p, w_prev): (&[T], &[T], &[T]),
    (w, y): (&[T], &[T]),
    (x_new, p_new): (&mut [T], &mut [T]),
) -> Result<bool, Error> {
    let [s, ni, o] = m.dims;
    // x̂⁻ = Φ x̂ + Γ₀ w_{n−1} + Γ₁ w.
    gemm(wk.xp, View::cm(m.phi, s), View::cm(x, s), [s, s, 1]);
    gemm(
        wk.vs,
        View::cm(m.gamma[0], s),
        View::cm(w_prev, ni),
        [s, ni, 1],
    );
    add_into(wk.xp, wk.vs);
    gemm(wk.vs, View::cm(m.gamma[1], s), View::cm(w, ni), [s, ni, 1]);
    add_into(wk.xp, wk.vs);
    predict_cov(wk.pm, [m.phi, p, m.q], wk.ss, s);
    innovation_flat([wk.xt, wk.si, wk.oo], [wk.pm, m.h, m.r], m.cross, [s, o]);
    // ν = y − H x̂⁻ − D w.
    gemm(wk.vo, View::cm(m.h, o), View::cm(wk.xp, s), [o, s, 1]);
    wk.innov.copy_from_slice(y);
    sub_into(wk.innov, wk.vo);
    gemm(wk.vo, View::cm(m.d, o), View::cm(w, ni), [o, ni, 1]);
    sub_into(wk.innov, wk.vo);
    let present = y.iter().all(|v| v.is_finite());
    if !present {
        x_new.copy_from_slice(wk.xp);
        p_new.copy_from_slice(wk.pm);
        return Ok(false);
    }
    wk.oo.copy_from_slice(wk.si);
    if !cholesky_cm(wk.oo, o) {
        return Err(Error::InvalidCovariance);
    }
    // Kᵀ = Σ⁻¹ Xᵀ.
    cholesky_solve_cm(wk.oo, wk.xt, o, s);
    gemm(wk.vs, View::tr(wk.xt, o), View::cm(wk.innov, o), [s, o, 1]);
    x_new.copy_from_slice(wk.xp);
    add_into(x_new, wk.vs);
    joseph_flat(
        [p_new, wk.ikh, wk.ss, wk.so],
        [wk.pm, wk.xt, m.h, m.r],
        m.cross,
        [s, o],
    );
    Ok(true)
}
