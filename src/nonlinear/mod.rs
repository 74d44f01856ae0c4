//! Nonlinear equations of motion `M u'' + F(u, u') = p(t)` (paper §5, Algorithm 2).
//!
//! The kinematics are those of the linear step (`q = u''` constant on the step at the mean
//! of its end values); the equation of motion is enforced at `t_n`:
//!
//! ```text
//! v̂ = v_{n−1} + (h/2) q_{n−1},   û = u_{n−1} + h v_{n−1} + (h²/4) q_{n−1}
//! find q_n:  R(q_n) = M q_n + F(û + (h²/4) q_n, v̂ + (h/2) q_n) − p_n = 0
//! v_n = v̂ + (h/2) q_n,            u_n = û + (h²/4) q_n
//! ```
//!
//! `R = 0` is solved by Newton's method from the predictor `q_{n−1}`, with the matrix
//! `J = M + (h/2) ∂F/∂v + (h²/4) ∂F/∂u`, factorized at every iteration: by LU with partial
//! pivoting, or — for a model whose `M`, `∂F/∂u`, `∂F/∂v` are symmetric tridiagonal (a
//! shear building, [`HistoryModel::trial_tridiagonal`]) — by `L D Lᵀ` on the three
//! diagonals while `J` is positive definite (pivoted LU of the same `J` otherwise).
//!
//! **Cost per step**, `k` Newton iterations (at most the budget): dense,
//! `k · (N³/3 + 4N² multiply-adds + one tangent evaluation) + (k + 1)` force evaluations
//! (without an analytic tangent the tangent evaluation is `N` extra force evaluations, a
//! directional finite difference per column of `J`); tridiagonal, `k · 26N` flops (`J` and
//! its scale `16N`, the solve `9N` with `N` divisions, the update `N`) and `(k + 1)` trials,
//! each with its tangent, plus `8N` for `M q` and the residual a trial. Stack: about three
//! `N×N` matrices of `T`.

/// `start_with_acceleration` of the nonlinear steppers (`Nonlinear`, `Varying`): the
/// state at `t = 0` from the given `u0, v0, a0`, checked finite
/// (`State::initial_given`), documented by the doc lines passed in and the shared
/// errors and cost. Expands inside an `impl` block with `T: Real` and `N` in scope.
macro_rules! start_with_acceleration {
    ($(#[doc = $doc:expr])*) => {
        $(#[doc = $doc])*
        ///
        /// Errors: [`Error::NonFiniteInput`]. Cost: O(N).
        pub fn start_with_acceleration(
            &self,
            u0: &SVector<T, N>,
            v0: &SVector<T, N>,
            a0: &SVector<T, N>,
        ) -> Result<State<T, N>, Error> {
            State::initial_given(u0, v0, a0)
        }
    };
}

pub(crate) mod varying;

use core::marker::PhantomData;

use nalgebra::{SMatrix, SVector};

use crate::hysteresis::{HistoryModel, Trial};
use crate::kinematics::{AemKinematics, Kinematics, check_time_step_as};
use crate::linalg::lu::{solve_in_place, solve_in_place_scaled};
use crate::linalg::tridiagonal;
pub use crate::linalg::tridiagonal::SymTridiagonal;
use crate::scalar::initial_inputs_finite;
use crate::{Error, Real, State};

/// The derivatives of the internal force `F(u, v)` at one point (the tangent operator).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tangent<T, const N: usize> {
    /// Tangent stiffness `∂F/∂u` (force per displacement), `N×N`.
    pub stiffness: SMatrix<T, N, N>,
    /// Tangent damping `∂F/∂v` (force per velocity), `N×N`.
    pub damping: SMatrix<T, N, N>,
}

/// The mass and the tangent of a model whose `M`, `∂F/∂u` and `∂F/∂v` are all symmetric
/// tridiagonal (a shear building with storey springs and storey or Rayleigh damping), as
/// [`HistoryModel::trial_tridiagonal`](crate::hysteresis::HistoryModel::trial_tridiagonal)
/// returns it with each trial: the [`Nonlinear`] stepper then forms and solves the Newton
/// matrix `J = M + (h/2) ∂F/∂v + (h²/4) ∂F/∂u` in `O(N)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TridiagonalTangent<T, const N: usize> {
    /// The mass matrix `M` (mass units); the same at every trial.
    pub mass: SymTridiagonal<T, N>,
    /// The tangent stiffness `∂F/∂u` (force per displacement).
    pub stiffness: SymTridiagonal<T, N>,
    /// The tangent damping `∂F/∂v` (force per velocity).
    pub damping: SymTridiagonal<T, N>,
}

/// A nonlinear structural model `M u'' + F(u, u') = p(t)`, implemented by the user.
///
/// `F` gathers every internal force (damping and restoring, linear or not). A model whose
/// `F` also depends on time can be passed to each step evaluated at that step's end time
/// `t_n` (the equation is enforced there): models are taken by reference per call.
///
/// Methods must not panic; a NaN or infinite result is reported as
/// [`Error::NonFiniteForce`] and the step is not taken.
pub trait Model<T: Real, const N: usize> {
    /// The constant mass matrix `M` (`N×N`). Called once per step and once per start.
    fn mass(&self) -> SMatrix<T, N, N>;

