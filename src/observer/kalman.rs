//! The full Kalman filter: the estimate and its covariance propagated every step (Joseph
//! form), for the host and for small firmware models.

use nalgebra::{SMatrix, SVector};

use super::fixed::{Estimate, initial_estimate};
use super::riccati::is_covariance;
use super::state_space::{Measurement, StateSpace};
use crate::linalg::{all_finite, finite_as, matrix_t, rows_f64, sym};
use crate::{Error, Real};

/// The state of a [`Kalman`] filter: the [`Estimate`] and its a-posteriori error
/// covariance `P` (`S×S`, units of `x` squared). Plain data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KalmanState<T, const S: usize, const I: usize> {
    estimate: Estimate<T, S, I>,
    p: SMatrix<T, S, S>,
}

impl<T: Real, const S: usize, const I: usize> KalmanState<T, S, I> {
    /// The estimate `x̂_n`, the last input, steps and missing measurements.
    pub fn estimate(&self) -> &Estimate<T, S, I> {
        &self.estimate
    }
    /// The a-posteriori error covariance `P_n = E (x − x̂)(x − x̂)ᵀ`.
    pub fn covariance(&self) -> &SMatrix<T, S, S> {
        &self.p
    }
}

/// A Kalman filter on a discrete linear model ([`StateSpace`]) with process noise `Q`
/// and measurement noise `R`:
///
/// ```text
/// x̂⁻ = Φ x̂ + Γ₀ w_{n−1} + Γ₁ w_n           P⁻ = Φ P Φᵀ + Q
/// K = P⁻ Hᵀ (H P⁻ Hᵀ + R)⁻¹                 x̂ = x̂⁻ + K (y − H x̂⁻ − D w)
/// P = (I − K H) P⁻ (I − K H)ᵀ + K R Kᵀ      (Joseph form: symmetric, positive)
/// ```
///
/// `P⁻` converges to the Riccati solution ([`SteadyState`](super::SteadyState)) and `K`
/// to its gain. A measurement with a non-finite entry is missing: predict only (counted).
/// Only a checked step ([`Kalman::try_step`]): the innovation covariance can lose
/// definiteness in `f32`, and a failed step changes nothing.
///
/// Cost of a step: about `3S³ + 3S²·O + 2S·O² + O³/6` multiply-adds (`≈ 3 900` for
/// `S = 10`, `O = 2`): for the host and small firmware models; on a microcontroller the
/// [`Observer`](super::Observer) with the steady-state gain costs `S²`. Size:
/// `S² + 2S·I + O·(S + I) + O²` values of `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kalman<T, const S: usize, const I: usize, const O: usize> {
    phi: SMatrix<T, S, S>,
    gamma0: SMatrix<T, S, I>,
    gamma1: SMatrix<T, S, I>,
    h: SMatrix<T, O, S>,
    d: SMatrix<T, O, I>,
    q: SMatrix<T, S, S>,
    r: SMatrix<T, O, O>,
}

