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

use super::kalman_core::{
    cross_is_valid, cross_riccati_start, definite_lu, innovation_parts, is_covariance, is_zero,
    symmetrize,
};
use super::state_space::{Measurement, StateSpace, lu_of};
use crate::Error;
use crate::linalg::{
    Mat, add_scaled, all_finite, identity, max_abs, mul, rows_f64, sqrt, transpose,
};

/// Iteration budget of the doubling algorithm: iterate `k` covers `2^k` steps of the
/// Riccati difference equation, so 64 cover any convergent case.
pub const RICCATI_MAX_ITERATIONS: u32 = 64;

/// The tolerance of [`SteadyState`]'s residual check, in units of `(2S + 5) ε`: every
/// entry of the residual `A P Aᵀ + K R Kᵀ + Q − P` (`K = Φ L`, `A = Φ − K H`, `L` the
/// returned gain) is at most this many units of `max(√(B_ii B_jj), B_ij)`, where
/// `B = |A||P||A|ᵀ + |K||R||K|ᵀ + |Q| + |P|` is the size of the equation's terms (the
/// normalization is invariant under a diagonal scaling of the state).
///
/// The unit is rounding: forming an entry of the residual rounds it by at most about
/// `(2S + 4) ε B_ij` (two products of length `S`, four additions), and `P` rounded to
/// `f64` leaves a true residual of up to `ε B_ij`. An accurate solution measures about one
/// unit; where the closed loop has a mode near the unit circle and `P` is nearly singular,
/// the refined solutions of the fuzz corpus measure up to about 60 (the correction's Stein
/// equation amplifies rounding by up to `1/(1 − ρ²)`). 256 units is `7e-13` relative for
/// `S = 4`: far below any model error, far above rounding.
pub const RICCATI_RESIDUAL_UNITS: f64 = 256.0;

/// The steady-state Kalman solution of a model and its measurement (all `f64`, row-major).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyState<const S: usize, const O: usize> {
    /// `P` (`S×S`): the a-priori (predicted) error covariance, the DARE solution (units of
    /// `x` squared).
    pub covariance: [[f64; S]; S],
    /// `L = P Hᵀ (H P Hᵀ + R)⁻¹` (`S×O`): the observer gain; with a cross covariance
    /// `N`, `L = (P Hᵀ + N) (H P Hᵀ + R + H N + Nᵀ Hᵀ)⁻¹` ([`SteadyState::from_parts_cross`]).
    pub gain: [[f64; O]; S],
    /// Doubling iterations taken (`≤` [`RICCATI_MAX_ITERATIONS`]).
    pub iterations: u32,
    /// The process–measurement cross covariance `N = E q_n r_nᵀ` (`S×O`) the solution was
    /// computed with (zero from [`SteadyState::from_parts`]), so that
    /// [`innovation_covariance`](crate::detection::innovation_covariance) and the
    /// [smoother](crate::estimation::smoother) use the same noise model.
    pub cross: [[f64; O]; S],
}

/// `L = P Hᵀ (H P Hᵀ + R)⁻¹` for a covariance `P` (a solve with the `O×O` innovation
/// covariance), or with a cross covariance `n`, `(P Hᵀ + N) Σ⁻¹` (the core's
/// [`innovation_parts`]). `None` if `Σ` is singular.
pub(crate) const fn gain_of<const S: usize, const O: usize>(
    p: &Mat<S, S>,
    h: &Mat<O, S>,
    r: &Mat<O, O>,
    n: Option<&Mat<S, O>>,
) -> Option<Mat<S, O>> {
    let (hp, si) = innovation_parts(p, h, r, n);
    let lu = match lu_of(&symmetrize(&si)) {
        Some(lu) => lu,
        None => return None,
    };
    // Lᵀ = (H P Hᵀ + R)⁻¹ H P (both symmetric).
    Some(transpose(&lu.solve(&hp)))
}

/// Newton refinements of the doubling's solution at most ([`SteadyState::from_parts`]).
const RICCATI_REFINEMENTS: u32 = 3;

/// A residual at or below this many units (of [`RICCATI_RESIDUAL_UNITS`]'s `(2S + 5) ε`)
/// is not refined: rounding in evaluating it is about one unit.
const RICCATI_RESIDUAL_REFINE: f64 = 4.0;

/// The doubling has converged once `‖A_k‖∞ ≤ 2^-26` (`√ε`): the updates of `X` still to
/// come are quadratic in it.
pub(crate) const A_SMALL: f64 = 1.4901161193847656e-8;

