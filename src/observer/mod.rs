//! Observer loops: virtual sensing on the structural model.
//!
//! The linear schemes' discrete model, corrected by measurements, estimates what no sensor
//! measures (every inter-storey drift of a building from two accelerometers, say):
//!
//! - [`StateSpace`]: the discrete state-space form `x_n = Φ x_{n−1} + Γ₀ w_{n−1} + Γ₁ w_n`
//!   of every linear scheme — the AEM ([`Linear`](crate::Linear),
//!   [`LinearInput`](crate::LinearInput)), [`Newmark`](crate::Newmark) (β, γ),
//!   [`GeneralizedAlpha`](crate::GeneralizedAlpha) and HHT-α (`x = [u; v; a]`, `3N`
//!   states), [`Exact`](crate::Exact) and [`Modal`](crate::Modal) (`R` modes, `2R`
//!   states) — with outputs `y = H x + D w` ([`Outputs`], [`Measurement`]) for
//!   displacements, drifts, velocities, relative or absolute accelerations. Plain `f64`
//!   matrices.
//! - [`SteadyState`]: the steady-state Kalman gain from the discrete algebraic Riccati
//!   equation, in `const fn` (a `static` observer keeps its gain in flash, no Riccati code
//!   linked) and at run time (the same code).
//! - [`Observer`]: the fixed-gain observer, `S² + 2S·I + 2S·O + O·I` multiply-adds a step,
//!   `f32`/`f64`; a NaN measurement skips the correction (counted), a failed checked step
//!   changes nothing. [`Readout`] reads estimated quantities from its state.
//! - [`Kalman`]: the full Kalman filter (covariance propagated in Joseph form), for the host
//!   and small firmware models.
//!
//! - `DynStateSpace`, `DynSteadyState`, `DynObserver` (feature `std`): the AEM model, its
//!   steady-state gain and the fixed-gain observer at sizes chosen at run time, on the same
//!   flat-slice build and step rows as the const-generic types (bit-identical where both
//!   serve; `tests/runtime_size_observer.rs`). Their gain solve costs `O(S³)` a piece;
//!   `DynSteadyState::new_with_stop` looks at a stop flag between pieces (Ctrl-C, a time
//!   budget).
//!
//! Sizes are const generics: `N` degrees of freedom, `S` states (`S = 2N`, `3N` for
//! generalized-α, or `2R` modal —
//! a parameter of its own, checked at construction: [`Error::StateSizeMismatch`](crate::Error::StateSizeMismatch)),
//! `I` inputs, `O` measurements.
//!
//! The scene (`cargo run --release -p xtask --bin observer_building`, `docs/observer.md`): the
//! 5-storey building under El Centro, absolute accelerations of floors 2 and 5 measured,
//! every drift estimated.
//!
//! # Noise that reaches the sensors
//!
//! Unmodelled forces on the floors are the usual process noise ([`StateSpace::input_noise`]
//! of a model with `B = I`). Accelerometers also feel them directly: `a = M⁻¹ (p − C v −
//! K u)`, the feedthrough `D_f` of the forces' model. The noise model the crate assumes
//! for the two-ended input: the noise force is `η_n` over step `n` at both of its ends
//! (independent from step to step, `E η ηᵀ = Q_w`), and a sensor at `t_n` reads the force
//! the step ended with. Then
//!
//! ```text
//! x_n = Φ x_{n−1} + … + q_n,   q_n = (Γ₀ + Γ₁) η_n
//! y_n = H x_n + … + r_n,        r_n = D_f η_n + v_n        (v_n: the sensors' own noise)
//! Q = (Γ₀ + Γ₁) Q_w (Γ₀ + Γ₁)ᵀ,  N = E q_n r_nᵀ = (Γ₀ + Γ₁) Q_w D_fᵀ,  R = R_v + D_f Q_w D_fᵀ
//! ```
//!
//! and `(q_n, r_n)` is white (independent of every other sample's): the filters' standard
//! model with a *cross covariance* `N` between the noise into sample `n` and that sample's
//! measurement noise. ([`StateSpace::input_noise`], [`StateSpace::input_cross_noise`],
//! [`StateSpace::feedthrough_noise`] compute the three.) Leaving `N` out (or `D_f Q_w D_fᵀ`
//! out of `R`) makes the innovations larger than the filter believes: the monitoring
//! scene's χ² statistic ran 3.4 % high (`tests/cross_covariance.rs`).
//!
//! A force sampled independently at every sample instead (`w_n` i.i.d., the step using
//! `w_{n−1}` and `w_n`) gives `q_n = Γ₀ w_{n−1} + Γ₁ w_n`: coloured across one step and
//! correlated with two measurements (`Γ₁ Q_w D_fᵀ` with `r_n`, `Γ₀ Q_w D_fᵀ` with
//! `r_{n−1}`). That is not the model above; it is white only after the change of state
//! `ξ = x − Γ₁ w` ([`estimation`](crate::estimation)), where it correlates the noise into
//! `ξ_{n+1}` with `r_n` (a predictor-form cross term) — not what these filters take.
//!
//! With `N` the innovation `ν = H e⁻ + r_n` (`E e⁻ r_nᵀ = N`: the a-priori error holds
//! `q_n`) has covariance `Σ = H P⁻ Hᵀ + R + H N + Nᵀ Hᵀ`, the gain is
//! `K = (P⁻ Hᵀ + N) Σ⁻¹`, and the Joseph form gains `− (I − K H) N Kᵀ − K Nᵀ (I − K H)ᵀ`.
//! The steady state ([`SteadyState::from_parts_cross`]) solves the Riccati equation with
//! the cross term: with `P⁻ = Y + Q`, `Y` follows the Riccati recursion of a predictor on
//! `(Φ, H)` with state noise `Φ q` and measurement noise `H q + r` (cross covariance
//! `Φ (Q Hᵀ + N)`, `R_y = H Q Hᵀ + R + H N + Nᵀ Hᵀ`), which the usual decorrelation
//! (`Φ − S_y R_y⁻¹ H`, `Q_y − S_y R_y⁻¹ S_yᵀ`) hands to the same doubling algorithm. One
//! place computes the cross term for every filter ([`Kalman::with_cross`],
//! [`SteadyState`], [`detection::innovation_covariance`](crate::detection::innovation_covariance),
//! the joint and augmented filters and the smoother of [`estimation`](crate::estimation)).
//! `N` must make `[Q N; Nᵀ R]` a covariance ([`Error::InvalidCovariance`](crate::Error::InvalidCovariance)
//! otherwise); `N = 0` gives every filter's original numbers bit for bit.
//! `tests/cross_covariance.rs` checks the steady state against the recursion written from
//! these equations, and by simulation of the monitoring scene (the floor forces drawn as
//! above) the innovations' covariance, the mean window statistic (150.0 ± 0.2 over 158 000
//! windows) and the false alarms at `α = 10⁻²` and `10⁻³` (inside their binomial bands).

