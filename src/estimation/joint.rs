//! The joint input–state filter of Gillijns & De Moor (2007, with direct feedthrough): its
//! steady-state gains, the fixed-gain filter and the time-varying filter (equations and
//! derivation in the [module docs](super)).

use nalgebra::{SMatrix, SVector};

use super::InputModel;
use crate::linalg::{self, Mat, add_scaled, all_finite, identity, max_abs, mul};
use crate::linalg::{matrix_t, round_rows, rows_f64, sym, transpose};
use crate::observer::symmetrize;
use crate::observer::{A_SMALL, balance, doubling_solution, inf_norm, is_covariance, lu_of};
use crate::observer::{check_counts, innovation_parts, innovation_t, is_zero, next_counts};
use crate::observer::{check_start_covariance, noise_fits};
use crate::observer::{checked_cross_t, cross_is_valid, cross_riccati_start, gain_t};
use crate::stepper::commit_if_finite;
use crate::{Error, Real, StepState};

/// Iteration budget of the doubling algorithm of [`InputStateGains::solve`] (iterate `k`
/// covers `2^k` steps of the covariance recursion).
pub const STEADY_MAX_ITERATIONS: u32 = 64;

/// Squarings allowed to certify the steady filter's error dynamics `E` stable (the
/// invariant-zero test of the [module docs](super)): `‖(D⁻¹ E D)^(2^k)‖∞ ≤ 2^-26` for some
/// `k ≤ 24` bounds the spectral radius by `2^(−26/2^24) ≈ 1 − 1.07e-6`.
pub const ZERO_SQUARINGS: u32 = 24;

/// The relative residual allowed of the steady covariance: one step of the paper's
/// recursion from `P⁻` moves no entry by more than `1e-9 · max|P⁻|` (far above the
/// rounding of a converged solution, a few `S ε` times the equation's conditioning —
/// `tests/estimation.rs` measures the steady `P⁻` within `2e-14` of the recursion's limit
/// for the 5-storey building; a residual above `1e-9` means the equation is too
/// ill-conditioned for `f64`).
const STEADY_RESIDUAL: f64 = 1e-9;

/// The steady-state solution of the joint input–state filter (all `f64`, row-major).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InputStateGains<const S: usize, const I: usize, const O: usize> {
    /// `P⁻` (`S×S`): the a-priori error covariance of `ξ` (units of `x` squared).
    pub covariance: [[f64; S]; S],
    /// `K = P⁻ Cᵀ R̃⁻¹` (`S×O`): the state gain.
    pub state_gain: [[f64; O]; S],
    /// `M = (D̃ᵀ R̃⁻¹ D̃)⁻¹ D̃ᵀ R̃⁻¹` (`I×O`): the input gain, `ŵ = M (y − C ξ⁻)`.
    pub input_gain: [[f64; O]; I],
    /// `Pʷ = (D̃ᵀ R̃⁻¹ D̃)⁻¹` (`I×I`): the error covariance of the input estimate (input
    /// units squared).
    pub input_covariance: [[f64; I]; I],
    /// `R̃ = C P⁻ Cᵀ + R` (`O×O`, output units squared): the covariance of
    /// `y_n − C ξ⁻ − D̃ w_n`. Whitened by it, the residual
    /// [`InputStateObserver::step_innovation`] returns has `νᵀ R̃⁻¹ ν ~ χ²` with `O − I`
    /// degrees of freedom: a [`Whitener`](crate::detection::Whitener) of `R̃` and a
    /// [`ChiSquareTest`](crate::detection::ChiSquareTest) of `O − I` outputs test it.
    pub innovation_covariance: [[f64; O]; O],
    /// Doubling iterations taken (`≤` [`STEADY_MAX_ITERATIONS`]).
    pub iterations: u32,
}

/// The gains of one step from an a-priori covariance `p`: `(K, M, Pʷ, R̃)`, or `None` if
/// `R̃` or `D̃ᵀ R̃⁻¹ D̃` is singular. With a cross covariance `n`, `R̃` and `K` carry it
/// (the Kalman core's [`innovation_parts`]).
#[allow(clippy::type_complexity)]
const fn step_gains<const S: usize, const I: usize, const O: usize>(
    m: &InputModel<S, I, O>,
    p: &Mat<S, S>,
    r: &Mat<O, O>,
    n: Option<&Mat<S, O>>,
) -> Option<(Mat<S, O>, Mat<I, O>, Mat<I, I>, Mat<O, O>)> {
    let (cp, rt) = innovation_parts(p, &m.c, r, n);
    let rt = symmetrize(&rt);
    let lu = match lu_of(&rt) {
        Some(lu) => lu,
        None => return None,
    };
    let k = transpose(&lu.solve(&cp));
    let rtd = lu.solve(&m.d);
    let f = symmetrize(&mul(&transpose(&m.d), &rtd));
    let luf = match lu_of(&f) {
        Some(lu) => lu,
        None => return None,
    };
    let pw = symmetrize(&luf.inverse());
    let gm = luf.solve(&transpose(&rtd));
    Some((k, gm, pw, rt))
}

/// The a-priori covariance after one step of the recursion from the a-priori `p`.
const fn recursion_step<const S: usize, const I: usize, const O: usize>(
    m: &InputModel<S, I, O>,
    q: &Mat<S, S>,
    p: &Mat<S, S>,
    k: &Mat<S, O>,
    pw: &Mat<I, I>,
    rt: &Mat<O, O>,
) -> Mat<S, S> {
    let dpd = mul(&m.d, &mul(pw, &transpose(&m.d)));
    let inner = add_scaled(rt, -1.0, &dpd);
    let post = add_scaled(p, -1.0, &mul(k, &mul(&inner, &transpose(k))));
    let pxw = scaled_neg(&mul(k, &mul(&m.d, pw)));
    let at = transpose(&m.a);
    let bt = transpose(&m.b);
    let apb = mul(&m.a, &mul(&pxw, &bt));
    let mut next = add_scaled(&mul(&m.a, &mul(&post, &at)), 1.0, &apb);
    next = add_scaled(&next, 1.0, &transpose(&apb));
    next = add_scaled(&next, 1.0, &mul(&m.b, &mul(pw, &bt)));
    symmetrize(&add_scaled(&next, 1.0, q))
}

