//! Change detection on an observer's innovations, and localization by a bank of models.
//!
//! A fixed-gain [`Observer`](crate::observer::Observer) built from the steady-state Kalman
//! gain of the model the structure is believed to be produces innovations
//! `ν_n = y_n − H x̂⁻_n − D w_n` ([`Observer::step_innovation`](crate::observer::Observer::step_innovation))
//! that, while the structure matches the model, are white, zero-mean and of covariance
//! `S = H P Hᵀ + R` (`P` the Riccati solution, [`SteadyState`]). A change of the structure
//! (a storey that loses stiffness) makes them larger and coloured.
//!
//! - [`Whitener`]: `S` factored once (`S = C Cᵀ`, Cholesky, `f64`, `const fn`); the
//!   normalized innovation squared `q_n = νᵀ S⁻¹ ν = |C⁻¹ ν|²` costs `O(O+1)/2`
//!   multiply-adds. Under the model, `q_n ~ χ²_O`.
//! - [`Window`]: the sum of `q` over the last `W` samples, in a ring buffer, exact (the
//!   terms are held in fixed point, so the running sum never drifts; see [`Window`]).
//! - [`ChiSquareTest`]: the windowed test. Under the model the window's sum is `χ²` with
//!   `W·O` degrees of freedom (the innovations are white: independent from sample to
//!   sample, for the steady-state Kalman gain of the true model); the
//!   threshold is its upper quantile at a stated false-alarm probability `α`
//!   ([`chi_square_quantile`], Wilson–Hilferty, `const fn`). Evaluated every sample, each
//!   evaluation is a false alarm with probability `α` (so `α` is the expected fraction of
//!   samples in alarm); evaluated at disjoint windows, the false alarms are independent
//!   Bernoulli(`α`) trials.
//! - [`Detector`]: a [`Whitener`] and a [`ChiSquareTest`] together, one call a sample.
//! - [`Cusum`]: Page's CUSUM on the same statistic, tuned to a covariance increase `λ`,
//!   its threshold `ln(1/α)` bounding the false-alarm rate per sample by `α`.
//! - With the load unknown, the joint input–state estimator's residual
//!   ([`InputStateObserver::step_innovation`](crate::estimation::InputStateObserver::step_innovation))
//!   is tested the same way: a [`Whitener`] of `R̃`
//!   ([`InputStateGains::innovation_covariance`](crate::estimation::InputStateGains::innovation_covariance))
//!   and a [`ChiSquareTest`] of `O − I` outputs (the estimated input takes `I` of the `O`
//!   directions; `tests/detection_joint.rs` checks the `χ²_{O−I}` law).
//! - [`ModelBank`]: `M` fixed-gain observers on the same measurements (e.g. the intact
//!   building and one model per storey with reduced stiffness), each with its own
//!   whitener; they are ranked by the Gaussian log-likelihood of their innovations over
//!   the last `W` samples ([`ModelBank::ranking`]).
//!
//! Everything is fixed size (`O` measurements, `W` samples, `M` models are const
//! generics), allocation-free and `no_std`; a missing sample (a NaN innovation) is
//! skipped and counted, while an infinite one enters a window as its capped term (an
//! alarm, [`Window::push`]); a failed step changes nothing.
//!
//! ```
//! use aemstep::detection::{ChiSquareTest, Detector, Whitener, Window, innovation_covariance};
//! use aemstep::models::{self, base_excitation};
//! use aemstep::nalgebra::SMatrix;
//! use aemstep::observer::{Observer, Outputs, StateSpace, SteadyState};
//! use aemstep::vector;
//!
//! let (m, c, k) = models::five_storey_building();
//! let ss = StateSpace::<5, 10, 1>::from_rows_aem(m, c, k, base_excitation(&m), 0.02)?;
//! let meas = ss.outputs(&Outputs::absolute_accelerations(Outputs::<5, 1, 2>::select([1, 4]), 0))?;
//! let q = SMatrix::<f64, 10, 10>::identity() * 1e-10;
//! let r = [[0.01, 0.0], [0.0, 0.01]];
//! let kf = SteadyState::new(&ss, &meas, &q, &SMatrix::from_fn(|i, j| r[i][j]))?;
//! let obs = Observer::<f64, 10, 1, 2>::new(&ss, &meas, &kf.gain_matrix())?;
//! // The innovation covariance S = H P Hᵀ + R, and a 1 s window at α = 10⁻³.
//! let s = innovation_covariance(&kf, &meas, &r)?;
//! let det = Detector::<f64, 2, 50>::new(Whitener::new(&s)?, ChiSquareTest::new(2, 1e-3)?);
//! let mut win = Window::<50>::new();
//! let mut e = obs.start_at_rest(&vector![0.0])?;
//! let nu = obs.step_innovation(&mut e, &vector![0.1], &vector![0.05, 0.02]);
//! let alarm = det.update(&mut win, &nu);
//! assert!(!alarm); // the window is not full yet
//! # Ok::<(), aemstep::Error>(())
//! ```

