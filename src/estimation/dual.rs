//! The dual Kalman filter (Eftekhar Azam, Chatzi & Papadimitriou 2015): two Kalman
//! filters in sequence each step, one for the input (a random walk), one for the state —
//! with fixed (steady) gains ([`DualGains`], [`DualFilter`]) or time-varying, the
//! covariances propagated as in the paper ([`DualKalmanFilter`]).
//!
//! On the standard form of [`InputModel`] (`ξ_n = A ξ_{n−1} + B w_{n−1}`,
//! `y_n = C ξ_n + D̃ w_n`) a step is, in the paper's order (its Steps 1–6):
//!
//! ```text
//! ŵ_n = ŵ_{n−1} + G_w (y_n − C ξ̂_{n−1} − D̃ ŵ_{n−1})   (input filter: w_n = w_{n−1} + η)
//! ξ⁻  = A ξ̂_{n−1} + B ŵ_n                              (state prediction, the new input)
//! ξ̂_n = ξ⁻ + G_x (y_n − C ξ⁻ − D̃ ŵ_n)                  (state filter)
//! ```
//!
//! The input stage's innovation uses the filtered state of the previous step, `C ξ̂_{n−1}`,
//! and the state is predicted with the new input `ŵ_n` — as the paper writes it (its
//! `d_k − G x̂_{k−1} − J p̂_{k−1}` and `A x̂_{k−1} + B p̂_k`). The gains are the
//! steady-state Kalman gains of the two stages, each from the crate's [`SteadyState`]:
//! `G_w` of the model `(I, D̃)` with process noise `Q_w` (the random walk), `G_x` of
//! `(A, C)` with `Q`, both with measurement noise `R`.
//!
//! Until issue 31 the crate ran the stages in another order ([`DualOrder::PredictedState`]:
//! the input updated from the predicted state `ξ⁻ = A ξ̂_{n−1} + B ŵ_{n−1}`, the state
//! predicted with the old input), arguing that `ξ⁻` is the model's own prediction. A scene
//! refutes that: the 5-storey building with an unknown roof force, the exact zero-order
//! hold at 200 Hz ([`StateSpace::zero_order_hold`](crate::observer::StateSpace::zero_order_hold)), accelerations of floors 1, 3, 5
//! (σ = 1 mm/s²) and the roof displacement (σ = 10 µm), process noise `Q = 1e-14 I`: with
//! the same gains, that order's error dynamics have a spectral radius of 1.0014 to 1.0018
//! for every random-walk variance `Q_w` from 1e4 to 1e10 N² (the force estimate grows
//! without bound), the paper's 0.9970 to 0.9989 (`tests/dual_order.rs` certifies both,
//! and a second scene, and runs them for 10⁶ steps). The old order stays as an option of the fixed-gain filter
//! ([`DualFilter::with_order`]) for models where it is shown stable (e.g. the crate's AEM
//! scene at 50 Hz, radius 0.9862); [`DualKalmanFilter`] runs the paper's order only.
//!
//! Neither order is stable for every tuning: the stages ignore their coupling, so no
//! covariance of the joint error is propagated and nothing guarantees that the joint
//! error dynamics ([`DualFilter::error_step`]) contract. On the scene above with
//! σ = 10 mm/s² accelerometers both orders have a radius above 1 (1.0002 to 1.0013 the
//! paper's, over the same `Q_w`). Certify the radius of the filter you deploy
//! (`tests/dual_order.rs` shows how: a power of the error matrix in a norm, with its
//! rounding bounded). With acceleration-only sensing the static force–displacement pair
//! `(ξ_s, w_c)`, `ξ_s = A ξ_s + B w_c`, `C ξ_s + D̃ w_c = 0`, is a fixed point of the
//! error dynamics of both orders for any gains (both innovations vanish on it): the dual
//! filter drifts like every estimator that uses only these data; `tests/estimation.rs`
//! shows it, and that a displacement removes it.

use nalgebra::{SMatrix, SVector};

use super::InputModel;
use super::joint::{JointEstimate, joint_start_covariances};
use crate::linalg::{self, finite_as, identity, matrix_t, round_rows, sym};
use crate::observer::bare_model;
use crate::observer::{SteadyState, is_covariance};
use crate::observer::{check_counts, mul2, next_counts};
use crate::observer::{gain_t, innovation_t, predict_t, short_form_t};
use crate::stepper::commit_if_finite;
use crate::{Error, Real};

/// The steady gains of a [`DualFilter`] (`f64`, row-major).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DualGains<const S: usize, const I: usize, const O: usize> {
    /// The input stage's Kalman solution: `G_w` (`I×O`) is its `gain`.
    pub input: SteadyState<I, O>,
    /// The state stage's Kalman solution: `G_x` (`S×O`) is its `gain`.
    pub state: SteadyState<S, O>,
}

