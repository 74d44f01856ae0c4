//! The dual Kalman filter (Eftekhar Azam, Chatzi & Papadimitriou 2015): two Kalman
//! filters in sequence each step, one for the input (a random walk), one for the state —
//! with fixed (steady) gains ([`DualGains`], [`DualFilter`]) or time-varying, the
//! covariances propagated as in the paper ([`DualKalmanFilter`]).
//!
//! On the standard form of [`InputModel`] (`ξ_n = A ξ_{n−1} + B w_{n−1}`,
//! `y_n = C ξ_n + D̃ w_n`) a step is
//!
//! ```text
//! ξ⁻ = A ξ̂_{n−1} + B ŵ_{n−1}
//! ŵ_n = ŵ_{n−1} + G_w (y_n − C ξ⁻ − D̃ ŵ_{n−1})      (input filter: w_n = w_{n−1} + η)
//! ξ̂_n = ξ⁻ + G_x (y_n − C ξ⁻ − D̃ ŵ_n)              (state filter, with the new ŵ_n)
//! ```
//!
//! The paper writes the input stage's innovation with `C x̂_{k−1}` and the state's
//! prediction with `B p̂_k`; in the `ξ` form the prediction `ξ⁻` needs only `ŵ_{n−1}`, so
//! both stages use it (the same structure, with the model's own timing). The gains are the
//! steady-state Kalman gains of the two stages, each from the crate's
//! [`SteadyState`]: `G_w` of the model `(I, D̃)` with process noise `Q_w` (the random
//! walk), `G_x` of `(A, C)` with `Q`, both with measurement noise `R`.
//!
//! The stages ignore their coupling, so no covariance of the joint error is propagated;
//! the joint error dynamics are those of [`DualFilter::error_step`]. With
//! acceleration-only sensing the static force–displacement pair `(ξ_s, w_c)`, `ξ_s =
//! A ξ_s + B w_c`, `C ξ_s + D̃ w_c = 0`, is a fixed point of them for any gains (both
//! innovations vanish on it): the dual filter drifts like every estimator that uses only
//! these data; `tests/estimation.rs` shows it, and that a displacement removes it.

use nalgebra::{SMatrix, SVector};

use super::InputModel;
use super::joint::{JointEstimate, joint_start, shift};
use crate::linalg::{self, all_finite, finite_as, identity, matrix_t, round_rows, sym};
use crate::observer::{Measurement, StateSpace, SteadyState, is_covariance};
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
        let input_model = StateSpace::<0, I, 0> {
            phi: identity(),
            gamma0: [[0.0; 0]; I],
            gamma1: [[0.0; 0]; I],
            dof_u: [],
            dof_v: [],
            dof_a: [],
            dof_a_input: [],
            time_step: model.time_step,
        };
        let input_meas = Measurement::<I, 0, O> {
            h: model.d,
            d: [[0.0; 0]; O],
        };
        let input = match SteadyState::from_parts(&input_model, &input_meas, qw, r) {
            Ok(s) => s,
            Err(Error::RiccatiNotConverged) => return Err(Error::InputNotIdentifiable),
            Err(e) => return Err(e),
        };
        let state_model = StateSpace::<0, S, 0> {
            phi: model.a,
            gamma0: [[0.0; 0]; S],
            gamma1: [[0.0; 0]; S],
            dof_u: [],
            dof_v: [],
            dof_a: [],
            dof_a_input: [],
            time_step: model.time_step,
        };
        let state_meas = Measurement::<S, 0, O> {
            h: model.c,
            d: [[0.0; 0]; O],
        };
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

/// The fixed-gain dual Kalman filter (the steps of the [module docs](self)), `S` states,
/// `I` inputs, `O` measurements, stepping in `T`. A measurement with a non-finite entry is
/// missing: `ξ̂_n = ξ⁻`, the input estimate held, counted.
///
/// Cost of a step: `S² + S·I + 2S·O + 3O·I` multiply-adds, fixed. Size:
/// `S² + 3S·I + 2S·O + 2O·I + 1` values of `T`. [`DualFilter::new`] and `from_parts_f32`/`_f64`
/// (`const fn`) are bit-identical.
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
}

