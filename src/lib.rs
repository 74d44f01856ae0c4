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
//! Newmark's average-acceleration rule). The method: J. T. Katsikadelis, *A new direct time
//! integration method for the equations of motion in structural dynamics*, ZAMM Z. Angew.
//! Math. Mech. (2013), DOI 10.1002/zamm.201200245.
//!
//! - [`Linear`]: constant `M, C, K`; operators built once (at run time, or by the compiler
//!   into flash with [`Linear::from_rows_f32`]); `3N²` multiply-adds a step.
//! - [`AForm`]: the paper's literal `U_n = A U_{n−1} + b p_n` (`12N²`), for reference and
//!   inspection.
//! - [`CompensatedLinear`]: the same step with the state update compensated (two-sum), for
//!   long undamped runs in `f32` (`docs/drift.md`).
//! - [`LinearInput`]: inputs through an influence matrix, `p = B w(t)` (`2N² + N·I`).
//! - [`Modal`]: `R` of the `N` modes, `I` inputs, `O` outputs (`R·I + 7R`; [`modal`]).
//! - [`State`], [`Stepper`]: the state and the interface every scheme shares.
//! - [`Nonlinear`], [`Model`]: `M u'' + F(u, u') = p(t)` by Newton on the acceleration,
//!   with a per-step [`NewtonReport`]; [`Varying`]: `M(t), C(t), K(t)` ([`TimeVarying`]).
//! - Comparator schemes behind the same interface: [`Newmark`] (β, γ), [`GeneralizedAlpha`]
//!   (ρ∞, HHT-α), [`Exact`] (matrix-exponential discretization, piecewise-linear load).
//! - [`KrAlpha`]: the explicit model-based schemes of real-time hybrid simulation, the
//!   Chen–Ricles algorithm and the KR-α family (ρ∞): displacement and velocity explicit,
//!   operators built once (also in `const fn`), `5N²` a step.
//! - [`hybrid`]: real-time hybrid simulation — the KR-α step split into a displacement
//!   command and a completion with the measured restoring force, actuator delay
//!   compensation, a storey specimen mapped onto two degrees of freedom.
//! - [`hysteresis`]: yielding structures — models with history committed only when a step
//!   succeeds ([`hysteresis::HistoryModel`]), bilinear, Bouc–Wen and friction laws, a
//!   hysteretic shear building.
//! - [`analysis`]: amplification matrix, spectral radius, period elongation and amplitude
//!   decay of any scheme on the 1-DOF oscillator.
//! - [`spectrum`]: response spectra: a bank of damped oscillators fed one
//!   ground-acceleration sample at a time, RotD50/RotD100, and (feature `std`) many
//!   records in parallel on the host.
//! - [`records`]: ground-motion record readers, PEER AT2 and one-column text, into a
//!   caller's buffer (`no_std`) or a `Vec` (feature `std`).
//! - `ida` (feature `std`): incremental dynamic analysis — hunt-and-fill tracing
//!   (Vamvatsikos & Cornell 2002) or stripes over a suite of records on the batch pool,
//!   IDA curves and their fractiles, for any analysis given as a closure (`docs/ida.md`).
//! - `batch` (feature `std`): many independent jobs (records, intensities, periods) on a
//!   work-stealing pool (rayon) of a chosen thread count, results in input order.
//! - [`observer`]: virtual sensing — the discrete state-space form of the linear schemes,
//!   a fixed-gain observer with the steady-state Kalman gain (also in `const fn`), a full
//!   Kalman filter, modal observers.
//! - [`estimation`]: virtual sensing with the load unknown — joint input–state estimation
//!   (Gillijns & De Moor), the augmented and dual Kalman filters, a fixed-lag smoother, and
//!   the check that the sensors can identify the input.
//! - [`detection`]: change detection on an observer's innovations — a windowed χ² test at a
//!   stated false-alarm probability, CUSUM, and a bank of models that names the storey.
//! - [`models`]: `const` builders for shear buildings and Rayleigh damping, and a model's
//!   natural frequencies ([`models::natural_frequencies`], `const`).
//! - [`prelude`]: the traits every stepping loop imports.
//! - [`Error`]: the one error type; a failed step never changes the caller's state.
//! - [`matrix!`], [`vector!`]: nalgebra's literal syntax for the crate's matrix and vector
//!   types, also in `const` and `static` items, with no `nalgebra` dependency of your own.
//!
//! Scalars are `f32` or `f64` ([`Real`]); sizes are const generics; nothing allocates.
//!
//! # Naming
//!
//! One rule for constructors and one name for the time step, across the crate:
//!
//! - **Run-time constructors** are `new` (variants `with`, `with_modes`, `aem`, …), generic
//!   over the scalar `T: Real`: [`Linear::new`], [`Modal::new`], [`spectrum::Bank::new`],
//!   [`observer::Observer::new`], [`observer::SteadyState::new`].
//! - **Compile-time constructors** (`const fn`: in a `static`, the compiler computes the
//!   operators into flash) are `from_rows` when they take row-major `f64` arrays (`m[i][j]`
//!   is row `i`, column `j`) and `from_parts` when they take other `const`-built values (a
//!   model, a measurement, a gain). Where a type has one impl per scalar, the name ends in
//!   the scalar — [`Linear::from_rows_f32`] / [`Linear::from_rows_f64`],
//!   [`Modal::from_rows_with_modes_f32`], [`observer::Observer::from_parts_f32`],
//!   [`spectrum::Bank::new_f32`], [`spectrum::RotD::new_f64`], … — so a typed `static`
//!   infers the sizes with no turbofish and never meets `E0034 multiple applicable items`.
//!   On a type with one scalar (`f64`), a variant ends in its kind:
//!   [`observer::StateSpace::from_rows_aem`], `from_rows_newmark`,
//!   `from_rows_generalized_alpha`, `from_rows_modal`; [`observer::SteadyState::from_parts`].
//!   The `const` twin of a run-time `new` that takes neither rows nor parts is
//!   `new_<scalar>`: [`spectrum::Bank::new_f32`], [`detection::ChiSquareTest::new_f32`],
//!   [`detection::Cusum::new_f64`]. A `const fn` that is generic over `T` (one impl,
//!   nothing of `T` to compute) carries no suffix: [`detection::Detector::from_parts`],
//!   [`detection::ModelBank::from_parts`] (both take `const`-built parts),
//!   [`detection::Whitener::from_rows_f32`] takes rows.
//! - **A state at rest** (`const fn`, so a state can live in a `static`, e.g. a
//!   `static Mutex<RefCell<State<f32, 4>>>`): `at_rest_f32` / `at_rest_f64` where it holds
//!   values of `T` ([`State::at_rest_f32`], `JointEstimate`, `Estimate`, `SplitState`, the
//!   actuator's, compensator's, CUSUM's and model bank's states, the hysteretic laws'
//!   histories), `at_rest` where it holds none ([`detection::Window::at_rest`]). Each
//!   equals the type's `Default` (the spelling generic code uses) and the start from rest
//!   of what steps it. A stepper's own start (`Observer::start_at_rest`,
//!   [`spectrum::Bank::at_rest`]) is a method of the stepper. Time-varying filters that
//!   carry a covariance (`Kalman`, the input–state and dual Kalman filters) start at run
//!   time only.
//! - **Statistics take their degrees of freedom from a type**:
//!   [`detection::ChiSquareTest::new`] and [`detection::Cusum::new`] take the estimator
//!   ([`detection::Innovations`]: `O` for an observer, `O − I` for the joint input–state
//!   estimator), or [`detection::Dof`] for a stated count — never a bare number.
//! - Stated exceptions: [`estimation::InputStateGains::solve`] and
//!   [`estimation::DualGains::solve`] (`const fn`) are named for what they do — solve the
//!   gains' Riccati equations, in `f64` — and build data, not a stepper.
//! - [`State::restore`] rebuilds a saved state (checked finite); it is not a `const`
//!   constructor.
//! - **The time step** is `time_step` everywhere: [`Stepper::time_step`], an inherent
//!   `const fn time_step` on the per-scalar steppers (usable in a `const`; generic code
//!   still calls the trait's), [`observer::Observer::time_step`],
//!   [`spectrum::Bank::time_step`], the field [`observer::StateSpace::time_step`]. In
//!   arguments it is `h` (s), the paper's symbol.
//!
//! ```
//! use aemstep::Linear;
//!
//! // u'' + 0.28 u' + 4 u = p, h = 2 ms: operators computed by the compiler.
//! static SYS: Linear<f32, 1> = match Linear::from_rows_f32([[1.0]], [[0.28]], [[4.0]], 0.002) {
//!     Ok(s) => s,
//!     Err(e) => panic!("{}", e.as_str()),
//! };
//! const H: f32 = SYS.time_step(); // s
//! const STEPS_PER_SECOND: u32 = (1.0 / H + 0.5) as u32;
//! assert_eq!(H, 0.002);
//! assert_eq!(STEPS_PER_SECOND, 500);
//! ```
//!
//! ```
//! use aemstep::models::{self, base_excitation};
//! use aemstep::observer::{Observer, Outputs, StateSpace};
//!
//! // The 5-storey building under ground acceleration, h = 0.02 s; the open-loop
//! // observer (gain 0) of the roof displacement, in f32, built by the compiler.
//! const B: ([[f64; 5]; 5], [[f64; 5]; 5], [[f64; 5]; 5]) = models::five_storey_building();
//! const SS: StateSpace<5, 10, 1> =
//!     match StateSpace::from_rows_aem(B.0, B.1, B.2, base_excitation(&B.0), 0.02) {
//!         Ok(s) => s,
//!         Err(e) => panic!("{}", e.as_str()),
//!     };
//! static OPEN_LOOP: Observer<f32, 10, 1, 1> =
//!     match SS.outputs(&Outputs::displacements(Outputs::<5, 1, 1>::select([4]))) {
//!         Ok(meas) => match Observer::from_parts_f32(&SS, &meas, &[[0.0]; 10]) {
//!             Ok(o) => o,
//!             Err(e) => panic!("{}", e.as_str()),
//!         },
//!         Err(e) => panic!("{}", e.as_str()),
//!     };
//! assert_eq!(SS.time_step, 0.02);
//! assert_eq!(OPEN_LOOP.time_step(), 0.02);
//! ```
#![no_std]
// docs.rs builds with `--cfg docsrs`: feature-gated items say which feature they need.
#![cfg_attr(docsrs, feature(doc_cfg))]
#![deny(missing_docs)]
// Denied everywhere; allowed only in `linalg::avx` (run-time AVX dispatch, argued there).
#![deny(unsafe_code)]
#![deny(clippy::undocumented_unsafe_blocks)]
// Matrix code reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

