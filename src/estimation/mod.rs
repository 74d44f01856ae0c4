//! Joint input–state estimation: virtual sensing when the load is unknown.
//!
//! The observers of [`observer`](crate::observer) need the input measured. Here the input
//! `w` (a wind force at the roof, traffic on a deck) is unknown and is estimated with the
//! state from a few sensors:
//!
//! - [`InputModel`]: the model in the form the filters are written in (derived below),
//!   and the identifiability checks ([`Error::InputNotIdentifiable`]).
//! - [`InputStateGains`], [`InputStateObserver`], [`InputStateFilter`]: the unbiased
//!   minimum-variance joint input–state filter of Gillijns & De Moor (2007, with direct
//!   feedthrough; Lourens et al. 2012, Maes et al. 2016 for structures) — its steady-state
//!   gains (`const fn`, in `f64`), the fixed-gain filter stepping in `f32`/`f64`, and the
//!   time-varying filter with its covariances (host).
//! - [`augmented`]: the augmented Kalman filter (Lourens et al. 2012), the state `[ξ; w]`
//!   with a random-walk force, reusing [`SteadyState`](crate::observer::SteadyState),
//!   [`Observer`](crate::observer::Observer) and [`Kalman`](crate::observer::Kalman).
//! - [`smoother`]: a fixed-lag smoother with steady gains on any observer model (on the
//!   augmented one it smooths the force too), `L` samples late.
//! - [`dual`]: the dual Kalman filter (Eftekhar Azam et al. 2015), an input and a state
//!   filter in sequence, each with a steady gain from [`SteadyState`](crate::observer::SteadyState)
//!   ([`DualFilter`]) or with its covariance propagated ([`DualKalmanFilter`], host).
//!
//! # The model the filters use
//!
//! The crate's linear schemes carry the input at both ends of a step
//! ([`StateSpace`]):
//!
//! ```text
//! x_n = Φ x_{n−1} + Γ₀ w_{n−1} + Γ₁ w_n,        y_n = H x_n + D w_n
//! ```
//!
//! while the papers write `ξ_{k+1} = A ξ_k + B w_k`, `y_k = C ξ_k + D̃ w_k`. With
//! `ξ_n = x_n − Γ₁ w_n` (the state less the part the current input puts in it):
//!
//! ```text
//! ξ_n = x_n − Γ₁ w_n = Φ x_{n−1} + Γ₀ w_{n−1}
//!     = Φ (ξ_{n−1} + Γ₁ w_{n−1}) + Γ₀ w_{n−1} = Φ ξ_{n−1} + (Φ Γ₁ + Γ₀) w_{n−1}
//! y_n = H (ξ_n + Γ₁ w_n) + D w_n = H ξ_n + (H Γ₁ + D) w_n
//! ```
//!
//! so `A = Φ`, `B = Φ Γ₁ + Γ₀`, `C = H`, `D̃ = H Γ₁ + D`: the standard form, exactly (no
//! approximation; `tests/estimation.rs` drives it with a known force and reproduces the
//! AEM stepper to rounding). The physical state is `x_n = ξ_n + Γ₁ w_n`, so every
//! estimator here returns `x̂_n = ξ̂_n + Γ₁ ŵ_n`, and drifts, velocities or accelerations
//! are read from `(x̂_n, ŵ_n)` with a [`Readout`](crate::observer::Readout) as for the
//! observers.
//!
//! A consequence of the two-ended input: `D̃` is not zero even for displacement or
//! velocity sensors (`H Γ₁ = β h² …`, `γ h …` of the Newmark corrector), so the filter
//! "with direct feedthrough" applies to every sensor set of a full model, and the
//! no-feedthrough variant (first Markov parameter `C B`) is not needed for these models.
//!
//! # Identifiability
//!
//! The input is identifiable (an unbiased estimator with a stable steady state exists)
//! when ([`InputModel::from_parts`] checks the first two, [`InputStateGains::solve`] the
//! third):
//!
//! 1. `O ≥ I`: at least as many sensors as unknown inputs;
//! 2. `D̃` has full column rank, judged on the noise-weighted Gram matrix
//!    `F₀ = D̃ᵀ R⁻¹ D̃`: each Cholesky pivot of `F₀` is at least
//!    [`RANK_TOLERANCE`]` · (F₀)_ii` (the `i`-th whitened column keeps at least `1e-5` of
//!    its length outside the span of the previous ones; invariant under the units of each
//!    input);
//! 3. every invariant zero of `(A, B, C, D̃)` lies strictly inside the unit circle. With
//!    `M₀ = F₀⁻¹ D̃ᵀ R⁻¹` the zeros are the modes of `Ā = A − B M₀ C` that the reduced
//!    output `C_r = Nᵀ C` (`Nᵀ D̃ = 0`) does not see — all eigenvalues of `Ā` when
//!    `O = I`. The test does not compute eigenvalues: the filter's steady-state
//!    covariance solves a Riccati equation in `(Ā, C_r)` ([`InputStateGains`]), which has a
//!    stabilizing solution only if those modes are inside the circle, and the steady
//!    filter's error dynamics `E = A − A K (I − D̃ M) C − B M C` keep them as
//!    eigenvalues. `E`, balanced by powers of two, must reach `‖E^(2^k)‖∞ ≤ 2^-26` within
//!    [`ZERO_SQUARINGS`] squarings, which certifies a spectral radius `≤ 2^(−26/2^24) ≈
//!    1 − 1.07e-6`: a zero within about `1e-6` of the unit circle counts as on it (a
//!    double zero at `z = 1` is moved by rounding by about `√ε ≈ 1.5e-8`, well inside this
//!    margin).
//!
//! Acceleration-only sensing of a structure has a double zero at `z = 1` (a constant force
//! and its static displacement give no acceleration: the drift of acceleration-only
//! estimation), displacement-only sensing with the AEM a double zero at `z = −1` (the
//! trapezoidal rule cannot see an input alternating at the Nyquist frequency); the two
//! together have none. `tests/estimation.rs` checks both on an oscillator (closed form) and
//! on the 5-storey building; `tests/identifiability.rs` checks the decision for every set
//! of one to three acceleration and displacement sensors of the building against invariant
//! zeros it computes itself (by SVD and Schur, none of this code), under process noises
//! eight decades apart (the decision is the model's, not the tuning's).
//!
//! # The joint input–state filter (Gillijns & De Moor 2007)
//!
//! On the standard form `ξ_n = A ξ_{n−1} + B w_{n−1} + q`, `y_n = C ξ_n + D̃ w_n + r`
//! ([`InputModel`]), `E q qᵀ = Q`, `E r rᵀ = R`, one step is
//!
//! ```text
//! ξ⁻ = A ξ̂_{n−1} + B ŵ_{n−1}              P⁻ = [A B] [P, Pˣʷ; Pʷˣ, Pʷ]_{n−1} [A B]ᵀ + Q
//! R̃ = C P⁻ Cᵀ + R                           Pʷ = (D̃ᵀ R̃⁻¹ D̃)⁻¹,   M = Pʷ D̃ᵀ R̃⁻¹
//! ŵ_n = M (y_n − C ξ⁻)                      K = P⁻ Cᵀ R̃⁻¹
//! ξ̂_n = ξ⁻ + K (y_n − C ξ⁻ − D̃ ŵ_n)        P = P⁻ − K (R̃ − D̃ Pʷ D̃ᵀ) Kᵀ,  Pˣʷ = −K D̃ Pʷ
//! ```
//!
//! ## Steady state
//!
//! With the fixed left inverse `M₀ = F₀⁻¹ D̃ᵀ R⁻¹`, `F₀ = D̃ᵀ R⁻¹ D̃`, and `N` a basis of
//! the left null space of `D̃`: `R̃⁻¹ (I − D̃ M) = N (Nᵀ R̃ N)⁻¹ Nᵀ`, and `M` is the unique
//! `X` with `X D̃ = I`, `X R̃ N = 0`, so `M = M₀ − M₀ R̃ N (Nᵀ R̃ N)⁻¹ Nᵀ`. The a-priori
//! error then obeys `e⁻_{n+1} = (Ā − 𝒦 C_r) e⁻_n + …` with `Ā = A − B M₀ C`,
//! `C_r = Nᵀ C` and the filter's gain `𝒦 = Ā P⁻ C_rᵀ (C_r P⁻ C_rᵀ + Nᵀ R N)⁻¹` — exactly
//! the Kalman predictor's gain of that pair — and its covariance the Riccati difference
//! equation of the Kalman
//! predictor of `(Ā, C_r)` with process noise `Q̄ = Q + B F₀⁻¹ Bᵀ` and measurement noise
//! `Nᵀ R N` (the cross covariance `−B M₀ R N` is zero since `M₀ R N = 0`). Its information
//! matrix `C_rᵀ (Nᵀ R N)⁻¹ C_r = Cᵀ Π₀ C`, `Π₀ = R⁻¹ − R⁻¹ D̃ F₀⁻¹ D̃ᵀ R⁻¹`, needs no `N`.
//! [`InputStateGains::solve`] solves this algebraic Riccati equation by the same doubling
//! algorithm as [`SteadyState`](crate::observer::SteadyState) and forms `K`, `M`, `Pʷ`
//! from its `P⁻` with the step's equations above. `tests/estimation.rs` checks them
//! against the limit of the paper's time-varying recursion.
//!
//! ## Noise that reaches the sensors
//!
//! Unmodelled floor forces as process noise on `ξ` also reach the accelerometers (noise
//! model: [`observer`](crate::observer), "Noise that reaches the sensors"). With
//! `ξ = x − Γ₁ w` of the *estimated* input the forces' noise enters `ξ_n` exactly as it
//! enters `x_n`, so the same `N = E q_n r_nᵀ` applies ([`InputStateGains::solve_cross`],
//! [`InputStateFilter::with_cross`], [`augmented::AugmentedModel::from_parts_cross`] with
//! `[N; 0]`). In the step only `R̃ = C P⁻ Cᵀ + R + C N + Nᵀ Cᵀ` and
//! `K = (P⁻ Cᵀ + N) R̃⁻¹` change (the unbiased minimum-variance derivation goes through
//! with `Cov(e⁻, C e⁻ + r) = P⁻ Cᵀ + N`; `P`, `Pˣʷ`, `Pʷ`, `M` keep their form). The
//! steady state: the a-priori error obeys
//! `e⁻_{n+1} = Ā e⁻_n − B M₀ r_n + q_{n+1} − 𝒦 z_n`, `z_n = Vᵀ (C e⁻_n + r_n)` (`V` the
//! left null basis of `D̃`), with `e⁻_n` correlated with `r_n` through `N`. Writing
//! `P⁻ = Y + Q` turns it into the Kalman core's predictor form on `(Ā, C)`:
//! `Q_y = Ā Q Āᵀ + B F₀⁻¹ Bᵀ − Ā N M₀ᵀ Bᵀ − B M₀ Nᵀ Āᵀ`,
//! `S_y = Ā (Q Cᵀ + N) − B M₀ Nᵀ Cᵀ` and the weight
//! `Π₁ = V (Vᵀ R₁ V)⁻¹ Vᵀ = R₁⁻¹ − R₁⁻¹ D̃ (D̃ᵀ R₁⁻¹ D̃)⁻¹ D̃ᵀ R₁⁻¹`,
//! `R₁ = C Q Cᵀ + R + C N + Nᵀ Cᵀ`, solved by the same doubling. `tests/cross_covariance.rs`
//! checks it against the paper's recursion with the cross term written in the test, and the
//! residual's `χ²_{O−I}` mean by simulation. (The dual filter does not take `N`.)

