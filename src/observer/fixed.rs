//! The fixed-gain observer (a steady-state Kalman filter, or any gain the user gives) and
//! the read-out of estimated quantities.

use nalgebra::{SMatrix, SVector};

use super::state_space::{Measurement, StateSpace};
use crate::kinematics::check_time_step_as;
use crate::linalg::{self, all_finite, all_finite_flat, all_fit, finite_as, round_rows, rows_f64};
use crate::stepper::commit_if_finite;
use crate::{Error, Real, StepState};

/// The state of an observer: the estimate `x̂` (`S` values, `[u; v]`, `[u; v; a]` or
/// `[η; η']`), the last input `w_{n−1}` (the next prediction uses it), the step count and
/// the number of missing measurements. Plain data.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate<T, const S: usize, const I: usize> {
    pub(crate) x: SVector<T, S>,
    pub(crate) w: SVector<T, I>,
    pub(crate) n: u64,
    pub(crate) missing: u64,
}

impl<T: Real, const S: usize, const I: usize> Estimate<T, S, I> {
    /// The estimate `x̂_n` (units of the model's state: m and m/s for `[u; v]`).
    pub fn x(&self) -> &SVector<T, S> {
        &self.x
    }
    /// The input of the last step, `w_n`.
    pub fn last_input(&self) -> &SVector<T, I> {
        &self.w
    }
}

/// The counters and the finiteness every estimate shares (the observers' [`Estimate`],
/// the joint estimators' [`JointEstimate`](crate::estimation::JointEstimate)): a state
/// `$x` (`S` values), the input `w` (`I` values), the step count `n` and the count of
/// missing samples `missing`.
macro_rules! estimate_counters {
    ($ty:ident, $x:ident) => {
        impl<T: $crate::Real, const S: usize, const I: usize> $ty<T, S, I> {
            /// Steps taken since the start.
            pub fn steps(&self) -> u64 {
                self.n
            }
            /// Steps whose measurement was missing (a non-finite entry): predicted, not
            /// corrected (a joint estimator also holds its input estimate).
            pub fn missing(&self) -> u64 {
                self.missing
            }
        }

        $crate::state::step_state!(
            $ty<S, I>,
            |self| self.$x.iter().chain(self.w.iter()).all(|v| v.is_finite()),
            n
        );
    };
}
pub(crate) use estimate_counters;

estimate_counters!(Estimate, x);

/// The counters after one more step of every estimator: the step count `n + 1` and the
/// count of missing samples, `missing + 1` unless the measurement is `present`; `None`
/// where either would pass `u64::MAX` (the step is then refused, never wrapped).
/// Cost: two checked additions.
#[inline(always)]
pub(crate) fn next_counts(n: u64, missing: u64, present: bool) -> Option<(u64, u64)> {
    match (n.checked_add(1), missing.checked_add(u64::from(!present))) {
        (Some(n), Some(missing)) => Some((n, missing)),
        _ => None,
    }
}

/// The checked steps' counter check: the step count `n` and, if `y` is missing (a
/// non-finite entry), the count of missing samples `missing` must have room for one more
/// ([`next_counts`]). Errors: [`Error::StepCountOverflow`].
pub(crate) fn check_counts<T: Real, const O: usize>(
    n: u64,
    missing: u64,
    y: &SVector<T, O>,
) -> Result<(), Error> {
    match next_counts(n, missing, y.iter().all(|v| v.is_finite())) {
        Some(_) => Ok(()),
        None => Err(Error::StepCountOverflow),
    }
}

/// The start of any observer: `x̂_0 = x0`, input `w0`, both finite.
pub(crate) fn initial_estimate<T: Real, const S: usize, const I: usize>(
    x0: &SVector<T, S>,
    w0: &SVector<T, I>,
) -> Result<Estimate<T, S, I>, Error> {
    let e = Estimate {
        x: *x0,
        w: *w0,
        n: 0,
        missing: 0,
    };
    if e.is_finite() {
        Ok(e)
    } else {
        Err(Error::NonFiniteInput)
    }
}

