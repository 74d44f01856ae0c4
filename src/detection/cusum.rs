//! Page's CUSUM on the normalized innovations squared, for an increase of their covariance.

use super::quantile::ln;
use crate::{Error, Param};

/// Page's CUSUM test for a change of the innovations' covariance from `S` to `λS`
/// (`λ > 1`), on the normalized innovations squared `q_n = νᵀ S⁻¹ ν` of `O` measurements
/// ([`Whitener::nis`](super::Whitener::nis)).
///
/// Each sample adds the log-likelihood ratio of `N(0, λS)` against `N(0, S)`,
///
/// ```text
/// s_n = ½ (1 − 1/λ) q_n − ½ O ln λ,      g_n = max(0, g_{n−1} + s_n),      alarm: g_n > h
/// ```
///
/// with `h = ln(1/α)`. **False alarms.** Under the model `e^{Σ s}` is a martingale of mean
/// 1, so a run of the CUSUM from 0 reaches `h` with probability at most `e^{−h}` before
/// it returns to 0, and the mean time between false alarms (restarting at 0 after each)
/// is at least `e^h = 1/α` samples (Lorden 1971): `α` bounds the long-run false-alarm
/// rate per sample from above (the bound is conservative: the overshoot of `h` is
/// ignored). Plain data, `const fn` construction; a step is two multiply-adds.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Cusum {
    slope: f64,
    offset: f64,
    threshold: f64,
}

/// The state of a [`Cusum`]: the statistic `g ≥ 0` and the skipped samples. Plain data.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CusumState {
    g: f64,
    skipped: u64,
}

impl CusumState {
    /// At rest, `g = 0`.
    pub const fn new() -> Self {
        Self { g: 0.0, skipped: 0 }
    }
    /// The statistic `g_n` (nats).
    pub fn statistic(&self) -> f64 {
        self.g
    }
    /// Restart at `g = 0` (after an alarm has been handled).
    pub fn reset(&mut self) {
        self.g = 0.0;
    }
    /// NaN samples skipped since the start.
    pub fn skipped(&self) -> u64 {
        self.skipped
    }
}

impl Cusum {
    /// The CUSUM of `outputs` measurements for a covariance ratio `lambda` (`> 1`,
    /// finite: the smallest increase it is tuned to detect quickly) and a false-alarm rate
    /// bound `alpha` per sample (`0 < alpha < 1`).
    ///
    /// Errors: [`Error::InvalidParameter`] (`outputs = 0`, `lambda` not finite or `≤ 1`,
    /// `alpha` NaN or outside `(0, 1)`). Cost: two logarithms.
    pub const fn new(outputs: usize, lambda: f64, alpha: f64) -> Result<Self, Error> {
        if outputs == 0 {
            return Err(Error::InvalidParameter(Param::Outputs));
        }
        if !(lambda > 1.0 && lambda.is_finite()) {
            return Err(Error::InvalidParameter(Param::CusumDrift));
        }
        if !(alpha > 0.0 && alpha < 1.0) {
            return Err(Error::InvalidParameter(Param::FalseAlarm));
        }
        Ok(Self {
            slope: 0.5 * (1.0 - 1.0 / lambda),
            offset: 0.5 * outputs as f64 * ln(lambda),
            threshold: -ln(alpha),
        })
    }

    /// The threshold `h = ln(1/α)` (nats).
    pub const fn threshold(&self) -> f64 {
        self.threshold
    }

    /// Push a normalized innovation squared `q` (NaN: skipped, counted) and test: `true`
    /// is an alarm (`g > h`; `g` is left as it is, [`CusumState::reset`] restarts). `+∞`
    /// gives `g = ∞`, an alarm. Cost: two multiply-adds.
    #[inline]
    pub fn update(&self, s: &mut CusumState, q: f64) -> bool {
        if q.is_nan() {
            s.skipped = s.skipped.wrapping_add(1);
            return false;
        }
        let g = s.g + (self.slope * q - self.offset);
        s.g = if g > 0.0 { g } else { 0.0 };
        s.g > self.threshold
    }
}