#[cfg(any(test, feature = "std"))]
extern crate std;

/// The `nalgebra` this crate's API is written in, version 0.35 (its documentation:
/// <https://docs.rs/nalgebra/0.35.0/nalgebra/>): use `aemstep::nalgebra` so your matrices
/// and vectors are the same types as the crate's, with no `nalgebra` dependency of your
/// own. Everything of nalgebra's root is here (`SMatrix`, `SVector`, `matrix!`, …).
///
/// A module re-exporting nalgebra's root rather than `pub use nalgebra;`: rustdoc links a
/// re-exported crate to the docs root that crate declares, and nalgebra 0.35 still declares
/// 0.25's. Links rustdoc makes to nalgebra's items (e.g. `SMatrix` in a signature) follow
/// the same root when the docs are built locally with `--no-deps`.
pub mod nalgebra {
    #[doc(no_inline)]
    pub use ::nalgebra::*;
}

/// The traits a stepping loop calls methods through, in one import:
/// `use aemstep::prelude::*;`.
///
/// - [`Stepper`]: `start`, `step`, `try_step`, `time_step` of every scheme.
/// - [`Model`]: a nonlinear model's mass, force and tangent ([`Nonlinear`]).
/// - [`HistoryModel`](crate::hysteresis::HistoryModel): a model whose history commits only
///   with a successful step (the hysteretic building).
/// - [`Law`](crate::hysteresis::Law): a hysteretic law's `trial` and `initial_history` (a
///   specimen or a storey).
/// - [`Compensator`](crate::hybrid::Compensator): an actuator delay compensator's `rest`
///   and `command`.
/// - [`Real`]: the scalar, `f32` or `f64`, for generic code.
///
/// ```
/// use aemstep::prelude::*;
/// use aemstep::{Linear, vector};
///
/// fn settle<T: Real, S: Stepper<T, 1, Input = aemstep::nalgebra::SVector<T, 1>>>(sys: &S, s: &mut S::State) {
///     for _ in 0..10 {
///         sys.step(s, &vector![T::zero()]);
///     }
/// }
/// let sys = Linear::<f64, 1>::from_rows_f64([[1.0]], [[0.1]], [[4.0]], 0.01)?;
/// let mut s = sys.start(&vector![0.01], &vector![0.0], &vector![0.0])?;
/// settle(&sys, &mut s);
/// assert_eq!(s.steps(), 10);
/// # Ok::<(), aemstep::Error>(())
/// ```
pub mod prelude {
    pub use crate::hybrid::Compensator;
    pub use crate::hysteresis::{HistoryModel, Law};
    pub use crate::{Model, Real, Stepper};
}