/// `−a`.
const fn scaled_neg<const R: usize, const C: usize>(a: &Mat<R, C>) -> Mat<R, C> {
    linalg::scaled(-1.0, a)
}

/// The doubling's start for the steady joint filter with a cross covariance `n` (module
/// docs, "Noise that reaches the sensors"): with `R₁ = C Q Cᵀ + R + C N + Nᵀ Cᵀ` and
/// `Π₁ = R₁⁻¹ − R₁⁻¹ D̃ (D̃ᵀ R₁⁻¹ D̃)⁻¹ D̃ᵀ R₁⁻¹`, the Kalman core's predictor form on
/// `(Ā, C)` with `Q_y = Ā Q Āᵀ + B F₀⁻¹ Bᵀ − Ā N M₀ᵀ Bᵀ − B M₀ Nᵀ Āᵀ`,
/// `S_y = Ā (Q Cᵀ + N) − B M₀ Nᵀ Cᵀ` and the weight `Π₁`.
#[allow(clippy::type_complexity)]
const fn cross_start<const S: usize, const I: usize, const O: usize>(
    m: &InputModel<S, I, O>,
    q: &Mat<S, S>,
    r: &Mat<O, O>,
    n: &Mat<S, O>,
    abar: &Mat<S, S>,
    m0: &Mat<I, O>,
    f0inv: &Mat<I, I>,
) -> Result<(Mat<S, S>, Mat<S, S>, Mat<S, S>), Error> {
    if !cross_is_valid(q, r, n) {
        return Err(Error::InvalidCovariance);
    }
    let (xt, r1) = innovation_parts(q, &m.c, r, Some(n));
    let lu1 = match lu_of(&symmetrize(&r1)) {
        Some(lu) => lu,
        None => return Err(Error::InvalidCovariance),
    };
    let r1d = lu1.solve(&m.d);
    let f1 = symmetrize(&mul(&transpose(&m.d), &r1d));
    let luf = match lu_of(&f1) {
        Some(lu) => lu,
        None => return Err(Error::InputNotIdentifiable),
    };
    let pi = symmetrize(&add_scaled(
        &lu1.inverse(),
        -1.0,
        &mul(&r1d, &luf.solve(&transpose(&r1d))),
    ));
    let bm0 = mul(&m.b, m0);
    let anb = mul(abar, &mul(n, &transpose(&bm0)));
    let qy = symmetrize(&add_scaled(
        &add_scaled(
            &mul(abar, &mul(q, &transpose(abar))),
            1.0,
            &mul(&m.b, &mul(f0inv, &transpose(&m.b))),
        ),
        -1.0,
        &add_scaled(&anb, 1.0, &transpose(&anb)),
    ));
    let sy = add_scaled(
        &mul(abar, &transpose(&xt)),
        -1.0,
        &mul(&bm0, &mul(&transpose(n), &transpose(&m.c))),
    );
    if !(all_finite(&qy) && all_finite(&sy) && all_finite(&pi)) {
        return Err(Error::OperatorOverflow);
    }
    Ok(cross_riccati_start(abar, &m.c, &qy, &sy, &pi))
}

/// The steady filter's error dynamics `E` certified stable within [`ZERO_SQUARINGS`]
/// balanced squarings.
const fn certified_stable<const S: usize>(e: &Mat<S, S>) -> bool {
    let (mut b, _) = balance(e);
    let mut k = 0;
    while k <= ZERO_SQUARINGS {
        let n = inf_norm(&b);
        if !n.is_finite() {
            return false;
        }
        if n <= A_SMALL {
            return true;
        }
        if k == ZERO_SQUARINGS {
            return false;
        }
        b = mul(&b, &b);
        k += 1;
    }
    false
}

impl<const S: usize, const I: usize, const O: usize> InputStateGains<S, I, O> {
    /// The steady-state gains of the joint input–state filter of `model` with process noise
    /// `q` (`S×S` on `ξ`, symmetric positive semidefinite, units of `x` squared per step)
    /// and measurement noise `r` (`O×O`, symmetric positive definite), checking the
    /// identifiability of the input ([module docs](super)). `const fn`: in a `static` the
    /// compiler computes the gains.
    ///
    /// Errors: [`Error::InvalidCovariance`] (`q`, `r`), [`Error::InputNotIdentifiable`]
    /// (rank of `D̃`; no stabilizing steady state — an invariant zero on or outside the
    /// unit circle, the acceleration-only drift; or error dynamics not certified with a
    /// spectral radius below `1 − 1.07e-6`), [`Error::RiccatiNotConverged`] (a steady
    /// covariance whose residual exceeds `1e-9` relative: too ill-conditioned for `f64`),
    /// [`Error::OperatorOverflow`].
    ///
    /// Cost: about `10 S³` flops a doubling iteration (≤ [`STEADY_MAX_ITERATIONS`],
    /// typically 10–25), then `O(S³)` for the gains, the residual and up to
    /// [`ZERO_SQUARINGS`] squarings of `E`. For much larger `S` than the 5-storey building
    /// rustc may stop a `static` with the `long_running_const_eval` lint: allow it at the
    /// firmware's crate root, or call [`InputStateGains::new`] at run time.
    pub const fn solve(
        model: &InputModel<S, I, O>,
        q: &[[f64; S]; S],
        r: &[[f64; O]; O],
    ) -> Result<Self, Error> {
        Self::solve_with(model, q, r, None)
    }

