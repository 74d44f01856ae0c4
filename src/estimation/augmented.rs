//! The augmented Kalman filter (Lourens et al. 2012): the unknown input joins the state
//! as a random walk.
//!
//! On the standard form of [`InputModel`] (`ξ_n = A ξ_{n−1} + B w_{n−1}`,
//! `y_n = C ξ_n + D̃ w_n`), the state `z = [ξ; w]` (`Z = S + I` values) with the force
//! model `w_n = w_{n−1} + η_n`, `E η ηᵀ = Q_w`:
//!
//! ```text
//! z_n = [A B; 0 I] z_{n−1} + [q; η]        y_n = [C D̃] z_n + r
//! ```
//!
//! is an ordinary linear model: [`AugmentedModel`] builds it as a
//! [`StateSpace`] with no known input (`I = 0`) and a [`Measurement`], so the crate's
//! [`SteadyState`] (the Riccati gain, `const fn`), [`Observer`](crate::observer::Observer)
//! (fixed gain, `f32`/`f64`, `S² + 2S·O` multiply-adds a step on the augmented size) and
//! [`Kalman`](crate::observer::Kalman) (covariance propagated) run it unchanged. The
//! estimate `z` splits into `x̂ = ξ̂ + Γ₁ ŵ` and `ŵ` ([`AugmentedModel::split`]).
//!
//! The random walk's eigenvalue `1` must be seen by the sensors: with acceleration-only
//! sensing the static force–displacement pair is invisible (an invariant zero at `z = 1`),
//! the augmented pair is not detectable and there is no steady state: the time-varying
//! filter drifts, and [`AugmentedModel::steady_state`] returns
//! [`Error::InputNotIdentifiable`]. One displacement (or strain) measurement removes it.

use nalgebra::SVector;

use super::InputModel;
use crate::linalg::{Mat, all_finite, identity, put};
use crate::observer::bare_model;
use crate::observer::{Measurement, StateSpace, SteadyState, is_covariance};
use crate::{Error, Real};

/// The augmented model of an [`InputModel`] with `S` states and `I` inputs: `Z = S + I`
/// states (checked: [`Error::StateSizeMismatch`]), `O` measurements; `f64`, row-major.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AugmentedModel<const S: usize, const I: usize, const Z: usize, const O: usize> {
    /// `[A B; 0 I]` as a model with no known input (`Γ₀ = Γ₁ = 0`, no output maps: use
    /// the measurement).
    pub model: StateSpace<0, Z, 0>,
    /// `[C D̃]` (`D = 0`).
    pub measurement: Measurement<Z, 0, O>,
    /// `diag(Q, Q_w)` (`Z×Z`).
    pub process_noise: [[f64; Z]; Z],
    /// `[N; 0]` (`Z×O`): the cross covariance of the process noise with the measurement
    /// noise (zero from [`AugmentedModel::from_parts`]; [`AugmentedModel::from_parts_cross`]).
    pub cross_noise: [[f64; O]; Z],
    /// `Γ₁` of the physical state `x = ξ + Γ₁ w`.
    pub gamma1: [[f64; I]; S],
}

impl<const S: usize, const I: usize, const Z: usize, const O: usize> AugmentedModel<S, I, Z, O> {
    /// The augmented model of `m` with process noise `q` on `ξ` (`S×S`, symmetric positive
    /// semidefinite) and the random walk's covariance `qw` (`I×I`, input units squared per
    /// step; it sets how fast the force estimate may move). `const fn`.
    ///
    /// Errors: [`Error::StateSizeMismatch`] (`Z ≠ S + I`), [`Error::InvalidCovariance`],
    /// [`Error::NonFiniteInput`] (a non-finite `A`, `B`, `C`, `D̃` or `Γ₁`). Cost: `O(Z²)`.
    pub const fn from_parts(
        m: &InputModel<S, I, O>,
        q: &[[f64; S]; S],
        qw: &[[f64; I]; I],
    ) -> Result<Self, Error> {
        Self::from_parts_cross(m, q, qw, &[[0.0; O]; S])
    }