    /// The internal force `F(u, v)` at displacement `u` and velocity `v`.
    fn force(&self, u: &SVector<T, N>, v: &SVector<T, N>) -> SVector<T, N>;

    /// The tangent `∂F/∂u`, `∂F/∂v` at `(u, v)`, or `None` (the default) to let the
    /// stepper form `J` by finite differences: `N` extra force evaluations per Newton
    /// iteration, one forward difference per column along `q_j`, which moves `u_j` by
    /// `s = √ε·max(|u_j|, 1)` and `v_j` by `(2/h)·s`. Exact for `F` linear in `v`; give
    /// the tangent when `F` is strongly nonlinear in `v` or a fixed, small iteration count
    /// must converge.
    fn tangent(&self, _u: &SVector<T, N>, _v: &SVector<T, N>) -> Option<Tangent<T, N>> {
        None
    }
}

/// How many Newton iterations a step may use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Iterations {
    /// Stop as soon as the step has converged (see [`NewtonSettings::tolerance`]), after
    /// at most this many iterations (`≥ 1`).
    UpTo(u32),
    /// Always exactly this many iterations (`≥ 1`): the same work every step, for hard
    /// real-time loops. Convergence is still judged (and reported) by the tolerance.
    Exactly(u32),
}

/// Newton settings of a [`Nonlinear`] stepper.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NewtonSettings<T> {
    /// Iteration budget and mode.
    pub iterations: Iterations,
    /// Convergence tolerance (dimensionless, finite, `≥ 0`). A step has converged when
    /// either
    /// - the relative residual `‖M q + F − p‖∞ / max(‖M q‖∞, ‖F‖∞, ‖p‖∞)` is `≤ tolerance`,
    ///   or
    /// - the last Newton correction `δq` was small against the accelerations the state
    ///   represents: `‖δq‖∞ ≤ tolerance · max(‖q‖∞, ‖u‖∞/(h²/4), ‖v‖∞/(h/2))`, i.e. it
    ///   moved `u_n` or `v_n` by at most `tolerance` relative to their size.
    ///
    /// The second test catches convergence at the rounding floor, where the forces nearly
    /// cancel (e.g. a spring passing its natural length) and the residual cannot fall
    /// below `ε` times the terms inside `F`.
    pub tolerance: T,
}

impl<T: Real> NewtonSettings<T> {
    /// Iterate until converged (see [`NewtonSettings::tolerance`]), at most
    /// `max_iterations` times.
    pub fn up_to(max_iterations: u32, tolerance: T) -> Self {
        Self {
            iterations: Iterations::UpTo(max_iterations),
            tolerance,
        }
    }

    /// Always `iterations` Newton iterations (constant work per step), convergence judged
    /// by `tolerance` afterwards.
    pub fn exactly(iterations: u32, tolerance: T) -> Self {
        Self {
            iterations: Iterations::Exactly(iterations),
            tolerance,
        }
    }

    /// The default tolerance, `max(1e-10, 128 ε)`: `1e-10` in `f64`, `1.5e-5` in `f32`.
    pub fn default_tolerance() -> T {
        let eps = T::default_epsilon().as_f64();
        T::from_f64_rounded(f64::max(1e-10, 128.0 * eps))
    }
}

impl<T: Real> Default for NewtonSettings<T> {
    /// Up to 20 iterations, [`NewtonSettings::default_tolerance`].
    fn default() -> Self {
        Self::up_to(20, Self::default_tolerance())
    }
}

/// What one nonlinear step's Newton iteration did.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NewtonReport<T> {
    /// Newton iterations used (factorizations of `J`); `0` if the predictor already met
    /// the tolerance.
    pub iterations: u32,
    /// Final relative residual `‖M q + F − p‖∞ / max(‖M q‖∞, ‖F‖∞, ‖p‖∞)` at the returned
    /// state (dimensionless; `0` if all three are zero).
    pub residual: T,
    /// Size of the last Newton correction, `‖δq‖∞ / max(‖q‖∞, ‖u‖∞/(h²/4), ‖v‖∞/(h/2))`
    /// at the returned state (dimensionless; `0` if no iteration was made).
    pub correction: T,
    /// `residual ≤ tolerance` or (`iterations ≥ 1` and `correction ≤ tolerance`).
    pub converged: bool,
    /// How many times the active branch of a [`HistoryModel`] changed between successive
    /// iterates (its [`Trial::branch`] differed from the previous iterate's), e.g. a storey
    /// that yielded at one iterate and unloaded elastically at the next. Newton converges
    /// quadratically only once the branch has settled; a change in the last iterations of
    /// a fixed-iteration step says the iteration was still choosing the branch. Always `0`
    /// for a memoryless [`Model`] (one branch).
    pub branch_changes: u32,
}