impl<T: Real, const S: usize, const I: usize, const O: usize> Kalman<T, S, I, O> {
    /// The filter of `model` measuring `meas`, process noise `q` (`S×S`, symmetric
    /// positive semidefinite), measurement noise `r` (`O×O`, symmetric positive
    /// definite), in `f64`, rounded once to `T`.
    ///
    /// Errors: [`Error::InvalidCovariance`], [`Error::NonFiniteInput`] (output matrices),
    /// [`Error::OperatorOverflow`]. Cost: `O(S³)` (the covariance checks).
    pub fn new<const N: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
    ) -> Result<Self, Error> {
        let (qr, rr) = (rows_f64(q), rows_f64(r));
        if !(is_covariance(&qr, false) && is_covariance(&rr, true)) {
            return Err(Error::InvalidCovariance);
        }
        if !(all_finite(&meas.h) && all_finite(&meas.d)) {
            return Err(Error::NonFiniteInput);
        }
        let fits = finite_as(&model.phi, T::MAX)
            && finite_as(&model.gamma0, T::MAX)
            && finite_as(&model.gamma1, T::MAX)
            && finite_as(&meas.h, T::MAX)
            && finite_as(&meas.d, T::MAX)
            && finite_as(&qr, T::MAX)
            && finite_as(&rr, T::MAX);
        if !fits {
            return Err(Error::OperatorOverflow);
        }
        Ok(Self {
            phi: matrix_t(&model.phi),
            gamma0: matrix_t(&model.gamma0),
            gamma1: matrix_t(&model.gamma1),
            h: matrix_t(&meas.h),
            d: matrix_t(&meas.d),
            q: matrix_t(&qr),
            r: matrix_t(&rr),
        })
    }

    /// The filter at `t = 0`: estimate `x0`, its covariance `p0` (symmetric positive
    /// semidefinite), input `w0`.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::InvalidCovariance`]. Cost: `O(S³)`.
    pub fn start(
        &self,
        x0: &SVector<T, S>,
        p0: &SMatrix<T, S, S>,
        w0: &SVector<T, I>,
    ) -> Result<KalmanState<T, S, I>, Error> {
        let estimate = initial_estimate(x0, w0)?;
        let pr: [[f64; S]; S] = rows_f64(p0);
        if !is_covariance(&pr, false) {
            return Err(Error::InvalidCovariance);
        }
        Ok(KalmanState { estimate, p: *p0 })
    }

    /// The a-priori covariance of the next step, `P⁻ = Φ P Φᵀ + Q` (what converges to
    /// the Riccati solution). Cost: `2S³`.
    pub fn predicted_covariance(&self, s: &KalmanState<T, S, I>) -> SMatrix<T, S, S> {
        sym(&(self.phi * s.p * self.phi.transpose() + self.q))
    }

    /// One filter step with input `w` (`w_n`) and measurement `y` (a non-finite entry:
    /// missing, predict only, counted in [`Estimate::missing`]).
    ///
    /// Errors, `s` unchanged: [`Error::NonFiniteInput`] (`w` not finite),
    /// [`Error::InvalidCovariance`] (the innovation covariance `H P⁻ Hᵀ + R` is not
    /// positive definite to working precision), [`Error::NonFiniteState`]. No allocation,
    /// no panic; cost in the type docs.
    pub fn try_step(
        &self,
        s: &mut KalmanState<T, S, I>,
        w: &SVector<T, I>,
        y: &SVector<T, O>,
    ) -> Result<(), Error> {
        self.try_step_innovation(s, w, y).map(|_| ())
    }

    /// [`Kalman::try_step`], returning this step's innovation `ν = y − H x̂⁻ − D w`
    /// (output units; non-finite where `y` is missing) and its covariance
    /// `H P⁻ Hᵀ + R` (`ν ~ N(0, ·)` under the model) — what a change detector tests
    /// ([`detection`](crate::detection)). Errors and cost: as [`Kalman::try_step`]
    /// (plus `S²·O` for the covariance of a missing sample).
    pub fn try_step_innovation(
        &self,
        s: &mut KalmanState<T, S, I>,
        w: &SVector<T, I>,
        y: &SVector<T, O>,
    ) -> Result<(SVector<T, O>, SMatrix<T, O, O>), Error> {
        if !w.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        let e = &s.estimate;
        let xp = self.phi * e.x + self.gamma0 * e.w + self.gamma1 * w;
        let pm = self.predicted_covariance(s);
        let mut next = *s;
        let hp = self.h * pm;
        let si = hp * self.h.transpose() + self.r;
        let si = (si + si.transpose()) * T::from_f64_rounded(0.5);
        let innov = y - self.h * xp - self.d * w;
        if y.iter().all(|v| v.is_finite()) {
            let chol = si.cholesky().ok_or(Error::InvalidCovariance)?;
            // Kᵀ = (H P⁻ Hᵀ + R)⁻¹ H P⁻.
            let k = chol.solve(&hp).transpose();
            let ikh = SMatrix::<T, S, S>::identity() - k * self.h;
            next.estimate.x = xp + k * innov;
            next.p = sym(&(ikh * pm * ikh.transpose() + k * self.r * k.transpose()));
        } else {
            next.estimate.x = xp;
            next.p = pm;
            next.estimate.missing = next.estimate.missing.wrapping_add(1);
        }
        next.estimate.w = *w;
        next.estimate.n = next.estimate.n.wrapping_add(1);
        let finite = next
            .estimate
            .x
            .iter()
            .chain(next.p.iter())
            .all(|v| v.is_finite());
        if !finite {
            return Err(Error::NonFiniteState);
        }
        *s = next;
        Ok((innov, si))
    }
}