/// A fixed-gain observer on a discrete linear model, `S` states, `I` inputs, `O`
/// measurements. Each step predicts with the model and corrects with the measurement:
///
/// ```text
/// x̂⁻ = Φ x̂ + Γ₀ w_{n−1} + Γ₁ w_n        x̂ = x̂⁻ + L (y_n − H x̂⁻ − D w_n)
/// ```
///
/// The gain `L` (`S×O`) is the steady-state Kalman gain ([`SteadyState`](super::SteadyState))
/// or any the user gives (`L = 0` is the open-loop model). With a modal model
/// ([`StateSpace::from_rows_modal`], `S = 2R`) it is a modal observer that pays only for
/// the kept modes.
///
/// Every operator is computed in `f64` and rounded once to `T`; [`Observer::new`] (run
/// time) and `Observer::from_parts_f32`/`_f64` (`const fn`: in a `static` the compiler computes the
/// model and the gain, and no factorization or Riccati code is linked) are bit-identical.
///
/// Cost of a step: `S² + 2S·I + 2S·O + O·I` multiply-adds, fixed (a missing measurement
/// skips the `S·O` of the correction). Size: `S² + 2S·I + 2S·O + O·I + 1` values of `T`.
///
/// ```
/// use aemstep::models::{self, base_excitation};
/// use aemstep::observer::{Observer, Outputs, StateSpace, SteadyState};
/// use aemstep::vector;
/// use aemstep::nalgebra::SMatrix;
///
/// // The 5-storey building, ground acceleration in, absolute accelerations of floors 2
/// // and 5 measured.
/// let (m, c, k) = models::five_storey_building();
/// let ss = StateSpace::<5, 10, 1>::from_rows_aem(m, c, k, base_excitation(&m), 0.02)?;
/// let meas = ss.outputs(&Outputs::absolute_accelerations(Outputs::<5, 1, 2>::select([1, 4]), 0))?;
/// let q = SMatrix::<f64, 10, 10>::identity() * 1e-10;
/// let r = SMatrix::<f64, 2, 2>::identity() * 0.01;
/// let kf = SteadyState::new(&ss, &meas, &q, &r)?;
/// let obs = Observer::<f64, 10, 1, 2>::new(&ss, &meas, &kf.gain_matrix())?;
/// let mut e = obs.start_at_rest(&vector![0.0])?;
/// obs.try_step(&mut e, &vector![0.1], &vector![0.05, 0.02])?;
/// obs.step(&mut e, &vector![0.1], &vector![f64::NAN, 0.0]); // a missing sample
/// assert_eq!(e.missing(), 1);
/// # Ok::<(), aemstep::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observer<T, const S: usize, const I: usize, const O: usize> {
    phi: [[T; S]; S],
    gamma0: [[T; I]; S],
    gamma1: [[T; I]; S],
    h: [[T; S]; O],
    d: [[T; I]; O],
    gain: [[T; O]; S],
    time_step: T,
}

/// Check a gain (finite, fits `T`) and the model's operators fit `T`.
const fn check_parts<const N: usize, const S: usize, const I: usize, const O: usize>(
    model: &StateSpace<N, S, I>,
    meas: &Measurement<S, I, O>,
    gain: &[[f64; O]; S],
    max: f64,
) -> Result<(), Error> {
    check_parts_flat(
        [
            model.phi.as_flattened(),
            model.gamma0.as_flattened(),
            model.gamma1.as_flattened(),
            meas.h.as_flattened(),
            meas.d.as_flattened(),
            gain.as_flattened(),
        ],
        model.time_step,
        max,
    )
}

/// [`check_parts`] on flat slices (`[Φ, Γ₀, Γ₁, H, D, L]`, time step `h`): the one check
/// of [`Observer`] and [`DynObserver`](super::DynObserver). Errors:
/// [`Error::NonFiniteInput`], [`Error::InvalidTimeStep`], [`Error::OperatorOverflow`].
pub(crate) const fn check_parts_flat(
    m: [&[f64]; 6],
    time_step: f64,
    max: f64,
) -> Result<(), Error> {
    let [phi, gamma0, gamma1, h, d, gain] = m;
    if !(all_finite_flat(gain) && all_finite_flat(h) && all_finite_flat(d)) {
        return Err(Error::NonFiniteInput);
    }
    // The time step too must fit `T` (an f32 observer of a model with h = 1e147 had an
    // infinite time step; found by fuzzing).
    if let Err(e) = check_time_step_as(time_step, max) {
        return Err(e);
    }
    if !(all_fit(phi, max)
        && all_fit(gamma0, max)
        && all_fit(gamma1, max)
        && all_fit(h, max)
        && all_fit(d, max)
        && all_fit(gain, max))
    {
        return Err(Error::OperatorOverflow);
    }
    Ok(())
}