/// The nonlinear AEM stepper for `M u'' + F(u, u') = p(t)` (paper Algorithm 2) with `N`
/// degrees of freedom, in `f32` or `f64`.
///
/// It holds only `h` and the Newton settings; the [`Model`] is passed to every call. A
/// step that fails (no convergence, singular `J`, non-finite force or load) returns an
/// [`Error`] and leaves the caller's [`State`] bit-identical; [`Nonlinear::trial_step`]
/// gives the unconverged candidate when the caller wants to decide itself.
///
/// Models with history (yielding storeys, hysteretic devices:
/// [`HistoryModel`](crate::hysteresis::HistoryModel)) step with
/// [`Nonlinear::try_step_with_history`]: the same Newton iteration, every trial evaluated
/// from the history committed at `t_{n−1}`, and state and history committed together only
/// when the step succeeds.
///
/// Each step solves, by Newton's method from the predictor `q_{n−1}`,
///
/// ```text
/// v̂ = v_{n−1} + (h/2) q_{n−1},   û = u_{n−1} + h v_{n−1} + (h²/4) q_{n−1}
/// R(q_n) = M q_n + F(û + (h²/4) q_n, v̂ + (h/2) q_n) − p_n = 0
/// J = M + (h/2) ∂F/∂v + (h²/4) ∂F/∂u          (factorized every iteration)
/// v_n = v̂ + (h/2) q_n,            u_n = û + (h²/4) q_n
/// ```
///
/// `J` is factorized by LU with partial pivoting; a model that gives its trials with a
/// tridiagonal tangent ([`HistoryModel::trial_tridiagonal`], e.g.
/// [`ShearBuilding`](crate::hysteresis::ShearBuilding) with Rayleigh or storey damping) has
/// `J` formed on its three diagonals and solved by `L D Lᵀ` in `O(N)` while positive
/// definite, by pivoted LU of the same `J` otherwise.
///
/// **Cost per step**, for `k` Newton iterations: dense, `k × (N³/3 + 4N² multiply-adds + one
/// tangent evaluation) + (k + 1)` force evaluations (without an analytic tangent, a tangent
/// evaluation is `N` force evaluations); tridiagonal, `k × 26N` flops and `(k + 1)` trials
/// with their tangents, `8N` flops more a trial (`M q`, residual). Stack: about three `N×N`
/// matrices of `T`.
///
/// A Duffing oscillator `u'' + 0.2 u' + u + u³ = p(t)` (paper Example 5), with two Newton
/// iterations every step:
///
/// ```
/// use aemstep::{Model, NewtonSettings, Nonlinear, Tangent};
/// use aemstep::{matrix, vector};
/// use aemstep::nalgebra::{SMatrix, SVector};
///
/// struct Duffing;
/// impl Model<f32, 1> for Duffing {
///     fn mass(&self) -> SMatrix<f32, 1, 1> {
///         matrix![1.0]
///     }
///     fn force(&self, u: &SVector<f32, 1>, v: &SVector<f32, 1>) -> SVector<f32, 1> {
///         vector![0.2 * v[0] + u[0] + u[0] * u[0] * u[0]]
///     }
///     fn tangent(&self, u: &SVector<f32, 1>, _v: &SVector<f32, 1>) -> Option<Tangent<f32, 1>> {
///         Some(Tangent { stiffness: matrix![1.0 + 3.0 * u[0] * u[0]], damping: matrix![0.2] })
///     }
/// }
///
/// // exact solution u = e^{-0.1t} sin t, so p(t) = -0.01 e^{-0.1t} sin t + e^{-0.3t} sin³t
/// let p = |t: f32| vector![-0.01 * (-0.1 * t).exp() * t.sin() + (-0.3 * t).exp() * t.sin().powi(3)];
/// let h = 0.01;
/// let stepper = Nonlinear::<f32, 1>::new(0.01, NewtonSettings::exactly(2, 1e-5))?;
/// let mut s = stepper.start(&Duffing, &vector![0.0], &vector![1.0], &p(0.0))?;
/// for n in 1..=300 {
///     let report = stepper.try_step(&Duffing, &mut s, &p(n as f32 * h))?;
///     assert!(report.converged && report.iterations == 2);
/// }
/// let t = 3.0f32;
/// assert!((s.u()[0] - (-0.1 * t).exp() * t.sin()).abs() < 1e-4);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nonlinear<T, const N: usize> {
    kin: AemKinematics<T>,
    settings: NewtonSettings<T>,
    _n: PhantomData<[T; N]>,
}

