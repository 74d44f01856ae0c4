//! The steady-state Kalman gain: the discrete algebraic Riccati equation (DARE), solved in
//! `const fn` `f64` by the structure-preserving doubling algorithm.
//!
//! For `x_n = Φ x_{n−1} + … + q_n` (`E q qᵀ = Q`) and `y = H x + D w + r` (`E r rᵀ = R`),
//! the a-priori (predicted) error covariance of the Kalman filter converges to the
//! stabilizing solution `P` of
//!
//! ```text
//! P = Φ P Φᵀ − Φ P Hᵀ (H P Hᵀ + R)⁻¹ H P Φᵀ + Q,        L = P Hᵀ (H P Hᵀ + R)⁻¹
//! ```
//!
//! The doubling algorithm (Chu, Fan, Lin 2005) iterates, from `A₀ = Φᵀ`,
//! `G₀ = Hᵀ R⁻¹ H`, `X₀ = Q`,
//!
//! ```text
//! W = I + G_k X_k,  A_{k+1} = A_k W⁻¹ A_k,  G_{k+1} = G_k + A_k W⁻¹ G_k A_kᵀ,
//! X_{k+1} = X_k + A_kᵀ X_k W⁻¹ A_k
//! ```
//!
//! `X_k` is the Riccati difference equation's iterate `2^k` (from `P₀ = Q`): quadratic
//! convergence, a few tens of iterations even for lightly damped structures, each a
//! factorization of `W` and solves — small enough for the compiler to evaluate (the gain of
//! a `static` observer sits in flash with no Riccati code linked).

use nalgebra::SMatrix;

use super::state_space::{Measurement, StateSpace, lu_of};
use crate::Error;
use crate::linalg::cholesky::cholesky;
use crate::linalg::{
    Mat, add_scaled, all_finite, identity, is_symmetric, max_abs, mul, rows_f64, transpose,
};

/// Iteration budget of the doubling algorithm: iterate `k` covers `2^k` steps of the
/// Riccati difference equation, so 64 cover any convergent case.
pub const RICCATI_MAX_ITERATIONS: u32 = 64;

/// The steady-state Kalman solution of a model and its measurement (all `f64`, row-major).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyState<const S: usize, const O: usize> {
    /// `P` (`S×S`): the a-priori (predicted) error covariance, the DARE solution (units of
    /// `x` squared).
    pub covariance: [[f64; S]; S],
    /// `L = P Hᵀ (H P Hᵀ + R)⁻¹` (`S×O`): the observer gain.
    pub gain: [[f64; O]; S],
    /// Doubling iterations taken (`≤` [`RICCATI_MAX_ITERATIONS`]).
    pub iterations: u32,
}

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

