//! The Kalman core shared by every filter: the correction with a process–measurement cross
//! covariance, and the start of the doubling algorithm for its Riccati equation.
//!
//! # The noise model
//!
//! Every filter of the crate is written for
//!
//! ```text
//! x_n = Φ x_{n−1} + (known input) + q_n,      y_n = H x_n + (known input) + r_n,
//! E q_n q_nᵀ = Q,   E r_n r_nᵀ = R,   E q_n r_nᵀ = N,   (q_n, r_n) independent of (q_m, r_m), m ≠ n
//! ```
//!
//! (`N`, `S×O`: the noise that drives the state into sample `n` and the noise of the
//! measurement at `n` are correlated; a force noise that reaches the accelerometers
//! through the feedthrough, [`StateSpace::input_cross_noise`](super::StateSpace::input_cross_noise)).
//! The a-priori error `e⁻ = x_n − x̂⁻_n = Φ e_{n−1} + q_n` is independent of the past
//! measurements and has `E e⁻ r_nᵀ = N`, so the innovation `ν = H e⁻ + r_n` and the
//! correction are
//!
//! ```text
//! Σ = H P⁻ Hᵀ + R + H N + Nᵀ Hᵀ,     K = (P⁻ Hᵀ + N) Σ⁻¹,
//! P = [I − K H, −K] [P⁻ N; Nᵀ R] [I − K H, −K]ᵀ
//!   = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ − (I − K H) N Kᵀ − K Nᵀ (I − K H)ᵀ   (Joseph form)
//! ```
//!
//! With `N = 0` (every entry exactly zero) the filters take their original code path, bit
//! for bit.
//!
//! # The Riccati equation with the cross term
//!
//! Write the a-priori covariance as `P⁻_n = Y_n + Q` (`Y_n` the covariance of the part of
//! `e⁻_n` that is not `q_n`, `ε_n`). Then `Y_{n+1}` is the covariance of `A ε + A q` given
//! `C ε + C q + r` — the Riccati difference equation of a *predictor* on `(A, C)` with
//! state noise `A q` and measurement noise `C q + r`, whose cross covariance is
//! `A (Q Cᵀ + N)`. Taking the cross term out in the usual way (`Ā = A − S_y R_y⁻¹ C`,
//! `Q̃ = Q_y − S_y R_y⁻¹ S_yᵀ`) leaves the form the doubling algorithm solves,
//! [`cross_riccati_start`]. For the Kalman filter `A = Φ`, `C = H`, `Q_y = Φ Q Φᵀ`,
//! `S_y = Φ (Q Hᵀ + N)`, `R_y = H Q Hᵀ + R + H N + Nᵀ Hᵀ` (the covariance of `H q + r`:
//! positive definite whenever `R` is and `[Q N; Nᵀ R]` is a covariance); the joint
//! input–state filter uses the same form on its zero dynamics
//! ([`estimation`](crate::estimation)).

use nalgebra::{Cholesky, SMatrix};

use super::kalman_flat::{cholesky_solve_cm, innovation_flat, predict_cov};
use super::state_space::lu_of;
use crate::linalg::cholesky::cholesky;
use crate::linalg::lu::Lu;
use crate::linalg::{Mat, add_scaled, all_finite, finite_as, is_symmetric, matrix_t, max_abs};
use crate::linalg::{mul, rows_f64, sym, transpose};
use crate::{Error, Real};

/// `a` symmetric to `64 ε max|a|` and all finite.
const fn symmetric<const N: usize>(a: &Mat<N, N>) -> bool {
    all_finite(a) && is_symmetric(a, 64.0 * f64::EPSILON)
}

/// `(a + aᵀ)/2`.
pub(crate) const fn symmetrize<const N: usize>(a: &Mat<N, N>) -> Mat<N, N> {
    let mut s = *a;
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < i {
            let m = 0.5 * (a[i][j] + a[j][i]);
            s[i][j] = m;
            s[j][i] = m;
            j += 1;
        }
        i += 1;
    }
    s
}

/// The LU (with row scales) of `a` if `a` is a positive definite covariance: finite,
/// symmetric, with a Cholesky factorization and that LU, which [`SteadyState`] solves
/// with. Both: at the edge of singularity the two judge rounding differently (an `R` with
/// relative determinant `−3e-21` passed the Cholesky and failed the LU, so `Kalman` took
/// what `SteadyState` refused; found by fuzzing). Cost: `N³/6 + N³/3` multiply-adds.
pub(crate) const fn definite_lu<const N: usize>(a: &Mat<N, N>) -> Option<Lu<N>> {
    if !symmetric(a) || cholesky(a).is_none() {
        return None;
    }
    lu_of(a)
}