mod bank;
mod cusum;
#[cfg(feature = "defmt")]
mod defmt_impls;
mod quantile;

pub use bank::{BankState, ModelBank};
pub use cusum::{Cusum, CusumState};
pub use quantile::{chi_square_quantile, normal_quantile};

use nalgebra::SVector;

use crate::linalg::cholesky::{cholesky, lower_solve};
use crate::linalg::{Mat, all_finite, finite_as, identity, round_rows};
use crate::observer::{Measurement, SteadyState};
use crate::scalar::sealed::Sealed;
use crate::{Error, Real};

/// Fractional bits of the fixed-point terms of a [`Window`]: a term `q` is held as the
/// integer nearest `q·2²⁴` (a quantum of `6·10⁻⁸`, the rounding of `f32` at 1).
pub const NIS_FRACTION_BITS: u32 = 24;

/// `2^NIS_FRACTION_BITS`.
const NIS_SCALE: f64 = (1u64 << NIS_FRACTION_BITS) as f64;

/// The innovation covariance `S = H P Hᵀ + R` (`O×O`, output units squared) of the
/// steady-state Kalman filter `kf` of a measurement `meas` with noise `r` (the same `R`
/// the gain was solved with). With a process–measurement cross covariance `N`
/// ([`SteadyState::from_parts_cross`], held in [`SteadyState::cross`]) it is
/// `S = H P Hᵀ + R + H N + Nᵀ Hᵀ`: the force noise that also reaches the sensors
/// ([observer](crate::observer), "Noise that reaches the sensors"); a zero `N` gives the first
/// form bit for bit. `const fn`. Errors: [`Error::InvalidCovariance`] (`r` or `N` not
/// finite),
/// [`Error::OperatorOverflow`] (`S` not finite). Cost: `O·S·(S + O)` flops.
pub const fn innovation_covariance<const S: usize, const I: usize, const O: usize>(
    kf: &SteadyState<S, O>,
    meas: &Measurement<S, I, O>,
    r: &[[f64; O]; O],
) -> Result<[[f64; O]; O], Error> {
    if !all_finite(r) || !all_finite(&kf.cross) {
        return Err(Error::InvalidCovariance);
    }
    // The one Kalman core's innovation covariance (the cross term only where N ≠ 0).
    let cross = if crate::observer::is_zero(&kf.cross) {
        None
    } else {
        Some(&kf.cross)
    };
    let (_, s) = crate::observer::innovation_parts(&kf.covariance, &meas.h, r, cross);
    if !all_finite(&s) {
        return Err(Error::OperatorOverflow);
    }
    // Symmetric to rounding: (S + Sᵀ)/2.
    let mut out = s;
    let mut i = 0;
    while i < O {
        let mut j = 0;
        while j < O {
            out[i][j] = 0.5 * (s[i][j] + s[j][i]);
            j += 1;
        }
        i += 1;
    }
    // (The sum of two entries near `f64::MAX` overflows where each is finite.)
    if !all_finite(&out) {
        return Err(Error::OperatorOverflow);
    }
    Ok(out)
}

