//! Hysteretic structures: nonlinear models whose force depends on the load path, with
//! fixed-size history committed only when a step succeeds.
//!
//! A [`HistoryModel`] gives the internal force at a *trial* displacement and velocity from
//! the history *committed* at the start of the step, together with the history that
//! accepting that trial would commit. It never mutates anything: the history is plain data
//! (`Copy`) held by the caller beside the [`State`](crate::State), and
//! [`Nonlinear::try_step_with_history`](crate::Nonlinear::try_step_with_history) assigns
//! both only when the step has converged to a finite state. A failed or refused step
//! therefore leaves state and history bit-identical — there is nothing to revert.
//! (Solvers that keep the trial state inside each material need `commit`/`revert` calls
//! for this; here the commit is the assignment of the accepted trial.)
//!
//! The built-in uniaxial [`Law`]s, each with its consistent (algorithmic) tangent:
//!
//! - [`Bilinear`]: elastic–plastic with linear kinematic hardening, by return mapping.
//! - [`BoucWen`]: smooth hysteresis; the internal variable `z` integrated over the step by
//!   the trapezoidal rule in the deformation (second order), solved by a scalar Newton
//!   inside the law.
//! - [`Friction`]: Coulomb friction regularized in the velocity, `f = f_s tanh(v / v_r)`.
//!
//! [`Parallel`] puts two laws side by side in one storey (a frame and a friction damper).
//! [`ShearBuilding`] assembles `N` storeys of one law type with linear damping into a
//! [`HistoryModel`] for the [`Nonlinear`](crate::Nonlinear) stepper; [`EnergyAccount`]
//! keeps its energy balance (input = kinetic + recoverable + viscous + hysteretic) beside
//! a run.
//!
//! Equations, measured accuracy and the commands that produce each figure:
//! `docs/hysteresis.md`.

mod bilinear;
mod bouc_wen;
mod building;
mod energy;
mod friction;
mod parallel;

pub use bilinear::{Bilinear, BilinearHistory};
pub use bouc_wen::{BoucWen, BoucWenHistory};
pub use building::ShearBuilding;
#[cfg(feature = "std")]
pub(crate) use building::{Bands, check_building, storeys_flat};
pub use energy::EnergyAccount;
pub use friction::Friction;
pub use parallel::Parallel;

use nalgebra::{SMatrix, SVector};

use crate::{Real, Tangent, TridiagonalTangent};

/// The force of a [`HistoryModel`] at a trial `(u, v)` and the history that accepting it
/// would commit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trial<T, const N: usize, H> {
    /// The internal force `F(u, v; history)` (force units), `N` entries.
    pub force: SVector<T, N>,
    /// The history after a step ending at this `(u, v)`: what the stepper commits if the
    /// step is accepted.
    pub history: H,
    /// A signature of the active branch (e.g. bit `i` set when storey `i` is on an
    /// inelastic branch). The stepper counts how often it changes between Newton iterates
    /// ([`NewtonReport::branch_changes`](crate::NewtonReport::branch_changes)); its value
    /// has no other meaning. `0` for a model with one branch.
    pub branch: u64,
}

/// A structural model `M u'' + F(u, u'; history) = p(t)` whose internal force depends on
/// the load path through a fixed-size history, for
/// [`Nonlinear::try_step_with_history`](crate::Nonlinear::try_step_with_history).
///
/// Both [`HistoryModel::trial`] and [`HistoryModel::tangent`] are pure functions of the
/// *committed* history (the one at the start of the step) and the trial `(u, v)`: Newton
/// may evaluate any number of trials in any order, and only the stepper decides what is
/// committed. A memoryless [`Model`](crate::Model) is the special case `History = ()`
/// (that is how the stepper runs it).
///
/// Methods must not panic; a NaN or infinite force or tangent is reported as
/// [`Error::NonFiniteForce`](crate::Error::NonFiniteForce) and the step is not taken.
pub trait HistoryModel<T: Real, const N: usize> {
    /// The internal variables (plastic deformations, hysteretic variables, …): plain,
    /// fixed-size data.
    type History: Copy;

    /// The history of the virgin structure (nothing has yielded). Cost: O(N).
    fn initial_history(&self) -> Self::History;

    /// The constant mass matrix `M` (`N×N`). Called once per step and once per start.
    fn mass(&self) -> SMatrix<T, N, N>;

    /// The force at the trial `(u, v)` from the `committed` history, and the trial
    /// history.
    fn trial(
        &self,
        committed: &Self::History,
        u: &SVector<T, N>,
        v: &SVector<T, N>,
    ) -> Trial<T, N, Self::History>;

    /// The consistent tangent `∂F/∂u`, `∂F/∂v` of [`HistoryModel::trial`]'s force at
    /// `(u, v)` (the derivative of the discrete update, not of the continuous law), or
    /// `None` (the default) for finite differences of `trial` (`N` extra trials per Newton
    /// iteration; see [`Model::tangent`](crate::Model::tangent)).
    fn tangent(
        &self,
        _committed: &Self::History,
        _u: &SVector<T, N>,
        _v: &SVector<T, N>,
    ) -> Option<Tangent<T, N>> {
        None
    }