/// The a-priori covariance the doubling algorithm solves for from `start = (A₀, G₀, X₀)`
/// within `max_iterations`, and the iterations taken; `None` if it breaks down, does not
/// converge, or stops at an iterate that is not a covariance (for a model with an
/// unobservable marginal mode, two free masses with only their sum measured, the doubling
/// stopped at a `P` with diagonal entries of −4e10: found by fuzzing). With the cross
/// term's start ([`cross_riccati_start`](super::kalman_core::cross_riccati_start)) the
/// doubling solves for `Y` and the a-priori covariance is `Y + Q`: pass `q_cross = Some(Q)`.
/// Shared by [`SteadyState`] and the joint filter's steady state. Cost: [`doubling`]'s,
/// plus `N³/6` flops for the check.
pub(crate) const fn doubling_solution<const S: usize>(
    start: (Mat<S, S>, Mat<S, S>, Mat<S, S>),
    max_iterations: u32,
    q_cross: Option<&Mat<S, S>>,
) -> Option<(Mat<S, S>, u32)> {
    let (x, k, converged) = match doubling(start.0, start.1, start.2, max_iterations) {
        Some(v) => v,
        None => return None,
    };
    if !(converged && is_covariance(&x, false)) {
        return None;
    }
    let x = match q_cross {
        None => x,
        Some(q) => symmetrize(&add_scaled(&x, 1.0, &symmetrize(q))),
    };
    Some((x, k))
}

/// The doubling algorithm for the filter Riccati equation `X = Aᵀ X A − …` in the form
/// `A₀ = Aᵀ`, `G₀ = G`, `X₀ = X`: `W = I + G X`, `X ← X + Aᵀ X W⁻¹ A`,
/// `G ← G + A W⁻¹ G Aᵀ`, `A ← A W⁻¹ A`, at most `max` times. Returns `(X, iterations,
/// converged)`, or `None` when `W` is singular or an iterate is not finite (each caller
/// names that failure its own way: no steady state of a Kalman filter, an unidentifiable
/// input of the joint filter).
///
/// Converged when X no longer moves (the update is below rounding of X) and A_k, which the
/// updates of X are quadratic in (`A_k ≈ (Φ − K H)ᵀ^(2^k)`), has become small: with a
/// closed-loop mode near the unit circle X can stand still for a few iterations while its
/// slow part has not yet accumulated (P stopped at iteration 2 with errors of 6e-14
/// relative, and its gain's observer had a spectral radius of 1.000008; found by fuzzing).
/// Below 2^-26 the remaining updates are below ε ‖X‖.
pub(crate) const fn doubling<const S: usize>(
    mut a: Mat<S, S>,
    mut g: Mat<S, S>,
    mut x: Mat<S, S>,
    max: u32,
) -> Option<(Mat<S, S>, u32, bool)> {
    let id: Mat<S, S> = identity();
    let mut k = 0;
    while k < max {
        k += 1;
        let w = add_scaled(&id, 1.0, &mul(&g, &x));
        let lu = match lu_of(&w) {
            Some(lu) => lu,
            None => return None,
        };
        let wa = lu.solve(&a);
        let wg = lu.solve(&g);
        let x1 = symmetrize(&add_scaled(&x, 1.0, &mul(&transpose(&a), &mul(&x, &wa))));
        let g1 = symmetrize(&add_scaled(&g, 1.0, &mul(&a, &mul(&wg, &transpose(&a)))));
        let a1 = mul(&a, &wa);
        if !(all_finite(&x1) && all_finite(&g1) && all_finite(&a1)) {
            return None;
        }
        let diff = max_abs(&add_scaled(&x1, -1.0, &x));
        x = x1;
        g = g1;
        a = a1;
        if diff <= 4.0 * f64::EPSILON * max_abs(&x) && inf_norm(&a) <= A_SMALL {
            return Some((x, k, true));
        }
    }
    Some((x, k, false))
}

/// `|a|` entry by entry.
pub(crate) const fn abs_of<const R: usize, const C: usize>(a: &Mat<R, C>) -> Mat<R, C> {
    let mut b = *a;
    let mut i = 0;
    while i < R {
        let mut j = 0;
        while j < C {
            b[i][j] = a[i][j].abs();
            j += 1;
        }
        i += 1;
    }
    b
}