impl<const S: usize, const I: usize, const O: usize> DualGains<S, I, O> {
    /// The two steady gains (`const fn`): input stage with the random walk's covariance
    /// `qw` (`I×I`, input units squared per step), state stage with `q` (`S×S` on `ξ`),
    /// both with measurement noise `r` (`O×O`, symmetric positive definite).
    ///
    /// Errors: [`Error::InvalidCovariance`], [`Error::InputNotIdentifiable`] (the input
    /// stage has no steady state: `D̃` without full column rank),
    /// [`Error::RiccatiNotConverged`] (the state stage has none: `(A, C)` not detectable
    /// or not stabilizable by `q`), [`Error::OperatorOverflow`].
    ///
    /// Cost: two [`SteadyState::from_parts`]s, sizes `I` and `S`.
    pub const fn solve(
        model: &InputModel<S, I, O>,
        q: &[[f64; S]; S],
        qw: &[[f64; I]; I],
        r: &[[f64; O]; O],
    ) -> Result<Self, Error> {
        let (input_model, input_meas) = bare_model(identity(), model.d, model.time_step);
        let input = match SteadyState::from_parts(&input_model, &input_meas, qw, r) {
            Ok(s) => s,
            Err(Error::RiccatiNotConverged) => return Err(Error::InputNotIdentifiable),
            Err(e) => return Err(e),
        };
        let (state_model, state_meas) = bare_model(model.a, model.c, model.time_step);
        let state = match SteadyState::from_parts(&state_model, &state_meas, q, r) {
            Ok(s) => s,
            Err(e) => return Err(e),
        };
        Ok(Self { input, state })
    }

    /// [`DualGains::solve`] with `nalgebra` covariances (run time; same numbers).
    ///
    /// Errors and cost: as [`DualGains::solve`].
    pub fn new(
        model: &InputModel<S, I, O>,
        q: &SMatrix<f64, S, S>,
        qw: &SMatrix<f64, I, I>,
        r: &SMatrix<f64, O, O>,
    ) -> Result<Self, Error> {
        use linalg::rows_f64;
        Self::solve(model, &rows_f64(q), &rows_f64(qw), &rows_f64(r))
    }
}

/// The order of the two stages of a [`DualFilter`] step (see the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DualOrder {
    /// Eftekhar Azam, Chatzi & Papadimitriou (2015): the input from the previous filtered
    /// state, `ŵ_n = ŵ_{n−1} + G_w (y_n − C ξ̂_{n−1} − D̃ ŵ_{n−1})`, then the state
    /// predicted with the new input, `ξ⁻ = A ξ̂_{n−1} + B ŵ_n`. The default.
    #[default]
    Paper,
    /// The crate's order before issue 31: `ξ⁻ = A ξ̂_{n−1} + B ŵ_{n−1}` first, the input
    /// from it, `ŵ_n = ŵ_{n−1} + G_w (y_n − C ξ⁻ − D̃ ŵ_{n−1})`, then
    /// `ξ̂_n = ξ⁻ + G_x (y_n − C ξ⁻ − D̃ ŵ_n)`. Stable on some models (the AEM 5-storey
    /// building at 50 Hz with three accelerometers and the roof displacement: radius
    /// 0.9862), **unstable on others** where the paper's order is stable (the same
    /// building as a zero-order hold at 200 Hz with quieter sensors: radius ≥ 1.0013,
    /// `tests/dual_order.rs`). Use it only with a certified radius of
    /// [`DualFilter::error_step`] below 1.
    PredictedState,
}

/// The fixed-gain dual Kalman filter (the steps of the [module docs](self), in the
/// paper's order unless [`DualFilter::with_order`] says otherwise), `S` states, `I`
/// inputs, `O` measurements, stepping in `T`. A measurement with a non-finite entry is
/// missing: `ξ̂_n = A ξ̂_{n−1} + B ŵ_{n−1}`, the input estimate held, counted.
///
/// Cost of a step: `S² + S·I + 3S·O + 3O·I` multiply-adds in the paper's order,
/// `S² + S·I + 2S·O + 3O·I` in [`DualOrder::PredictedState`], fixed. Size:
/// `S² + 2S·I + 2S·O + 2O·I + 1` values of `T` (`A`, `B`, `C`, `D̃`, `G_w`, `G_x`, `Γ₁`,
/// `h`) and a [`DualOrder`]. [`DualFilter::new`] and `from_parts_f32`/`_f64` (`const fn`)
/// are bit-identical.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualFilter<T, const S: usize, const I: usize, const O: usize> {
    a: [[T; S]; S],
    b: [[T; I]; S],
    c: [[T; S]; O],
    d: [[T; I]; O],
    gain_w: [[T; O]; I],
    gain_x: [[T; O]; S],
    gamma1: [[T; I]; S],
    time_step: T,
    order: DualOrder,
}