/// The inverse Cholesky factor `C⁻¹` and `ln det S` of a symmetric positive definite `S`.
const fn whitener_parts<const O: usize>(
    s: &Mat<O, O>,
    max: f64,
) -> Result<(Mat<O, O>, f64), Error> {
    if O == 0 {
        return Err(Error::InvalidParameter);
    }
    if !all_finite(s) || !crate::linalg::is_symmetric(s, 64.0 * f64::EPSILON) {
        return Err(Error::InvalidCovariance);
    }
    let c = match cholesky(s) {
        Some(c) => c,
        None => return Err(Error::InvalidCovariance),
    };
    let cinv = lower_solve(&c, &identity());
    let mut log_det = 0.0;
    let mut i = 0;
    while i < O {
        log_det += 2.0 * quantile::ln(c[i][i]);
        i += 1;
    }
    if !(finite_as(&cinv, max) && log_det.is_finite()) {
        return Err(Error::OperatorOverflow);
    }
    Ok((cinv, log_det))
}

/// The normalized innovation squared of an innovation covariance `S` (`O×O`): holds
/// `C⁻¹` (`S = C Cᵀ`, `C` lower triangular, rounded once to `T`) and `ln det S`.
///
/// [`Whitener::nis`] is `q = νᵀ S⁻¹ ν = |C⁻¹ ν|²` (dimensionless; `χ²_O` under the
/// model), `O(O+1)/2` multiply-adds. Size: `O²` values of `T` and one `f64`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Whitener<T, const O: usize> {
    cinv: [[T; O]; O],
    log_det: f64,
}

impl<T: Real, const O: usize> Whitener<T, O> {
    /// From `S` (`f64`, symmetric positive definite, output units squared), e.g.
    /// [`innovation_covariance`]. Run time; bit-identical to the `const fn`
    /// `Whitener::from_rows_f32`/`from_rows_f64`.
    ///
    /// Errors: [`Error::InvalidParameter`] (`O = 0`), [`Error::InvalidCovariance`] (`S`
    /// not finite, not symmetric or not positive definite), [`Error::OperatorOverflow`]
    /// (`C⁻¹` does not fit `T`). Cost: `O³/2` flops.
    pub fn new(s: &[[f64; O]; O]) -> Result<Self, Error> {
        let (cinv, log_det) = whitener_parts(s, T::MAX)?;
        Ok(Self {
            cinv: round_rows(&cinv),
            log_det,
        })
    }

    /// `ln det S` (`S` in output units squared).
    pub fn log_det(&self) -> f64 {
        self.log_det
    }

    /// `q = νᵀ S⁻¹ ν` of an innovation `ν` (output units): dimensionless, `≥ 0`; NaN if
    /// `ν` has a NaN (a missing sample); `+∞` where a finite `ν` overflows `T` (its
    /// whitened terms `∞ − ∞`: an alarm, not a missing sample). Cost: `O(O+1)/2`
    /// multiply-adds.
    #[inline]
    pub fn nis(&self, nu: &SVector<T, O>) -> T {
        let mut q = T::zero();
        for i in 0..O {
            let mut z = T::zero();
            for j in 0..=i {
                z += self.cinv[i][j] * nu[j];
            }
            q += z * z;
        }
        // NaN (a sum of squares is otherwise ≥ 0), compared in `T` (no widening to `f64`).
        if q.partial_cmp(&T::zero()).is_none() && nu.iter().all(|v| v.is_finite()) {
            return T::from_f64_rounded(f64::INFINITY);
        }
        q
    }
}

macro_rules! whitener_const {
    ($t:ident, $from_rows:ident) => {
        impl<const O: usize> Whitener<$t, O> {
            /// `const fn` twin of [`Whitener::new`], bit-identical to it (in a `static`,
            /// the compiler factors `S`). Errors: as [`Whitener::new`].
            pub const fn $from_rows(s: &[[f64; O]; O]) -> Result<Self, Error> {
                match whitener_parts(s, $t::MAX as f64) {
                    Ok((cinv, log_det)) => Ok(Self {
                        cinv: crate::linalg::const_round!($t, rows cinv),
                        log_det,
                    }),
                    Err(e) => Err(e),
                }
            }
        }
    };
}
whitener_const!(f32, from_rows_f32);
whitener_const!(f64, from_rows_f64);