impl<T: Real, const N: usize> Nonlinear<T, N> {
    /// A stepper with time step `h` (s, in `f64` like every constructor; the kinematics
    /// are rounded once to `T`) and the given Newton settings.
    ///
    /// Errors: [`Error::InvalidTimeStep`] (`h` not finite or `≤ 0`),
    /// [`Error::InvalidNewtonSettings`] (zero iterations, or a tolerance that is negative
    /// or not finite). Cost: O(1).
    pub fn new(h: f64, settings: NewtonSettings<T>) -> Result<Self, Error> {
        let kin = AemKinematics::new(check_time_step_as(h, T::MAX)?)?.round();
        let budget = match settings.iterations {
            Iterations::UpTo(k) | Iterations::Exactly(k) => k,
        };
        if budget == 0 || !settings.tolerance.is_finite() || settings.tolerance < T::zero() {
            return Err(Error::InvalidNewtonSettings);
        }
        Ok(Self {
            kin,
            settings,
            _n: PhantomData,
        })
    }

    /// The time step `h` (s).
    pub fn time_step(&self) -> T {
        self.kin.h
    }

    /// The Newton settings.
    pub fn settings(&self) -> NewtonSettings<T> {
        self.settings
    }

    /// The step's kinematics `h`, `h/2`, `h²/4` in `T` (the run-time-sized stepper, `std`,
    /// takes them from here: one check and one rounding). Cost: O(1).
    #[cfg(feature = "std")]
    pub(crate) fn kinematics(&self) -> AemKinematics<T> {
        self.kin
    }

    /// The state at `t = 0`, with `q0 = M⁻¹ (p0 − F(u0, v0))` (paper eq. 45).
    ///
    /// Errors: [`Error::NonFiniteInput`] (`u0`, `v0`, `p0` or `M`),
    /// [`Error::NonFiniteForce`], [`Error::SingularMass`] (then use
    /// [`Nonlinear::start_with_acceleration`]), [`Error::NonFiniteState`].
    /// Cost: one force evaluation and one `N×N` LU solve.
    pub fn start<Mo: Model<T, N> + ?Sized>(
        &self,
        model: &Mo,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        p0: &SVector<T, N>,
    ) -> Result<State<T, N>, Error> {
        self.start_with_history(&Memoryless(model), u0, v0, p0, &())
            .map(|(s, ())| s)
    }

    /// The state at `t = 0` of a model with history, with `q0 = M⁻¹ (p0 − F(u0, v0))`,
    /// `F` the model's trial force at `(u0, v0)` from `history0` (e.g.
    /// [`HistoryModel::initial_history`], the virgin material). Returns the state and the
    /// history to step from: the trial history at `(u0, v0)`, committed.
    ///
    /// Errors: as [`Nonlinear::start`]. Cost: one trial evaluation and one `N×N` LU solve.
    pub fn start_with_history<Mo: HistoryModel<T, N> + ?Sized>(
        &self,
        model: &Mo,
        u0: &SVector<T, N>,
        v0: &SVector<T, N>,
        p0: &SVector<T, N>,
        history0: &Mo::History,
    ) -> Result<(State<T, N>, Mo::History), Error> {
        if !initial_inputs_finite(u0, v0, p0) {
            return Err(Error::NonFiniteInput);
        }
        let m = model.mass();
        if !m.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        let trial = model.trial(history0, u0, v0);
        if !all_finite(&trial.force) {
            return Err(Error::NonFiniteForce);
        }
        let state = initial_from_equation(u0, v0, &m, p0 - trial.force)?;
        Ok((state, trial.history))
    }

    start_with_acceleration! {
        /// The state at `t = 0` with a known initial acceleration `a0` (for singular `M`).
        /// A model with history starts from its history as given (e.g.
        /// [`HistoryModel::initial_history`]).
    }

    /// Advance `state` from `t_{n−1}` to `t_n` under the load `p_n = p(t_n)`, committing
    /// only a converged, finite result.
    ///
    /// Returns the Newton report (its `converged` is always `true` on `Ok`).
    ///
    /// Errors (each leaves `state` bit-identical): [`Error::NonFiniteInput`] (`p_n` or
    /// `M`), [`Error::NonFiniteForce`] (the model returned NaN/∞ at some iterate),
    /// [`Error::SingularJacobian`], [`Error::NotConverged`] (not converged after the
    /// iteration budget, see [`NewtonSettings::tolerance`]), [`Error::NonFiniteState`].
    ///
    /// Cost: see [`Nonlinear`]; no allocation, no panic.
    pub fn try_step<Mo: Model<T, N> + ?Sized>(
        &self,
        model: &Mo,
        state: &mut State<T, N>,
        p: &SVector<T, N>,
    ) -> Result<NewtonReport<T>, Error> {
        self.try_step_with_history(&Memoryless(model), state, &mut (), p)
    }

    /// The candidate next state and its Newton report, without touching `state` — even
    /// when Newton did not converge (then `report.converged` is `false` and the caller
    /// decides: accept it, retry with a smaller step, or stop).
    ///
    /// Errors: as [`Nonlinear::try_step`] except [`Error::NotConverged`]. Cost: as a step.
    pub fn trial_step<Mo: Model<T, N> + ?Sized>(
        &self,
        model: &Mo,
        state: &State<T, N>,
        p: &SVector<T, N>,
    ) -> Result<(State<T, N>, NewtonReport<T>), Error> {
        self.newton(&Memoryless(model), &(), state, p)
            .map(|(next, (), report)| (next, report))
    }