    /// The trial at `(u, v)` (as [`HistoryModel::trial`]), writing the mass and the
    /// consistent tangent at that trial in symmetric tridiagonal form into `tangent`, for a
    /// model whose `M`, `∂F/∂u` and `∂F/∂v` are all symmetric tridiagonal: the
    /// [`Nonlinear`](crate::Nonlinear) stepper then forms and solves each Newton system in
    /// `O(N)` from what the trial already computed, instead of a dense tangent and an
    /// `N³/3` factorization. Return the same trial as [`HistoryModel::trial`] and write the
    /// same matrices as [`HistoryModel::mass`] and [`HistoryModel::tangent`] (their three
    /// diagonals, the rest being zero); return `Some` for every `(u, v)` or for none.
    /// (`tangent` is written in place, not returned: it is six `N`-vectors, filled once a
    /// trial.)
    ///
    /// `None` (the default), leaving `tangent` as it was, keeps the dense path.
    /// [`ShearBuilding`] returns `Some` when its damping matrix is symmetric tridiagonal
    /// (storey dashpots, Rayleigh damping).
    fn trial_tridiagonal(
        &self,
        _committed: &Self::History,
        _u: &SVector<T, N>,
        _v: &SVector<T, N>,
        _tangent: &mut TridiagonalTangent<T, N>,
    ) -> Option<Trial<T, N, Self::History>> {
        None
    }
}

/// One uniaxial law's response at a trial deformation.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LawTrial<T, H> {
    /// The force `f` (force units).
    pub force: T,
    /// The consistent tangent stiffness `∂f/∂d` of the discrete update (force per
    /// deformation).
    pub stiffness: T,
    /// The tangent damping `∂f/∂ḋ` (force per deformation rate).
    pub damping: T,
    /// The history a step ending at this trial commits.
    pub history: H,
    /// On an inelastic branch (yielding, loading branch of the hysteresis, sliding).
    pub inelastic: bool,
}

/// A uniaxial hysteretic law `f(d, ḋ; history)`: a storey spring or a device, with
/// deformation `d` and deformation rate `ḋ`.
///
/// Like [`HistoryModel`], a law evaluates a trial from the committed history and never
/// mutates; to drive one under a prescribed deformation (a test, a material calibration),
/// keep `trial.history` of each accepted step as the next committed history.
pub trait Law<T: Real> {
    /// The internal variables, plain data.
    type History: Copy + PartialEq + core::fmt::Debug;

    /// The virgin history (zero deformation, nothing yielded). Cost: O(1).
    fn initial_history(&self) -> Self::History;

    /// Force, consistent tangent and trial history at deformation `d` and rate `rate`
    /// from the `committed` history (the one at the start of the step).
    fn trial(&self, committed: &Self::History, d: T, rate: T) -> LawTrial<T, Self::History>;

    /// The strain energy recoverable by elastic unloading to zero internal force, at the
    /// committed `history` and deformation `d` (energy units). What the law has absorbed
    /// beyond it (work `∫ f dd` minus this) is the hysteretic energy.
    fn recoverable_energy(&self, history: &Self::History, d: T) -> T;
}

/// `x` finite and `> 0`.
pub(crate) fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// `x` finite and in `[0, 1)`.
pub(crate) fn unit_ratio(x: f64) -> bool {
    x.is_finite() && (0.0..1.0).contains(&x)
}

/// The elastic–plastic parameters every law with a yield point shares: stiffness `k` and
/// yield force `fy` finite and `> 0`, post-yield ratio `alpha` in `[0, 1)`.
///
/// Errors: [`Error::InvalidMaterial`](crate::Error::InvalidMaterial) naming the first
/// parameter out of range.
pub(crate) fn check_elastic_plastic(k: f64, fy: f64, alpha: f64) -> Result<(), crate::Error> {
    use crate::{Error, Param};
    if !positive(k) {
        return Err(Error::InvalidMaterial(Param::Stiffness));
    }
    if !positive(fy) {
        return Err(Error::InvalidMaterial(Param::YieldForce));
    }
    if !unit_ratio(alpha) {
        return Err(Error::InvalidMaterial(Param::PostYieldRatio));
    }
    Ok(())
}

/// Every coefficient of a law or model, computed in `f64`, fits `T` (finite and at most
/// `T::MAX` in size): else it would round to `∞` (found by fuzzing: `Bilinear::<f32>` with
/// `k = 1.6e293` had an infinite stiffness).
///
/// Errors: [`Error::OperatorOverflow`](crate::Error::OperatorOverflow).
pub(crate) fn fits<T: Real>(xs: &[f64]) -> Result<(), crate::Error> {
    if crate::linalg::all_fit(xs, T::MAX) {
        Ok(())
    } else {
        Err(crate::Error::OperatorOverflow)
    }
}

/// The coefficients `c` of a law, computed in `f64`, checked to fit `T` ([`fits`]) and each
/// rounded once to `T`: the laws' constructors store these. Cost: `K` comparisons and
/// roundings.
///
/// Errors: [`Error::OperatorOverflow`](crate::Error::OperatorOverflow).
pub(crate) fn rounded<T: Real, const K: usize>(c: [f64; K]) -> Result<[T; K], crate::Error> {
    fits::<T>(&c)?;
    Ok(c.map(T::from_f64_rounded))
}