/// The sum of a statistic over the last `W` samples: a ring buffer of `W` fixed-point
/// terms. Plain data, `8W + 32` bytes, `const`-constructible.
///
/// **No drift.** A term `q ≥ 0` is stored as the integer `round(q·2²⁴)`
/// ([`NIS_FRACTION_BITS`]), capped at `⌊(2⁶⁴ − 1)/W⌋`, and the running sum is the `u64`
/// sum of the stored integers: adding the new term and subtracting the one it replaces is
/// exact integer arithmetic, so the sum equals the sum of the `W` stored terms after any
/// number of steps (by induction; the cap keeps it below `2⁶⁴`). The only error is each
/// term's rounding, `≤ 2⁻²⁵` absolute, so the sum is within `W·2⁻²⁵` of the exact sum of
/// the window's values whatever the run's length — a floating running sum instead
/// accumulates the rounding of every add and subtract it ever did (a random walk growing
/// without bound as the square root of the run's length), and recomputing it every `W`
/// samples would make the cost of a step uneven.
/// A capped term is at least `2⁴⁰/W` (above the largest threshold
/// [`ChiSquareTest::new`] accepts), so capping never hides an alarm.
///
/// A NaN term (a missing sample) is skipped and counted ([`Window::skipped`]). Cost of a
/// push: a multiply, a conversion, two integer adds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window<const W: usize> {
    terms: [u64; W],
    head: usize,
    len: usize,
    sum: u64,
    skipped: u64,
}

impl<const W: usize> Default for Window<W> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const W: usize> Window<W> {
    /// The largest stored term, `⌊(2⁶⁴ − 1)/W⌋` (`u64::MAX` for `W = 0`).
    const CAP: u64 = if W == 0 {
        u64::MAX
    } else {
        u64::MAX / W as u64
    };

    /// An empty window.
    pub const fn new() -> Self {
        Self {
            terms: [0; W],
            head: 0,
            len: 0,
            sum: 0,
            skipped: 0,
        }
    }

    /// Push a term `q ≥ 0` (dimensionless, e.g. [`Whitener::nis`]), dropping the oldest
    /// once `W` are held. NaN: skipped, counted. `+∞` or a term above the cap: stored as
    /// the cap. A window of `W = 0` holds nothing. Cost `O(1)`.
    #[inline]
    pub fn push(&mut self, q: f64) {
        self.push_fixed(Sealed::fixed_round(q, NIS_FRACTION_BITS));
    }

    /// Push a term already in fixed point (`None`: a NaN, skipped and counted); capped.
    #[inline]
    fn push_fixed(&mut self, t: Option<u64>) {
        let Some(t) = t else {
            self.skipped = self.skipped.wrapping_add(1);
            return;
        };
        if W == 0 {
            return;
        }
        // The cap keeps the sum below 2⁶⁴.
        let t = if t > Self::CAP { Self::CAP } else { t };
        // `head < W` always; said so the compiler drops the bounds checks (no panic path
        // in the step, `scripts/qemu.sh`'s call-graph check).
        let h = if self.head < W { self.head } else { 0 };
        let old = if self.len == W {
            self.terms[h]
        } else {
            self.len += 1;
            0
        };
        self.terms[h] = t;
        self.sum = self.sum.wrapping_sub(old).wrapping_add(t);
        self.head = if h + 1 == W { 0 } else { h + 1 };
    }

    /// The sum of the held terms (dimensionless), within `len()·2⁻²⁵` of their exact sum.
    pub fn sum(&self) -> f64 {
        self.sum as f64 / NIS_SCALE
    }

    /// The sum in fixed point (units of `2⁻²⁴`).
    pub fn sum_fixed(&self) -> u64 {
        self.sum
    }

    /// Terms held (`≤ W`).
    pub fn len(&self) -> usize {
        self.len
    }

    /// No term held yet.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// `W` terms held.
    pub fn is_full(&self) -> bool {
        W > 0 && self.len == W
    }