/// The Riccati equation's residual in Joseph form, `A P Aᵀ + K R Kᵀ + Q − P` with the
/// predictor gain `K = Φ L` and the closed loop `A = Φ − K H` (the a-priori error
/// dynamics), the size of its terms `B = |A||P||A|ᵀ + |K||R||K|ᵀ + |Q| + |P|`, and `A`.
/// With a cross covariance `n` the a-priori error `e⁻` and the measurement noise are
/// correlated (`E e⁻ rᵀ = N`): the residual gains `− A N Kᵀ − K Nᵀ Aᵀ` and the size
/// `2 |A||N||K|ᵀ`.
///
/// The Joseph form is the Riccati equation where `L` is its gain, and it is stationary in
/// `L`: an error `δL` changes it by `δK S δKᵀ` only (second order), so the residual is not
/// spoiled by the conditioning of `S = H P Hᵀ + R` as the textbook form
/// `Φ P Φᵀ − Φ P Hᵀ S⁻¹ H P Φᵀ + Q − P` is. Cost: about `6 S³ + 4 S² O` flops.
const fn joseph_residual<const S: usize, const O: usize>(
    phi: &Mat<S, S>,
    h: &Mat<O, S>,
    q: &Mat<S, S>,
    r: &Mat<O, O>,
    p: &Mat<S, S>,
    l: &Mat<S, O>,
    n: Option<&Mat<S, O>>,
) -> (Mat<S, S>, Mat<S, S>, Mat<S, S>) {
    let k = mul(phi, l);
    let a = add_scaled(phi, -1.0, &mul(&k, h));
    let kt = transpose(&k);
    let at = transpose(&a);
    let mut res = add_scaled(
        &add_scaled(
            &add_scaled(&mul(&a, &mul(p, &at)), 1.0, &mul(&k, &mul(r, &kt))),
            1.0,
            q,
        ),
        -1.0,
        p,
    );
    let (aa, ka) = (abs_of(&a), abs_of(&k));
    let mut bound = add_scaled(
        &add_scaled(
            &add_scaled(
                &mul(&aa, &mul(&abs_of(p), &transpose(&aa))),
                1.0,
                &mul(&ka, &mul(&abs_of(r), &transpose(&ka))),
            ),
            1.0,
            &abs_of(q),
        ),
        1.0,
        &abs_of(p),
    );
    if let Some(n) = n {
        let ank = mul(&a, &mul(n, &kt));
        res = add_scaled(&res, -1.0, &add_scaled(&ank, 1.0, &transpose(&ank)));
        let sz = mul(&aa, &mul(&abs_of(n), &transpose(&ka)));
        bound = add_scaled(&bound, 1.0, &add_scaled(&sz, 1.0, &transpose(&sz)));
    }
    (res, bound, a)
}

/// The largest `|res_ij| / ((2S + 5) ε max(√(B_ii B_jj), B_ij))` (`∞` if any entry is not
/// finite, or nonzero where its scale is zero).
const fn residual_units<const S: usize>(res: &Mat<S, S>, bound: &Mat<S, S>) -> f64 {
    let unit = (2 * S + 5) as f64 * f64::EPSILON;
    let mut worst = 0.0f64;
    let mut i = 0;
    while i < S {
        let mut j = 0;
        while j < S {
            let x = res[i][j].abs();
            let b = bound[i][j];
            if !(x.is_finite() && b.is_finite()) {
                return f64::INFINITY;
            }
            let mut scale = sqrt(bound[i][i]) * sqrt(bound[j][j]);
            if b > scale {
                scale = b;
            }
            if x > 0.0 {
                let u = x / (unit * scale);
                if u > worst || u.is_nan() {
                    worst = u;
                }
            }
            j += 1;
        }
        i += 1;
    }
    worst
}

/// `max_i Σ_j |a_ij|` (NaN if an entry is NaN).
pub(crate) const fn inf_norm<const N: usize>(a: &Mat<N, N>) -> f64 {
    let mut m = 0.0f64;
    let mut i = 0;
    while i < N {
        let mut s = 0.0;
        let mut j = 0;
        while j < N {
            s += a[i][j].abs();
            j += 1;
        }
        if s > m || s.is_nan() {
            m = s;
        }
        i += 1;
    }
    m
}