/// `a` is a valid covariance: finite, symmetric and positive semidefinite (`definite`:
/// positive definite, as [`definite_lu`] judges it). Semidefiniteness is tested by a
/// Cholesky factorization of `a + δI`, `δ = 16 N ε max|a|`: a rank-deficient `a` passes,
/// an eigenvalue below `−δ` fails. Cost: `N³/6` flops (`N³/3` more for `definite`).
pub(crate) const fn is_covariance<const N: usize>(a: &Mat<N, N>, definite: bool) -> bool {
    if definite {
        return definite_lu(a).is_some();
    }
    if !symmetric(a) {
        return false;
    }
    let delta = 16.0 * N as f64 * f64::EPSILON * max_abs(a) + f64::MIN_POSITIVE;
    let mut b = *a;
    let mut i = 0;
    while i < N {
        b[i][i] += delta;
        i += 1;
    }
    cholesky(&b).is_some()
}

/// Every entry of `a` is exactly zero (`±0`): no cross covariance.
pub(crate) const fn is_zero<const R: usize, const C: usize>(a: &Mat<R, C>) -> bool {
    let mut i = 0;
    while i < R {
        let mut j = 0;
        while j < C {
            if a[i][j] != 0.0 {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

/// The cross covariance `n` (`S×O`) is finite and `[q n; nᵀ r]` is a covariance, for a
/// positive semidefinite `q` and a positive definite `r` (checked by the caller): the Schur
/// complement `q − n r⁻¹ nᵀ` is positive semidefinite (as [`is_covariance`] judges it).
/// Cost: `O³/3 + S·O² + S²·O + S³/6` flops.
pub(crate) const fn cross_is_valid<const S: usize, const O: usize>(
    q: &Mat<S, S>,
    r: &Mat<O, O>,
    n: &Mat<S, O>,
) -> bool {
    if !all_finite(n) {
        return false;
    }
    let lu = match lu_of(r) {
        Some(lu) => lu,
        None => return false,
    };
    // r⁻¹ nᵀ (O×S).
    let rn = lu.solve(&transpose(n));
    let schur = symmetrize(&add_scaled(q, -1.0, &mul(n, &rn)));
    all_finite(&schur) && is_covariance(&schur, false)
}

/// The innovation's parts for an a-priori covariance `p`: `Xᵀ = H P + Nᵀ` (`O×S`, the
/// transpose of the covariance of the a-priori error with the innovation) and
/// `Σ = H P Hᵀ + R + H N + Nᵀ Hᵀ` (`O×O`, not symmetrized); without `n` exactly
/// `H P` and `R + H P Hᵀ` as the filters have always formed them. Cost: `S²·O + S·O²`
/// flops (`2 S·O²` more with `n`).
pub(crate) const fn innovation_parts<const S: usize, const O: usize>(
    p: &Mat<S, S>,
    h: &Mat<O, S>,
    r: &Mat<O, O>,
    n: Option<&Mat<S, O>>,
) -> (Mat<O, S>, Mat<O, O>) {
    let hp = mul(h, p);
    let si = add_scaled(r, 1.0, &mul(&hp, &transpose(h)));
    match n {
        None => (hp, si),
        Some(n) => {
            let hn = mul(h, n);
            (
                add_scaled(&hp, 1.0, &transpose(n)),
                add_scaled(&si, 1.0, &add_scaled(&hn, 1.0, &transpose(&hn))),
            )
        }
    }
}

/// The doubling algorithm's start `(A₀, G₀, X₀)` for the Riccati equation with a cross
/// term in the predictor form of the [module docs](self): the recursion
/// `Y' = a Y aᵀ + q_y − (a Y cᵀ + s_y) (c Y cᵀ + R_y)⁻¹ (a Y cᵀ + s_y)ᵀ` with the weight
/// `pi = R_y⁻¹` (or, for the joint filter, the inverse of `R_y` on the output directions
/// the input does not take), decorrelated: `Ā = a − s_y π c`, `A₀ = Āᵀ`,
/// `G₀ = cᵀ π c`, `X₀ = q_y − s_y π s_yᵀ`. The doubling's `X` is then the fixed point `Y`,
/// and the a-priori covariance is `Y + Q`. Cost: about `3 S²·O + S·O² + S³` flops.
#[allow(clippy::type_complexity)]
pub(crate) const fn cross_riccati_start<const S: usize, const O: usize>(
    a: &Mat<S, S>,
    c: &Mat<O, S>,
    qy: &Mat<S, S>,
    sy: &Mat<S, O>,
    pi: &Mat<O, O>,
) -> (Mat<S, S>, Mat<S, S>, Mat<S, S>) {
    let sp = mul(sy, pi);
    let abar = add_scaled(a, -1.0, &mul(&sp, c));
    let g = symmetrize(&mul(&transpose(c), &mul(pi, c)));
    let x0 = symmetrize(&add_scaled(qy, -1.0, &mul(&sp, &transpose(sy))));
    (transpose(&abar), g, x0)
}

/// The innovation's parts in the filter's scalar type (as [`innovation_parts`]):
/// `Xᵀ = H P⁻ (+ Nᵀ)` and `Σ` symmetrized, `(Σ + Σᵀ)/2`: [`innovation_flat`] on the
/// arrays (the operations the time-varying filters have always done). Cost: `S²·O + S·O²`
/// multiply-adds (`S·O²` more with `n`).
pub(crate) fn innovation_t<T: Real, const S: usize, const O: usize>(
    pm: &SMatrix<T, S, S>,
    h: &SMatrix<T, O, S>,
    r: &SMatrix<T, O, O>,
    n: Option<&SMatrix<T, S, O>>,
) -> (SMatrix<T, O, S>, SMatrix<T, O, O>) {
    let mut xt = SMatrix::<T, O, S>::zeros();
    let (mut si, mut tmp) = (SMatrix::<T, O, O>::zeros(), SMatrix::<T, O, O>::zeros());
    innovation_flat(
        [xt.as_mut_slice(), si.as_mut_slice(), tmp.as_mut_slice()],
        [pm.as_slice(), h.as_slice(), r.as_slice()],
        n.map(|n| n.as_slice()),
        [S, O],
    );
    (xt, si)
}

/// The gain `K = Xᵀᵀ Σ⁻¹` from the factored `Σ` and `Xᵀ` of [`innovation_t`]
/// ([`cholesky_solve_cm`] on the factor). Cost: `S·O²` multiply-adds.
pub(crate) fn gain_t<T: Real, const S: usize, const O: usize>(
    chol: &Cholesky<T, nalgebra::Const<O>>,
    xt: &SMatrix<T, O, S>,
) -> SMatrix<T, S, O> {
    let mut kt = *xt;
    cholesky_solve_cm(chol.l_dirty().as_slice(), kt.as_mut_slice(), O, S);
    kt.transpose()
}

/// The a-priori covariance `P⁻ = Φ P Φᵀ + Q`, symmetrized ([`predict_cov`] on the
/// arrays): the prediction of the time-varying filters whose state noise enters alone
/// (the Kalman filter, the dual filter's state stage). Cost: `2S³` multiply-adds.
pub(crate) fn predict_t<T: Real, const S: usize>(
    phi: &SMatrix<T, S, S>,
    p: &SMatrix<T, S, S>,
    q: &SMatrix<T, S, S>,
) -> SMatrix<T, S, S> {
    let (mut pm, mut tmp) = (SMatrix::<T, S, S>::zeros(), SMatrix::<T, S, S>::zeros());
    predict_cov(
        pm.as_mut_slice(),
        [phi.as_slice(), p.as_slice(), q.as_slice()],
        tmp.as_mut_slice(),
        S,
    );
    pm
}

/// The a-posteriori covariance in the short form, `P⁻ − K Xᵀ` (`Xᵀ = H P⁻` of
/// [`innovation_t`] without a cross term), symmetrized: the form of the filters that
/// publish it (the dual filter's stages). Cost: `S²·O` multiply-adds.
pub(crate) fn short_form_t<T: Real, const S: usize, const O: usize>(
    pm: &SMatrix<T, S, S>,
    k: &SMatrix<T, S, O>,
    xt: &SMatrix<T, O, S>,
) -> SMatrix<T, S, S> {
    sym(&(pm - k * xt))
}

/// The cross covariance `n` (`S×O`) of a time-varying filter with noises `q` (`S×S`) and
/// `r` (`O×O`, both checked by the caller), rounded to `T`: `None` when every entry is
/// exactly zero (the filters' original code path, bit for bit), else `n` after
/// [`cross_is_valid`]. Whether `n` fits `T` is [`noise_fits`]'s to say.
/// Errors: [`Error::InvalidCovariance`]. Cost: as [`cross_is_valid`].
pub(crate) fn checked_cross_t<T: Real, const S: usize, const O: usize>(
    q: &Mat<S, S>,
    r: &Mat<O, O>,
    n: &Mat<S, O>,
) -> Result<Option<SMatrix<T, S, O>>, Error> {
    if is_zero(n) {
        Ok(None)
    } else if cross_is_valid(q, r, n) {
        Ok(Some(matrix_t(n)))
    } else {
        Err(Error::InvalidCovariance)
    }
}

/// The noise model `q` (`S×S`), `r` (`O×O`) and `n` (`S×O`) rounds to finite values of the
/// scalar type whose largest finite value is `max`. Cost: `S² + O² + S·O` comparisons.
pub(crate) const fn noise_fits<const S: usize, const O: usize>(
    q: &Mat<S, S>,
    r: &Mat<O, O>,
    n: &Mat<S, O>,
    max: f64,
) -> bool {
    finite_as(q, max) && finite_as(r, max) && finite_as(n, max)
}

/// A filter's start covariance `p` (`S×S`, in the filter's scalar type) is a covariance:
/// finite, symmetric, positive semidefinite ([`is_covariance`] on its `f64` values).
/// Errors: [`Error::InvalidCovariance`]. Cost: `S³/6` flops.
pub(crate) fn check_start_covariance<T: Real, const S: usize>(
    p: &SMatrix<T, S, S>,
) -> Result<(), Error> {
    let pr: Mat<S, S> = rows_f64(p);
    if is_covariance(&pr, false) {
        Ok(())
    } else {
        Err(Error::InvalidCovariance)
    }
}