impl<T: Real, const S: usize, const I: usize, const O: usize> Observer<T, S, I, O> {
    /// The observer of `model` measuring `meas` with gain `gain` (`S×O`, `f64`, e.g.
    /// [`SteadyState::gain_matrix`](super::SteadyState::gain_matrix), or zero for the open
    /// loop). Rounded once to `T`.
    ///
    /// Errors: [`Error::NonFiniteInput`] (a non-finite gain or output matrix),
    /// [`Error::InvalidTimeStep`] (the model's time step is not a valid time step in `T`),
    /// [`Error::OperatorOverflow`] (an operator does not fit `T`). Cost: `O(S²)`.
    pub fn new<const N: usize>(
        model: &StateSpace<N, S, I>,
        meas: &Measurement<S, I, O>,
        gain: &SMatrix<f64, S, O>,
    ) -> Result<Self, Error> {
        let gain = rows_f64(gain);
        check_parts(model, meas, &gain, T::MAX)?;
        Ok(Self {
            phi: round_rows(&model.phi),
            gamma0: round_rows(&model.gamma0),
            gamma1: round_rows(&model.gamma1),
            h: round_rows(&meas.h),
            d: round_rows(&meas.d),
            gain: round_rows(&gain),
            time_step: T::from_f64_rounded(model.time_step),
        })
    }

    /// The time step `h` (s).
    pub fn time_step(&self) -> T {
        self.time_step
    }

    /// The gain `L` (`S×O`) as stepped.
    pub fn gain(&self) -> SMatrix<T, S, O> {
        SMatrix::from_fn(|i, j| self.gain[i][j])
    }

    /// The estimate at `t = 0`: `x̂_0 = x0` (e.g. `[u0; v0]`, `[u0; v0; a0]` for
    /// generalized-α — [`StateSpace::initial_state`] — or the modal coordinates), input
    /// `w0`. Errors: [`Error::NonFiniteInput`].
    pub fn start(
        &self,
        x0: &SVector<T, S>,
        w0: &SVector<T, I>,
    ) -> Result<Estimate<T, S, I>, Error> {
        initial_estimate(x0, w0)
    }

    /// [`Observer::start`] at rest, `x̂_0 = 0`. Errors: [`Error::NonFiniteInput`].
    pub fn start_at_rest(&self, w0: &SVector<T, I>) -> Result<Estimate<T, S, I>, Error> {
        self.start(&SVector::zeros(), w0)
    }

    /// The predicted measurement `H x + D w` of a state. Cost: `O·(S + I)`.
    pub fn predicted_output(&self, x: &SVector<T, S>, w: &SVector<T, I>) -> SVector<T, O> {
        mul2(&self.h, &self.d, x, w)
    }

    /// One step: predict with the input `w` (`w_n`; `w_{n−1}` is kept in the estimate),
    /// then correct with the measurement `y`. If any entry of `y` is not finite (NaN: a
    /// missing sample) the correction is skipped and counted ([`Estimate::missing`]).
    ///
    /// Fixed cost (`S² + 2S·I + 2S·O + O·I` multiply-adds), no allocation, no panic. A
    /// non-finite input `w` gives a non-finite estimate, and the counters wrap after
    /// `2⁶⁴` steps (`10¹⁰` years at 50 Hz): use [`Observer::try_step`] where that must not
    /// happen.
    #[inline]
    pub fn step(&self, e: &mut Estimate<T, S, I>, w: &SVector<T, I>, y: &SVector<T, O>) {
        self.step_innovation(e, w, y);
    }

    /// [`Observer::step`], returning the innovation `ν = y_n − H x̂⁻ − D w_n` (output
    /// units) that corrected it — what a change detector tests
    /// ([`detection`](crate::detection)). Non-finite where `y` is (a missing sample).
    /// Cost: as [`Observer::step`].
    #[inline(always)]
    pub fn step_innovation(
        &self,
        e: &mut Estimate<T, S, I>,
        w: &SVector<T, I>,
        y: &SVector<T, O>,
    ) -> SVector<T, O> {
        // Sums start from −0 (`−0 + x = x` exactly, so the compiler drops the add) and the
        // prediction is built in place (no zeroed temporary). The same arithmetic as the
        // run-time-sized observer's rows (`observer::dynamic`'s `predict_row`, `innovation_row`,
        // `correct_row`; `tests/runtime_size_observer.rs` checks the bits), written on
        // the arrays here: the slice rows cost the Cortex-M4F controller's step
        // (`Controller<f32, 6, 1, 3>`) 457 instructions against 274 (`scripts/qemu.sh`).
        let neg_zero = -T::zero();
        let xp: [T; S] = core::array::from_fn(|i| {
            let mut s = neg_zero;
            for j in 0..I {
                s += self.gamma0[i][j] * e.w[j];
                s += self.gamma1[i][j] * w[j];
            }
            for j in 0..S {
                s += self.phi[i][j] * e.x[j];
            }
            s
        });
        let mut innov = [T::zero(); O];
        let mut measured = true;
        for o in 0..O {
            let mut s = y[o];
            for j in 0..I {
                s -= self.d[o][j] * w[j];
            }
            for j in 0..S {
                s -= self.h[o][j] * xp[j];
            }
            innov[o] = s;
            measured &= y[o].is_finite();
        }
        if measured {
            for i in 0..S {
                let mut s = xp[i];
                for o in 0..O {
                    s += self.gain[i][o] * innov[o];
                }
                e.x[i] = s;
            }
        } else {
            e.x = xp.into();
            e.missing = e.missing.wrapping_add(1);
        }
        e.w = *w;
        e.n = e.n.wrapping_add(1);
        innov.into()
    }