    /// [`InputStateGains::solve`] with a process–measurement cross covariance
    /// `n = E q_n r_nᵀ` (`S×O`): the process noise on `ξ` correlated with the measurement
    /// noise of the same sample (unmodelled floor forces that also reach the
    /// accelerometers: [`StateSpace::input_cross_noise`](crate::observer::StateSpace::input_cross_noise)
    /// of the forces' model, with its
    /// [`feedthrough_noise`](crate::observer::StateSpace::feedthrough_noise) in `r`). The
    /// step's `R̃ = C P⁻ Cᵀ + R + C N + Nᵀ C` and `K = (P⁻ Cᵀ + N) R̃⁻¹` ([module
    /// docs](super), "Noise that reaches the sensors"); `n = 0` is
    /// [`InputStateGains::solve`], bit for bit. `const fn`.
    ///
    /// Errors: as [`InputStateGains::solve`]; [`Error::InvalidCovariance`] also when `n` is
    /// not finite or `[q n; nᵀ r]` is not a covariance. Cost: as
    /// [`InputStateGains::solve`] plus `O(S²·O + S·O² + O³)`.
    pub const fn solve_cross(
        model: &InputModel<S, I, O>,
        q: &[[f64; S]; S],
        r: &[[f64; O]; O],
        n: &[[f64; O]; S],
    ) -> Result<Self, Error> {
        Self::solve_with(model, q, r, Some(n))
    }

    const fn solve_with(
        model: &InputModel<S, I, O>,
        q: &[[f64; S]; S],
        r: &[[f64; O]; O],
        n: Option<&[[f64; O]; S]>,
    ) -> Result<Self, Error> {
        if !is_covariance(q, false) {
            return Err(Error::InvalidCovariance);
        }
        // A zero cross covariance takes the original path (bit-identical).
        let n = match n {
            Some(m) if is_zero(m) => None,
            other => other,
        };
        let (f0, rd) = match model.weighted_feedthrough(r) {
            Ok(v) => v,
            Err(e) => return Err(e),
        };
        let (lu_f0, lu_r) = match (lu_of(&f0), lu_of(r)) {
            (Some(a), Some(b)) => (a, b),
            _ => return Err(Error::InputNotIdentifiable),
        };
        let f0inv = symmetrize(&lu_f0.inverse());
        let m0 = lu_f0.solve(&transpose(&rd));
        // Ā = A − B M₀ C, Q̄ = Q + B F₀⁻¹ Bᵀ, G = Cᵀ (R⁻¹ − R⁻¹ D̃ F₀⁻¹ D̃ᵀ R⁻¹) C.
        let abar = add_scaled(&model.a, -1.0, &mul(&model.b, &mul(&m0, &model.c)));
        let qbar = symmetrize(&add_scaled(
            q,
            1.0,
            &mul(&model.b, &mul(&f0inv, &transpose(&model.b))),
        ));
        let pi0 = symmetrize(&add_scaled(
            &lu_r.inverse(),
            -1.0,
            &mul(&rd, &mul(&f0inv, &transpose(&rd))),
        ));
        let g = symmetrize(&mul(&transpose(&model.c), &mul(&pi0, &model.c)));
        if !(all_finite(&abar) && all_finite(&qbar) && all_finite(&g)) {
            return Err(Error::OperatorOverflow);
        }
        // The doubling algorithm (as `SteadyState`): A₀ = Āᵀ, G₀ = G, X₀ = Q̄; with a cross
        // covariance the Kalman core's predictor form on the zero dynamics (module docs).
        let start = match n {
            None => (transpose(&abar), g, qbar),
            Some(n) => match cross_start(model, q, r, n, &abar, &m0, &f0inv) {
                Ok(v) => v,
                Err(e) => return Err(e),
            },
        };
        // With the cross term the doubling solved for Y: P⁻ = Y + Q.
        let q_cross = match n {
            None => None,
            Some(_) => Some(q),
        };
        let (x, k) = match doubling_solution(start, STEADY_MAX_ITERATIONS, q_cross) {
            Some(v) => v,
            None => return Err(Error::InputNotIdentifiable),
        };
        let (kx, gm, pw, rt) = match step_gains(model, &x, r, n) {
            Some(v) => v,
            None => return Err(Error::InputNotIdentifiable),
        };
        if !(all_finite(&kx) && all_finite(&gm) && all_finite(&pw)) {
            return Err(Error::OperatorOverflow);
        }
        // E = A − A K (I − D̃ M) C − B M C: the a-priori error dynamics.
        let idm = add_scaled(&identity(), -1.0, &mul(&model.d, &gm));
        let akc = mul(&model.a, &mul(&kx, &mul(&idm, &model.c)));
        let e = add_scaled(
            &add_scaled(&model.a, -1.0, &akc),
            -1.0,
            &mul(&model.b, &mul(&gm, &model.c)),
        );
        if !certified_stable(&e) {
            return Err(Error::InputNotIdentifiable);
        }
        let next = recursion_step(model, q, &x, &kx, &pw, &rt);
        // (With N the step's gains carry it; the recursion's form is unchanged.)
        let res = max_abs(&add_scaled(&next, -1.0, &x));
        // (NaN fails too.)
        if res.is_nan() || res > STEADY_RESIDUAL * max_abs(&x) {
            return Err(Error::RiccatiNotConverged);
        }
        Ok(Self {
            covariance: x,
            state_gain: kx,
            input_gain: gm,
            input_covariance: pw,
            innovation_covariance: rt,
            iterations: k,
        })
    }