/// Every operator finite and fitting `T` (the checks of every fixed-gain estimator).
const fn dual_checks<const S: usize, const I: usize, const O: usize>(
    model: &InputModel<S, I, O>,
    gains: &DualGains<S, I, O>,
    max: f64,
) -> Result<(), Error> {
    let (gw, gx) = (&gains.input.gain, &gains.state.gain);
    model.check_fixed_gains(gx, gx, gw, max)
}

joint_accessors!(fixed DualFilter);

impl<T: Real, const S: usize, const I: usize, const O: usize> DualFilter<T, S, I, O> {
    /// The dual filter of `model` with the steady `gains`, rounded once to `T`.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
    /// [`Error::OperatorOverflow`]. Cost: `O(S²)`.
    pub fn new(model: &InputModel<S, I, O>, gains: &DualGains<S, I, O>) -> Result<Self, Error> {
        dual_checks(model, gains, T::MAX)?;
        Ok(Self {
            a: round_rows(&model.a),
            b: round_rows(&model.b),
            c: round_rows(&model.c),
            d: round_rows(&model.d),
            gain_w: round_rows(&gains.input.gain),
            gain_x: round_rows(&gains.state.gain),
            gamma1: round_rows(&model.gamma1),
            time_step: T::from_f64_rounded(model.time_step),
            order: DualOrder::Paper,
        })
    }

    /// The same filter with its stages in `order` (`const fn`; [`DualFilter::new`] gives
    /// [`DualOrder::Paper`]). Cost: a copy.
    pub const fn with_order(mut self, order: DualOrder) -> Self {
        self.order = order;
        self
    }

    /// The order of the stages.
    pub const fn order(&self) -> DualOrder {
        self.order
    }

    /// One step of the joint error dynamics without noise (a constant input and state
    /// increment, exact data): the errors `(ξ − ξ̂, w − ŵ)` of a step from the errors
    /// `(ex, ew)` before it, in the filter's [`DualOrder`]:
    ///
    /// ```text
    /// Paper:          e_w' = e_w − G_w (C e_ξ + D̃ e_w),  e⁻ = A e_ξ + B e_w',
    ///                 e_ξ' = e⁻ − G_x (C e⁻ + D̃ e_w')
    /// PredictedState: e⁻ = A e_ξ + B e_w,  e_w' = e_w − G_w (C e⁻ + D̃ e_w),
    ///                 e_ξ' = e⁻ − G_x (C e⁻ + D̃ e_w')
    /// ```
    ///
    /// Applied to the unit vectors it gives the matrix whose spectral radius says whether
    /// the filter's errors die out. In the paper's order the errors are also driven by the
    /// increments of the true state and input (`C (ξ_n − ξ_{n−1})` in the input stage's
    /// innovation, `B (w_{n−1} − w_n)` in the prediction), bounded when the structure's
    /// response is: with a radius below 1 the errors stay bounded. Cost: about a step.
    pub fn error_step(
        &self,
        ex: &SVector<T, S>,
        ew: &SVector<T, I>,
    ) -> (SVector<T, S>, SVector<T, I>) {
        let predict = |ex: &SVector<T, S>, ew: &SVector<T, I>| mul2(&self.a, &self.b, ex, ew);
        let output = |ex: &SVector<T, S>, ew: &SVector<T, I>| mul2(&self.c, &self.d, ex, ew);
        let (em, ew1) = match self.order {
            DualOrder::Paper => {
                let ew1 = less_gain(ew, &self.gain_w, &output(ex, ew));
                (predict(ex, &ew1), ew1)
            }
            DualOrder::PredictedState => {
                let em = predict(ex, ew);
                (em, less_gain(ew, &self.gain_w, &output(&em, ew)))
            }
        };
        let ex1 = less_gain(&em, &self.gain_x, &output(&em, &ew1));
        (ex1, ew1)
    }

