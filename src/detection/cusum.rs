//! Page's CUSUM on the normalized innovations squared, for an increase of their covariance.

use super::Innovations;
use super::quantile::ln;
use crate::{Error, Param, Real};

/// Page's CUSUM test for a change of the innovations' covariance from `S` to `λS`
/// (`λ > 1`), on the normalized innovations squared `q_n = νᵀ S⁻¹ ν` of `k` degrees of
/// freedom a sample ([`Whitener::nis`](super::Whitener::nis); `k` is the estimator's
/// [`Innovations::DOF`]: `O` measurements of an observer, `O − I` of the joint
/// input–state estimator).
///
/// Each sample adds the log-likelihood ratio of `N(0, λS)` against `N(0, S)`,
///
/// ```text
/// s_n = ½ (1 − 1/λ) q_n − ½ k ln λ,      g_n = max(0, g_{n−1} + s_n),      alarm: g_n > h
/// ```
///
/// with `h = ln(1/α)`. **False alarms.** Under the model `e^{Σ s}` is a martingale of mean
/// 1, so a run of the CUSUM from 0 reaches `h` with probability at most `e^{−h}` before
/// it returns to 0, and the mean time between false alarms (restarting at 0 after each)
/// is at least `e^h = 1/α` samples (Lorden 1971): `α` bounds the long-run false-alarm
/// rate per sample from above (the bound is conservative: the overshoot of `h` is
/// ignored). The coefficients are computed in `f64` and rounded once to `T`; a step is in
/// `T` only. Plain data, `const fn` construction (`Cusum::new_f32`/`new_f64`); a step is
/// two multiply-adds.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Cusum<T> {
    slope: T,
    offset: T,
    threshold: T,
}

/// The state of a [`Cusum`]: the statistic `g ≥ 0` and the skipped samples. Plain data;
/// `const` at rest (`CusumState::at_rest_f32`/`at_rest_f64`, equal to `Default`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CusumState<T> {
    g: T,
    skipped: u64,
}

/// At rest: as `CusumState::at_rest_f32`/`at_rest_f64`, for any `T`.
impl<T: Real> Default for CusumState<T> {
    fn default() -> Self {
        Self {
            g: T::zero(),
            skipped: 0,
        }
    }
}

macro_rules! cusum_state_const {
    ($t:ident, $at_rest:ident) => {
        impl CusumState<$t> {
            /// At rest, `g = 0`, nothing skipped: `const fn` (for a `static`), equal to
            /// `CusumState::default()`. Cost: none.
            ///
            /// ```
            /// use aemstep::detection::CusumState;
            #[doc = concat!("static G: CusumState<", stringify!($t), "> = CusumState::", stringify!($at_rest), "();")]
            /// assert_eq!(G, CusumState::default());
            /// ```
            pub const fn $at_rest() -> Self {
                Self { g: 0.0, skipped: 0 }
            }
        }
    };
}
cusum_state_const!(f32, at_rest_f32);
cusum_state_const!(f64, at_rest_f64);

impl<T: Real> CusumState<T> {
    /// The statistic `g_n` (nats).
    pub fn statistic(&self) -> T {
        self.g
    }
    /// Restart at `g = 0` (after an alarm has been handled).
    pub fn reset(&mut self) {
        self.g = T::zero();
    }
    /// NaN samples skipped since the start.
    pub fn skipped(&self) -> u64 {
        self.skipped
    }
}

/// `(slope, offset, threshold)` in `f64`.
const fn cusum_parts(dof: usize, lambda: f64, alpha: f64) -> Result<[f64; 3], Error> {
    if dof == 0 {
        return Err(Error::InvalidParameter(Param::Outputs));
    }
    if !(lambda > 1.0 && lambda.is_finite()) {
        return Err(Error::InvalidParameter(Param::CusumDrift));
    }
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(Error::InvalidParameter(Param::FalseAlarm));
    }
    Ok([
        0.5 * (1.0 - 1.0 / lambda),
        0.5 * dof as f64 * ln(lambda),
        -ln(alpha),
    ])
}

impl<T: Real> Cusum<T> {
    /// The CUSUM of `estimator`'s innovations (only its type is read:
    /// [`Innovations::DOF`] degrees of freedom a sample) for a covariance ratio `lambda`
    /// (`> 1`, finite: the smallest increase it is tuned to detect quickly) and a
    /// false-alarm rate bound `alpha` per sample (`0 < alpha < 1`). Bit-identical to the
    /// `const fn` `Cusum::new_f32`/`new_f64`.
    ///
    /// Errors: [`Error::InvalidParameter`] (no degree of freedom, `lambda` not finite or
    /// `≤ 1`, `alpha` NaN or outside `(0, 1)`). Cost: two logarithms.
    pub fn new<E: Innovations + ?Sized>(
        estimator: &E,
        lambda: f64,
        alpha: f64,
    ) -> Result<Self, Error> {
        let _ = estimator;
        let [slope, offset, threshold] = cusum_parts(E::DOF, lambda, alpha)?;
        Ok(Self {
            slope: T::from_f64_rounded(slope),
            offset: T::from_f64_rounded(offset),
            threshold: T::from_f64_rounded(threshold),
        })
    }

    /// The threshold `h = ln(1/α)` (nats), rounded to `T`.
    pub fn threshold(&self) -> T {
        self.threshold
    }

    /// Push a normalized innovation squared `q` (NaN: skipped, counted) and test: `true`
    /// is an alarm (`g > h`; `g` is left as it is, [`CusumState::reset`] restarts). `+∞`
    /// gives `g = ∞`, an alarm. In `T` only. Cost: two multiply-adds.
    #[inline]
    pub fn update(&self, s: &mut CusumState<T>, q: T) -> bool {
        // NaN (compared in `T`).
        if q.partial_cmp(&q).is_none() {
            s.skipped = s.skipped.wrapping_add(1);
            return false;
        }
        let g = s.g + (self.slope * q - self.offset);
        s.g = if g > T::zero() { g } else { T::zero() };
        s.g > self.threshold
    }
}

macro_rules! cusum_const {
    ($t:ident, $new:ident) => {
        impl Cusum<$t> {
            /// `const fn` twin of [`Cusum::new`], bit-identical to it. Errors: as
            /// [`Cusum::new`].
            pub const fn $new<E: Innovations + ?Sized>(
                estimator: &E,
                lambda: f64,
                alpha: f64,
            ) -> Result<Self, Error> {
                let _ = estimator;
                match cusum_parts(E::DOF, lambda, alpha) {
                    Ok([slope, offset, threshold]) => Ok(Self {
                        slope: slope as $t,
                        offset: offset as $t,
                        threshold: threshold as $t,
                    }),
                    Err(e) => Err(e),
                }
            }
        }
    };
}
cusum_const!(f32, new_f32);
cusum_const!(f64, new_f64);