/// The accessors the joint input–state estimators share (each keeps `gamma1: [[T; I]; S]`
/// and, the fixed-gain ones, `time_step: T`): for a fixed-gain estimator on
/// [`JointEstimate`] (`fixed`) the time step, the start and the physical state; for a
/// time-varying one (`varying`, with its state type) the physical state.
macro_rules! joint_accessors {
    (fixed $ty:ident) => {
        impl<T: $crate::Real, const S: usize, const I: usize, const O: usize> $ty<T, S, I, O> {
            /// The time step `h` (s).
            pub fn time_step(&self) -> T {
                self.time_step
            }

            /// The start from a physical state `x0` and input `w0`: `ξ̂_0 = x0 − Γ₁ w0`,
            /// `ŵ_0 = w0`. Errors: [`Error::NonFiniteInput`](crate::Error::NonFiniteInput).
            /// Cost: `S·I` multiply-adds.
            pub fn start(
                &self,
                x0: &nalgebra::SVector<T, S>,
                w0: &nalgebra::SVector<T, I>,
            ) -> Result<$crate::estimation::JointEstimate<T, S, I>, $crate::Error> {
                $crate::estimation::joint::joint_start(&self.gamma1, x0, w0)
            }

            /// The physical state estimate `x̂_n = ξ̂_n + Γ₁ ŵ_n` (`[u; v]` for a full model:
            /// read drifts etc. from `(x̂_n, ŵ_n)` with a
            /// [`Readout`](crate::observer::Readout)). Cost: `S·I` multiply-adds.
            pub fn state(
                &self,
                e: &$crate::estimation::JointEstimate<T, S, I>,
            ) -> nalgebra::SVector<T, S> {
                $crate::estimation::joint::shift(&self.gamma1, &e.xi, &e.w, T::one())
            }
        }
    };
    (varying $ty:ident, $state:ident) => {
        impl<T: $crate::Real, const S: usize, const I: usize, const O: usize> $ty<T, S, I, O> {
            /// The physical state estimate `x̂_n = ξ̂_n + Γ₁ ŵ_n`. Cost: `S·I` multiply-adds.
            pub fn state(&self, s: &$state<T, S, I, O>) -> nalgebra::SVector<T, S> {
                let e = &s.estimate;
                $crate::estimation::joint::shift(&self.gamma1, &e.xi, &e.w, T::one())
            }
        }
    };
}