/// `a` balanced: `D⁻¹ a D` and `D` (its diagonal), `D` powers of two (exact, the same
/// eigenvalues) chosen as LAPACK's `gebal` does so that each row and column have comparable
/// off-diagonal sums. A badly scaled closed loop (`H ≈ 7e41` of a modal form with
/// `M = 2e-84`) has a norm far above its spectral radius, and its squares would be all
/// rounding. Cost: `O(S²)` a sweep, a few sweeps.
pub(crate) const fn balance<const N: usize>(a: &Mat<N, N>) -> (Mat<N, N>, [f64; N]) {
    let mut b = *a;
    let mut d = [1.0f64; N];
    let mut sweep = 0;
    while sweep < 64 {
        let mut changed = false;
        let mut i = 0;
        while i < N {
            let (mut c, mut r) = (0.0f64, 0.0f64);
            let mut j = 0;
            while j < N {
                if j != i {
                    c += b[j][i].abs();
                    r += b[i][j].abs();
                }
                j += 1;
            }
            if c > 0.0 && r > 0.0 && c.is_finite() && r.is_finite() {
                let s = c + r;
                let mut f = 1.0f64;
                let mut steps = 0;
                while c < 0.5 * r && steps < 2100 {
                    f *= 2.0;
                    c *= 2.0;
                    r *= 0.5;
                    steps += 1;
                }
                while c >= 2.0 * r && steps < 2100 {
                    f *= 0.5;
                    c *= 0.5;
                    r *= 2.0;
                    steps += 1;
                }
                let di = d[i] * f;
                if c + r < 0.95 * s && f.is_normal() && di.is_normal() {
                    let mut j = 0;
                    while j < N {
                        b[j][i] *= f;
                        b[i][j] /= f;
                        j += 1;
                    }
                    d[i] = di;
                    changed = true;
                }
            }
            i += 1;
        }
        if !changed {
            break;
        }
        sweep += 1;
    }
    (b, d)
}

/// The solution `X` of the Stein equation `X = A X Aᵀ + W` by doubling (Smith's
/// iteration, `X ← X + A_k X A_kᵀ`, `A_{k+1} = A_k²`) in balanced coordinates, or `None`
/// if the closed loop `A` is not certified stable: its balanced squares reach
/// `‖A^(2^k)‖∞ ≤ 2^-26` for some `k < 64` (which bounds its spectral radius by
/// `2^(−26/2^k) < 1`; the terms still to come are then below `ε ‖X‖`), or else `None` — a
/// spectral radius ≥ 1, within rounding of the squarings of 1, or a power that is not
/// finite. Cost: `3 S³` flops a squaring, about `log₂(1/(1 − ρ))` of them.
pub(crate) const fn stein<const N: usize>(a: &Mat<N, N>, w: &Mat<N, N>) -> Option<Mat<N, N>> {
    let (mut b, d) = balance(a);
    // W in the balanced coordinates, D⁻¹ W D⁻¹ (exact: powers of two).
    let mut x = *w;
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            x[i][j] = w[i][j] / d[i] / d[j];
            j += 1;
        }
        i += 1;
    }
    let mut k = 0;
    while k < 64 {
        let n = inf_norm(&b);
        if !n.is_finite() || !all_finite(&x) {
            return None;
        }
        if n <= A_SMALL {
            let mut i = 0;
            while i < N {
                let mut j = 0;
                while j < N {
                    x[i][j] = x[i][j] * d[i] * d[j];
                    j += 1;
                }
                i += 1;
            }
            return if all_finite(&x) { Some(x) } else { None };
        }
        x = add_scaled(&x, 1.0, &mul(&b, &mul(&x, &transpose(&b))));
        b = mul(&b, &b);
        k += 1;
    }
    None
}