    /// NaN terms skipped since the start.
    pub fn skipped(&self) -> u64 {
        self.skipped
    }

    /// Count `n` more skipped terms (a window emptied and restarted keeps its count).
    pub(crate) fn add_skipped(&mut self, n: u64) {
        self.skipped = self.skipped.wrapping_add(n);
    }
}

/// The windowed χ² test: alarm when the sum of the normalized innovations squared over
/// the last `W` samples exceeds the upper `α` quantile of `χ²` with `W·O` degrees of
/// freedom (`O` measurements). Under the model the window's sum is `χ²_{W·O}`, so each
/// evaluation on a full window is a false alarm with probability `α` (to the accuracy of
/// [`chi_square_quantile`]). Plain data; `const fn` construction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiSquareTest<const W: usize> {
    dof: u64,
    alpha: f64,
    threshold: f64,
    threshold_fixed: u64,
}

impl<const W: usize> ChiSquareTest<W> {
    /// The test of a window of `W` samples of `outputs` measurements each, at false-alarm
    /// probability `alpha` per evaluation (`0 < alpha < 1`).
    ///
    /// Errors: [`Error::InvalidParameter`] (`W = 0`, `outputs = 0`, `alpha` NaN or outside
    /// `(0, 1)`, or a threshold of `2⁴⁰/W` or more, where [`Window`] caps its terms:
    /// `W·O` beyond about `10⁶`). Cost: a few hundred flops.
    pub const fn new(outputs: usize, alpha: f64) -> Result<Self, Error> {
        if W == 0 || outputs == 0 || !(alpha > 0.0 && alpha < 1.0) {
            return Err(Error::InvalidParameter);
        }
        let dof = (W as u64).saturating_mul(outputs as u64);
        let threshold = chi_square_quantile(dof, alpha);
        let cap = (u64::MAX / W as u64) as f64 / NIS_SCALE;
        if !(threshold.is_finite() && threshold < cap) {
            return Err(Error::InvalidParameter);
        }
        Ok(Self {
            dof,
            alpha,
            threshold,
            threshold_fixed: (threshold * NIS_SCALE) as u64,
        })
    }

    /// Degrees of freedom of the window's sum, `W·O`.
    pub const fn dof(&self) -> u64 {
        self.dof
    }

    /// The false-alarm probability per evaluation.
    pub const fn false_alarm(&self) -> f64 {
        self.alpha
    }

    /// The threshold (dimensionless): the upper `α` quantile of `χ²_{W·O}`.
    pub const fn threshold(&self) -> f64 {
        self.threshold
    }

    /// Alarm: the window is full and its sum exceeds the threshold. Cost: a comparison.
    pub fn alarm(&self, window: &Window<W>) -> bool {
        window.is_full() && window.sum_fixed() > self.threshold_fixed
    }
}

/// A [`Whitener`] and a [`ChiSquareTest`]: one call per sample, beside the observer.
/// Plain data (`static`-able: both parts have `const fn` constructors).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detector<T, const O: usize, const W: usize> {
    /// The innovations' normalization.
    pub whitener: Whitener<T, O>,
    /// The test on the window.
    pub test: ChiSquareTest<W>,
}

impl<T: Real, const O: usize, const W: usize> Detector<T, O, W> {
    /// The detector of `whitener`'s innovations with `test`.
    pub const fn new(whitener: Whitener<T, O>, test: ChiSquareTest<W>) -> Self {
        Self { whitener, test }
    }

    /// Push the innovation `nu` (output units; a NaN entry: skipped, counted in
    /// [`Window::skipped`]) and test: `true` is an alarm. No allocation, no panic. Cost:
    /// `O(O+1)/2` multiply-adds and `O(1)`.
    #[inline]
    pub fn update(&self, window: &mut Window<W>, nu: &SVector<T, O>) -> bool {
        // The same term as `push(nis.as_f64())`, rounded in `T` (no `f64` on an `f32` core).
        window.push_fixed(Sealed::fixed_round(
            self.whitener.nis(nu),
            NIS_FRACTION_BITS,
        ));
        self.test.alarm(window)
    }
}