    /// [`InputStateGains::solve`] with `nalgebra` covariances (run time; same numbers).
    ///
    /// Errors and cost: as [`InputStateGains::solve`].
    pub fn new(
        model: &InputModel<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
    ) -> Result<Self, Error> {
        Self::solve(model, &rows_f64(q), &rows_f64(r))
    }

    /// [`InputStateGains::solve_cross`] with `nalgebra` matrices (run time; same numbers).
    ///
    /// Errors and cost: as [`InputStateGains::solve_cross`].
    pub fn new_cross(
        model: &InputModel<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
        n: &SMatrix<f64, S, O>,
    ) -> Result<Self, Error> {
        Self::solve_cross(model, &rows_f64(q), &rows_f64(r), &rows_f64(n))
    }

    /// `K` as a `nalgebra` matrix.
    pub fn state_gain_matrix(&self) -> SMatrix<f64, S, O> {
        crate::linalg::matrix_t(&self.state_gain)
    }
    /// `M` as a `nalgebra` matrix.
    pub fn input_gain_matrix(&self) -> SMatrix<f64, I, O> {
        crate::linalg::matrix_t(&self.input_gain)
    }
    /// `P⁻` as a `nalgebra` matrix.
    pub fn covariance_matrix(&self) -> SMatrix<f64, S, S> {
        crate::linalg::matrix_t(&self.covariance)
    }
    /// `Pʷ` as a `nalgebra` matrix.
    pub fn input_covariance_matrix(&self) -> SMatrix<f64, I, I> {
        crate::linalg::matrix_t(&self.input_covariance)
    }
}

/// The state of a joint input–state estimator: `ξ̂_n` (`S` values), the input estimate
/// `ŵ_n` (`I` values), the step count and the number of missing measurements. Plain data.
/// The physical state is `x̂_n = ξ̂_n + Γ₁ ŵ_n` ([`InputStateObserver::state`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointEstimate<T, const S: usize, const I: usize> {
    pub(super) xi: SVector<T, S>,
    pub(super) w: SVector<T, I>,
    pub(super) n: u64,
    pub(super) missing: u64,
}

impl<T: Real, const S: usize, const I: usize> JointEstimate<T, S, I> {
    /// `ξ̂_n = x̂_n − Γ₁ ŵ_n` (units of the model's state).
    pub fn xi(&self) -> &SVector<T, S> {
        &self.xi
    }
    /// The input estimate `ŵ_n` (units of the model's input, e.g. N).
    pub fn input(&self) -> &SVector<T, I> {
        &self.w
    }
}

crate::observer::estimate_counters!(JointEstimate, xi);

/// At rest: as `JointEstimate::at_rest_f32`/`at_rest_f64`, for any `T`.
impl<T: Real, const S: usize, const I: usize> Default for JointEstimate<T, S, I> {
    fn default() -> Self {
        Self {
            xi: SVector::zeros(),
            w: SVector::zeros(),
            n: 0,
            missing: 0,
        }
    }
}

macro_rules! joint_estimate_at_rest {
    ($t:ident, $at_rest:ident, $zeros:ident) => {
        impl<const S: usize, const I: usize> JointEstimate<$t, S, I> {
            /// At rest with no input (`ξ̂_0 = 0`, `ŵ_0 = 0`, step 0): `const fn`, for a
            /// `static`; equal to `JointEstimate::default()` and to
            /// [`InputStateObserver::start_at_rest`]. Cost: none in a `static`.
            pub const fn $at_rest() -> Self {
                Self {
                    xi: crate::state::$zeros(),
                    w: crate::state::$zeros(),
                    n: 0,
                    missing: 0,
                }
            }
        }
    };
}
joint_estimate_at_rest!(f32, at_rest_f32, zeros_f32);
joint_estimate_at_rest!(f64, at_rest_f64, zeros_f64);

/// `x − Γ₁ w` (or `+` with `sign = 1`) in `T`.
pub(super) fn shift<T: Real, const S: usize, const I: usize>(
    gamma1: &[[T; I]; S],
    x: &SVector<T, S>,
    w: &SVector<T, I>,
    sign: T,
) -> SVector<T, S> {
    SVector::from_fn(|i, _| {
        let mut s = x[i];
        for j in 0..I {
            s += sign * gamma1[i][j] * w[j];
        }
        s
    })
}

/// The start of a joint estimate: `ξ̂_0 = x0 − Γ₁ w0`, `ŵ_0 = w0`, all finite.
pub(super) fn joint_start<T: Real, const S: usize, const I: usize>(
    gamma1: &[[T; I]; S],
    x0: &SVector<T, S>,
    w0: &SVector<T, I>,
) -> Result<JointEstimate<T, S, I>, Error> {
    let e = JointEstimate {
        xi: shift(gamma1, x0, w0, -T::one()),
        w: *w0,
        n: 0,
        missing: 0,
    };
    if x0.iter().chain(w0.iter()).all(|v| v.is_finite()) && e.is_finite() {
        Ok(e)
    } else {
        Err(Error::NonFiniteInput)
    }
}

/// The start of a time-varying joint filter ([`InputStateFilter`], the dual
/// [`DualKalmanFilter`](super::DualKalmanFilter)): [`joint_start`], and the covariances of
/// `ξ̂_0` (`p0`, `S×S`) and `ŵ_0` (`pw0`, `I×I`) symmetric positive semidefinite.
/// Errors: [`Error::NonFiniteInput`], [`Error::InvalidCovariance`]. Cost: `O(S³ + I³)`.
pub(super) fn joint_start_covariances<T: Real, const S: usize, const I: usize>(
    gamma1: &[[T; I]; S],
    x0: &SVector<T, S>,
    p0: &SMatrix<T, S, S>,
    w0: &SVector<T, I>,
    pw0: &SMatrix<T, I, I>,
) -> Result<JointEstimate<T, S, I>, Error> {
    let estimate = joint_start(gamma1, x0, w0)?;
    check_start_covariance(p0)?;
    check_start_covariance(pw0)?;
    Ok(estimate)
}

