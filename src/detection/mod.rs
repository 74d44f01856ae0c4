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
//! - [`Innovations`]: the degrees of freedom `k` a sample of an estimator's innovations
//!   carry, from its type (`O` for an [`Observer`](crate::observer::Observer), `O − I`
//!   for the joint input–state estimator), so a test cannot be given the wrong number.
//! - [`ChiSquareTest`]: the windowed test. Under the model the window's sum is `χ²` with
//!   `W·k` degrees of freedom (the innovations are white: independent from sample to
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
//!   and a [`ChiSquareTest`] built for the estimator, so of `O − I` degrees of freedom a
//!   sample (the estimated input takes `I` of the `O` directions;
//!   `tests/detection_joint.rs` checks the `χ²_{O−I}` law).
//! - [`ModelBank`]: `M` fixed-gain observers on the same measurements (e.g. the intact
//!   building and one model per storey with reduced stiffness), each with its own
//!   whitener; they are ranked by the Gaussian log-likelihood of their innovations over
//!   the last `W` samples ([`ModelBank::ranking`]).
//!
//! Everything is fixed size (`O` measurements, `W` samples, `M` models are const
//! generics), allocation-free and `no_std`; a missing sample (a NaN innovation) is
//! skipped and counted, while an infinite one enters a window as its capped term (an
//! alarm, [`Window::push`]); a failed step changes nothing. Every type is generic over
//! the scalar `T` of its estimator and stays in it: an `f32` detector (whitener, window,
//! test, CUSUM) takes, holds and gives `f32` only, so logging its statistic on a Cortex-M4F
//! links no double-precision routine. The states ([`Window`], [`CusumState`],
//! [`BankState`]) have `const` at-rest constructors and `Default`, for a `static`.
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
//! // Degrees of freedom from the observer's type: 2 a sample.
//! let det = Detector::from_parts(Whitener::new(&s)?, ChiSquareTest::new(&obs, 1e-3)?);
//! assert_eq!(det.test.dof(), 100);
//! let mut win = Window::<f64, 50>::at_rest();
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

use core::marker::PhantomData;

use nalgebra::SVector;

use crate::linalg::cholesky::{cholesky, lower_solve};
use crate::linalg::{Mat, all_finite, finite_as, identity, round_rows};
use crate::observer::{Measurement, SteadyState};
use crate::scalar::sealed::Sealed;
use crate::{Error, Param, Real};

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
        return Err(Error::InvalidParameter(Param::Outputs));
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
    if !(finite_as(&cinv, max) && log_det.is_finite() && log_det.abs() <= max) {
        return Err(Error::OperatorOverflow);
    }
    Ok((cinv, log_det))
}

/// The normalized innovation squared of an innovation covariance `S` (`O×O`): holds
/// `C⁻¹` (`S = C Cᵀ`, `C` lower triangular) and `ln det S`, both computed in `f64` and
/// rounded once to `T`.
///
/// [`Whitener::nis`] is `q = νᵀ S⁻¹ ν = |C⁻¹ ν|²` (dimensionless; `χ²_O` under the
/// model), `O(O+1)/2` multiply-adds. Size: `O² + 1` values of `T` (an `f32` whitener holds
/// no `f64`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Whitener<T, const O: usize> {
    cinv: [[T; O]; O],
    log_det: T,
}

impl<T: Real, const O: usize> Whitener<T, O> {
    /// From `S` (`f64`, symmetric positive definite, output units squared), e.g.
    /// [`innovation_covariance`]. Run time; bit-identical to the `const fn`
    /// `Whitener::from_rows_f32`/`from_rows_f64`.
    ///
    /// Errors: [`Error::InvalidParameter`] (`O = 0`), [`Error::InvalidCovariance`] (`S`
    /// not finite, not symmetric or not positive definite), [`Error::OperatorOverflow`]
    /// (`C⁻¹` or `ln det S` does not fit `T`). Cost: `O³/2` flops.
    pub fn new(s: &[[f64; O]; O]) -> Result<Self, Error> {
        let (cinv, log_det) = whitener_parts(s, T::MAX)?;
        Ok(Self {
            cinv: round_rows(&cinv),
            log_det: T::from_f64_rounded(log_det),
        })
    }

