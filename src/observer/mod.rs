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
//! Sizes are const generics: `N` degrees of freedom, `S` states (`S = 2N`, `3N` for
//! generalized-α, or `2R` modal —
//! a parameter of its own, checked at construction: [`Error::StateSizeMismatch`](crate::Error::StateSizeMismatch)),
//! `I` inputs, `O` measurements.
//!
//! The scene (`cargo run --release -p xtask --bin observer_building`, `docs/observer.md`): the
//! 5-storey building under El Centro, absolute accelerations of floors 2 and 5 measured,
//! every drift estimated.

mod fixed;
mod kalman;
// The one Kalman core: the correction and the Riccati equation with the cross covariance.
mod kalman_core;
mod riccati;
mod state_space;

pub use fixed::{Estimate, Observer, Readout};
pub use kalman::{Kalman, KalmanState};
// For the joint input–state estimators (`crate::estimation`).
pub(crate) use kalman_core::{
    cross_is_valid, cross_riccati_start, gain_t, innovation_parts, innovation_t, is_zero,
};
pub(crate) use riccati::{A_SMALL, balance, doubling, inf_norm, is_covariance, symmetrize};
pub use riccati::{RICCATI_MAX_ITERATIONS, RICCATI_RESIDUAL_UNITS, SteadyState};
pub(crate) use state_space::lu_of;
pub use state_space::{Measurement, Outputs, StateSpace};