/// The fixed-gain joint input–state filter (the steady state of Gillijns & De Moor 2007)
/// on `S` states, `I` unknown inputs, `O` measurements:
///
/// ```text
/// ξ⁻ = A ξ̂ + B ŵ        ν = y_n − C ξ⁻        ŵ_n = M ν        ξ̂_n = ξ⁻ + L ν
/// ```
///
/// with `L = K (I − D̃ M)` (the step of the [module docs](super) with `ŵ_n` substituted).
/// A measurement with a non-finite entry is missing: `ξ̂_n = ξ⁻`, the input estimate held
/// (`ŵ_n = ŵ_{n−1}`), counted.
///
/// Cost of a step: `S² + S·I + 2S·O + I·O` multiply-adds, fixed (`S = 10`, `I = 1`,
/// `O = 4`: 194); [`InputStateObserver::state`] adds `S·I`. Size:
/// `S² + 2S·I + 2S·O + 2I·O + 1` values of `T` (`A`, `B`, `C`, `L`, `M`, `D̃`, `Γ₁`, `h`). Every operator is computed in `f64` and
/// rounded once to `T`; [`InputStateObserver::new`] and `from_parts_f32`/`_f64` (`const fn`: a
/// `static` keeps the gains in flash) are bit-identical.
///
/// ```
/// use aemstep::estimation::{InputModel, InputStateGains, InputStateObserver};
/// use aemstep::models;
/// use aemstep::observer::{Outputs, StateSpace};
/// use aemstep::nalgebra::SMatrix;
/// use aemstep::vector;
///
/// // The 5-storey building, an unknown force at the roof; absolute accelerations of
/// // floors 1, 3, 5 and the roof displacement measured (fixed base: no ground input).
/// let (m, c, k) = models::five_storey_building();
/// let roof = [[0.0], [0.0], [0.0], [0.0], [1.0]];
/// let ss = StateSpace::<5, 10, 1>::from_rows_aem(m, c, k, roof, 0.02)?;
/// let mut out = Outputs::<5, 1, 4>::zero();
/// out.a = [[1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 1.0], [0.0; 5]];
/// out.u[3] = [0.0, 0.0, 0.0, 0.0, 1.0];
/// let model = InputModel::from_parts(&ss, &ss.outputs(&out)?)?;
/// let q = SMatrix::<f64, 10, 10>::identity() * 1e-14;
/// let r = SMatrix::<f64, 4, 4>::from_diagonal(&vector![1e-4, 1e-4, 1e-4, 1e-8]);
/// let gains = InputStateGains::new(&model, &q, &r)?;
/// let f = InputStateObserver::<f32, 10, 1, 4>::new(&model, &gains)?;
/// let mut e = f.start_at_rest();
/// f.try_step(&mut e, &vector![0.01, 0.02, 0.03, 1e-4])?;
/// let force = e.input()[0]; // N
/// assert!(force.is_finite());
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputStateObserver<T, const S: usize, const I: usize, const O: usize> {
    a: [[T; S]; S],
    b: [[T; I]; S],
    c: [[T; S]; O],
    gain_x: [[T; O]; S],
    gain_w: [[T; O]; I],
    d: [[T; I]; O],
    gamma1: [[T; I]; S],
    time_step: T,
}

/// `L = K (I − D̃ M)` and the checks that every operator fits `T`.
const fn observer_parts<const S: usize, const I: usize, const O: usize>(
    model: &InputModel<S, I, O>,
    gains: &InputStateGains<S, I, O>,
    max: f64,
) -> Result<Mat<S, O>, Error> {
    // (`L` from unchecked gains is only compared, never kept: the checks come first in
    // effect.)
    let kd = mul(&gains.state_gain, &model.d);
    let l = add_scaled(&gains.state_gain, -1.0, &mul(&kd, &gains.input_gain));
    if let Err(e) = model.check_fixed_gains(&gains.state_gain, &l, &gains.input_gain, max) {
        return Err(e);
    }
    Ok(l)
}

joint_accessors!(fixed InputStateObserver);

impl<T: Real, const S: usize, const I: usize, const O: usize> InputStateObserver<T, S, I, O> {
    /// The fixed-gain filter of `model` with the steady-state `gains`, rounded once to `T`.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`] (the model's `time_step` in
    /// `T`), [`Error::OperatorOverflow`]. Cost: `O(S²·O)`.
    pub fn new(
        model: &InputModel<S, I, O>,
        gains: &InputStateGains<S, I, O>,
    ) -> Result<Self, Error> {
        let l = observer_parts(model, gains, T::MAX)?;
        Ok(Self {
            a: round_rows(&model.a),
            b: round_rows(&model.b),
            c: round_rows(&model.c),
            gain_x: round_rows(&l),
            gain_w: round_rows(&gains.input_gain),
            d: round_rows(&model.d),
            gamma1: round_rows(&model.gamma1),
            time_step: T::from_f64_rounded(model.time_step),
        })
    }

    /// The start at rest with no input (`ξ̂_0 = 0`, `ŵ_0 = 0`).
    pub fn start_at_rest(&self) -> JointEstimate<T, S, I> {
        JointEstimate::default()
    }

    /// One step with the measurement `y` (`y_n`). A non-finite entry of `y` is a missing
    /// sample: predict only, hold the input estimate, count it.
    ///
    /// Fixed cost (type docs), no allocation, no panic.
    #[inline]
    pub fn step(&self, e: &mut JointEstimate<T, S, I>, y: &SVector<T, O>) {
        // The residual is dead code here: the compiler drops it (the step's cost is the
        // type docs' count, measured in the firmware's cost table).
        self.step_innovation(e, y);
    }