pub mod augmented;
pub mod dual;
mod joint;
pub mod smoother;

pub use dual::{DualFilter, DualGains, DualKalmanFilter, DualKalmanFilterState};
pub use joint::{InputStateFilter, InputStateFilterState, InputStateGains, InputStateObserver};
pub use joint::{JointEstimate, STEADY_MAX_ITERATIONS, ZERO_SQUARINGS};

use nalgebra::{SMatrix, SVector};

use crate::Error;
use crate::linalg::cholesky::cholesky;
use crate::linalg::{Mat, add_scaled, all_finite, finite_as, mul, transpose};
use crate::observer::{Measurement, StateSpace, is_covariance, lu_of, symmetrize};

/// A model in the standard form of the input–state filters (derivation in the
/// [module docs](self)): `ξ_{n} = A ξ_{n−1} + B w_{n−1}`, `y_n = C ξ_n + D̃ w_n`, with
/// `ξ = x − Γ₁ w`, `S` states, `I` unknown inputs, `O` measurements; `f64`, row-major.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InputModel<const S: usize, const I: usize, const O: usize> {
    /// `A = Φ` (`S×S`).
    pub a: [[f64; S]; S],
    /// `B = Φ Γ₁ + Γ₀` (`S×I`).
    pub b: [[f64; I]; S],
    /// `C = H` (`O×S`).
    pub c: [[f64; S]; O],
    /// `D̃ = H Γ₁ + D` (`O×I`).
    pub d: [[f64; I]; O],
    /// `Γ₁` (`S×I`): the physical state is `x = ξ + Γ₁ w`.
    pub gamma1: [[f64; I]; S],
    /// The time step `h` (s).
    pub time_step: f64,
}