// `matrix!` and `vector!` (exported at the crate root) and the helper they expand to.
mod macros;
#[doc(hidden)]
pub use macros::rows_to_columns as __rows_to_columns;

// Independent jobs on a work-stealing pool (host only).
#[cfg(feature = "std")]
#[cfg_attr(docsrs, doc(cfg(feature = "std")))]
pub mod batch;

// Models of any size, with the number of degrees of freedom chosen at run time (host only).
#[cfg(feature = "std")]
#[cfg_attr(docsrs, doc(cfg(feature = "std")))]
pub mod dynamic;
#[cfg(feature = "std")]
#[cfg_attr(docsrs, doc(cfg(feature = "std")))]
pub use dynamic::{
    DynBuildingState, DynEnergyAccount, DynLinear, DynNonlinear, DynShearBuilding, DynState,
};

// Incremental dynamic analysis over a suite of records on the batch pool (host only).
#[cfg(feature = "std")]
#[cfg_attr(docsrs, doc(cfg(feature = "std")))]
pub mod ida;

// The state and the interface every scheme shares.
mod error;
mod scalar;
pub mod spectrum;
mod state;
mod stepper;

// The kernel: the shared predictor–corrector and the blocked step over interleaved rows.
mod kernel;
mod kinematics;

// Dense linear algebra (LU, Cholesky, symmetric eigen, matrix exponential), in one place.
mod linalg;