    /// [`InputStateObserver::step`], returning the residual `ν = y_n − C ξ⁻ − D̃ ŵ_n`
    /// (output units): what is left of the measurement once the input estimated from it
    /// is taken out — what a change detector tests ([`detection`](crate::detection)).
    /// While the structure matches the model, `ν` is zero-mean and `νᵀ R̃⁻¹ ν ~ χ²_{O−I}`
    /// whatever the input (`R̃` is [`InputStateGains::innovation_covariance`]; `I` of the
    /// `O` directions are spent on the input). Non-finite where `y` is (a missing sample:
    /// then `ν = y − C ξ⁻`, nothing corrected).
    ///
    /// Cost: [`InputStateObserver::step`] plus `O·I` multiply-adds.
    #[inline(always)]
    pub fn step_innovation(
        &self,
        e: &mut JointEstimate<T, S, I>,
        y: &SVector<T, O>,
    ) -> SVector<T, O> {
        let neg_zero = -T::zero();
        let xp: [T; S] = core::array::from_fn(|i| {
            let mut s = neg_zero;
            for j in 0..I {
                s += self.b[i][j] * e.w[j];
            }
            for j in 0..S {
                s += self.a[i][j] * e.xi[j];
            }
            s
        });
        let mut innov = [T::zero(); O];
        let mut measured = true;
        for o in 0..O {
            let mut s = y[o];
            for j in 0..S {
                s -= self.c[o][j] * xp[j];
            }
            innov[o] = s;
            measured &= y[o].is_finite();
        }
        if measured {
            for i in 0..I {
                let mut s = neg_zero;
                for o in 0..O {
                    s += self.gain_w[i][o] * innov[o];
                }
                e.w[i] = s;
            }
            for i in 0..S {
                let mut s = xp[i];
                for o in 0..O {
                    s += self.gain_x[i][o] * innov[o];
                }
                e.xi[i] = s;
            }
            for (o, v) in innov.iter_mut().enumerate() {
                for j in 0..I {
                    *v -= self.d[o][j] * e.w[j];
                }
            }
        } else {
            e.xi = xp.into();
            e.missing = e.missing.wrapping_add(1);
        }
        e.n = e.n.wrapping_add(1);
        innov.into()
    }

    /// [`InputStateObserver::step`], checked: the new estimate must be finite, else `e` is
    /// left bit-identical. A non-finite measurement is a missing sample, not an error.
    ///
    /// Errors: [`Error::NonFiniteState`], [`Error::StepCountOverflow`] (the step count, or
    /// the count of missing samples, would pass `u64::MAX`: refused rather than wrapped;
    /// the unchecked [`InputStateObserver::step`] wraps after `2⁶⁴` steps). Cost: a step
    /// plus a copy and a scan.
    pub fn try_step(&self, e: &mut JointEstimate<T, S, I>, y: &SVector<T, O>) -> Result<(), Error> {
        check_counts(e.n, e.missing, y)?;
        commit_if_finite(e, |next| self.step(next, y))
    }

    /// [`InputStateObserver::step_innovation`], checked as [`InputStateObserver::try_step`]:
    /// on an error `e` is left bit-identical and no residual is returned.
    ///
    /// Errors: [`Error::NonFiniteState`], [`Error::StepCountOverflow`]. Cost: a step plus
    /// a copy and a scan.
    pub fn try_step_innovation(
        &self,
        e: &mut JointEstimate<T, S, I>,
        y: &SVector<T, O>,
    ) -> Result<SVector<T, O>, Error> {
        check_counts(e.n, e.missing, y)?;
        let mut nu = SVector::zeros();
        commit_if_finite(e, |next| nu = self.step_innovation(next, y))?;
        Ok(nu)
    }
}

macro_rules! joint_const {
    ($t:ident, $from_parts:ident) => {
        impl<const S: usize, const I: usize, const O: usize> InputStateObserver<$t, S, I, O> {
            /// `const fn` twin of [`InputStateObserver::new`] (a `static` keeps the gains in
            /// flash); bit-identical to it.
            ///
            /// Errors: as [`InputStateObserver::new`].
            pub const fn $from_parts(
                model: &InputModel<S, I, O>,
                gains: &InputStateGains<S, I, O>,
            ) -> Result<Self, Error> {
                let l = match observer_parts(model, gains, $t::MAX as f64) {
                    Ok(l) => l,
                    Err(e) => return Err(e),
                };
                Ok(Self {
                    a: linalg::const_round!($t, rows model.a),
                    b: linalg::const_round!($t, rows model.b),
                    c: linalg::const_round!($t, rows model.c),
                    gain_x: linalg::const_round!($t, rows l),
                    gain_w: linalg::const_round!($t, rows gains.input_gain),
                    d: linalg::const_round!($t, rows model.d),
                    gamma1: linalg::const_round!($t, rows model.gamma1),
                    time_step: model.time_step as $t,
                })
            }
        }
    };
}
joint_const!(f32, from_parts_f32);
joint_const!(f64, from_parts_f64);

/// The state of an [`InputStateFilter`]: the [`JointEstimate`], the a-posteriori
/// covariances `P` (`S×S`, of `ξ`), `Pˣʷ` (`S×I`), `Pʷ` (`I×I`, of `ŵ`), and the gains
/// `K`, `M` of the last corrected step. Plain data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputStateFilterState<T, const S: usize, const I: usize, const O: usize> {
    estimate: JointEstimate<T, S, I>,
    p: SMatrix<T, S, S>,
    pxw: SMatrix<T, S, I>,
    pw: SMatrix<T, I, I>,
    k: SMatrix<T, S, O>,
    m: SMatrix<T, I, O>,
}