/// Relative pivot tolerance of the rank test of `D̃` (see the [module docs](self)):
/// `1e-10` of the Gram matrix's diagonal, i.e. a relative component of `1e-5` of a whitened
/// column outside the span of the others.
pub const RANK_TOLERANCE: f64 = 1e-10;

impl<const S: usize, const I: usize, const O: usize> InputModel<S, I, O> {
    /// Every matrix finite: the estimators' first check of a model (which may have been
    /// built or edited by hand). Errors: [`Error::NonFiniteInput`].
    pub(crate) const fn check_finite(&self) -> Result<(), Error> {
        if all_finite(&self.a)
            && all_finite(&self.b)
            && all_finite(&self.c)
            && all_finite(&self.d)
            && all_finite(&self.gamma1)
        {
            Ok(())
        } else {
            Err(Error::NonFiniteInput)
        }
    }

    /// Every matrix rounds to a finite value of the scalar type whose largest finite value
    /// is `max`.
    pub(crate) const fn fits(&self, max: f64) -> bool {
        finite_as(&self.a, max)
            && finite_as(&self.b, max)
            && finite_as(&self.c, max)
            && finite_as(&self.d, max)
            && finite_as(&self.gamma1, max)
    }

    /// The checks of a fixed-gain estimator on this model (`const fn`, the run-time
    /// constructors and the `const fn` twins alike): the model, the state gain `gx`
    /// (`S×O`) and the input gain `gw` (`I×O`) finite, the time step a valid one of the
    /// scalar type whose largest finite value is `max`, and the model, `stored` (the
    /// state gain as the estimator keeps it: `gx` itself, or the joint filter's
    /// `L = K (I − D̃ M)`) and `gw` fitting that type.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`],
    /// [`Error::OperatorOverflow`]. Cost: `O(S² + S·O)` comparisons.
    pub(crate) const fn check_fixed_gains(
        &self,
        gx: &Mat<S, O>,
        stored: &Mat<S, O>,
        gw: &Mat<I, O>,
        max: f64,
    ) -> Result<(), Error> {
        if let Err(e) = self.check_finite() {
            return Err(e);
        }
        if !(all_finite(gx) && all_finite(gw)) {
            return Err(Error::NonFiniteInput);
        }
        if let Err(e) = crate::kinematics::check_time_step_as(self.time_step, max) {
            return Err(e);
        }
        if !(self.fits(max) && finite_as(stored, max) && finite_as(gw, max)) {
            return Err(Error::OperatorOverflow);
        }
        Ok(())
    }