    /// [`Nonlinear::try_step`] for a model with history: advance `state` and commit
    /// `history` together, only when the step converged to a finite state. The committed
    /// history is the model's trial history at the accepted `(u_n, v_n)`, evaluated from
    /// the history committed at `t_{n−1}` — every Newton iterate starts from that same
    /// committed history, so a rejected iterate leaves no trace.
    ///
    /// Errors: as [`Nonlinear::try_step`]; on every error both `state` and `history` are
    /// left bit-identical. Cost: as a step, with one [`HistoryModel::trial`] per force
    /// evaluation and one [`HistoryModel::tangent`] per Newton iteration.
    pub fn try_step_with_history<Mo: HistoryModel<T, N> + ?Sized>(
        &self,
        model: &Mo,
        state: &mut State<T, N>,
        history: &mut Mo::History,
        p: &SVector<T, N>,
    ) -> Result<NewtonReport<T>, Error> {
        let (next, next_history, report) = self.newton(model, history, state, p)?;
        if !report.converged {
            return Err(Error::NotConverged);
        }
        *state = next;
        *history = next_history;
        Ok(report)
    }

    /// [`Nonlinear::trial_step`] for a model with history: the candidate next state, the
    /// history that accepting it would commit, and the Newton report, without touching
    /// `state` or `history` (commit both yourself to accept an unconverged candidate).
    ///
    /// Errors: as [`Nonlinear::try_step_with_history`] except [`Error::NotConverged`].
    /// Cost: as a step.
    pub fn trial_step_with_history<Mo: HistoryModel<T, N> + ?Sized>(
        &self,
        model: &Mo,
        state: &State<T, N>,
        history: &Mo::History,
        p: &SVector<T, N>,
    ) -> Result<Candidate<T, N, Mo::History>, Error> {
        self.newton(model, history, state, p)
    }

    /// The one Newton iteration of every nonlinear step (memoryless models through
    /// [`Memoryless`], `History = ()`): from the predictor `q_{n−1}`, every trial from the
    /// `committed` history. Returns the last iterate, its trial history and the report.
    ///
    /// A model that gives its trials with a tridiagonal tangent
    /// ([`HistoryModel::trial_tridiagonal`]) has its Newton systems formed and solved in
    /// `O(N)` ([`Linearization`]); every other the dense way. The iteration is the same.
    fn newton<Mo: HistoryModel<T, N> + ?Sized>(
        &self,
        model: &Mo,
        committed: &Mo::History,
        state: &State<T, N>,
        p: &SVector<T, N>,
    ) -> Result<Candidate<T, N, Mo::History>, Error> {
        if !all_finite(p) {
            return Err(Error::NonFiniteInput);
        }
        let zero = SymTridiagonal::zero();
        let path = Linearization {
            model,
            committed,
            tangent: TridiagonalTangent {
                mass: zero,
                stiffness: zero,
                damping: zero,
            },
            banded: false,
            mass: None,
        };
        self.iterate(path, state, p)
    }

    /// Newton's iteration on `R(q) = M q + F(û + (h²/4) q, v̂ + (h/2) q) − p = 0` from the
    /// predictor `q_{n−1}`, the trials and the Newton systems given by `path`.
    fn iterate<Mo: HistoryModel<T, N> + ?Sized>(
        &self,
        mut path: Linearization<'_, Mo, Mo::History, T, N>,
        state: &State<T, N>,
        p: &SVector<T, N>,
    ) -> Result<Candidate<T, N, Mo::History>, Error> {
        let (b, c) = (self.kin.half_h, self.kin.quarter_h2);
        let (vh, uh) = self.kin.predict_all(&state.u, &state.v, &state.a);
        let mut newton = Progress::new(self.settings, norm_inf(p), (b, c));
        let mut q = state.a;
        loop {
            let (v, u) = self.kin.correct_all(&vh, &uh, &q);
            let (trial, mq) = path.evaluate(&u, &v, &q)?;
            let Trial {
                force: f,
                history,
                branch,
            } = trial;
            if !all_finite(&f) {
                return Err(Error::NonFiniteForce);
            }
            let r = mq + f - p;
            let forces = [r.as_slice(), mq.as_slice(), f.as_slice()];
            if let Some(report) = newton.judge(branch, forces, [&q, &u, &v].map(|x| x.as_slice())) {
                let next = State::unchecked(u, v, q, state.n.wrapping_add(1));
                if !next.is_finite() {
                    return Err(Error::NonFiniteState);
                }
                return Ok((next, history, report));
            }
            let mut delta = r;
            path.solve(&u, &v, &f, b, c, &mut delta)?;
            q -= delta;
            newton.corrected(norm_inf(&delta));
        }
    }
}