impl<T: Real, const S: usize, const I: usize, const O: usize> InputStateFilterState<T, S, I, O> {
    /// The estimate `ξ̂_n`, `ŵ_n`, steps and missing measurements.
    pub fn estimate(&self) -> &JointEstimate<T, S, I> {
        &self.estimate
    }
    /// `P_n`, the a-posteriori error covariance of `ξ̂_n`.
    pub fn covariance(&self) -> &SMatrix<T, S, S> {
        &self.p
    }
    /// `Pʷ_n`, the error covariance of `ŵ_n`.
    pub fn input_covariance(&self) -> &SMatrix<T, I, I> {
        &self.pw
    }
    /// `Pˣʷ_n`, the cross covariance of the errors of `ξ̂_n` and `ŵ_n`.
    pub fn cross_covariance(&self) -> &SMatrix<T, S, I> {
        &self.pxw
    }
    /// The state gain `K` of the last corrected step (zero before the first).
    pub fn state_gain(&self) -> &SMatrix<T, S, O> {
        &self.k
    }
    /// The input gain `M` of the last corrected step (zero before the first).
    pub fn input_gain(&self) -> &SMatrix<T, I, O> {
        &self.m
    }
}

/// The time-varying joint input–state filter of Gillijns & De Moor (2007, with direct
/// feedthrough): the step of the [module docs](super), covariances propagated. Its
/// a-priori covariance converges to [`InputStateGains`]' when the input is identifiable;
/// with acceleration-only sensing it does not converge (the drift shows as a growing
/// `P`).
///
/// A measurement with a non-finite entry is missing: predict only (`P = P⁻`), the input
/// estimate and its covariances held, counted. Only a checked step: a failed step changes
/// nothing.
///
/// Cost of a step: about `3S³ + 3S²·(I + O) + 2S·O² + O³` multiply-adds (`≈ 4 900` for
/// `S = 10`, `I = 1`, `O = 4`): for the host and small firmware models; the
/// [`InputStateObserver`] with the steady gains costs `S² + S·I + 2S·O + I·O`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InputStateFilter<T, const S: usize, const I: usize, const O: usize> {
    a: SMatrix<T, S, S>,
    b: SMatrix<T, S, I>,
    c: SMatrix<T, O, S>,
    d: SMatrix<T, O, I>,
    gamma1: [[T; I]; S],
    q: SMatrix<T, S, S>,
    r: SMatrix<T, O, O>,
    /// `N`, or `None` when it is zero (the original code path, bit for bit).
    cross: Option<SMatrix<T, S, O>>,
}

joint_accessors!(varying InputStateFilter, InputStateFilterState);

impl<T: Real, const S: usize, const I: usize, const O: usize> InputStateFilter<T, S, I, O> {
    /// The filter of `model`, process noise `q` (`S×S` on `ξ`, symmetric positive
    /// semidefinite), measurement noise `r` (`O×O`, symmetric positive definite), in
    /// `f64`, rounded once to `T`.
    ///
    /// Errors: [`Error::InvalidCovariance`], [`Error::InputNotIdentifiable`] (`D̃` without
    /// full column rank; the zeros are not checked: a zero on the unit circle shows as a
    /// drift), [`Error::NonFiniteInput`], [`Error::OperatorOverflow`]. Cost: `O(S³)`.
    pub fn new(
        model: &InputModel<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
    ) -> Result<Self, Error> {
        Self::build(model, q, r, &[[0.0; O]; S])
    }

    /// [`InputStateFilter::new`] with a process–measurement cross covariance
    /// `n = E q_n r_nᵀ` (`S×O`, as [`InputStateGains::solve_cross`]): `R̃` and `K` of each
    /// step carry it. `n = 0` is [`InputStateFilter::new`], bit for bit.
    ///
    /// Errors: as [`InputStateFilter::new`]; [`Error::InvalidCovariance`] also when `n` is
    /// not finite or `[q n; nᵀ r]` is not a covariance. Cost: `O(S³)`.
    pub fn with_cross(
        model: &InputModel<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
        n: &SMatrix<f64, S, O>,
    ) -> Result<Self, Error> {
        Self::build(model, q, r, &rows_f64(n))
    }

    fn build(
        model: &InputModel<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
        n: &Mat<S, O>,
    ) -> Result<Self, Error> {
        let (qr, rr) = (rows_f64(q), rows_f64(r));
        if !is_covariance(&qr, false) {
            return Err(Error::InvalidCovariance);
        }
        model.check_finite()?;
        model.weighted_feedthrough(&rr)?;
        let cross = checked_cross_t(&qr, &rr, n)?;
        if !(model.fits(T::MAX) && noise_fits(&qr, &rr, n, T::MAX)) {
            return Err(Error::OperatorOverflow);
        }
        Ok(Self {
            a: matrix_t(&model.a),
            b: matrix_t(&model.b),
            c: matrix_t(&model.c),
            d: matrix_t(&model.d),
            gamma1: round_rows(&model.gamma1),
            q: matrix_t(&qr),
            r: matrix_t(&rr),
            cross,
        })
    }

    /// The filter at `t = 0`: physical state `x0` with covariance `p0` (taken as the
    /// covariance of `ξ̂_0`), input `w0` with covariance `pw0`, uncorrelated.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidCovariance`] (`p0`, `pw0` not
    /// symmetric positive semidefinite). Cost: `O(S³)`.
    pub fn start(
        &self,
        x0: &SVector<T, S>,
        p0: &SMatrix<T, S, S>,
        w0: &SVector<T, I>,
        pw0: &SMatrix<T, I, I>,
    ) -> Result<InputStateFilterState<T, S, I, O>, Error> {
        let estimate = joint_start_covariances(&self.gamma1, x0, p0, w0, pw0)?;
        Ok(InputStateFilterState {
            estimate,
            p: *p0,
            pxw: SMatrix::zeros(),
            pw: *pw0,
            k: SMatrix::zeros(),
            m: SMatrix::zeros(),
        })
    }