    /// One step with the measurement `y` (`y_n`; a non-finite entry: missing). Fixed cost
    /// (type docs), no allocation, no panic. A step whose step or missing-sample counter
    /// would pass `u64::MAX` is refused and changes nothing ([`DualFilter::try_step`]
    /// reports it).
    #[inline]
    pub fn step(&self, e: &mut JointEstimate<T, S, I>, y: &SVector<T, O>) {
        let present = y.iter().all(|v| v.is_finite());
        let Some((n, missing)) = next_counts(e.n, e.missing, present) else {
            return;
        };
        e.n = n;
        e.missing = missing;
        if !present {
            e.xi = self.predict(&e.xi, &e.w).into();
            return;
        }
        match self.order {
            DualOrder::Paper => {
                // Input stage: ν = y − C ξ̂_{n−1} − D̃ ŵ_{n−1}, ŵ_n = ŵ_{n−1} + G_w ν.
                let nu = self.innovation(y, &e.xi.into(), &e.w);
                self.correct_input(&mut e.w, &nu);
                // State stage: ξ⁻ = A ξ̂_{n−1} + B ŵ_n, ξ̂_n = ξ⁻ + G_x (y − C ξ⁻ − D̃ ŵ_n).
                let xp = self.predict(&e.xi, &e.w);
                let nu = self.innovation(y, &xp, &e.w);
                self.correct_state(&mut e.xi, &xp, &nu);
            }
            DualOrder::PredictedState => {
                let xp = self.predict(&e.xi, &e.w);
                let nu = self.innovation(y, &xp, &e.w);
                self.correct_input(&mut e.w, &nu);
                let nu = self.innovation(y, &xp, &e.w);
                self.correct_state(&mut e.xi, &xp, &nu);
            }
        }
    }

    /// `B w + A ξ` (in that order, from `−0`).
    #[inline(always)]
    fn predict(&self, xi: &SVector<T, S>, w: &SVector<T, I>) -> [T; S] {
        let neg_zero = -T::zero();
        core::array::from_fn(|i| {
            let mut s = neg_zero;
            for j in 0..I {
                s += self.b[i][j] * w[j];
            }
            for j in 0..S {
                s += self.a[i][j] * xi[j];
            }
            s
        })
    }

    /// `y − C ξ − D̃ w`.
    #[inline(always)]
    fn innovation(&self, y: &SVector<T, O>, xi: &[T; S], w: &SVector<T, I>) -> [T; O] {
        core::array::from_fn(|o| {
            let mut s = y[o];
            for j in 0..S {
                s -= self.c[o][j] * xi[j];
            }
            for j in 0..I {
                s -= self.d[o][j] * w[j];
            }
            s
        })
    }

    /// `w += G_w ν`.
    #[inline(always)]
    fn correct_input(&self, w: &mut SVector<T, I>, nu: &[T; O]) {
        for i in 0..I {
            let mut s = w[i];
            for o in 0..O {
                s += self.gain_w[i][o] * nu[o];
            }
            w[i] = s;
        }
    }

    /// `ξ = ξ⁻ + G_x ν`.
    #[inline(always)]
    fn correct_state(&self, xi: &mut SVector<T, S>, xp: &[T; S], nu: &[T; O]) {
        for i in 0..S {
            let mut s = xp[i];
            for o in 0..O {
                s += self.gain_x[i][o] * nu[o];
            }
            xi[i] = s;
        }
    }

    /// [`DualFilter::step`], checked: the new estimate must be finite, else `e` is left
    /// bit-identical.
    ///
    /// Errors: [`Error::NonFiniteState`]; [`Error::StepCountOverflow`] when the step
    /// counter would pass `u64::MAX` (1.8e19 steps: 2.9 million years at 200 kHz, so only
    /// a corrupted or forged estimate), `e` unchanged.
    pub fn try_step(&self, e: &mut JointEstimate<T, S, I>, y: &SVector<T, O>) -> Result<(), Error> {
        check_counts(e.n, e.missing, y)?;
        commit_if_finite(e, |next| self.step(next, y))
    }
}

/// `e − G ν`: an error after a stage's correction with gain `G`. Cost: `R·O`
/// multiply-adds.
fn less_gain<T: Real, const R: usize, const O: usize>(
    e: &SVector<T, R>,
    g: &[[T; O]; R],
    nu: &SVector<T, O>,
) -> SVector<T, R> {
    SVector::from_fn(|i, _| {
        let mut s = e[i];
        for o in 0..O {
            s -= g[i][o] * nu[o];
        }
        s
    })
}

macro_rules! dual_const {
    ($t:ident, $from_parts:ident) => {
        impl<const S: usize, const I: usize, const O: usize> DualFilter<$t, S, I, O> {
            /// `const fn` twin of [`DualFilter::new`]; bit-identical to it.
            ///
            /// Errors: as [`DualFilter::new`].
            pub const fn $from_parts(
                model: &InputModel<S, I, O>,
                gains: &DualGains<S, I, O>,
            ) -> Result<Self, Error> {
                if let Err(e) = dual_checks(model, gains, $t::MAX as f64) {
                    return Err(e);
                }
                Ok(Self {
                    a: linalg::const_round!($t, rows model.a),
                    b: linalg::const_round!($t, rows model.b),
                    c: linalg::const_round!($t, rows model.c),
                    d: linalg::const_round!($t, rows model.d),
                    gain_w: linalg::const_round!($t, rows gains.input.gain),
                    gain_x: linalg::const_round!($t, rows gains.state.gain),
                    gamma1: linalg::const_round!($t, rows model.gamma1),
                    time_step: model.time_step as $t,
                    order: DualOrder::Paper,
                })
            }
        }
    };
}
dual_const!(f32, from_parts_f32);
dual_const!(f64, from_parts_f64);