/// How a Newton iteration gets its trials and solves its systems. A model whose trials
/// come with `M`, `∂F/∂u`, `∂F/∂v` on three diagonals ([`HistoryModel::trial_tridiagonal`])
/// has `J` formed on them (`8N` flops) and solved by `L D Lᵀ` (`N` divisions, `6N` flops)
/// when positive definite, else by pivoted LU of the same `J` laid out densely. Every other
/// model: [`HistoryModel::trial`], a dense tangent (the model's, or finite differences) and
/// LU with partial pivoting, `N³/3` multiply-adds a system.
struct Linearization<'a, Mo: ?Sized, H, T, const N: usize> {
    model: &'a Mo,
    committed: &'a H,
    /// The tridiagonal mass and tangent of the last trial, when `banded`.
    tangent: TridiagonalTangent<T, N>,
    /// The last trial came with [`Linearization::tangent`].
    banded: bool,
    /// The dense mass, fetched (and checked finite) once, when a trial came without one.
    mass: Option<SMatrix<T, N, N>>,
}

impl<T: Real, const N: usize, Mo: HistoryModel<T, N> + ?Sized>
    Linearization<'_, Mo, Mo::History, T, N>
{
    /// The trial at `(u, v)` and `M q`.
    ///
    /// Errors: [`Error::NonFiniteInput`] (`M` not finite).
    #[inline(always)]
    fn evaluate(
        &mut self,
        u: &SVector<T, N>,
        v: &SVector<T, N>,
        q: &SVector<T, N>,
    ) -> Result<Evaluated<T, N, Mo::History>, Error> {
        if let Some(trial) = self
            .model
            .trial_tridiagonal(self.committed, u, v, &mut self.tangent)
        {
            if !self.tangent.mass.is_finite() {
                return Err(Error::NonFiniteInput);
            }
            self.banded = true;
            return Ok((trial, self.tangent.mass.mul(q)));
        }
        self.banded = false;
        let m = self.dense_mass()?;
        Ok((self.model.trial(self.committed, u, v), m * q))
    }

    /// The model's dense `M`, checked finite once.
    fn dense_mass(&mut self) -> Result<SMatrix<T, N, N>, Error> {
        if let Some(m) = self.mass {
            return Ok(m);
        }
        let m = self.model.mass();
        if !m.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        self.mass = Some(m);
        Ok(m)
    }

    /// `r ← J⁻¹ r`, `J = M + b ∂F/∂v + c ∂F/∂u` at the last evaluated `(u, v)`, whose
    /// force was `f`.
    ///
    /// Errors: [`Error::NonFiniteForce`] (a tangent entry), [`Error::SingularJacobian`].
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn solve(
        &mut self,
        u: &SVector<T, N>,
        v: &SVector<T, N>,
        f: &SVector<T, N>,
        b: T,
        c: T,
        r: &mut SVector<T, N>,
    ) -> Result<(), Error> {
        if !self.banded {
            let m = self.dense_mass()?;
            return dense_solve(self.model, self.committed, &m, u, v, f, b, c, r);
        }
        let t = &self.tangent;
        if !t.stiffness.is_finite() || !t.damping.is_finite() {
            return Err(Error::NonFiniteForce);
        }
        let mut j = SymTridiagonal::zero();
        let scale = jacobian_flat(
            [t.mass.diagonal.as_slice(), t.mass.off.as_slice()],
            [t.damping.diagonal.as_slice(), t.damping.off.as_slice()],
            [t.stiffness.diagonal.as_slice(), t.stiffness.off.as_slice()],
            b,
            c,
            &mut j.diagonal.data.0[0],
            &mut j.off.data.0[0],
        );
        let rhs = *r;
        if tridiagonal::solve_positive(&j, r, scale) {
            return Ok(());
        }
        // Not positive definite (a softening storey): pivot, on the same J.
        *r = rhs;
        if !solve_in_place(&mut j.to_matrix(), r, scale) {
            return Err(Error::SingularJacobian);
        }
        Ok(())
    }
}