    /// The standard form of `model` measured by `meas` (`const fn`): `A = Φ`,
    /// `B = Φ Γ₁ + Γ₀`, `C = H`, `D̃ = H Γ₁ + D`. Checks the first identifiability
    /// condition, `O ≥ I`.
    ///
    /// Errors: [`Error::NonFiniteInput`] (a non-finite matrix),
    /// [`Error::InputNotIdentifiable`] (`O < I`), [`Error::OperatorOverflow`] (`B` or `D̃`
    /// not finite). Cost: `S²·I + O·S·I` flops.
    pub const fn from_parts<const N: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
    ) -> Result<Self, Error> {
        if !(all_finite(&model.phi)
            && all_finite(&model.gamma0)
            && all_finite(&model.gamma1)
            && all_finite(&meas.h)
            && all_finite(&meas.d))
        {
            return Err(Error::NonFiniteInput);
        }
        if O < I {
            return Err(Error::InputNotIdentifiable);
        }
        let b = add_scaled(&model.gamma0, 1.0, &mul(&model.phi, &model.gamma1));
        let d = add_scaled(&meas.d, 1.0, &mul(&meas.h, &model.gamma1));
        if !(all_finite(&b) && all_finite(&d)) {
            return Err(Error::OperatorOverflow);
        }
        Ok(Self {
            a: model.phi,
            b,
            c: meas.h,
            d,
            gamma1: model.gamma1,
            time_step: model.time_step,
        })
    }

    /// The noise-weighted Gram matrix `F₀ = D̃ᵀ R⁻¹ D̃` (`I×I`) and `R⁻¹ D̃` (`O×I`), after
    /// checking `r` (symmetric positive definite) and the rank of `D̃` (second
    /// identifiability condition).
    pub(crate) const fn weighted_feedthrough(
        &self,
        r: &Mat<O, O>,
    ) -> Result<(Mat<I, I>, Mat<O, I>), Error> {
        if !is_covariance(r, true) {
            return Err(Error::InvalidCovariance);
        }
        let lu_r = match lu_of(r) {
            Some(lu) => lu,
            None => return Err(Error::InvalidCovariance),
        };
        let rd = lu_r.solve(&self.d);
        let f0 = symmetrize(&mul(&transpose(&self.d), &rd));
        if !(all_finite(&f0) && all_finite(&rd)) {
            return Err(Error::OperatorOverflow);
        }
        if !full_rank(&f0) {
            return Err(Error::InputNotIdentifiable);
        }
        Ok((f0, rd))
    }

    /// The zero dynamics `Ā = A − B M₀ C`, `M₀ = (D̃ᵀ R⁻¹ D̃)⁻¹ D̃ᵀ R⁻¹` (`S×S`): its
    /// eigenvalues that the reduced output `C_r` does not see are the invariant zeros of
    /// the model (all of its eigenvalues when `O = I`, where `Ā = A − B D̃⁻¹ C` and `R`
    /// does not matter). For inspection; the filters test the zeros through their steady
    /// state ([module docs](self)).
    ///
    /// Errors: [`Error::InvalidCovariance`] (`r`), [`Error::InputNotIdentifiable`] (the
    /// rank of `D̃`), [`Error::OperatorOverflow`] (`Ā` not finite). Cost: `O(S²·O + O³)`
    /// flops.
    pub fn zero_dynamics(&self, r: &SMatrix<f64, O, O>) -> Result<SMatrix<f64, S, S>, Error> {
        let rr: Mat<O, O> = core::array::from_fn(|i| core::array::from_fn(|j| r[(i, j)]));
        let (f0, rd) = self.weighted_feedthrough(&rr)?;
        let m0 = match lu_of(&f0) {
            Some(lu) => lu.solve(&transpose(&rd)),
            None => return Err(Error::InputNotIdentifiable),
        };
        let abar = add_scaled(&self.a, -1.0, &mul(&self.b, &mul(&m0, &self.c)));
        if !all_finite(&abar) {
            return Err(Error::OperatorOverflow);
        }
        Ok(SMatrix::from_fn(|i, j| abar[i][j]))
    }

    /// The physical state `x = ξ + Γ₁ w` (`f64`). Cost: `S·I` flops.
    pub fn physical_state(&self, xi: &SVector<f64, S>, w: &SVector<f64, I>) -> SVector<f64, S> {
        SVector::from_fn(|i, _| {
            let mut s = xi[i];
            for j in 0..I {
                s += self.gamma1[i][j] * w[j];
            }
            s
        })
    }

    /// `ξ = x − Γ₁ w` of a physical state (`f64`). Cost: `S·I` flops.
    pub fn xi_of(&self, x: &SVector<f64, S>, w: &SVector<f64, I>) -> SVector<f64, S> {
        SVector::from_fn(|i, _| {
            let mut s = x[i];
            for j in 0..I {
                s -= self.gamma1[i][j] * w[j];
            }
            s
        })
    }

    /// `A` as a `nalgebra` matrix.
    pub fn a_matrix(&self) -> SMatrix<f64, S, S> {
        crate::linalg::matrix_t(&self.a)
    }
    /// `B` as a `nalgebra` matrix.
    pub fn b_matrix(&self) -> SMatrix<f64, S, I> {
        crate::linalg::matrix_t(&self.b)
    }
    /// `C` as a `nalgebra` matrix.
    pub fn c_matrix(&self) -> SMatrix<f64, O, S> {
        crate::linalg::matrix_t(&self.c)
    }
    /// `D̃` as a `nalgebra` matrix.
    pub fn d_matrix(&self) -> SMatrix<f64, O, I> {
        crate::linalg::matrix_t(&self.d)
    }
}