/// Every operator finite and fitting `T`.
const fn dual_checks<const S: usize, const I: usize, const O: usize>(
    model: &InputModel<S, I, O>,
    gains: &DualGains<S, I, O>,
    max: f64,
) -> Result<(), Error> {
    let (gw, gx) = (&gains.input.gain, &gains.state.gain);
    if !(all_finite(&model.a)
        && all_finite(&model.b)
        && all_finite(&model.c)
        && all_finite(&model.d)
        && all_finite(&model.gamma1)
        && all_finite(gw)
        && all_finite(gx))
    {
        return Err(Error::NonFiniteInput);
    }
    if let Err(e) = crate::kinematics::check_time_step_as(model.time_step, max) {
        return Err(e);
    }
    if !(finite_as(&model.a, max)
        && finite_as(&model.b, max)
        && finite_as(&model.c, max)
        && finite_as(&model.d, max)
        && finite_as(&model.gamma1, max)
        && finite_as(gw, max)
        && finite_as(gx, max))
    {
        return Err(Error::OperatorOverflow);
    }
    Ok(())
}

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
        })
    }

    /// The time step `h` (s).
    pub fn time_step(&self) -> T {
        self.time_step
    }

    /// The start from a physical state `x0` and input `w0` (`ξ̂_0 = x0 − Γ₁ w0`).
    /// Errors: [`Error::NonFiniteInput`].
    pub fn start(
        &self,
        x0: &SVector<T, S>,
        w0: &SVector<T, I>,
    ) -> Result<JointEstimate<T, S, I>, Error> {
        joint_start(&self.gamma1, x0, w0)
    }

    /// The physical state estimate `x̂_n = ξ̂_n + Γ₁ ŵ_n`. Cost: `S·I`.
    pub fn state(&self, e: &JointEstimate<T, S, I>) -> SVector<T, S> {
        shift(&self.gamma1, &e.xi, &e.w, T::one())
    }

    /// One step of the joint error dynamics without noise (a constant input, exact
    /// data): the errors `(ξ − ξ̂, w − ŵ)` of a step from the errors `(ex, ew)` before
    /// it ([module docs](self)):
    ///
    /// ```text
    /// e⁻ = A e_ξ + B e_w,  e_w' = e_w − G_w (C e⁻ + D̃ e_w),  e_ξ' = e⁻ − G_x (C e⁻ + D̃ e_w')
    /// ```
    ///
    /// Applied to the unit vectors it gives the matrix whose spectral radius says whether
    /// the filter's errors die out. Cost: about a step.
    pub fn error_step(
        &self,
        ex: &SVector<T, S>,
        ew: &SVector<T, I>,
    ) -> (SVector<T, S>, SVector<T, I>) {
        let em = SVector::<T, S>::from_fn(|i, _| {
            let mut s = T::zero();
            for j in 0..S {
                s += self.a[i][j] * ex[j];
            }
            for j in 0..I {
                s += self.b[i][j] * ew[j];
            }
            s
        });
        let innov = |w: &SVector<T, I>| {
            SVector::<T, O>::from_fn(|o, _| {
                let mut s = T::zero();
                for j in 0..S {
                    s += self.c[o][j] * em[j];
                }
                for j in 0..I {
                    s += self.d[o][j] * w[j];
                }
                s
            })
        };
        let nu = innov(ew);
        let ew1 = SVector::<T, I>::from_fn(|i, _| {
            let mut s = ew[i];
            for o in 0..O {
                s -= self.gain_w[i][o] * nu[o];
            }
            s
        });
        let nu2 = innov(&ew1);
        let ex1 = SVector::<T, S>::from_fn(|i, _| {
            let mut s = em[i];
            for o in 0..O {
                s -= self.gain_x[i][o] * nu2[o];
            }
            s
        });
        (ex1, ew1)
    }

    /// One step with the measurement `y` (`y_n`; a non-finite entry: missing). Fixed cost
    /// (type docs), no allocation, no panic.
    #[inline]
    pub fn step(&self, e: &mut JointEstimate<T, S, I>, y: &SVector<T, O>) {
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
        if !y.iter().all(|v| v.is_finite()) {
            e.xi = xp.into();
            e.missing = e.missing.wrapping_add(1);
            e.n = e.n.wrapping_add(1);
            return;
        }
        // ν₀ = y − C ξ⁻; the input stage's innovation ν₀ − D̃ ŵ_{n−1}.
        let nu0: [T; O] = core::array::from_fn(|o| {
            let mut s = y[o];
            for j in 0..S {
                s -= self.c[o][j] * xp[j];
            }
            s
        });
        let mut nu = nu0;
        for o in 0..O {
            for j in 0..I {
                nu[o] -= self.d[o][j] * e.w[j];
            }
        }
        for i in 0..I {
            let mut s = e.w[i];
            for o in 0..O {
                s += self.gain_w[i][o] * nu[o];
            }
            e.w[i] = s;
        }
        // The state stage's innovation ν₀ − D̃ ŵ_n.
        for o in 0..O {
            let mut s = nu0[o];
            for j in 0..I {
                s -= self.d[o][j] * e.w[j];
            }
            nu[o] = s;
        }
        for i in 0..S {
            let mut s = xp[i];
            for o in 0..O {
                s += self.gain_x[i][o] * nu[o];
            }
            e.xi[i] = s;
        }
        e.n = e.n.wrapping_add(1);
    }

    /// [`DualFilter::step`], checked: the new estimate must be finite, else `e` is left
    /// bit-identical. Errors: [`Error::NonFiniteState`].
    pub fn try_step(&self, e: &mut JointEstimate<T, S, I>, y: &SVector<T, O>) -> Result<(), Error> {
        commit_if_finite(e, |next| self.step(next, y))
    }
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
/// the step of the [module docs](self) with both stages' covariances propagated, as the
/// paper writes it:
///
/// ```text
/// input stage:  Pʷ⁻ = Pʷ_{n−1} + Q_w        G_w = Pʷ⁻ D̃ᵀ (D̃ Pʷ⁻ D̃ᵀ + R)⁻¹
///               ŵ_n = ŵ_{n−1} + G_w (y_n − C ξ⁻ − D̃ ŵ_{n−1})     Pʷ_n = Pʷ⁻ − G_w D̃ Pʷ⁻
/// state stage:  P⁻ = A P_{n−1} Aᵀ + Q          G_x = P⁻ Cᵀ (C P⁻ Cᵀ + R)⁻¹
///               ξ̂_n = ξ⁻ + G_x (y_n − C ξ⁻ − D̃ ŵ_n)              P_n = P⁻ − G_x C P⁻
/// ```
///
/// with `ξ⁻ = A ξ̂_{n−1} + B ŵ_{n−1}`. As in the paper, each stage's innovation
/// covariance holds only its own uncertainty and `R`: the input stage's leaves out
/// `C P⁻ Cᵀ` (the state's error in its innovation), the state stage's leaves out
/// `D̃ Pʷ D̃ᵀ`, and `P⁻` leaves out `B Pʷ Bᵀ`. The two recursions are therefore
/// independent of the data and of each other, and each is the Riccati recursion whose
/// limit [`DualGains`] solves: `Pʷ⁻ → DualGains::input.covariance`,
/// `P⁻ → DualGains::state.covariance`, the gains to theirs (`tests/estimation_dual.rs`).
/// The covariances are those of the stages' models, not the errors of the coupled
/// filter.
///
/// A measurement with a non-finite entry is missing: predict only (`ξ̂_n = ξ⁻`,
/// `P_n = P⁻`, `ŵ_n = ŵ_{n−1}` with `Pʷ_n = Pʷ⁻`: the random walk's prediction), counted.
/// Only a checked step: a failed step changes nothing.
///
/// Cost of a step: about `2S³ + 2S²·O + 2S·O² + O³/3` multiply-adds for the state stage
/// and `2O·I² + 2O²·I + O³/3` for the input stage, plus the fixed filter's
/// `S² + S·I + 2S·O + 3O·I` (`≈ 3 400` for `S = 10`, `I = 1`, `O = 4`): for the host and
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
        let estimate = joint_start(&self.gamma1, x0, w0)?;
        let (pr, pwr) = (linalg::rows_f64(p0), linalg::rows_f64(pw0));
        if !(is_covariance(&pr, false) && is_covariance(&pwr, false)) {
            return Err(Error::InvalidCovariance);
        }
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
        (
            sym(&(self.a * s.p * self.a.transpose() + self.q)),
            sym(&(s.pw + self.qw)),
        )
    }

    /// The physical state estimate `x̂_n = ξ̂_n + Γ₁ ŵ_n`. Cost: `S·I`.
    pub fn state(&self, s: &DualKalmanFilterState<T, S, I, O>) -> SVector<T, S> {
        shift(&self.gamma1, &s.estimate.xi, &s.estimate.w, T::one())
    }

    /// One filter step with the measurement `y` (`y_n`; a non-finite entry: missing).
    ///
    /// Errors, `s` left bit-identical: [`Error::InvalidCovariance`] (`D̃ Pʷ⁻ D̃ᵀ + R` or
    /// `C P⁻ Cᵀ + R` not positive definite to working precision),
    /// [`Error::NonFiniteState`] (a non-finite estimate, covariance or gain). No
    /// allocation, no panic; cost in the type docs.
    pub fn try_step(
        &self,
        s: &mut DualKalmanFilterState<T, S, I, O>,
        y: &SVector<T, O>,
    ) -> Result<(), Error> {
        let e = &s.estimate;
        let xp = self.a * e.xi + self.b * e.w;
        let (pm, pwm) = self.predicted_covariances(s);
        let mut next = *s;
        if y.iter().all(|v| v.is_finite()) {
            // ν₀ = y − C ξ⁻.
            let nu0 = y - self.c * xp;
            // Input stage: the random walk measured through D̃.
            let dp = self.d * pwm;
            let sw = sym(&(dp * self.d.transpose() + self.r));
            let cw = sw.cholesky().ok_or(Error::InvalidCovariance)?;
            let gw = cw.solve(&dp).transpose();
            let w = e.w + gw * (nu0 - self.d * e.w);
            // State stage, with the new ŵ_n.
            let cp = self.c * pm;
            let sx = sym(&(cp * self.c.transpose() + self.r));
            let cx = sx.cholesky().ok_or(Error::InvalidCovariance)?;
            let gx = cx.solve(&cp).transpose();
            next.estimate.xi = xp + gx * (nu0 - self.d * w);
            next.estimate.w = w;
            next.pw = sym(&(pwm - gw * dp));
            next.p = sym(&(pm - gx * cp));
            next.gain_w = gw;
            next.gain_x = gx;
        } else {
            next.estimate.xi = xp;
            next.p = pm;
            next.pw = pwm;
            next.estimate.missing = next.estimate.missing.wrapping_add(1);
        }
        next.estimate.n = next.estimate.n.wrapping_add(1);
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
