//! # aemstep
//!
//! A `no_std`, allocation-free stepping kernel for the equations of motion of structures,
//!
//! ```text
//! M u'' + C u' + K u = p(t)
//! ```
//!
//! by Katsikadelis' analog equation method (AEM): the acceleration `q = u''` is the
//! "fictitious load" of the analog equation `u'' = q`, taken as the mean of its end values
//! on each step; the equation of motion is enforced at the end of the step. For linear
//! systems the step is second-order accurate and unconditionally stable (it coincides with
//! Newmark's average-acceleration rule).
//!
//! - [`Linear`]: constant `M, C, K`; operators built once (at run time, or by the compiler
//!   into flash with [`Linear::from_rows`]); `3N²` multiply-adds a step.
//! - [`AForm`]: the paper's literal `U_n = A U_{n−1} + b p_n` (`12N²`), for reference and
//!   inspection.
//! - [`LinearInput`]: inputs through an influence matrix, `p = B w(t)` (`2N² + N·I`).
//! - [`Modal`]: `R` of the `N` modes, `I` inputs, `O` outputs (`R·I + 7R`; [`modal`]).
//! - [`State`], [`Stepper`]: the state and the interface every scheme shares.
//! - [`Nonlinear`], [`Model`]: `M u'' + F(u, u') = p(t)` by Newton on the acceleration,
//!   with a per-step [`NewtonReport`]; [`Varying`]: `M(t), C(t), K(t)` ([`TimeVarying`]).
//! - Comparator schemes behind the same interface: [`Newmark`] (β, γ), [`GeneralizedAlpha`]
//!   (ρ∞, HHT-α), [`Exact`] (matrix-exponential discretization, piecewise-linear load).
//! - [`analysis`]: amplification matrix, spectral radius, period elongation and amplitude
//!   decay of any scheme on the 1-DOF oscillator.
//! - [`spectrum`]: response spectra: a bank of damped oscillators fed one
//!   ground-acceleration sample at a time, RotD50/RotD100, and (feature `std`) many
//!   records in parallel on the host.
//! - [`models`]: `const` builders for shear buildings and Rayleigh damping.
//! - [`Error`]: the one error type; a failed step never changes the caller's state.
//!
//! Scalars are `f32` or `f64` ([`Real`]); sizes are const generics; nothing allocates.
#![no_std]
#![deny(missing_docs)]
#![forbid(unsafe_code)]
// Matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

#[cfg(feature = "std")]
extern crate std;

mod aform;
pub mod analysis;
mod error;
mod exact;
mod generalized_alpha;
mod input;
mod linear;
pub mod modal;
pub mod models;
mod newmark;
mod nonlinear;
mod ops;
mod scalar;
pub mod spectrum;
mod state;
mod varying;

pub use aform::AForm;
pub use error::Error;
pub use exact::Exact;
pub use generalized_alpha::{AlphaParameters, GeneralizedAlpha};
pub use input::LinearInput;
pub use linear::Linear;
pub use modal::{Damping, Modal, ModalState};
pub use newmark::Newmark;
pub use nonlinear::{Iterations, Model, NewtonReport, NewtonSettings, Nonlinear, Tangent};
pub use scalar::Real;
pub use state::{State, Stepper};
pub use varying::{Coefficients, TimeVarying, Varying};

/// The README's code blocks, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