impl<const S: usize, const O: usize> SteadyState<S, O> {
    /// Solve the DARE for the model's `Φ` and the measurement's `H`, with process noise
    /// `q` (`S×S`, symmetric positive semidefinite, units of `x` squared per step) and
    /// measurement noise `r` (`O×O`, symmetric positive definite, output units squared),
    /// and form the gain (`const fn`: in a `static` the compiler computes it).
    ///
    /// The result is verified before it is returned: an `Ok` carries a `P` that is a
    /// covariance, whose closed loop `Φ (I − L H)` is certified stable (a power
    /// `‖(D⁻¹ Φ (I − L H) D)^(2^k)‖∞ ≤ 2^-26`, `D` a balancing diagonal, so its spectral
    /// radius is below 1), and whose Riccati residual is within
    /// [`RICCATI_RESIDUAL_UNITS`] units of rounding of the equation's terms. A doubling
    /// solution above 4 units is first refined by up to 3 Newton (Hewer) steps.
    ///
    /// Errors: [`Error::InvalidCovariance`] (`q` or `r` not finite, not symmetric, or not
    /// positive (semi)definite), [`Error::RiccatiNotConverged`] (no stabilizing solution
    /// within [`RICCATI_MAX_ITERATIONS`]: a mode neither measured nor driven by `q`, or an
    /// unstable one; or a solution that fails its verification — a closed loop not
    /// certified stable, or a residual above the tolerance after refinement: an equation
    /// too ill-conditioned for `f64`), [`Error::OperatorOverflow`].
    ///
    /// Cost: about `10 S³` flops a doubling iteration, `≤ 64` iterations (typically
    /// 10–25; the doubling stops once `X` stands still and `‖A_k‖∞ ≤ 2^-26`), then the
    /// verification: about `6 S³` for the residual and `3 S³` a squaring of the closed
    /// loop (about `log₂(1/(1 − ρ))` of them, `ρ` its spectral radius), the same again for
    /// each refinement; a few `S×S` `f64` temporaries on the stack. In a `static` the
    /// compiler evaluates it; `S = 10` (the 5-storey building, 10 iterations) is pinned by
    /// `tests/observer.rs` (`CONST_GAIN`). Much larger `S` may stop rustc with the
    /// `long_running_const_eval` lint, as for the steppers' `from_rows_f32`/`_f64`: allow it at the
    /// firmware's crate root, or solve at run time with [`SteadyState::new`].
    pub const fn from_parts<const N: usize, const I: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        q: &[[f64; S]; S],
        r: &[[f64; O]; O],
    ) -> Result<Self, Error> {
        Self::solve(model, meas, q, r, None)
    }

    /// [`SteadyState::from_parts`] with a process–measurement cross covariance
    /// `n = E q_n r_nᵀ` (`S×O`, units of `x` times output units): the noise that drives the
    /// state into sample `n` correlated with the noise of the measurement at `n` — a force
    /// noise that also reaches the accelerometers through the feedthrough
    /// ([`StateSpace::input_cross_noise`], with [`StateSpace::feedthrough_noise`] in `r`).
    /// The gain is `L = (P Hᵀ + N) Σ⁻¹`, `Σ = H P Hᵀ + R + H N + Nᵀ Hᵀ` (the innovation
    /// covariance), `P` the a-priori covariance of the Riccati equation with the cross term
    /// (noise model and derivation: the [observer module docs](super), "Noise that reaches
    /// the sensors").
    /// `n = 0` (every entry zero) is [`SteadyState::from_parts`], bit for bit. `const fn`.
    ///
    /// Errors: as [`SteadyState::from_parts`]; [`Error::InvalidCovariance`] also when `n`
    /// is not finite or `[q n; nᵀ r]` is not a covariance (`q − n r⁻¹ nᵀ` not positive
    /// semidefinite). Cost: as [`SteadyState::from_parts`], plus `O(S²·O + O³)` flops for
    /// the cross term's form and check.
    pub const fn from_parts_cross<const N: usize, const I: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        q: &[[f64; S]; S],
        r: &[[f64; O]; O],
        n: &[[f64; O]; S],
    ) -> Result<Self, Error> {
        Self::solve(model, meas, q, r, Some(n))
    }

    /// The solution of [`SteadyState::from_parts`] (`n` absent or zero) and
    /// [`SteadyState::from_parts_cross`].
    const fn solve<const N: usize, const I: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        q: &[[f64; S]; S],
        r: &[[f64; O]; O],
        n: Option<&[[f64; O]; S]>,
    ) -> Result<Self, Error> {
        if !is_covariance(q, false) {
            return Err(Error::InvalidCovariance);
        }
        let lu_r = match definite_lu(r) {
            Some(lu) => lu,
            None => return Err(Error::InvalidCovariance),
        };
        let h = &meas.h;
        if !all_finite(h) {
            return Err(Error::NonFiniteInput);
        }
        let cross: Mat<S, O> = match n {
            Some(n) => *n,
            None => [[0.0; O]; S],
        };
        // A zero cross covariance takes the original path (bit-identical).
        let n = match n {
            Some(m) if is_zero(m) => None,
            other => other,
        };
        let start = match n {
            None => (
                transpose(&model.phi),
                symmetrize(&mul(&transpose(h), &lu_r.solve(h))),
                symmetrize(q),
            ),
            Some(n) => {
                if !cross_is_valid(q, r, n) {
                    return Err(Error::InvalidCovariance);
                }
                // The predictor form of the core (`P = Y + Q`): R_y = H Q Hᵀ + R + H N + Nᵀ Hᵀ,
                // S_y = Φ (Q Hᵀ + N), Q_y = Φ Q Φᵀ.
                let (xt, ry) = innovation_parts(q, h, r, Some(n));
                let lu_y = match definite_lu(&symmetrize(&ry)) {
                    Some(lu) => lu,
                    None => return Err(Error::InvalidCovariance),
                };
                let phi = &model.phi;
                let qy = symmetrize(&mul(phi, &mul(q, &transpose(phi))));
                let sy = mul(phi, &transpose(&xt));
                let pi = symmetrize(&lu_y.inverse());
                if !(all_finite(&qy) && all_finite(&sy) && all_finite(&pi)) {
                    return Err(Error::OperatorOverflow);
                }
                cross_riccati_start(phi, h, &qy, &sy, &pi)
            }
        };
        let q_cross = match n {
            None => None,
            Some(_) => Some(q),
        };
        let (x, k) = match doubling_solution(start, RICCATI_MAX_ITERATIONS, q_cross) {
            Some(v) => v,
            None => return Err(Error::RiccatiNotConverged),
        };
        // The solution verified, not trusted: an iterate that stops moving is not
        // necessarily the stabilizing solution to working accuracy (found by fuzzing). Its
        // closed loop is certified stable and its residual measured; one above
        // `RICCATI_RESIDUAL_REFINE` units is refined by Newton's method for the Riccati
        // equation (Hewer's iteration: the closed loop's Stein equation for the correction,
        // solved by doubling), at most `RICCATI_REFINEMENTS` times, keeping the best
        // iterate. Every iterate's gain is computed from its own `P`.
        let mut p = x;
        let mut best: Option<(Mat<S, S>, Mat<S, O>, f64)> = None;
        let mut step = 0;
        while step <= RICCATI_REFINEMENTS {
            let gain = match gain_of(&p, h, r, n) {
                Some(l) => l,
                None => break,
            };
            if !all_finite(&gain) {
                if best.is_none() && step == 0 {
                    return Err(Error::OperatorOverflow);
                }
                break;
            }
            let (res, bound, a_cl) = joseph_residual(&model.phi, h, q, r, &p, &gain, n);
            let units = residual_units(&res, &bound);
            // Hewer's step needs a stabilizing gain: its Stein solve is the certificate.
            let delta = match stein(&a_cl, &res) {
                Some(d) => d,
                None => break,
            };
            let better = match &best {
                Some((_, _, u)) => units < *u,
                None => units <= f64::INFINITY,
            };
            if better && is_covariance(&p, false) {
                best = Some((p, gain, units));
            }
            if units <= RICCATI_RESIDUAL_REFINE {
                break;
            }
            p = symmetrize(&add_scaled(&p, 1.0, &delta));
            step += 1;
        }
        match best {
            Some((p, gain, units)) if units <= RICCATI_RESIDUAL_UNITS => Ok(Self {
                covariance: p,
                gain,
                iterations: k,
                cross,
            }),
            _ => Err(Error::RiccatiNotConverged),
        }
    }

    /// [`SteadyState::from_parts`] with `nalgebra` covariances (run time; same numbers).
    ///
    /// Errors and cost: as [`SteadyState::from_parts`].
    pub fn new<const N: usize, const I: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
    ) -> Result<Self, Error> {
        Self::from_parts(model, meas, &rows_f64(q), &rows_f64(r))
    }

    /// [`SteadyState::from_parts_cross`] with `nalgebra` matrices (run time; same numbers).
    ///
    /// Errors and cost: as [`SteadyState::from_parts_cross`].
    pub fn new_cross<const N: usize, const I: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
        n: &SMatrix<f64, S, O>,
    ) -> Result<Self, Error> {
        Self::from_parts_cross(model, meas, &rows_f64(q), &rows_f64(r), &rows_f64(n))
    }

    /// `N` as a `nalgebra` matrix.
    pub fn cross_matrix(&self) -> SMatrix<f64, S, O> {
        SMatrix::from_fn(|i, j| self.cross[i][j])
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
