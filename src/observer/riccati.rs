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

use super::flat::{
    LuFlat, OutScratch, RiccatiParts, Scratch, Sensors, abs_into, balance_flat, check_noise,
    doubling_solution_flat, inf_norm_flat, plain_start, solve_from_start, stein_flat,
};
use super::kalman_core::{
    cross_is_valid, cross_riccati_start, definite_lu, innovation_parts, is_zero, symmetrize,
};
use super::state_space::{Measurement, StateSpace};
use crate::Error;
use crate::linalg::{Mat, all_finite, mul, rows_f64, transpose};

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

/// The doubling has converged once `‖A_k‖∞ ≤ 2^-26` (`√ε`): the updates of `X` still to
/// come are quadratic in it.
pub(crate) const A_SMALL: f64 = 1.4901161193847656e-8;

/// Stack scratch of the flat core ([`flat`](super::flat)) for `S` states: eight `S×S`
/// matrices, a vector and an LU. Size: `9 S² + 3 S` values.
pub(crate) struct SquareStack<const S: usize> {
    m: [Mat<S, S>; 8],
    d: [f64; S],
    lu: Mat<S, S>,
    perm: [usize; S],
    scales: [f64; S],
}

impl<const S: usize> SquareStack<S> {
    /// Zeroed scratch.
    pub(crate) const fn new() -> Self {
        Self {
            m: [[[0.0; S]; S]; 8],
            d: [0.0; S],
            lu: [[0.0; S]; S],
            perm: [0; S],
            scales: [0.0; S],
        }
    }

    /// The flat core's view of it.
    pub(crate) const fn scratch(&mut self) -> Scratch<'_> {
        let [m0, m1, m2, m3, m4, m5, m6, m7] = &mut self.m;
        Scratch {
            m: [
                m0.as_flattened_mut(),
                m1.as_flattened_mut(),
                m2.as_flattened_mut(),
                m3.as_flattened_mut(),
                m4.as_flattened_mut(),
                m5.as_flattened_mut(),
                m6.as_flattened_mut(),
                m7.as_flattened_mut(),
            ],
            d: &mut self.d,
            lu: LuFlat {
                lu: self.lu.as_flattened_mut(),
                perm: &mut self.perm,
                scales: &mut self.scales,
            },
        }
    }
}

/// Stack scratch of the flat core's output side for `S` states and `O` outputs.
struct OutStack<const S: usize, const O: usize> {
    on: [Mat<O, S>; 2],
    oo: [Mat<O, O>; 3],
    no: [Mat<S, O>; 2],
    lu: Mat<O, O>,
    perm: [usize; O],
    scales: [f64; O],
}

impl<const S: usize, const O: usize> OutStack<S, O> {
    /// Zeroed scratch.
    const fn new() -> Self {
        Self {
            on: [[[0.0; S]; O]; 2],
            oo: [[[0.0; O]; O]; 3],
            no: [[[0.0; O]; S]; 2],
            lu: [[0.0; O]; O],
            perm: [0; O],
            scales: [0.0; O],
        }
    }

    /// The flat core's view of it.
    const fn scratch(&mut self) -> OutScratch<'_> {
        let [on0, on1] = &mut self.on;
        let [oo0, oo1, oo2] = &mut self.oo;
        let [no0, no1] = &mut self.no;
        OutScratch {
            on: [on0.as_flattened_mut(), on1.as_flattened_mut()],
            oo: [
                oo0.as_flattened_mut(),
                oo1.as_flattened_mut(),
                oo2.as_flattened_mut(),
            ],
            no: [no0.as_flattened_mut(), no1.as_flattened_mut()],
            lu: LuFlat {
                lu: self.lu.as_flattened_mut(),
                perm: &mut self.perm,
                scales: &mut self.scales,
            },
        }
    }
}

/// The a-priori covariance the doubling algorithm solves for from `start = (A₀, G₀, X₀)`
/// within `max_iterations`, and the iterations taken; `None` if it breaks down, does not
/// converge, or stops at an iterate that is not a covariance (for a model with an
/// unobservable marginal mode, two free masses with only their sum measured, the doubling
/// stopped at a `P` with diagonal entries of −4e10: found by fuzzing). With the cross
/// term's start ([`cross_riccati_start`](super::kalman_core::cross_riccati_start)) the
/// doubling solves for `Y` and the a-priori covariance is `Y + Q`: pass `q_cross = Some(Q)`.
/// Shared by [`SteadyState`] and the joint filter's steady state; the flat core's
/// `doubling_solution_flat` on stack arrays.
///
/// The doubling (Chu, Fan, Lin 2005) for `X = Aᵀ X A − …` from `A₀ = Aᵀ`, `G₀ = G`,
/// `X₀ = X`: `W = I + G X`, `X ← X + Aᵀ X W⁻¹ A`, `G ← G + A W⁻¹ G Aᵀ`, `A ← A W⁻¹ A`.
/// Converged when X no longer moves (the update is below rounding of X) and A_k, which the
/// updates of X are quadratic in (`A_k ≈ (Φ − K H)ᵀ^(2^k)`), has become small: with a
/// closed-loop mode near the unit circle X can stand still for a few iterations while its
/// slow part has not yet accumulated (P stopped at iteration 2 with errors of 6e-14
/// relative, and its gain's observer had a spectral radius of 1.000008; found by fuzzing).
/// Below 2^-26 the remaining updates are below ε ‖X‖. Cost: about `10 S³` flops an
/// iteration, plus `S³/6` for the check.
pub(crate) const fn doubling_solution<const S: usize>(
    start: (Mat<S, S>, Mat<S, S>, Mat<S, S>),
    max_iterations: u32,
    q_cross: Option<&Mat<S, S>>,
) -> Option<(Mat<S, S>, u32)> {
    let (mut a, mut g, mut x) = start;
    let mut st = SquareStack::<S>::new();
    let q = match q_cross {
        Some(q) => Some(q.as_flattened()),
        None => None,
    };
    match doubling_solution_flat(
        [
            a.as_flattened_mut(),
            g.as_flattened_mut(),
            x.as_flattened_mut(),
        ],
        S,
        max_iterations,
        q,
        &mut st.scratch(),
    ) {
        Some(k) => Some((x, k)),
        None => None,
    }
}