/// The state of a [`DualKalmanFilter`]: the [`JointEstimate`], the a-posteriori
/// covariances `P` (`S×S`, of `ξ̂_n`, units of `x` squared) and `Pʷ` (`I×I`, of `ŵ_n`,
/// input units squared), and the gains `G_x`, `G_w` of the last corrected step. Plain
/// data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualKalmanFilterState<T, const S: usize, const I: usize, const O: usize> {
    estimate: JointEstimate<T, S, I>,
    p: SMatrix<T, S, S>,
    pw: SMatrix<T, I, I>,
    gain_x: SMatrix<T, S, O>,
    gain_w: SMatrix<T, I, O>,
}

impl<T: Real, const S: usize, const I: usize, const O: usize> DualKalmanFilterState<T, S, I, O> {
    /// The estimate `ξ̂_n`, `ŵ_n`, steps and missing measurements.
    pub fn estimate(&self) -> &JointEstimate<T, S, I> {
        &self.estimate
    }
    /// `P_n`, the a-posteriori error covariance of `ξ̂_n` as the state stage computes it
    /// (units of `x` squared).
    pub fn covariance(&self) -> &SMatrix<T, S, S> {
        &self.p
    }
    /// `Pʷ_n`, the a-posteriori error covariance of `ŵ_n` as the input stage computes it
    /// (input units squared).
    pub fn input_covariance(&self) -> &SMatrix<T, I, I> {
        &self.pw
    }
    /// The state stage's gain `G_x` (`S×O`) of the last corrected step (zero before the
    /// first); converges to [`DualGains::state`]'s `gain`.
    pub fn state_gain(&self) -> &SMatrix<T, S, O> {
        &self.gain_x
    }
    /// The input stage's gain `G_w` (`I×O`) of the last corrected step (zero before the
    /// first); converges to [`DualGains::input`]'s `gain`.
    pub fn input_gain(&self) -> &SMatrix<T, I, O> {
        &self.gain_w
    }
}