/// `a` is a valid covariance: finite, symmetric and positive semidefinite (`definite`:
/// positive definite). Semidefiniteness is tested by a Cholesky factorization of
/// `a + δI`, `δ = 16 N ε max|a|`: a rank-deficient `a` passes, an eigenvalue below `−δ`
/// fails. Cost: `N³/6` flops.
pub(crate) const fn is_covariance<const N: usize>(a: &Mat<N, N>, definite: bool) -> bool {
    if !symmetric(a) {
        return false;
    }
    if definite {
        return cholesky(a).is_some();
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

/// `L = P Hᵀ (H P Hᵀ + R)⁻¹` for a covariance `P` (a solve with the `O×O` innovation
/// covariance). `None` if it is singular.
pub(crate) const fn gain_of<const S: usize, const O: usize>(
    p: &Mat<S, S>,
    h: &Mat<O, S>,
    r: &Mat<O, O>,
) -> Option<Mat<S, O>> {
    let hp = mul(h, p);
    let si = add_scaled(r, 1.0, &mul(&hp, &transpose(h)));
    let lu = match lu_of(&symmetrize(&si)) {
        Some(lu) => lu,
        None => return None,
    };
    // Lᵀ = (H P Hᵀ + R)⁻¹ H P (both symmetric).
    Some(transpose(&lu.solve(&hp)))
}

impl<const S: usize, const O: usize> SteadyState<S, O> {
    /// Solve the DARE for the model's `Φ` and the measurement's `H`, with process noise
    /// `q` (`S×S`, symmetric positive semidefinite, units of `x` squared per step) and
    /// measurement noise `r` (`O×O`, symmetric positive definite, output units squared),
    /// and form the gain (`const fn`: in a `static` the compiler computes it).
    ///
    /// Errors: [`Error::InvalidCovariance`] (`q` or `r` not finite, not symmetric, or not
    /// positive (semi)definite), [`Error::RiccatiNotConverged`] (no stabilizing solution
    /// within [`RICCATI_MAX_ITERATIONS`]: a mode neither measured nor driven by `q`, or an
    /// unstable one), [`Error::OperatorOverflow`].
    ///
    /// Cost: about `10 S³` flops an iteration, `≤ 64` iterations (typically 10–25), and a
    /// few `S×S` `f64` temporaries on the stack. In a `static` the compiler evaluates it;
    /// `S = 10` (the 5-storey building, 10 iterations) is pinned by `tests/observer.rs`
    /// (`CONST_GAIN`). Much larger `S` may stop rustc with the `long_running_const_eval`
    /// lint, as for the steppers' `from_rows`: allow it at the firmware's crate root, or
    /// solve at run time with [`SteadyState::new`].
    pub const fn solve<const N: usize, const I: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        q: &[[f64; S]; S],
        r: &[[f64; O]; O],
    ) -> Result<Self, Error> {
        if !(is_covariance(q, false) && is_covariance(r, true)) {
            return Err(Error::InvalidCovariance);
        }
        let h = &meas.h;
        if !all_finite(h) {
            return Err(Error::NonFiniteInput);
        }
        let lu_r = match lu_of(r) {
            Some(lu) => lu,
            None => return Err(Error::InvalidCovariance),
        };
        let id: Mat<S, S> = identity();
        let mut a = transpose(&model.phi);
        let mut g = symmetrize(&mul(&transpose(h), &lu_r.solve(h)));
        let mut x = symmetrize(q);
        let mut k = 0;
        let mut converged = false;
        while k < RICCATI_MAX_ITERATIONS {
            k += 1;
            let w = add_scaled(&id, 1.0, &mul(&g, &x));
            let lu = match lu_of(&w) {
                Some(lu) => lu,
                None => return Err(Error::RiccatiNotConverged),
            };
            let wa = lu.solve(&a);
            let wg = lu.solve(&g);
            let x1 = symmetrize(&add_scaled(&x, 1.0, &mul(&transpose(&a), &mul(&x, &wa))));
            let g1 = symmetrize(&add_scaled(&g, 1.0, &mul(&a, &mul(&wg, &transpose(&a)))));
            let a1 = mul(&a, &wa);
            if !(all_finite(&x1) && all_finite(&g1) && all_finite(&a1)) {
                return Err(Error::RiccatiNotConverged);
            }
            // Converged when X no longer moves (the update is below rounding of X).
            let diff = max_abs(&add_scaled(&x1, -1.0, &x));
            x = x1;
            g = g1;
            a = a1;
            if diff <= 4.0 * f64::EPSILON * max_abs(&x) {
                converged = true;
                break;
            }
        }
        // A "converged" iterate that is not a covariance is no solution: for a model with
        // an unobservable marginal mode (two free masses, only their sum measured) the
        // doubling stopped at a P with diagonal entries of −4e10 (found by fuzzing).
        if !(converged && is_covariance(&x, false)) {
            return Err(Error::RiccatiNotConverged);
        }
        let gain = match gain_of(&x, h, r) {
            Some(l) => l,
            None => return Err(Error::RiccatiNotConverged),
        };
        if !all_finite(&gain) {
            return Err(Error::OperatorOverflow);
        }
        Ok(Self {
            covariance: x,
            gain,
            iterations: k,
        })
    }

    /// [`SteadyState::solve`] with `nalgebra` covariances (run time; same numbers).
    ///
    /// Errors and cost: as [`SteadyState::solve`].
    pub fn new<const N: usize, const I: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
    ) -> Result<Self, Error> {
        Self::solve(model, meas, &rows_f64(q), &rows_f64(r))
    }

    /// `P` as a `nalgebra` matrix.
    pub fn covariance_matrix(&self) -> SMatrix<f64, S, S> {
        SMatrix::from_fn(|i, j| self.covariance[i][j])
    }

    /// `L` as a `nalgebra` matrix.
    pub fn gain_matrix(&self) -> SMatrix<f64, S, O> {
        SMatrix::from_fn(|i, j| self.gain[i][j])
    }
}