/// `|a|` entry by entry.
pub(crate) const fn abs_of<const R: usize, const C: usize>(a: &Mat<R, C>) -> Mat<R, C> {
    let mut b = *a;
    abs_into(b.as_flattened_mut(), a.as_flattened());
    b
}

/// `max_i Σ_j |a_ij|` (NaN if an entry is NaN).
pub(crate) const fn inf_norm<const N: usize>(a: &Mat<N, N>) -> f64 {
    inf_norm_flat(a.as_flattened(), N)
}

/// `a` balanced: `D⁻¹ a D` and `D` (its diagonal), `D` powers of two (exact, the same
/// eigenvalues) chosen as LAPACK's `gebal` does so that each row and column have comparable
/// off-diagonal sums. A badly scaled closed loop (`H ≈ 7e41` of a modal form with
/// `M = 2e-84`) has a norm far above its spectral radius, and its squares would be all
/// rounding. Cost: `O(S²)` a sweep, a few sweeps.
pub(crate) const fn balance<const N: usize>(a: &Mat<N, N>) -> (Mat<N, N>, [f64; N]) {
    let mut b = *a;
    let mut d = [1.0f64; N];
    balance_flat(b.as_flattened_mut(), &mut d, N);
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
    let mut x = [[0.0; N]; N];
    let mut st = SquareStack::<N>::new();
    if stein_flat(
        a.as_flattened(),
        w.as_flattened(),
        N,
        x.as_flattened_mut(),
        &mut st.scratch(),
    ) {
        Some(x)
    } else {
        None
    }
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
        let cross: Mat<S, O> = match n {
            Some(n) => *n,
            None => [[0.0; O]; S],
        };
        // A zero cross covariance takes the original path (bit-identical).
        let n = match n {
            Some(m) if is_zero(m) => None,
            other => other,
        };
        let sn = Sensors {
            h: meas.h.as_flattened(),
            r: r.as_flattened(),
            cross: match n {
                Some(m) => Some(m.as_flattened()),
                None => None,
            },
            o: O,
        };
        let (mut sq, mut out) = (SquareStack::<S>::new(), OutStack::<S, O>::new());
        let (mut s, mut t) = (sq.scratch(), out.scratch());
        if let Err(e) = check_noise(q.as_flattened(), S, &sn, &mut s, &mut t) {
            return Err(e);
        }
        let h = &meas.h;
        let (mut a, mut g, mut x) = ([[0.0; S]; S], [[0.0; S]; S], [[0.0; S]; S]);
        match n {
            None => plain_start(
                model.phi.as_flattened(),
                q.as_flattened(),
                S,
                &sn,
                [
                    a.as_flattened_mut(),
                    g.as_flattened_mut(),
                    x.as_flattened_mut(),
                ],
                &mut t,
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
                (a, g, x) = cross_riccati_start(phi, h, &qy, &sy, &pi);
            }
        }
        // The solution verified, not trusted: an iterate that stops moving is not
        // necessarily the stabilizing solution to working accuracy (found by fuzzing). Its
        // closed loop is certified stable and its residual measured; one above 4 units is
        // refined by Newton's method for the Riccati equation (Hewer's iteration: the
        // closed loop's Stein equation for the correction, solved by doubling), at most 3
        // times, keeping the best iterate. Every iterate's gain is computed from its own
        // `P`. (The flat core's `solve_from_start`, shared with `DynSteadyState`.)
        let (mut covariance, mut gain) = ([[0.0; S]; S], [[0.0; O]; S]);
        let (mut res, mut bound, mut delta, mut best) =
            ([[0.0; S]; S], [[0.0; S]; S], [[0.0; S]; S], [[0.0; O]; S]);
        match solve_from_start(&mut RiccatiParts {
            phi: model.phi.as_flattened(),
            q: q.as_flattened(),
            n: S,
            sn: &sn,
            q_cross: n.is_some(),
            start: [
                a.as_flattened_mut(),
                g.as_flattened_mut(),
                x.as_flattened_mut(),
            ],
            out: (covariance.as_flattened_mut(), gain.as_flattened_mut()),
            work: [
                res.as_flattened_mut(),
                bound.as_flattened_mut(),
                delta.as_flattened_mut(),
                best.as_flattened_mut(),
            ],
            s: &mut s,
            t: &mut t,
        }) {
            Ok(k) => Ok(Self {
                covariance,
                gain,
                iterations: k,
                cross,
            }),
            Err(e) => Err(e),
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