    /// `ln det S` (`S` in output units squared), computed in `f64` and rounded once to
    /// `T` (relative error `≤ ε_T/2`). Cost: none.
    pub fn log_det(&self) -> T {
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
                        log_det: log_det as $t,
                    }),
                    Err(e) => Err(e),
                }
            }
        }
    };
}
whitener_const!(f32, from_rows_f32);
whitener_const!(f64, from_rows_f64);

/// An estimator whose innovations a detector tests: the degrees of freedom of one
/// innovation's normalized square `νᵀ S⁻¹ ν` under the model, taken from the estimator's
/// type so that a [`ChiSquareTest`] or a [`Cusum`] cannot be given the wrong number.
///
/// - [`Observer`](crate::observer::Observer) of `O` measurements: `O`.
/// - [`InputStateObserver`](crate::estimation::InputStateObserver) of `I` unknown inputs
///   and `O` measurements: `O − I` (the input estimate takes `I` of the `O` directions;
///   `0` if `I ≥ O`, which the tests refuse).
/// - [`Dof`]: a stated number, for a statistic from an estimator of your own (or
///   implement this trait for it).
///
/// ```
/// use aemstep::detection::{Dof, Innovations};
/// use aemstep::estimation::InputStateObserver;
/// use aemstep::observer::Observer;
///
/// assert_eq!(<Observer<f32, 10, 1, 3> as Innovations>::DOF, 3);
/// // Three sensors, one identified force: two degrees of freedom a sample.
/// assert_eq!(<InputStateObserver<f32, 10, 1, 3> as Innovations>::DOF, 2);
/// assert_eq!(<Dof<5> as Innovations>::DOF, 5);
/// ```
pub trait Innovations {
    /// Degrees of freedom a sample of the normalized innovation squared (`χ²_DOF` under
    /// the model).
    const DOF: usize;
}

impl<T, const S: usize, const I: usize, const O: usize> Innovations
    for crate::observer::Observer<T, S, I, O>
{
    const DOF: usize = O;
}

impl<T, const S: usize, const I: usize, const O: usize> Innovations
    for crate::estimation::InputStateObserver<T, S, I, O>
{
    const DOF: usize = O.saturating_sub(I);
}

/// `K` degrees of freedom a sample, stated: the [`Innovations`] of a statistic that is not
/// one of the crate's estimators' (e.g. `Dof::<3>` for a filter of your own with three
/// independent innovation directions). Zero-sized.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Dof<const K: usize>;

impl<const K: usize> Innovations for Dof<K> {
    const DOF: usize = K;
}

/// The sum of a statistic over the last `W` samples: a ring buffer of `W` fixed-point
/// terms. Plain data, `8W + 32` bytes, `const`-constructible ([`Window::at_rest`], also
/// in a `static`). `T` is the scalar of the terms pushed and of the sum read: an `f32`
/// window never converts to or from `f64`.
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
#[derive(Clone, Copy, Debug)]
pub struct Window<T, const W: usize> {
    terms: [u64; W],
    head: usize,
    len: usize,
    sum: u64,
    skipped: u64,
    scalar: PhantomData<T>,
}

impl<T, const W: usize> PartialEq for Window<T, W> {
    fn eq(&self, other: &Self) -> bool {
        self.terms == other.terms
            && self.head == other.head
            && self.len == other.len
            && self.sum == other.sum
            && self.skipped == other.skipped
    }
}

impl<T, const W: usize> Eq for Window<T, W> {}

/// [`Window::at_rest`].
impl<T, const W: usize> Default for Window<T, W> {
    fn default() -> Self {
        Self::at_rest()
    }
}

impl<T, const W: usize> Window<T, W> {
    /// The largest stored term, `⌊(2⁶⁴ − 1)/W⌋` (`u64::MAX` for `W = 0`).
    const CAP: u64 = if W == 0 {
        u64::MAX
    } else {
        u64::MAX / W as u64
    };