// The constant-coefficient schemes, one file each.
mod schemes;

// Nonlinear (Newton) and time-varying steppers.
mod nonlinear;

// Many nonlinear analyses at once, one per SIMD lane (the yielding shear building).
pub mod lanes;

// Change detection on an observer's innovations, localization by a bank of models.
pub mod detection;

// Modal reduction, stability analysis, ready-made models.
pub mod analysis;
pub mod control;
pub mod estimation;
pub mod hybrid;
pub mod hysteresis;
pub mod modal;
pub mod models;
pub mod observer;
pub mod records;

// `defmt::Format` for the types that hold nalgebra data (feature `defmt`).
#[cfg(feature = "defmt")]
mod defmt_impls;

pub use error::{Error, Param};
pub use modal::{Damping, Modal, ModalState};
pub use nonlinear::varying::{Coefficients, TimeVarying, Varying};
pub use nonlinear::{
    Iterations, Model, NewtonReport, NewtonSettings, Nonlinear, SymTridiagonal, Tangent,
    TridiagonalTangent,
};
pub use scalar::Real;
pub use schemes::{
    AForm, AlphaParameters, CompensatedLinear, CompensatedState, Exact, GeneralizedAlpha, KrAlpha,
    Linear, LinearInput, Newmark,
};
pub use state::State;
pub use stepper::{StepInput, StepState, Stepper};

/// The README's code blocks, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// The code blocks of the docs pages, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../docs/modal.md")]
pub struct ModalDocDoctests;

/// As [`ModalDocDoctests`].
#[cfg(doctest)]
#[doc = include_str!("../docs/nonlinear.md")]
pub struct NonlinearDocDoctests;

/// As [`ModalDocDoctests`].
#[cfg(doctest)]
#[doc = include_str!("../docs/schemes.md")]
pub struct SchemesDocDoctests;

/// As [`ModalDocDoctests`].
#[cfg(doctest)]
#[doc = include_str!("../docs/hysteresis.md")]
pub struct HysteresisDocDoctests;

/// As [`ModalDocDoctests`].
#[cfg(doctest)]
#[doc = include_str!("../docs/spectrum.md")]
pub struct SpectrumDocDoctests;

/// As [`ModalDocDoctests`].
#[cfg(doctest)]
#[doc = include_str!("../docs/observer.md")]
pub struct ObserverDocDoctests;

/// As [`ModalDocDoctests`].
#[cfg(doctest)]
#[doc = include_str!("../docs/estimation.md")]
pub struct EstimationDocDoctests;

/// As [`ModalDocDoctests`].
#[cfg(doctest)]
#[doc = include_str!("../docs/detection.md")]
pub struct DetectionDocDoctests;

/// As [`ModalDocDoctests`].
#[cfg(doctest)]
#[doc = include_str!("../docs/hybrid.md")]
pub struct HybridDocDoctests;

/// As [`ModalDocDoctests`].
#[cfg(doctest)]
#[doc = include_str!("../docs/control.md")]
pub struct ControlDocDoctests;

/// As [`ModalDocDoctests`].
#[cfg(doctest)]
#[doc = include_str!("../docs/control-tradeoff.md")]
pub struct ControlTradeoffDocDoctests;

/// As [`ModalDocDoctests`] (its code needs the feature `std`).
#[cfg(all(doctest, feature = "std"))]
#[doc = include_str!("../docs/ida.md")]
pub struct IdaDocDoctests;
