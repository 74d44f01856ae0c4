//! The full Kalman filter: the estimate and its covariance propagated every step (Joseph
//! form), for the host and for small firmware models.

use nalgebra::{SMatrix, SVector};

use super::fixed::{Estimate, initial_estimate, next_counts};
use super::kalman_core::is_covariance;
use super::kalman_core::{check_start_covariance, checked_cross_t, noise_fits, predict_t};
use super::kalman_flat::{KalmanModel, KalmanWork, kalman_step_flat};
use super::state_space::{Measurement, StateSpace};
use crate::linalg::{Mat, all_finite, finite_as, matrix_t, rows_f64};
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
/// With a process–measurement cross covariance `N = E q_n r_nᵀ` ([`Kalman::with_cross`]:
/// a force noise that also reaches the sensors through the feedthrough) the correction is
/// `K = (P⁻ Hᵀ + N) Σ⁻¹`, `Σ = H P⁻ Hᵀ + R + H N + Nᵀ Hᵀ`, and the Joseph form gains
/// `− (I − K H) N Kᵀ − K Nᵀ (I − K H)ᵀ` ([module docs](super), "Noise that reaches the
/// sensors").
///
/// Cost of a step: about `3S³ + 3S²·O + 2S·O² + O³/6` multiply-adds (`≈ 3 900` for
/// `S = 10`, `O = 2`; `3S²·O` more with `N`): for the host and small firmware models; on a
/// microcontroller the [`Observer`](super::Observer) with the steady-state gain costs
/// `S²`. Size: `S² + 2S·I + O·(S + I) + O² + S·O` values of `T` and a flag.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kalman<T, const S: usize, const I: usize, const O: usize> {
    phi: SMatrix<T, S, S>,
    gamma0: SMatrix<T, S, I>,
    gamma1: SMatrix<T, S, I>,
    h: SMatrix<T, O, S>,
    d: SMatrix<T, O, I>,
    q: SMatrix<T, S, S>,
    r: SMatrix<T, O, O>,
    /// `N`, or `None` when it is zero (the original code path, bit for bit).
    cross: Option<SMatrix<T, S, O>>,
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
        Self::build(model, meas, q, r, &[[0.0; O]; S])
    }

    /// [`Kalman::new`] with a process–measurement cross covariance `n = E q_n r_nᵀ`
    /// (`S×O`, units of `x` times output units; e.g.
    /// [`StateSpace::input_cross_noise`]). `n = 0` is [`Kalman::new`], bit for bit.
    ///
    /// Errors: as [`Kalman::new`]; [`Error::InvalidCovariance`] also when `n` is not
    /// finite or `[q n; nᵀ r]` is not a covariance. Cost: `O(S³)`.
    pub fn with_cross<const N: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
        n: &SMatrix<f64, S, O>,
    ) -> Result<Self, Error> {
        Self::build(model, meas, q, r, &rows_f64(n))
    }

    fn build<const N: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        q: &SMatrix<f64, S, S>,
        r: &SMatrix<f64, O, O>,
        n: &Mat<S, O>,
    ) -> Result<Self, Error> {
        let (qr, rr) = (rows_f64(q), rows_f64(r));
        if !(is_covariance(&qr, false) && is_covariance(&rr, true)) {
            return Err(Error::InvalidCovariance);
        }
        let cross = checked_cross_t(&qr, &rr, n)?;
        if !(all_finite(&meas.h) && all_finite(&meas.d)) {
            return Err(Error::NonFiniteInput);
        }
        let fits = finite_as(&model.phi, T::MAX)
            && finite_as(&model.gamma0, T::MAX)
            && finite_as(&model.gamma1, T::MAX)
            && finite_as(&meas.h, T::MAX)
            && finite_as(&meas.d, T::MAX)
            && noise_fits(&qr, &rr, n, T::MAX);
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
            cross,
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
        check_start_covariance(p0)?;
        Ok(KalmanState { estimate, p: *p0 })
    }

    /// The model as the flat step's slices.
    fn flat(&self) -> KalmanModel<'_, T> {
        KalmanModel {
            phi: self.phi.as_slice(),
            gamma: [self.gamma0.as_slice(), self.gamma1.as_slice()],
            h: self.h.as_slice(),
            d: self.d.as_slice(),
            q: self.q.as_slice(),
            r: self.r.as_slice(),
            cross: self.cross.as_ref().map(|n| n.as_slice()),
            dims: [S, I, O],
        }
    }

    /// The a-priori covariance of the next step, `P⁻ = Φ P Φᵀ + Q` (what converges to
    /// the Riccati solution). Cost: `2S³`.
    pub fn predicted_covariance(&self, s: &KalmanState<T, S, I>) -> SMatrix<T, S, S> {
        predict_t(&self.phi, &s.p, &self.q)
    }

    /// One filter step with input `w` (`w_n`) and measurement `y` (a non-finite entry:
    /// missing, predict only, counted in [`Estimate::missing`]).
    ///
    /// Errors, `s` unchanged: [`Error::NonFiniteInput`] (`w` not finite),
    /// [`Error::InvalidCovariance`] (the innovation covariance `H P⁻ Hᵀ + R` is not
    /// positive definite to working precision), [`Error::NonFiniteState`],
    /// [`Error::StepCountOverflow`] (the step count, or the count of missing samples,
    /// would pass `u64::MAX`). No allocation, no panic; cost in the type docs.
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
    /// `H P⁻ Hᵀ + R` (`+ H N + Nᵀ Hᵀ` with a cross covariance; `ν ~ N(0, ·)` under the
    /// model) — what a change detector tests
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
        let z = SMatrix::<T, S, S>::zeros;
        let (mut pm, mut ikh, mut ss) = (z(), z(), z());
        let mut so = SMatrix::<T, S, O>::zeros();
        let mut xt = SMatrix::<T, O, S>::zeros();
        let (mut si, mut oo) = (SMatrix::<T, O, O>::zeros(), SMatrix::<T, O, O>::zeros());
        let (mut xp, mut vs) = (SVector::<T, S>::zeros(), SVector::<T, S>::zeros());
        let (mut innov, mut vo) = (SVector::<T, O>::zeros(), SVector::<T, O>::zeros());
        let mut wk = KalmanWork {
            pm: pm.as_mut_slice(),
            ikh: ikh.as_mut_slice(),
            ss: ss.as_mut_slice(),
            so: so.as_mut_slice(),
            xt: xt.as_mut_slice(),
            si: si.as_mut_slice(),
            oo: oo.as_mut_slice(),
            xp: xp.as_mut_slice(),
            vs: vs.as_mut_slice(),
            innov: innov.as_mut_slice(),
            vo: vo.as_mut_slice(),
        };
        let mut next = *s;
        let e = &s.estimate;
        // The one Kalman step (shared with `DynKalman`).
        let present = kalman_step_flat(
            &self.flat(),
            &mut wk,
            (e.x.as_slice(), s.p.as_slice(), e.w.as_slice()),
            (w.as_slice(), y.as_slice()),
            (next.estimate.x.as_mut_slice(), next.p.as_mut_slice()),
        )?;
        next.estimate.w = *w;
        (next.estimate.n, next.estimate.missing) =
            next_counts(s.estimate.n, s.estimate.missing, present)
                .ok_or(Error::StepCountOverflow)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::observer::building_fixture;

    /// Regression: the checked step wrapped its counters (`u64::MAX + 1 = 0`); it now
    /// refuses with a typed error and leaves the state bit-identical.
    #[test]
    fn kalman_step_refuses_to_wrap_its_counters() {
        let (ss, meas) = building_fixture();
        let q = SMatrix::<f64, 10, 10>::identity() * 1e-10;
        let r = SMatrix::<f64, 2, 2>::identity() * 0.01;
        let kal = Kalman::<f64, 10, 1, 2>::new(&ss, &meas, &q, &r).unwrap();
        let w = SVector::from([0.1]);
        let mut s = kal.start(&SVector::zeros(), &(q * 10.0), &w).unwrap();
        s.estimate.n = u64::MAX;
        let before = s;
        let y = SVector::from([0.0, 0.0]);
        assert_eq!(kal.try_step(&mut s, &w, &y), Err(Error::StepCountOverflow));
        assert_eq!(s, before);
        s.estimate.n = 3;
        s.estimate.missing = u64::MAX;
        let before = s;
        let gap = SVector::from([f64::NAN, 0.0]);
        assert_eq!(
            kal.try_step(&mut s, &w, &gap),
            Err(Error::StepCountOverflow)
        );
        assert_eq!(s, before);
        kal.try_step(&mut s, &w, &y).unwrap();
        assert_eq!((s.estimate.steps(), s.estimate.missing()), (4, u64::MAX));
    }
}