    /// An empty window (no term held, none skipped). `const fn` (a `static` of a window
    /// needs no run-time start); equal to `Window::default()`. Cost: `W` stores.
    ///
    /// ```
    /// use aemstep::detection::Window;
    /// static WIN: Window<f32, 50> = Window::at_rest();
    /// assert!(WIN.is_empty() && WIN == Window::default());
    /// ```
    pub const fn at_rest() -> Self {
        Self {
            terms: [0; W],
            head: 0,
            len: 0,
            sum: 0,
            skipped: 0,
            scalar: PhantomData,
        }
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

impl<T: Real, const W: usize> Window<T, W> {
    /// Push a term `q ≥ 0` (dimensionless, e.g. [`Whitener::nis`]), dropping the oldest
    /// once `W` are held. NaN: skipped, counted. `+∞` or a term above the cap: stored as
    /// the cap. A window of `W = 0` holds nothing. The rounding to fixed point is done in
    /// `T` (the value `f64` arithmetic gives). Cost `O(1)`.
    #[inline]
    pub fn push(&mut self, q: T) {
        self.push_fixed(Sealed::fixed_round(q, NIS_FRACTION_BITS));
    }

    /// The sum of the held terms (dimensionless): [`Window::sum_fixed`] converted to `T`
    /// (rounded once) and scaled by `2⁻²⁴` (exact), so within `len()·2⁻²⁵` of the terms'
    /// exact sum plus the rounding of `T`. No `f64` in an `f32` window. Cost: a
    /// conversion and a multiply.
    pub fn sum(&self) -> T {
        // `from_u64` is `as` (never `None` for a float); 2⁻²⁴ is exact in both types.
        T::from_u64(self.sum).unwrap_or_else(T::zero) * T::from_f64_rounded(1.0 / NIS_SCALE)
    }
}

/// The threshold of a window of `W` samples of `per_sample` degrees of freedom at `alpha`:
/// `(dof, threshold, threshold in fixed point)`.
const fn test_parts<const W: usize>(
    per_sample: usize,
    alpha: f64,
) -> Result<(u64, f64, u64), Error> {
    if W == 0 {
        return Err(Error::InvalidParameter(Param::Window));
    }
    if per_sample == 0 {
        return Err(Error::InvalidParameter(Param::Outputs));
    }
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(Error::InvalidParameter(Param::FalseAlarm));
    }
    let dof = (W as u64).saturating_mul(per_sample as u64);
    let threshold = chi_square_quantile(dof, alpha);
    let cap = (u64::MAX / W as u64) as f64 / NIS_SCALE;
    if !(threshold.is_finite() && threshold < cap) {
        return Err(Error::InvalidParameter(Param::Threshold));
    }
    Ok((dof, threshold, (threshold * NIS_SCALE) as u64))
}

/// The windowed χ² test: alarm when the sum of the normalized innovations squared over
/// the last `W` samples exceeds the upper `α` quantile of `χ²` with `W·k` degrees of
/// freedom, `k` the estimator's [`Innovations::DOF`] (`O` measurements of an observer,
/// `O − I` of the joint input–state estimator). Under the model the window's sum is
/// `χ²_{W·k}`, so each evaluation on a full window is a false alarm with probability `α`
/// (to the accuracy of [`chi_square_quantile`]). Plain data; `const fn` construction.
///
/// The threshold is computed in `f64` and held twice: in the window's fixed point (the
/// comparison, exact integers) and rounded once to `T` ([`ChiSquareTest::threshold`], to
/// log beside [`Window::sum`] with no `f64`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiSquareTest<T, const W: usize> {
    dof: u64,
    alpha: T,
    threshold: T,
    threshold_fixed: u64,
}