    /// The a-priori covariance of the next step, `P⁻ = [A B] [P, Pˣʷ; Pʷˣ, Pʷ] [A B]ᵀ + Q`
    /// (what converges to [`InputStateGains::covariance`]). Cost: `2S³ + 2S²·I`.
    pub fn predicted_covariance(&self, s: &InputStateFilterState<T, S, I, O>) -> SMatrix<T, S, S> {
        let apb = self.a * s.pxw * self.b.transpose();
        sym(&(self.a * s.p * self.a.transpose()
            + apb
            + apb.transpose()
            + self.b * s.pw * self.b.transpose()
            + self.q))
    }

    /// One filter step with the measurement `y` (`y_n`; a non-finite entry: missing).
    ///
    /// Errors, `s` unchanged: [`Error::InvalidCovariance`] (`R̃ = C P⁻ Cᵀ + R` or
    /// `D̃ᵀ R̃⁻¹ D̃` not positive definite to working precision), [`Error::NonFiniteState`],
    /// [`Error::StepCountOverflow`] (the step count, or the count of missing samples, would
    /// pass `u64::MAX`). No allocation, no panic; cost in the type docs.
    pub fn try_step(
        &self,
        s: &mut InputStateFilterState<T, S, I, O>,
        y: &SVector<T, O>,
    ) -> Result<(), Error> {
        let e = &s.estimate;
        let xp = self.a * e.xi + self.b * e.w;
        let pm = self.predicted_covariance(s);
        let mut next = *s;
        let present = y.iter().all(|v| v.is_finite());
        if present {
            // R̃ and K from the one Kalman core (with N where it is set).
            let (cp, rt) = innovation_t(&pm, &self.c, &self.r, self.cross.as_ref());
            let chol = rt.cholesky().ok_or(Error::InvalidCovariance)?;
            let k = gain_t(&chol, &cp);
            let rtd = chol.solve(&self.d);
            let f = self.d.transpose() * rtd;
            let f = (f + f.transpose()) * T::from_f64_rounded(0.5);
            let cf = f.cholesky().ok_or(Error::InvalidCovariance)?;
            let pw = cf.inverse();
            let m = cf.solve(&rtd.transpose());
            let innov = y - self.c * xp;
            let w = m * innov;
            next.estimate.w = w;
            next.estimate.xi = xp + k * (innov - self.d * w);
            let dpd = self.d * pw * self.d.transpose();
            next.p = sym(&(pm - k * (rt - dpd) * k.transpose()));
            next.pxw = -(k * self.d * pw);
            next.pw = sym(&pw);
            next.k = k;
            next.m = m;
        } else {
            next.estimate.xi = xp;
            next.p = pm;
        }
        (next.estimate.n, next.estimate.missing) =
            next_counts(e.n, e.missing, present).ok_or(Error::StepCountOverflow)?;
        let finite = next
            .estimate
            .xi
            .iter()
            .chain(next.estimate.w.iter())
            .chain(next.p.iter())
            .chain(next.pxw.iter())
            .chain(next.pw.iter())
            .all(|v| v.is_finite());
        if !finite {
            return Err(Error::NonFiniteState);
        }
        *s = next;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::roof_force_fixture as model;
    use super::*;

    /// Regression: the checked steps of the joint estimators wrapped their counters
    /// (`u64::MAX + 1 = 0`); they now refuse with a typed error, the state unchanged.
    #[test]
    fn joint_estimators_refuse_to_wrap_their_counters() {
        let md = model();
        let q = SMatrix::<f64, 10, 10>::identity() * 1e-14;
        let r = SMatrix::<f64, 2, 2>::from_diagonal(&nalgebra::vector![1e-4, 1e-8]);
        let gains = InputStateGains::new(&md, &q, &r).unwrap();
        let obs = InputStateObserver::<f64, 10, 1, 2>::new(&md, &gains).unwrap();
        let (y, gap) = (SVector::from([0.01, 1e-4]), SVector::from([f64::NAN, 0.0]));
        let mut e = obs.start_at_rest();
        e.n = u64::MAX;
        let before = e;
        assert_eq!(obs.try_step(&mut e, &y), Err(Error::StepCountOverflow));
        assert_eq!(
            obs.try_step_innovation(&mut e, &y),
            Err(Error::StepCountOverflow)
        );
        assert_eq!(e, before);
        e.n = 1;
        e.missing = u64::MAX;
        let before = e;
        assert_eq!(obs.try_step(&mut e, &gap), Err(Error::StepCountOverflow));
        assert_eq!(e, before);
        obs.try_step(&mut e, &y).unwrap();
        assert_eq!((e.steps(), e.missing()), (2, u64::MAX));

        let f = InputStateFilter::<f64, 10, 1, 2>::new(&md, &q, &r).unwrap();
        let mut s = f
            .start(
                &SVector::zeros(),
                &(q * 1e3),
                &SVector::zeros(),
                &SMatrix::identity(),
            )
            .unwrap();
        s.estimate.n = u64::MAX;
        let before = s;
        assert_eq!(f.try_step(&mut s, &y), Err(Error::StepCountOverflow));
        assert_eq!(s, before);
        s.estimate.n = 0;
        s.estimate.missing = u64::MAX;
        let before = s;
        assert_eq!(f.try_step(&mut s, &gap), Err(Error::StepCountOverflow));
        assert_eq!(s, before);
    }
}