    /// [`Observer::step`], checked: the input must be finite and the new estimate
    /// finite, else `e` is left bit-identical. A non-finite measurement is not an error
    /// (it is a missing sample, counted).
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::NonFiniteState`],
    /// [`Error::StepCountOverflow`] (the step count, or the count of missing samples,
    /// would pass `u64::MAX`: refused rather than wrapped). Cost: a step plus a copy and a
    /// scan.
    pub fn try_step(
        &self,
        e: &mut Estimate<T, S, I>,
        w: &SVector<T, I>,
        y: &SVector<T, O>,
    ) -> Result<(), Error> {
        if !w.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFiniteInput);
        }
        check_counts(e.n, e.missing, y)?;
        commit_if_finite(e, |next| self.step(next, w, y))
    }
}

/// Const-fn construction: model and gain computed by the compiler into flash.
macro_rules! const_ctor {
    ($t:ident, $from_parts:ident) => {
        impl<const S: usize, const I: usize, const O: usize> Observer<$t, S, I, O> {
            /// `const fn` twin of [`Observer::new`] with the gain as row-major `f64`
            /// (`S×O`, e.g. [`SteadyState::gain`](super::SteadyState::gain));
            /// bit-identical to it.
            ///
            /// ```
            /// use aemstep::models::{self, base_excitation};
            /// use aemstep::observer::{Observer, Outputs, StateSpace};
            /// const B: ([[f64; 5]; 5], [[f64; 5]; 5], [[f64; 5]; 5]) = models::five_storey_building();
            /// const SS: StateSpace<5, 10, 1> = match StateSpace::from_rows_aem(
            ///     B.0, B.1, B.2, base_excitation(&B.0), 0.02) {
            ///     Ok(s) => s,
            ///     Err(e) => panic!("{}", e.as_str()),
            /// };
            /// static OPEN_LOOP: Observer<f32, 10, 1, 1> = match SS.outputs(
            ///     &Outputs::displacements(Outputs::<5, 1, 1>::select([4]))) {
            ///     Ok(meas) => match Observer::<f32, 10, 1, 1>::from_parts_f32(&SS, &meas, &[[0.0]; 10]) {
            ///         Ok(o) => o,
            ///         Err(e) => panic!("{}", e.as_str()),
            ///     },
            ///     Err(e) => panic!("{}", e.as_str()),
            /// };
            /// assert_eq!(OPEN_LOOP.time_step(), 0.02);
            /// ```
            ///
            /// Errors: as [`Observer::new`].
            pub const fn $from_parts<const N: usize>(
                model: &StateSpace<N, S, I>,
                meas: &Measurement<S, I, O>,
                gain: &[[f64; O]; S],
            ) -> Result<Self, Error> {
                if let Err(e) = check_parts(model, meas, gain, $t::MAX as f64) {
                    return Err(e);
                }
                Ok(Self {
                    phi: linalg::const_round!($t, rows model.phi),
                    gamma0: linalg::const_round!($t, rows model.gamma0),
                    gamma1: linalg::const_round!($t, rows model.gamma1),
                    h: linalg::const_round!($t, rows meas.h),
                    d: linalg::const_round!($t, rows meas.d),
                    gain: linalg::const_round!($t, rows * gain),
                    time_step: model.time_step as $t,
                })
            }
        }
    };
}
const_ctor!(f32, from_parts_f32);
const_ctor!(f64, from_parts_f64);