impl<T: Real, const W: usize> ChiSquareTest<T, W> {
    /// The test of a window of `W` samples of `estimator`'s innovations (only its type is
    /// read: [`Innovations::DOF`] degrees of freedom a sample), at false-alarm probability
    /// `alpha` per evaluation (`0 < alpha < 1`). Bit-identical to the `const fn`
    /// `ChiSquareTest::new_f32`/`new_f64`.
    ///
    /// Errors: [`Error::InvalidParameter`] (`W = 0`, no degree of freedom, `alpha` NaN or
    /// outside `(0, 1)`, or a threshold of `2⁴⁰/W` or more, where [`Window`] caps its
    /// terms: `W·k` beyond about `10⁶`). Cost: a few hundred flops.
    ///
    /// ```
    /// use aemstep::detection::{ChiSquareTest, Dof};
    /// // 100 samples, 2 degrees of freedom each (three sensors, one identified force).
    /// let t = ChiSquareTest::<f64, 100>::new(&Dof::<2>, 1e-6)?;
    /// assert_eq!(t.dof(), 200);
    /// assert!((t.threshold() - 310.0).abs() < 1.0);
    /// # Ok::<(), aemstep::Error>(())
    /// ```
    pub fn new<E: Innovations + ?Sized>(estimator: &E, alpha: f64) -> Result<Self, Error> {
        let _ = estimator;
        let (dof, threshold, threshold_fixed) = test_parts::<W>(E::DOF, alpha)?;
        Ok(Self {
            dof,
            alpha: T::from_f64_rounded(alpha),
            threshold: T::from_f64_rounded(threshold),
            threshold_fixed,
        })
    }

    /// Degrees of freedom of the window's sum, `W·k`.
    pub const fn dof(&self) -> u64 {
        self.dof
    }

    /// The false-alarm probability per evaluation (rounded to `T`).
    pub fn false_alarm(&self) -> T {
        self.alpha
    }

    /// The threshold (dimensionless): the upper `α` quantile of `χ²_{W·k}`, rounded once
    /// to `T`.
    pub fn threshold(&self) -> T {
        self.threshold
    }

    /// The threshold in the window's fixed point (units of `2⁻²⁴`): the alarm is
    /// `sum_fixed() > threshold_fixed()`.
    pub const fn threshold_fixed(&self) -> u64 {
        self.threshold_fixed
    }

    /// Alarm: the window is full and its sum exceeds the threshold. Cost: a comparison.
    pub fn alarm(&self, window: &Window<T, W>) -> bool {
        window.is_full() && window.sum_fixed() > self.threshold_fixed
    }
}

macro_rules! chi_square_const {
    ($t:ident, $new:ident) => {
        impl<const W: usize> ChiSquareTest<$t, W> {
            /// `const fn` twin of [`ChiSquareTest::new`], bit-identical to it (in a
            /// `static`, the compiler computes the threshold). Errors: as
            /// [`ChiSquareTest::new`].
            pub const fn $new<E: Innovations + ?Sized>(
                estimator: &E,
                alpha: f64,
            ) -> Result<Self, Error> {
                let _ = estimator;
                match test_parts::<W>(E::DOF, alpha) {
                    Ok((dof, threshold, threshold_fixed)) => Ok(Self {
                        dof,
                        alpha: alpha as $t,
                        threshold: threshold as $t,
                        threshold_fixed,
                    }),
                    Err(e) => Err(e),
                }
            }
        }
    };
}
chi_square_const!(f32, new_f32);
chi_square_const!(f64, new_f64);

/// A [`Whitener`] and a [`ChiSquareTest`]: one call per sample, beside the observer.
/// Plain data (`static`-able: both parts have `const fn` constructors, and
/// [`Detector::from_parts`] is one). Its state is a [`Window`] of the same `T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detector<T, const O: usize, const W: usize> {
    /// The innovations' normalization.
    pub whitener: Whitener<T, O>,
    /// The test on the window.
    pub test: ChiSquareTest<T, W>,
}

impl<T: Real, const O: usize, const W: usize> Detector<T, O, W> {
    /// The detector of `whitener`'s innovations with `test` (built for the same
    /// estimator). `const fn`. Cost: a copy.
    pub const fn from_parts(whitener: Whitener<T, O>, test: ChiSquareTest<T, W>) -> Self {
        Self { whitener, test }
    }

    /// Push the innovation `nu` (output units; a NaN entry: skipped, counted in
    /// [`Window::skipped`]) and test: `true` is an alarm. No allocation, no panic, no
    /// `f64` for `T = f32`. Cost: `O(O+1)/2` multiply-adds and `O(1)`.
    #[inline]
    pub fn update(&self, window: &mut Window<T, W>, nu: &SVector<T, O>) -> bool {
        window.push(self.whitener.nis(nu));
        self.test.alarm(window)
    }
}