/// `r ← J⁻¹ r` with the dense tangent (the model's, or finite differences of its trials)
/// and LU with partial pivoting. Cost: `N³/3 + 3N²` and one tangent evaluation (without
/// one, `N` trial evaluations).
#[allow(clippy::too_many_arguments)]
fn dense_solve<T: Real, const N: usize, Mo: HistoryModel<T, N> + ?Sized>(
    model: &Mo,
    committed: &Mo::History,
    m: &SMatrix<T, N, N>,
    u: &SVector<T, N>,
    v: &SVector<T, N>,
    f: &SVector<T, N>,
    b: T,
    c: T,
    r: &mut SVector<T, N>,
) -> Result<(), Error> {
    // J = M + (h/2) ∂F/∂v + (h²/4) ∂F/∂u, with an entry scale for the pivot test.
    let (mut j, scale) = match model.tangent(committed, u, v) {
        Some(t) => {
            if !t
                .stiffness
                .iter()
                .chain(t.damping.iter())
                .all(|x| x.is_finite())
            {
                return Err(Error::NonFiniteForce);
            }
            let j = m + t.damping * b + t.stiffness * c;
            let scale = m
                .iter()
                .zip(t.damping.iter())
                .zip(t.stiffness.iter())
                .fold(T::zero(), |s, ((x, d), k)| {
                    s.max(x.abs() + b * d.abs() + c * k.abs())
                });
            (j, scale)
        }
        // No tangent: `J = M + ∂F(û + c q, v̂ + b q)/∂q` by one forward difference per
        // column (`N` trial evaluations), scale `max |M_ij| + |(J − M)_ij|`.
        None => {
            let sqrt_eps = T::default_epsilon().sqrt();
            let one = T::one();
            let mut j = *m;
            let mut scale = T::zero();
            // Column-major arrays: plain array indexing with loop-bounded indices, which the
            // compiler proves in bounds (no panic path in the binary).
            let (u_a, v_a, f_a) = (&u.data.0[0], &v.data.0[0], &f.data.0[0]);
            for col in 0..N {
                let (uj, vj) = (u_a[col], v_a[col]);
                // u_j moves by √ε·max(|u_j|, 1), rounded so the step is exact in floating point;
                // v_j moves along the same q_j direction, by (b/c) times that.
                let shifted = uj + sqrt_eps * uj.abs().max(one);
                let delta = (shifted - uj) / c;
                let (mut up, mut vp) = (*u, *v);
                up.data.0[0][col] = shifted;
                vp.data.0[0][col] = vj + b * delta;
                let fp = model.trial(committed, &up, &vp).force;
                if !all_finite(&fp) {
                    return Err(Error::NonFiniteForce);
                }
                let fp_a = &fp.data.0[0];
                let j_col = &mut j.data.0[col];
                for row in 0..N {
                    let d = (fp_a[row] - f_a[row]) / delta;
                    scale = scale.max(j_col[row].abs() + d.abs());
                    j_col[row] += d;
                }
            }
            (j, scale)
        }
    };
    if !solve_in_place(&mut j, r, scale) {
        return Err(Error::SingularJacobian);
    }
    Ok(())
}

/// A trial and `M q` at one Newton iterate.
type Evaluated<T, const N: usize, H> = (Trial<T, N, H>, SVector<T, N>);

/// A candidate step of a model with history: the state, the history accepting it would
/// commit, and the Newton report.
type Candidate<T, const N: usize, H> = (State<T, N>, H, NewtonReport<T>);

/// A memoryless [`Model`] as a [`HistoryModel`] with `History = ()` and one branch: how
/// [`Nonlinear::start`], [`Nonlinear::try_step`] and [`Nonlinear::trial_step`] share the
/// Newton iteration of the models with history.
struct Memoryless<'a, Mo: ?Sized>(&'a Mo);

impl<T: Real, const N: usize, Mo: Model<T, N> + ?Sized> HistoryModel<T, N> for Memoryless<'_, Mo> {
    type History = ();

    #[inline(always)]
    fn initial_history(&self) {}

    #[inline(always)]
    fn mass(&self) -> SMatrix<T, N, N> {
        self.0.mass()
    }

    #[inline(always)]
    fn trial(&self, _: &(), u: &SVector<T, N>, v: &SVector<T, N>) -> Trial<T, N, ()> {
        Trial {
            force: self.0.force(u, v),
            history: (),
            branch: 0,
        }
    }

    #[inline(always)]
    fn tangent(&self, _: &(), u: &SVector<T, N>, v: &SVector<T, N>) -> Option<Tangent<T, N>> {
        self.0.tangent(u, v)
    }
}

fn all_finite<T: Real, const N: usize>(x: &SVector<T, N>) -> bool {
    x.iter().all(|e| e.is_finite())
}

fn norm_inf<T: Real, const N: usize>(x: &SVector<T, N>) -> T {
    norm_inf_flat(x.as_slice())
}

/// `‖x‖∞`, folded in index order. Cost: `n`.
#[inline(always)]
pub(crate) fn norm_inf_flat<T: Real>(x: &[T]) -> T {
    x.iter().fold(T::zero(), |s, e| s.max(e.abs()))
}

/// The bookkeeping of one step's Newton iteration, shared by the const-generic and the
/// run-time-sized (`std`) iterations: the budget, the tolerance, the iterations and the
/// last correction, the branch changes. Cost: none beyond [`Progress::judge`].
pub(crate) struct Progress<T> {
    budget: u32,
    fixed: bool,
    tol: T,
    /// `‖p‖∞`.
    p_size: T,
    /// `(h/2, h²/4)`.
    bc: (T, T),
    iterations: u32,
    /// `‖δq‖∞` of the last correction.
    last_delta: T,
    branch_changes: u32,
    last_branch: u64,
}

