//! Response spectra: a bank of damped oscillators fed one ground-acceleration sample at a
//! time ([`Bank`], `no_std`, allocation-free, `f32`/`f64`), the orientation-independent
//! RotD50/RotD100 of two horizontal components ([`RotD`]), and, with the `std` feature,
//! many records in parallel on the host (`batch`).
//!
//! ```
//! use aemstep::spectrum::Bank;
//!
//! // 3 periods, 5 % damping, h = 0.01 s; operators computed by the compiler.
//! static BANK: Bank<f32, 3> = match Bank::new_f32([0.1, 0.5, 2.0], [0.05; 3], 0.01) {
//!     Ok(b) => b,
//!     Err(e) => panic!("{}", e.as_str()),
//! };
//! let mut r = BANK.at_rest();
//! for n in 0..1000 {
//!     let ag = (6.0 * n as f32 * 0.01).sin(); // m/s²
//!     BANK.step(&mut r, ag);
//! }
//! BANK.free_vibration(&mut r, BANK.free_vibration_samples());
//! let (sd, psa) = (r.sd(), BANK.psa(r.sd())); // m, m/s²
//! assert!(sd[0] > 0.0 && psa[2] > 0.0);
//! ```
//!
//! **Schemes** ([`Scheme`]): `Exact` (default) steps each oscillator exactly for a ground
//! acceleration linear between samples (the piecewise-exact method of Nigam and Jennings;
//! operators by a `const fn` matrix exponential); `Aem` is the analog equation method
//! (Newmark average acceleration), second order, with the same cost per step here (its
//! whole-interval map is the composition of its sub-steps, so sub-steps also make its
//! state more accurate); it is kept for the speed–accuracy comparison.
//!
//! **Short periods** ([`Substeps`]): the state at the samples is exact whatever `T/h`,
//! but the peak falls between samples. Oscillator `p` has `n_p` sub-steps per sample
//! (load linear between samples) at whose ends the peaks are taken; they are walked only
//! for the intervals where a bound on the motion says the peak could rise (about 2 % of
//! them on El Centro, [`Response::walks`]), so the cost per sample stays close to one
//! vectorized step of the bank. The default rule [`Substeps::AUTO`] was chosen by
//! measurement (`docs/spectrum.md`).
//!
//! **Long periods**: the peak can come after the record ends. [`Bank::step`] stops with
//! the last sample; [`Bank::free_vibration`] continues with zero ground acceleration, and
//! [`Bank::free_vibration_samples`] (one period of the longest oscillator) is long enough.
//! The difference it makes on El Centro is in `docs/spectrum.md`.
//!
//! **Inelastic spectra** ([`inelastic`]): a bank of yielding oscillators (bilinear with
//! kinematic hardening, elastic–perfectly plastic at `α = 0`) stepped by the same AEM
//! kinematics, the implicit step solved exactly by return mapping at a fixed cost; over a
//! record, the constant-strength spectrum (ductility for given `R`) and the
//! constant-ductility spectrum (the largest strength giving a target ductility, bracketed
//! on a grid then refined by a safeguarded root find).
//!
//! **Bad input**: a non-positive or non-finite period, periods out of order, or a damping
//! ratio outside `[0, 1)` are typed errors at build time ([`Error::InvalidPeriod`],
//! [`Error::InvalidDamping`]).
//!
//! **Non-finite samples** (NaN, ±∞) follow the bank's [`NonFinite`] policy, one rule for
//! every record-level and checked call ([`Bank`], [`RotD`], [`inelastic::Yielding`],
//! `batch::spectra`, and `ida::spectral_acceleration`
//! with `std`). By default ([`NonFinite::Refuse`]) such a sample is
//! [`Error::NonFiniteInput`]: the checked steps leave the response unchanged (its
//! [`Response::samples`] is then the index of the refused sample), the record-level calls
//! refuse the record before stepping it ([`first_non_finite`] gives the index of the sample
//! they refused). With [`NonFinite::Skip`], chosen explicitly
//! ([`Bank::with_non_finite`], [`inelastic::Yielding::with_non_finite`]), the sample is
//! skipped: the last finite sample is held in its place (`0`, the value at rest, before
//! any), time still advances, and it is counted ([`Response::skipped`],
//! [`inelastic::YieldResponse::skipped`],
//! [`inelastic::ConstantDuctility::skipped`]). The unchecked [`Bank::step`] keeps its cost
//! and has no error to return: it always skips and counts, whatever the policy.
//!
//! **Extreme records**: a *finite* sample so large that a state or a peak overflows
//! (`±1e308`, or a record times `1e290`) is an error, never a response with `±∞`/NaN in
//! it: the checked steps ([`Bank::try_step`], [`RotD::try_step`],
//! [`inelastic::Yielding::try_step`]) leave the response unchanged and return
//! [`Error::NonFiniteState`]; the record-level calls ([`Bank::response`],
//! [`inelastic::Yielding::response`] and the spectra built on it, `batch::spectra`) return
//! it too, and [`Error::OperatorOverflow`] for a derived result that overflows (a
//! ductility, a pseudo-acceleration). The unchecked [`Bank::step`] keeps its cost and does
//! not check. A time step so small that the free-vibration tail would exceed
//! [`MAX_FREE_VIBRATION_SAMPLES`] is [`Error::InvalidTimeStep`] in the record-level calls.
//!
//! [`Error::NonFiniteState`]: crate::Error::NonFiniteState
//! [`Error::InvalidTimeStep`]: crate::Error::InvalidTimeStep
//! [`Error::OperatorOverflow`]: crate::Error::OperatorOverflow
//!
//! [`Error::InvalidPeriod`]: crate::Error::InvalidPeriod
//! [`Error::InvalidDamping`]: crate::Error::InvalidDamping
//! [`Error::NonFiniteInput`]: crate::Error::NonFiniteInput