/// Estimated quantities read from a state, `z = H x + D w` (e.g. every inter-storey drift
/// from `[u; v]`): the output matrices of [`StateSpace::outputs`] rounded once to `T`.
/// Cost per read: `P·(S + I)` multiply-adds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Readout<T, const S: usize, const I: usize, const P: usize> {
    h: [[T; S]; P],
    d: [[T; I]; P],
}

impl<T: Real, const S: usize, const I: usize, const P: usize> Readout<T, S, I, P> {
    /// From output matrices (run time). Errors: [`Error::NonFiniteInput`],
    /// [`Error::OperatorOverflow`].
    pub fn new(m: &Measurement<S, I, P>) -> Result<Self, Error> {
        if !(all_finite(&m.h) && all_finite(&m.d)) {
            return Err(Error::NonFiniteInput);
        }
        if !(finite_as(&m.h, T::MAX) && finite_as(&m.d, T::MAX)) {
            return Err(Error::OperatorOverflow);
        }
        Ok(Self {
            h: round_rows(&m.h),
            d: round_rows(&m.d),
        })
    }

    /// `z = H x + D w`. Cost: `P·(S + I)` multiply-adds.
    pub fn read(&self, x: &SVector<T, S>, w: &SVector<T, I>) -> SVector<T, P> {
        mul2(&self.h, &self.d, x, w)
    }
}

/// `M₁ x + M₂ w` row by row (`M₁` `R×S`, `M₂` `R×I`; from `+0`, `M₁`'s terms first): the
/// one sum of [`Observer::predicted_output`] and [`Readout::read`] (`H x + D w`) and of
/// the dual filter's error dynamics (`A e_ξ + B e_w`, `C e_ξ + D̃ e_w`). Cost: `R·(S + I)`
/// multiply-adds.
#[inline]
pub(crate) fn mul2<T: Real, const R: usize, const S: usize, const I: usize>(
    m1: &[[T; S]; R],
    m2: &[[T; I]; R],
    x: &SVector<T, S>,
    w: &SVector<T, I>,
) -> SVector<T, R> {
    SVector::from_fn(|r, _| {
        let mut s = T::zero();
        for j in 0..S {
            s += m1[r][j] * x[j];
        }
        for j in 0..I {
            s += m2[r][j] * w[j];
        }
        s
    })
}

macro_rules! readout_const {
    ($t:ident, $from_parts:ident) => {
        impl<const S: usize, const I: usize, const P: usize> Readout<$t, S, I, P> {
            /// `const fn` twin of [`Readout::new`], bit-identical to it.
            ///
            /// Errors: as [`Readout::new`].
            pub const fn $from_parts(m: &Measurement<S, I, P>) -> Result<Self, Error> {
                if !(all_finite(&m.h) && all_finite(&m.d)) {
                    return Err(Error::NonFiniteInput);
                }
                if !(finite_as(&m.h, $t::MAX as f64) && finite_as(&m.d, $t::MAX as f64)) {
                    return Err(Error::OperatorOverflow);
                }
                Ok(Self {
                    h: linalg::const_round!($t, rows m.h),
                    d: linalg::const_round!($t, rows m.d),
                })
            }
        }
    };
}
readout_const!(f32, from_parts_f32);
readout_const!(f64, from_parts_f64);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::observer::building_fixture;

    /// Regression: the checked step wrapped its counters (`u64::MAX + 1 = 0`); it now
    /// refuses with a typed error and leaves the estimate bit-identical.
    #[test]
    fn observer_try_step_refuses_to_wrap_its_counters() {
        let (ss, meas) = building_fixture();
        let obs = Observer::<f64, 10, 1, 2>::new(&ss, &meas, &SMatrix::zeros()).unwrap();
        let w = SVector::from([0.1]);
        let mut e = obs.start_at_rest(&w).unwrap();
        e.n = u64::MAX;
        let before = e;
        assert_eq!(
            obs.try_step(&mut e, &w, &SVector::from([0.0, 0.0])),
            Err(Error::StepCountOverflow)
        );
        assert_eq!(e, before);
        // The missing-sample count: at its limit a missing sample is refused, a measured
        // one is taken.
        e.n = 7;
        e.missing = u64::MAX;
        let before = e;
        assert_eq!(
            obs.try_step(&mut e, &w, &SVector::from([f64::NAN, 0.0])),
            Err(Error::StepCountOverflow)
        );
        assert_eq!(e, before);
        obs.try_step(&mut e, &w, &SVector::from([0.0, 0.0]))
            .unwrap();
        assert_eq!((e.steps(), e.missing()), (8, u64::MAX));
    }
}