impl<T: Real> Progress<T> {
    /// Before the first iterate, for a step with `settings`, load size `p_size = ‖p‖∞`
    /// and kinematics `bc = (h/2, h²/4)`.
    #[inline(always)]
    pub(crate) fn new(settings: NewtonSettings<T>, p_size: T, bc: (T, T)) -> Self {
        let (budget, fixed) = match settings.iterations {
            Iterations::UpTo(k) => (k, false),
            Iterations::Exactly(k) => (k, true),
        };
        Self {
            budget,
            fixed,
            tol: settings.tolerance,
            p_size,
            bc,
            iterations: 0,
            last_delta: T::zero(),
            branch_changes: 0,
            last_branch: 0,
        }
    }

    /// The convergence test of an iterate ([`NewtonSettings::tolerance`]): its residual
    /// `r = M q + F − p`, `M q` and `F`, its `q`, `u`, `v` (each `N` values) and its
    /// trial's `branch`. The report when the iteration stops here (converged, or the
    /// budget spent), else `None` (correct and judge the next iterate). The relative
    /// residual `‖r‖∞ / max(‖M q‖∞, ‖F‖∞, ‖p‖∞)` is `0` when the denominator is (then
    /// `r = 0` too). Cost: `7N` comparisons, 3 divisions.
    #[inline(always)]
    pub(crate) fn judge(
        &mut self,
        branch: u64,
        [r, mq, f]: [&[T]; 3],
        [q, u, v]: [&[T]; 3],
    ) -> Option<NewtonReport<T>> {
        let iterations = self.iterations;
        if iterations > 0 && branch != self.last_branch {
            self.branch_changes += 1;
        }
        self.last_branch = branch;
        let (b, c) = self.bc;
        let scale = norm_inf_flat(mq).max(norm_inf_flat(f)).max(self.p_size);
        let residual = if scale > T::zero() {
            norm_inf_flat(r) / scale
        } else {
            T::zero()
        };
        let correction = if iterations == 0 {
            T::zero()
        } else {
            let reference = norm_inf_flat(q)
                .max(norm_inf_flat(u) / c)
                .max(norm_inf_flat(v) / b);
            if self.last_delta <= T::zero() {
                T::zero()
            } else if reference > T::zero() {
                self.last_delta / reference
            } else {
                T::one()
            }
        };
        let converged = residual <= self.tol || (iterations > 0 && correction <= self.tol);
        let done = iterations >= self.budget || (!self.fixed && converged);
        done.then_some(NewtonReport {
            iterations,
            residual,
            correction,
            converged,
            branch_changes: self.branch_changes,
        })
    }

    /// After a Newton correction of size `delta = ‖δq‖∞`.
    #[inline(always)]
    pub(crate) fn corrected(&mut self, delta: T) {
        self.last_delta = delta;
        self.iterations += 1;
    }
}

/// The Newton matrix `J = M + b ∂F/∂v + c ∂F/∂u` on three diagonals (`jd`, `jo`; `jo[0]`
/// left as it is) from the bands `[diagonal, off]` of `M`, `∂F/∂v` (`d`) and `∂F/∂u`
/// (`k`), and its entry scale `max |M| + b |∂F/∂v| + c |∂F/∂u|` for the pivot tests: the
/// one assembly of the const-generic and the run-time-sized (`std`) tridiagonal Newton
/// paths. Every slice holds `n = jd.len()` values. Cost: `16n` flops.
#[inline(always)]
pub(crate) fn jacobian_flat<T: Real>(
    [md, mo]: [&[T]; 2],
    [dd, doff]: [&[T]; 2],
    [kd, ko]: [&[T]; 2],
    b: T,
    c: T,
    jd: &mut [T],
    jo: &mut [T],
) -> T {
    let mut scale = T::zero();
    for i in 0..jd.len() {
        jd[i] = md[i] + b * dd[i] + c * kd[i];
        scale = scale.max(md[i].abs() + b * dd[i].abs() + c * kd[i].abs());
        if i > 0 {
            jo[i] = mo[i] + b * doff[i] + c * ko[i];
            scale = scale.max(mo[i].abs() + b * doff[i].abs() + c * ko[i].abs());
        }
    }
    scale
}

/// The state at step 0 with the acceleration from the equation of motion,
/// `a0 = M⁻¹ r` (`r = p0 − F(u0, v0)`, or `p0 − C v0 − K u0`), solved with pivots
/// judged against the row scales of `M`.
///
/// Errors: [`Error::SingularMass`], [`Error::NonFiniteState`]. Cost: `N³/3 + N²`.
pub(crate) fn initial_from_equation<T: Real, const N: usize>(
    u0: &SVector<T, N>,
    v0: &SVector<T, N>,
    m: &SMatrix<T, N, N>,
    mut r: SVector<T, N>,
) -> Result<State<T, N>, Error> {
    // Row scales of M (pivots judged row by row, as every operator build).
    let scales =
        SVector::<T, N>::from_fn(|i, _| m.row(i).iter().fold(T::zero(), |s, x| s.max(x.abs())));
    let mut lu = *m;
    if !solve_in_place_scaled(&mut lu, &mut r, &scales) {
        return Err(Error::SingularMass);
    }
    State::initial_computed(u0, v0, r)
}