mod bank;
mod operators;
mod rotd;

pub mod inelastic;

#[cfg(feature = "std")]
#[cfg_attr(docsrs, doc(cfg(feature = "std")))]
pub mod batch;

pub use bank::{Bank, Response};
pub use rotd::{RotD, RotDResponse};

/// `x` is finite: `x − x` is 0 exactly for finite `x` (NaN for NaN and ±∞). Only ring
/// operations, so it holds for any [`Real`](crate::Real).
#[inline(always)]
#[allow(clippy::eq_op)]
pub(crate) fn finite<T: crate::Real>(x: T) -> bool {
    x - x == T::from_f64_rounded(0.0)
}

/// What the checked and record-level calls of a spectrum bank do with a non-finite
/// ground-acceleration sample (NaN, ±∞): one policy for the elastic [`Bank`] (and the
/// [`RotD`] stepped on it, and `batch::spectra`) and the yielding
/// [`inelastic::Yielding`], chosen when the bank is built ([`Bank::with_non_finite`],
/// [`inelastic::Yielding::with_non_finite`]; `const fn`). The default is
/// [`NonFinite::Refuse`]. The unchecked steps ([`Bank::step`], [`RotD::step`],
/// [`inelastic::Yielding::step`]) have no error to return and always skip. Cost of the
/// check: one comparison per sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum NonFinite {
    /// The sample is [`Error::NonFiniteInput`](crate::Error::NonFiniteInput): a checked
    /// step (`try_step`) leaves the response unchanged, a record-level call (`response`,
    /// the spectra) refuses the whole record before stepping it ([`first_non_finite`]
    /// names the sample). The default: a record with NaN in it has no spectrum.
    #[default]
    Refuse,
    /// The sample is skipped: the last finite sample is held in its place (`0`, the
    /// value at rest, if none came before), time still advances by `h`, so later samples
    /// stay on their times, and it is counted (`skipped`). For records with known gaps;
    /// the result is that of the record with each gap filled by the sample before it.
    Skip,
}

/// The index of the first non-finite sample (NaN, ±∞) of `record`, `None` if every
/// sample is finite: the sample a record-level call refuses with
/// [`Error::NonFiniteInput`](crate::Error::NonFiniteInput) under [`NonFinite::Refuse`]
/// (the error itself carries no index). Cost: a scan, one comparison per sample.
///
/// ```
/// use aemstep::{Error, spectrum::{Bank, first_non_finite}};
/// let bank = Bank::<f64, 2>::new([0.2, 1.0], [0.05; 2], 0.01)?;
/// let record = [0.0, 1.0, f64::NAN, 0.5];
/// assert_eq!(bank.response(&record), Err(Error::NonFiniteInput));
/// assert_eq!(first_non_finite(&record), Some(2));
/// # Ok::<(), Error>(())
/// ```
pub fn first_non_finite<T: crate::Real>(record: &[T]) -> Option<usize> {
    record.iter().position(|&a| !finite(a))
}

/// The number of non-finite samples of `record`: what [`NonFinite::Skip`] skips.
pub(crate) fn non_finite_count<T: crate::Real>(record: &[T]) -> u64 {
    record.iter().filter(|&&a| !finite(a)).count() as u64
}

/// `Err(NonFiniteInput)` if `policy` refuses and `record` has a non-finite sample.
/// Cost: a scan under [`NonFinite::Refuse`], none under [`NonFinite::Skip`].
pub(crate) fn check_record<T: crate::Real>(
    policy: NonFinite,
    record: &[T],
) -> Result<(), crate::Error> {
    match policy {
        NonFinite::Refuse if !all_finite(record) => Err(crate::Error::NonFiniteInput),
        _ => Ok(()),
    }
}