/// The time-varying dual Kalman filter of Eftekhar Azam, Chatzi & Papadimitriou (2015):
/// the step of the [module docs](self) (the paper's order) with both stages' covariances
/// propagated, as the paper writes it:
///
/// ```text
/// input stage:  Pʷ⁻ = Pʷ_{n−1} + Q_w        G_w = Pʷ⁻ D̃ᵀ (D̃ Pʷ⁻ D̃ᵀ + R)⁻¹
///               ŵ_n = ŵ_{n−1} + G_w (y_n − C ξ̂_{n−1} − D̃ ŵ_{n−1})    Pʷ_n = Pʷ⁻ − G_w D̃ Pʷ⁻
/// state stage:  ξ⁻ = A ξ̂_{n−1} + B ŵ_n      P⁻ = A P_{n−1} Aᵀ + Q
///               G_x = P⁻ Cᵀ (C P⁻ Cᵀ + R)⁻¹
///               ξ̂_n = ξ⁻ + G_x (y_n − C ξ⁻ − D̃ ŵ_n)                 P_n = P⁻ − G_x C P⁻
/// ```
///
/// As in the paper, each stage's innovation
/// covariance holds only its own uncertainty and `R`: the input stage's leaves out
/// `C P⁻ Cᵀ` (the state's error in its innovation), the state stage's leaves out
/// `D̃ Pʷ D̃ᵀ`, and `P⁻` leaves out `B Pʷ Bᵀ`. The two recursions are therefore
/// independent of the data and of each other, and each is the Riccati recursion whose
/// limit [`DualGains`] solves: `Pʷ⁻ → DualGains::input.covariance`,
/// `P⁻ → DualGains::state.covariance`, the gains to theirs (`tests/estimation_dual.rs`).
/// The covariances are those of the stages' models, not the errors of the coupled
/// filter.
///
/// A measurement with a non-finite entry is missing: predict only (`ŵ_n = ŵ_{n−1}` with
/// `Pʷ_n = Pʷ⁻`: the random walk's prediction; `ξ̂_n = A ξ̂_{n−1} + B ŵ_{n−1}`,
/// `P_n = P⁻`), counted.
/// Only a checked step: a failed step changes nothing.
///
/// Cost of a step: about `2S³ + 2S²·O + 2S·O² + O³/3` multiply-adds for the state stage
/// and `2O·I² + 2O²·I + O³/3` for the input stage, plus the fixed filter's
/// `S² + S·I + 3S·O + 3O·I` (`≈ 3 400` for `S = 10`, `I = 1`, `O = 4`): for the host and
/// small firmware models; the [`DualFilter`] with the steady [`DualGains`] costs the last
/// term only. Size: `2S² + 2S·I + S·O + O·I + I² + O² + 1` values of `T`; its state
/// ([`DualKalmanFilterState`]) `S² + S + I² + I + S·O + I·O` values and two `u64`. No
/// allocation.
///
/// ```
/// use aemstep::estimation::{DualGains, DualKalmanFilter, InputModel};
/// use aemstep::models;
/// use aemstep::observer::{Outputs, StateSpace};
/// use aemstep::nalgebra::{SMatrix, SVector};
/// use aemstep::vector;
///
/// // The 5-storey building, an unknown force at the roof (N); absolute accelerations of
/// // floors 1, 3, 5 (m/s²) and the roof displacement (m) measured.
/// let (m, c, k) = models::five_storey_building();
/// let roof = [[0.0], [0.0], [0.0], [0.0], [1.0]];
/// let ss = StateSpace::<5, 10, 1>::from_rows_aem(m, c, k, roof, 0.02)?;
/// let mut out = Outputs::<5, 1, 4>::zero();
/// out.a = [[1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 1.0], [0.0; 5]];
/// out.u[3] = [0.0, 0.0, 0.0, 0.0, 1.0];
/// let model = InputModel::from_parts(&ss, &ss.outputs(&out)?)?;
/// let q = SMatrix::<f64, 10, 10>::identity() * 1e-14;
/// let qw = SMatrix::<f64, 1, 1>::from_element(1e6); // the random walk: σ = 1 kN per step
/// let r = SMatrix::<f64, 4, 4>::from_diagonal(&vector![1e-4, 1e-4, 1e-4, 1e-8]);
/// let f = DualKalmanFilter::<f64, 10, 1, 4>::new(&model, &q, &qw, &r)?;
/// let p0 = SMatrix::<f64, 10, 10>::identity() * 1e-8;
/// let mut s = f.start(&SVector::zeros(), &p0, &SVector::zeros(), &SMatrix::from_element(1e10))?;
/// f.try_step(&mut s, &vector![0.01, 0.02, 0.03, 1e-4])?;
/// f.try_step(&mut s, &vector![f64::NAN, 0.02, 0.03, 1e-4])?; // missing: predicted
/// assert_eq!((s.estimate().steps(), s.estimate().missing()), (2, 1));
/// assert!(s.estimate().input()[0].is_finite()); // N
/// // The gains tend to the steady ones the fixed-gain `DualFilter` uses.
/// let steady = DualGains::new(&model, &q, &qw, &r)?;
/// assert!(steady.input.gain[0].iter().all(|g| g.is_finite()));
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualKalmanFilter<T, const S: usize, const I: usize, const O: usize> {
    a: SMatrix<T, S, S>,
    b: SMatrix<T, S, I>,
    c: SMatrix<T, O, S>,
    d: SMatrix<T, O, I>,
    gamma1: [[T; I]; S],
    q: SMatrix<T, S, S>,
    qw: SMatrix<T, I, I>,
    r: SMatrix<T, O, O>,
    time_step: T,
}

joint_accessors!(varying DualKalmanFilter, DualKalmanFilterState);