/// `f` (symmetric, `I×I`) has every Cholesky pivot at least `RANK_TOLERANCE` of its diagonal
/// entry (and positive).
const fn full_rank<const I: usize>(f: &Mat<I, I>) -> bool {
    let l = match cholesky(f) {
        Some(l) => l,
        None => return false,
    };
    let mut i = 0;
    while i < I {
        if !(f[i][i] > 0.0 && l[i][i] * l[i][i] >= RANK_TOLERANCE * f[i][i]) {
            return false;
        }
        i += 1;
    }
    true
}

/// The fixture of the estimators' unit tests: the 5-storey building (AEM, `h = 0.02` s)
/// with an unknown force at the roof, the roof's absolute acceleration and displacement
/// measured.
#[cfg(test)]
fn roof_force_fixture() -> InputModel<10, 1, 2> {
    use crate::observer::Outputs;
    let (m, c, k) = crate::models::five_storey_building();
    let roof = [[0.0], [0.0], [0.0], [0.0], [1.0]];
    let ss = StateSpace::<5, 10, 1>::from_rows_aem(m, c, k, roof, 0.02).unwrap();
    let mut out = Outputs::<5, 1, 2>::zero();
    out.a[0][4] = 1.0;
    out.u[1][4] = 1.0;
    InputModel::from_parts(&ss, &ss.outputs(&out).unwrap()).unwrap()
}