/// `Err(NonFiniteInput)` if `policy` refuses and the sample `ag` is not finite. Cost: one
/// comparison.
#[inline(always)]
pub(crate) fn check_sample<T: crate::Real>(policy: NonFinite, ag: T) -> Result<(), crate::Error> {
    if policy == NonFinite::Refuse && !finite(ag) {
        Err(crate::Error::NonFiniteInput)
    } else {
        Ok(())
    }
}

/// A bank's bookkeeping of one new ground-acceleration sample `ag` (shared by [`Bank`] and
/// [`inelastic::Yielding`]): a non-finite sample is counted in `skipped` and replaced by the
/// last finite one ([`NonFinite::Skip`]); `last` becomes the sample held; the first sample (at rest, `t = 0`)
/// closes no interval, every later one the interval `(a_{n−1}, a_n)` returned.
/// Cost: a few comparisons.
#[inline(always)]
pub(crate) fn take_sample<T: crate::Real>(
    last: &mut T,
    samples: &mut u64,
    skipped: &mut u64,
    ag: T,
) -> Option<(T, T)> {
    let a1 = if finite(ag) {
        ag
    } else {
        *skipped += 1;
        *last
    };
    let first = *samples == 0;
    *samples += 1;
    let a0 = core::mem::replace(last, a1);
    (!first).then_some((a0, a1))
}

/// One period of the longest oscillator in samples of `h`, `⌈T_max/h⌉` (saturating at
/// `u32::MAX`): the free vibration that catches every peak after a record. Cost: a scan.
pub(crate) fn longest_period_samples(periods: &[f64], h: f64) -> u32 {
    let t = periods
        .iter()
        .fold(0.0f64, |m, &p| if p > m { p } else { m });
    let x = t / h;
    let f = x as u32; // saturating cast
    if (f as f64) < x {
        f.saturating_add(1)
    } else {
        f
    }
}

/// The longest free-vibration tail (samples of `h`) the record-level calls append
/// ([`inelastic::Yielding::response`], [`Bank::response`],
/// `ida::spectral_acceleration` with `std`): `2²⁰ = 1 048 576`, one period of
/// `T_max = 10 s` down to `h ≈ 1e-5 s`. A tail of one longest period
/// (`⌈T_max/h⌉`, [`Bank::free_vibration_samples`]) longer than this is refused with
/// [`Error::InvalidTimeStep`](crate::Error::InvalidTimeStep) rather than stepped: at
/// `h = 1e-9 s` it would be `10⁹` samples (minutes of stepping per pass, hours for a
/// constant-ductility search). Resample the record to a coarser step
/// ([`records::resample_into`](crate::records::resample_into)) instead.
pub const MAX_FREE_VIBRATION_SAMPLES: u32 = 1 << 20;

/// The free-vibration tail of a record-level call: one longest period in samples of `h`,
/// refused above [`MAX_FREE_VIBRATION_SAMPLES`]. Cost: a scan of the periods.
pub(crate) fn checked_tail(periods: &[f64], h: f64) -> Result<u32, crate::Error> {
    let n = longest_period_samples(periods, h);
    if n > MAX_FREE_VIBRATION_SAMPLES {
        Err(crate::Error::InvalidTimeStep)
    } else {
        Ok(n)
    }
}

/// Every value of `xs` is finite. Cost: a scan.
#[inline]
pub(crate) fn all_finite<T: crate::Real>(xs: &[T]) -> bool {
    let mut ok = true;
    for &x in xs {
        ok &= finite(x);
    }
    ok
}

/// The smallest positive normal value of `T` (`MIN_POSITIVE`), as `f64`.
pub(crate) fn min_normal<T: crate::Real>() -> f64 {
    if T::MAX > f32::MAX as f64 {
        f64::MIN_POSITIVE
    } else {
        f32::MIN_POSITIVE as f64
    }
}

/// The largest number of sub-steps per sample an oscillator takes (`Substeps` is clamped
/// to it).
pub const MAX_SUBSTEPS: u16 = 1024;

/// The stepping scheme of a [`Bank`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Scheme {
    /// Exact for a ground acceleration linear between samples (matrix exponential of the
    /// augmented system): error only from rounding and the load's interpolation.
    Exact,
    /// The analog equation method (Newmark average acceleration): unconditionally stable,
    /// second order; period elongation `(ωh)²/12` relative.
    Aem,
}

/// How many sub-steps per sample each oscillator takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Substeps {
    /// The same count for every oscillator (`1 ..= MAX_SUBSTEPS`).
    Fixed(u16),
    /// `n_p = ⌈r·h/T_p⌉`, clamped to `1 ..= MAX_SUBSTEPS`: at least `r` points per period
    /// where the peak is taken (`r ≥ 1`).
    PointsPerPeriod(u16),
}

impl Substeps {
    /// The default rule, chosen by measurement (`docs/spectrum.md`, short-period table).
    pub const AUTO: Substeps = Substeps::PointsPerPeriod(20);
}