impl<T: Real, const S: usize, const I: usize, const O: usize> DualKalmanFilter<T, S, I, O> {
    /// The filter of `model` with process noise `q` (`S×S` on `ξ`, symmetric positive
    /// semidefinite, units of `x` squared per step), the random walk's covariance `qw`
    /// (`I×I`, symmetric positive semidefinite, input units squared per step) and
    /// measurement noise `r` (`O×O`, symmetric positive definite), in `f64`, rounded once
    /// to `T`. The identifiability of the input is not checked (the stages need none:
    /// `R` keeps both innovation covariances definite); [`DualGains::solve`] checks that
    /// the recursion has a limit.
    ///
    /// Errors: [`Error::InvalidCovariance`], [`Error::NonFiniteInput`],
    /// [`Error::InvalidTimeStep`] (the model's `time_step` in `T`),
    /// [`Error::OperatorOverflow`]. Cost: `O(S² + O³)`.
    pub fn new(
        model: &InputModel<S, I, O>,
        q: &SMatrix<f64, S, S>,
        qw: &SMatrix<f64, I, I>,
        r: &SMatrix<f64, O, O>,
    ) -> Result<Self, Error> {
        let (qr, qwr, rr) = (
            linalg::rows_f64(q),
            linalg::rows_f64(qw),
            linalg::rows_f64(r),
        );
        if !(is_covariance(&qr, false) && is_covariance(&qwr, false) && is_covariance(&rr, true)) {
            return Err(Error::InvalidCovariance);
        }
        model.check_finite()?;
        crate::kinematics::check_time_step_as(model.time_step, T::MAX)?;
        let fits = model.fits(T::MAX)
            && finite_as(&qr, T::MAX)
            && finite_as(&qwr, T::MAX)
            && finite_as(&rr, T::MAX);
        if !fits {
            return Err(Error::OperatorOverflow);
        }
        Ok(Self {
            a: matrix_t(&model.a),
            b: matrix_t(&model.b),
            c: matrix_t(&model.c),
            d: matrix_t(&model.d),
            gamma1: round_rows(&model.gamma1),
            q: matrix_t(&qr),
            qw: matrix_t(&qwr),
            r: matrix_t(&rr),
            time_step: T::from_f64_rounded(model.time_step),
        })
    }

    /// The time step `h` (s).
    pub fn time_step(&self) -> T {
        self.time_step
    }

    /// The filter at `t = 0`: physical state `x0` with covariance `p0` (taken as the
    /// covariance of `ξ̂_0`, units of `x` squared), input `w0` with covariance `pw0` (input
    /// units squared); `ξ̂_0 = x0 − Γ₁ w0`.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidCovariance`] (`p0`, `pw0` not
    /// symmetric positive semidefinite). Cost: `O(S³)`.
    pub fn start(
        &self,
        x0: &SVector<T, S>,
        p0: &SMatrix<T, S, S>,
        w0: &SVector<T, I>,
        pw0: &SMatrix<T, I, I>,
    ) -> Result<DualKalmanFilterState<T, S, I, O>, Error> {
        let estimate = joint_start_covariances(&self.gamma1, x0, p0, w0, pw0)?;
        Ok(DualKalmanFilterState {
            estimate,
            p: *p0,
            pw: *pw0,
            gain_x: SMatrix::zeros(),
            gain_w: SMatrix::zeros(),
        })
    }

    /// The a-priori covariances of the next step, `(P⁻, Pʷ⁻) = (A P Aᵀ + Q, Pʷ + Q_w)`
    /// (what converge to [`DualGains`]' `state.covariance` and `input.covariance`).
    /// Cost: `2S³`.
    pub fn predicted_covariances(
        &self,
        s: &DualKalmanFilterState<T, S, I, O>,
    ) -> (SMatrix<T, S, S>, SMatrix<T, I, I>) {
        (predict_t(&self.a, &s.p, &self.q), sym(&(s.pw + self.qw)))
    }