#[cfg(feature = "std")]
mod dynamic;
mod fixed;
mod kalman;
// The one Kalman core: the correction and the Riccati equation with the cross covariance.
mod flat;
mod kalman_core;
mod kalman_flat;
mod riccati;
mod state_space;

#[cfg(feature = "std")]
pub use dynamic::{
    DynEstimate, DynKalman, DynKalmanState, DynMeasurement, DynObserver, DynStateSpace,
    DynSteadyState,
};
pub use fixed::{Estimate, Observer, Readout};
pub(crate) use fixed::{check_counts, estimate_counters, mul2, next_counts};
pub use kalman::{Kalman, KalmanState};
// For the joint input–state estimators (`crate::estimation`).
pub(crate) use flat::cholesky_flat;
pub(crate) use kalman_core::{
    check_start_covariance, checked_cross_t, cross_is_valid, cross_riccati_start, gain_t,
    innovation_parts, innovation_t, is_zero, noise_fits, predict_t, short_form_t,
};
pub(crate) use kalman_core::{definite_lu, is_covariance, symmetrize};
pub(crate) use riccati::{A_SMALL, abs_of, balance, doubling_solution, inf_norm, stein};
pub use riccati::{RICCATI_MAX_ITERATIONS, RICCATI_RESIDUAL_UNITS, SteadyState};
pub use state_space::{Measurement, Outputs, StateSpace};
pub(crate) use state_space::{bare_model, lu_of};

/// The fixture of the filters' unit tests: the 5-storey building (AEM, `h = 0.02` s)
/// under ground acceleration, the absolute accelerations of floors 2 and 5 measured.
#[cfg(test)]
pub(crate) fn building_fixture() -> (StateSpace<5, 10, 1>, Measurement<10, 1, 2>) {
    let (m, c, k) = crate::models::five_storey_building();
    let excitation = crate::models::base_excitation(&m);
    let ss = StateSpace::<5, 10, 1>::from_rows_aem(m, c, k, excitation, 0.02).unwrap();
    let outputs = Outputs::absolute_accelerations(Outputs::<5, 1, 2>::select([1, 4]), 0);
    let meas = ss.outputs(&outputs).unwrap();
    (ss, meas)
}