    /// [`AugmentedModel::from_parts`] with a cross covariance `n = E q_n r_nᵀ` (`S×O`) of
    /// the process noise on `ξ` with the measurement noise (unmodelled forces that also
    /// reach the sensors, [`StateSpace::input_cross_noise`]; the random walk's noise is
    /// taken independent of the sensors'): the augmented model's is `[N; 0]`, which
    /// [`AugmentedModel::steady_state`] passes to [`SteadyState::from_parts_cross`].
    /// `n = 0` is [`AugmentedModel::from_parts`]. `const fn`.
    ///
    /// Errors: as [`AugmentedModel::from_parts`] (a non-finite `n`:
    /// [`Error::InvalidCovariance`]; whether `[Q N; Nᵀ R]` is a covariance is checked with
    /// `R` by [`AugmentedModel::steady_state`]). Cost: `O(Z²)`.
    pub const fn from_parts_cross(
        m: &InputModel<S, I, O>,
        q: &[[f64; S]; S],
        qw: &[[f64; I]; I],
        n: &[[f64; O]; S],
    ) -> Result<Self, Error> {
        if Z != S + I {
            return Err(Error::StateSizeMismatch);
        }
        if !(is_covariance(q, false) && is_covariance(qw, false) && all_finite(n)) {
            return Err(Error::InvalidCovariance);
        }
        // Γ₁ too: `split` forms x̂ = ξ̂ + Γ₁ ŵ from it (a NaN there gave NaN states).
        if let Err(e) = m.check_finite() {
            return Err(e);
        }
        let mut phi: Mat<Z, Z> = [[0.0; Z]; Z];
        put(&mut phi, &m.a, 0, 0);
        put(&mut phi, &m.b, 0, S);
        put(&mut phi, &identity::<I>(), S, S);
        let mut pn: Mat<Z, Z> = [[0.0; Z]; Z];
        put(&mut pn, q, 0, 0);
        put(&mut pn, qw, S, S);
        let mut cross: Mat<Z, O> = [[0.0; O]; Z];
        put(&mut cross, n, 0, 0);
        let mut h: Mat<O, Z> = [[0.0; Z]; O];
        put(&mut h, &m.c, 0, 0);
        put(&mut h, &m.d, 0, S);
        let (model, measurement) = bare_model(phi, h, m.time_step);
        Ok(Self {
            model,
            measurement,
            process_noise: pn,
            cross_noise: cross,
            gamma1: m.gamma1,
        })
    }

    /// The steady-state Kalman gain of the augmented model with measurement noise `r`
    /// ([`SteadyState::from_parts_cross`] with [`AugmentedModel::cross_noise`], which is
    /// [`SteadyState::from_parts`] where it is zero; `const fn`), for an
    /// [`Observer`](crate::observer::Observer) on `(self.model, self.measurement)`.
    ///
    /// Errors: [`Error::InputNotIdentifiable`] where the Riccati equation has no
    /// stabilizing solution (the random walk not detectable: an invariant zero at `z = 1`,
    /// acceleration-only sensing), and the other errors of [`SteadyState::from_parts`]
    /// ([`Error::InvalidCovariance`] — also `[Q N; Nᵀ R]` not a covariance —,
    /// [`Error::OperatorOverflow`]).
    ///
    /// Cost: that of [`SteadyState::from_parts`] with `S = Z`.
    pub const fn steady_state(&self, r: &[[f64; O]; O]) -> Result<SteadyState<Z, O>, Error> {
        match SteadyState::from_parts_cross(
            &self.model,
            &self.measurement,
            &self.process_noise,
            r,
            &self.cross_noise,
        ) {
            Ok(s) => Ok(s),
            Err(Error::RiccatiNotConverged) => Err(Error::InputNotIdentifiable),
            Err(e) => Err(e),
        }
    }

    /// The physical state `x̂ = ξ̂ + Γ₁ ŵ` and the input `ŵ` of an augmented estimate
    /// `z = [ξ̂; ŵ]` (`Γ₁` rounded to `T`). Cost: `S·I` multiply-adds.
    pub fn split<T: Real>(&self, z: &SVector<T, Z>) -> (SVector<T, S>, SVector<T, I>) {
        let w = SVector::<T, I>::from_fn(|i, _| z[S + i]);
        let x = SVector::<T, S>::from_fn(|i, _| {
            let mut s = z[i];
            for j in 0..I {
                s += T::from_f64_rounded(self.gamma1[i][j]) * w[j];
            }
            s
        });
        (x, w)
    }
}

#[cfg(test)]
mod tests {
    use super::super::roof_force_fixture;
    use super::*;

    /// Regression: `from_parts` did not check `Γ₁`, and a NaN there gave NaN states from
    /// `split`; it is now refused with a typed error.
    #[test]
    fn augmented_model_refuses_a_non_finite_gamma1() {
        let mut model = roof_force_fixture();
        let q = [[0.0; 10]; 10];
        let qw = [[1.0]];
        assert!(AugmentedModel::<10, 1, 11, 2>::from_parts(&model, &q, &qw).is_ok());
        model.gamma1[3][0] = f64::NAN;
        assert_eq!(
            AugmentedModel::<10, 1, 11, 2>::from_parts(&model, &q, &qw),
            Err(Error::NonFiniteInput)
        );
        model.gamma1[3][0] = f64::INFINITY;
        assert_eq!(
            AugmentedModel::<10, 1, 11, 2>::from_parts(&model, &q, &qw),
            Err(Error::NonFiniteInput)
        );
    }
}