    /// One filter step with the measurement `y` (`y_n`; a non-finite entry: missing).
    ///
    /// Errors, `s` left bit-identical: [`Error::InvalidCovariance`] (`D̃ Pʷ⁻ D̃ᵀ + R` or
    /// `C P⁻ Cᵀ + R` not positive definite to working precision),
    /// [`Error::NonFiniteState`] (a non-finite estimate, covariance or gain),
    /// [`Error::StepCountOverflow`] (the step or missing-sample counter would pass
    /// `u64::MAX`: only a corrupted or forged state, see [`DualFilter::try_step`]). No
    /// allocation, no panic; cost in the type docs.
    pub fn try_step(
        &self,
        s: &mut DualKalmanFilterState<T, S, I, O>,
        y: &SVector<T, O>,
    ) -> Result<(), Error> {
        let e = &s.estimate;
        let present = y.iter().all(|v| v.is_finite());
        let (n, missing) = next_counts(e.n, e.missing, present).ok_or(Error::StepCountOverflow)?;
        let (pm, pwm) = self.predicted_covariances(s);
        let mut next = *s;
        if present {
            // Input stage (the paper's Steps 1–3): the random walk measured through D̃,
            // its innovation from the previous filtered state.
            // Each stage is the Kalman core's correction (no cross term) in the paper's
            // short form.
            let (dp, sw) = innovation_t(&pwm, &self.d, &self.r, None);
            let cw = sw.cholesky().ok_or(Error::InvalidCovariance)?;
            let gw = gain_t(&cw, &dp);
            let w = e.w + gw * (y - self.c * e.xi - self.d * e.w);
            // State stage (Steps 4–6): predicted with the new ŵ_n.
            let xp = self.a * e.xi + self.b * w;
            let (cp, sx) = innovation_t(&pm, &self.c, &self.r, None);
            let cx = sx.cholesky().ok_or(Error::InvalidCovariance)?;
            let gx = gain_t(&cx, &cp);
            next.estimate.xi = xp + gx * (y - self.c * xp - self.d * w);
            next.estimate.w = w;
            next.pw = short_form_t(&pwm, &gw, &dp);
            next.p = short_form_t(&pm, &gx, &cp);
            next.gain_w = gw;
            next.gain_x = gx;
        } else {
            next.estimate.xi = self.a * e.xi + self.b * e.w;
            next.p = pm;
            next.pw = pwm;
        }
        next.estimate.n = n;
        next.estimate.missing = missing;
        let finite = next
            .estimate
            .xi
            .iter()
            .chain(next.estimate.w.iter())
            .chain(next.p.iter())
            .chain(next.pw.iter())
            .chain(next.gain_x.iter())
            .chain(next.gain_w.iter())
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
    //! The counters of a step (issue 31): a step whose step or missing-sample counter
    //! would pass `u64::MAX` is refused, typed, and changes nothing (the counters used to
    //! wrap to 0). Here because only the crate can make an estimate that old.

    use super::*;
    use crate::models;
    use crate::observer::{Outputs, StateSpace};

    fn model() -> InputModel<4, 1, 2> {
        let (m, k) = models::shear_building([1.0e3, 1.0e3], [1.0e6, 1.0e6]);
        let c = models::rayleigh(&m, &k, 0.1, 1e-3);
        let ss = StateSpace::<2, 4, 1>::from_rows_aem(m, c, k, [[0.0], [1.0]], 0.01).unwrap();
        let mut out = Outputs::<2, 1, 2>::zero();
        out.a[0][1] = 1.0;
        out.u[1][1] = 1.0;
        InputModel::from_parts(&ss, &ss.outputs(&out).unwrap()).unwrap()
    }

    #[test]
    fn dual_counters_that_would_overflow_refuse_the_step() {
        let model = model();
        let (q, qw) = (
            SMatrix::<f64, 4, 4>::identity() * 1e-10,
            SMatrix::from([[1e4]]),
        );
        let r = SMatrix::<f64, 2, 2>::from_diagonal(&SVector::from([1e-4, 1e-10]));
        let y = SVector::<f64, 2>::from([0.1, 1e-4]);
        let gap = SVector::<f64, 2>::from([f64::NAN, 1e-4]);
        let fixed =
            DualFilter::<f64, 4, 1, 2>::new(&model, &DualGains::new(&model, &q, &qw, &r).unwrap())
                .unwrap();
        for order in [DualOrder::Paper, DualOrder::PredictedState] {
            let f = fixed.with_order(order);
            let mut e = f.start(&SVector::zeros(), &SVector::zeros()).unwrap();
            e.n = u64::MAX;
            e.missing = 7;
            let before = e;
            assert_eq!(f.try_step(&mut e, &y), Err(Error::StepCountOverflow));
            assert_eq!(f.try_step(&mut e, &gap), Err(Error::StepCountOverflow));
            f.step(&mut e, &y);
            f.step(&mut e, &gap);
            assert_eq!(e, before);
            // The missing-sample counter alone (a forged estimate): refused only when the
            // sample is missing.
            e.n = 5;
            e.missing = u64::MAX;
            let before = e;
            assert_eq!(f.try_step(&mut e, &gap), Err(Error::StepCountOverflow));
            f.step(&mut e, &gap);
            assert_eq!(e, before);
            assert_eq!(f.try_step(&mut e, &y), Ok(()));
            assert_eq!((e.n, e.missing), (6, u64::MAX));
        }
        let tv = DualKalmanFilter::<f64, 4, 1, 2>::new(&model, &q, &qw, &r).unwrap();
        let mut s = tv
            .start(
                &SVector::zeros(),
                &SMatrix::identity(),
                &SVector::zeros(),
                &SMatrix::identity(),
            )
            .unwrap();
        s.estimate.n = u64::MAX;
        let before = s;
        assert_eq!(tv.try_step(&mut s, &y), Err(Error::StepCountOverflow));
        assert_eq!(tv.try_step(&mut s, &gap), Err(Error::StepCountOverflow));
        assert_eq!(s, before);
        s.estimate.n = 5;
        s.estimate.missing = u64::MAX;
        let before = s;
        assert_eq!(tv.try_step(&mut s, &gap), Err(Error::StepCountOverflow));
        assert_eq!(s, before);
        assert_eq!(tv.try_step(&mut s, &y), Ok(()));
        assert_eq!((s.estimate.n, s.estimate.missing), (6, u64::MAX));
    }
}
