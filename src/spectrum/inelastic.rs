//! Inelastic response spectra: a bank of yielding oscillators ([`Yielding`]) fed one
//! ground-acceleration sample at a time (`no_std`, allocation-free, `f32`/`f64`), and over
//! a whole record ([`&[T]`](slice)) the constant-strength spectrum (ductility demand for
//! given strength-reduction factors, [`Yielding::constant_strength`]) and the
//! constant-ductility spectrum (the strength giving a target ductility, by a safeguarded
//! root find, [`Yielding::constant_ductility`]).
//!
//! ```
//! use aemstep::spectrum::inelastic::{Search, Yielding};
//!
//! // 3 periods, 5 % damping, elastic–perfectly plastic (α = 0), h = 0.01 s.
//! static BANK: Yielding<f64, 3> = match Yielding::new_f64([0.2, 0.5, 1.0], [0.05; 3], 0.0, 0.01) {
//!     Ok(b) => b,
//!     Err(e) => panic!("{}", e.as_str()),
//! };
//! let record: Vec<f64> = (0..1000).map(|n| 3.0 * (7.0 * n as f64 * 0.01).sin()).collect(); // m/s²
//!
//! // Constant strength: R = 4 at every period; ductility demand μ = max|u| / u_y.
//! let cs = BANK.constant_strength(&record, &[4.0; 3])?;
//! assert!(cs.ductility.iter().all(|&mu| mu > 1.0));
//!
//! // Constant ductility: the largest strength f_y/m (m/s²) with μ = 4.
//! let cd = BANK.constant_ductility(&record, 4.0, &Search::DEFAULT)?;
//! assert!(cd.yield_acceleration[1] < cd.elastic[1]);
//!
//! // Streaming, one sample at a time, with strengths of your own (f_y/m, m/s²).
//! let mut r = BANK.at_rest(&[1.0; 3])?;
//! for &a in &record {
//!     BANK.step(&mut r, a);
//! }
//! let mu = r.ductility();
//! # let _ = mu;
//! # Ok::<(), aemstep::Error>(())
//! ```
//!
//! **The oscillator** (per unit mass, initial period `T_p`, `ω_p = 2π/T_p`, damping ratio
//! `ζ_p` on the initial stiffness): `u'' + 2ζω u' + f(u) = −a_g(t)`, `u` relative to the
//! ground, `f` the restoring force per unit mass (m/s²): bilinear with kinematic hardening,
//! initial stiffness `ω²`, yield force `a_y = f_y/m`, post-yield stiffness `αω²`
//! (`α ∈ [0, 1)`; `α = 0` is elastic–perfectly plastic), the law of
//! [`hysteresis::Bilinear`](crate::hysteresis::Bilinear): elastic inside the band
//! `|f − αω²u| ≤ (1 − α) a_y`, on its edges `f = αω²u ± (1 − α) a_y` while yielding. Yield
//! displacement `u_y = a_y/ω²`, ductility `μ = max|u| / u_y`.
//!
//! **The step** is the AEM (Newmark average acceleration, the kinematics of
//! [`Scheme::Aem`](super::Scheme::Aem)), implicit, with the equation of motion at the end
//! of the step: `κ Δu + f(u₀ + Δu) = (4/h) v₀ − f₀ − (a_{g0} + a_{g1})`,
//! `κ = 4/h² + 2c/h`, `c = 2ζω`, `v₁ = (2/h) Δu − v₀`. Its left side is strictly
//! increasing and piecewise linear in `Δu`, so the step has one solution, found exactly
//! without iteration by return mapping: the elastic trial `Δu = (b − f₀)/(κ + ω²)`; if it
//! leaves the band on side `s = ±1`, the plastic re-solve
//! `Δu = (b − αω²u₀ − s(1 − α)a_y)/(κ + αω²)`, `f₁ = αω²u₁ + s(1 − α)a_y` (a step that
//! goes from one edge past the other is caught too: `s` is the side left). This is the
//! solution the crate's nonlinear AEM with Newton converges to, at a fixed cost: about
//! 30 flops and 4 comparisons per sub-step, the peak and the plastic work included (both
//! branches computed, then selected: the work does not depend on the data). With `a_y = +∞` the oscillator never yields and the step is the
//! elastic [`Bank`](super::Bank) with [`Scheme::Aem`](super::Scheme::Aem) (same sub-steps),
//! to rounding.
//!
//! **Sub-steps**: the load is linear between samples and each sample interval is `n_p`
//! sub-steps ([`Substeps`], as in the elastic bank, default [`Yielding::SUBSTEPS`] = 40 points
//! per initial period); every sub-step is taken (a yielding step cannot be composed into
//! one map), and the peaks are taken at the sub-step ends. Measured on El Centro
//! (`tests/inelastic.rs`, 10 periods 0.1–3 s, 5 %, EPP and `α = 0.05`, `R = 2, 4`): the
//! worst ductility error is 7.6e-3 relative with 20 points per period, 2.7e-3 with 40,
//! 9.4e-4 with 80 (against 2 000, EPP, `R = 4`), and against the independent reference
//! 6.1e-3 at 40 (1.3e-4 at 400); 40 cuts the error of 20 by about 3 for twice the
//! sub-steps, and is within 1 % everywhere tested.
//!
//! **Cost**: [`Yielding::step`] is `Σ_p n_p` sub-steps per sample
//! ([`Yielding::substeps_per_sample`]; on the host, x86-64, about 8 ns per oscillator
//! sub-step in `f64` and 9 in `f32`: a serial chain per oscillator, not vectorized across
//! the bank; it is the step the Cortex-M firmware and streaming use). The record-level
//! calls ([`Yielding::response`] and the spectra) instead step the oscillators 4 at a time
//! side by side in SIMD lanes (`f64 × 4` with AVX, chosen at run time, `× 2` on SSE2), each
//! group over the whole record, a lane with fewer sub-steps a sample than its group's
//! most frozen for the rest (its state kept by a select), with exactly the scalar step's
//! operations: the same bits (`tests/inelastic_lanes.rs`); the constant-ductility search
//! steps only the trials not yet finished. Measured (host timing, `cargo bench -p xtask
//! --bench inelastic`, 40 periods 0.05–3 s, El Centro, 240 searches): 2.0 s before, 0.55 s
//! after. A *record pass* is `N` samples plus
//! [`Yielding::free_vibration_samples`] of free vibration: the constant-strength spectrum
//! takes 2 passes, the constant-ductility spectrum `1 + (points − 1) + refinement` at most
//! (see [`Yielding::constant_ductility`]; the passes are reported). No allocation, no
//! panic.
//!
//! **Bad input**: periods and damping as the elastic bank ([`Error::InvalidPeriod`],
//! [`Error::InvalidDamping`], [`Error::InvalidTimeStep`], [`Error::OperatorOverflow`]); a
//! post-yield ratio outside `[0, 1)` or a yield strength not `> 0` (NaN) is
//! [`Error::InvalidMaterial`], as for [`hysteresis::Bilinear`](crate::hysteresis::Bilinear);
//! a strength-reduction factor, target ductility or search setting out of range is
//! [`Error::InvalidParameter`]. A non-finite sample follows the bank's
//! [`NonFinite`] policy, as in the elastic bank: by default
//! [`Error::NonFiniteInput`] ([`Yielding::try_step`] leaves the response unchanged; the
//! record-level calls refuse the record before stepping it); with
//! [`Yielding::with_non_finite`]`(NonFinite::Skip)` it is held and counted
//! ([`YieldResponse::skipped`], [`ConstantDuctility::skipped`]).
//!
//! **Extreme records**: every field of a record-level result is finite, or the call is a
//! typed error: a finite sample that makes the response overflow (one sample of `5e307`
//! m/s²) is [`Error::NonFiniteState`] ([`Yielding::try_step`] leaves the response
//! unchanged; [`Yielding::response`] and the spectra check it once per pass), a ductility
//! or elastic strength that overflows is [`Error::OperatorOverflow`], a strength whose
//! yield displacement is subnormal is [`Error::InvalidMaterial`] from
//! [`Yielding::at_rest`] and [`Error::OperatorUnderflow`] from the spectra (`R = 1e308`),
//! and a free-vibration tail over
//! [`MAX_FREE_VIBRATION_SAMPLES`](super::MAX_FREE_VIBRATION_SAMPLES) is
//! [`Error::InvalidTimeStep`].

use super::bank::{Oscillator, check_interval, oscillator};
use super::{NonFinite, Substeps};
use crate::linalg::all_fit;
use crate::macros::const_try;
use crate::{Error, Param, Real};

/// A bank of `P` yielding single-degree-of-freedom oscillators (bilinear, kinematic
/// hardening, post-yield ratio `α` shared by the bank; see the [module](self)), fed one
/// ground-acceleration sample at a time. The strengths are not part of the bank: each
/// [`YieldResponse`] carries its own ([`Yielding::at_rest`]), so one bank serves every
/// strength of a root find.
///
/// Non-finite samples follow the bank's [`NonFinite`] policy
/// ([`Yielding::with_non_finite`]; by default refused by the checked and record-level
/// calls).
///
/// Size: `9P + 1` values of `T`, `2P` bytes, `2P + 2` `f64` and the policy byte.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Yielding<T, const P: usize> {
    /// `ω²` (1/s²).
    w2: [T; P],
    /// `1/ω²` (s²).
    inv_w2: [T; P],
    /// `αω²` (1/s²).
    aw2: [T; P],
    /// `H = αω²/(1 − α)` (1/s²): the back force per unit plastic deformation.
    hard: [T; P],
    /// `4/h_s` (1/s), `h_s = h/n_p`.
    four_h: [T; P],
    /// `2/h_s` (1/s).
    two_h: [T; P],
    /// `1/(κ + ω²)`, `κ = 4/h_s² + 4ζω/h_s` (s²).
    inv_de: [T; P],
    /// `1/(κ + αω²)` (s²).
    inv_dp: [T; P],
    /// `1/n_p`.
    inv_n: [T; P],
    /// `1 − α`.
    one_minus_alpha: T,
    /// Sub-steps per sample `n_p`.
    n: [u16; P],
    /// Periods (s), as given.
    period: [f64; P],
    /// Damping ratios, as given.
    damping: [f64; P],
    /// Post-yield ratio `α`, as given.
    alpha: f64,
    /// Sample interval `h` (s).
    time_step: f64,
    /// What the checked calls do with a non-finite sample.
    non_finite: NonFinite,
}

/// The coefficients of a bank in `f64`, before rounding to `T` (shared by the `const` and
/// the generic constructors, so both round the same values).
struct Coeffs<const P: usize> {
    c: [[f64; P]; 9],
    n: [u16; P],
}

/// Check the inputs and compute the `f64` coefficients (`max`: the largest finite value of
/// the scalar type they are rounded to).
const fn coeffs<const P: usize>(
    period: &[f64; P],
    damping: &[f64; P],
    alpha: f64,
    h: f64,
    rule: Substeps,
    max: f64,
) -> Result<Coeffs<P>, Error> {
    const_try!(check_interval(h, rule));
    let mut out = Coeffs {
        c: [[0.0; P]; 9],
        n: [1; P],
    };
    // Bad data (periods, damping, α) is reported before an overflow.
    let mut fits = true;
    let mut p = 0;
    while p < P {
        let Oscillator { w, z, n, hs } = const_try!(oscillator(period, damping, p, h, rule));
        let w2 = w * w;
        let kappa = 4.0 / (hs * hs) + 4.0 * z * w / hs;
        let aw2 = alpha * w2;
        let row = [
            w2,
            1.0 / w2,
            aw2,
            aw2 / (1.0 - alpha),
            4.0 / hs,
            2.0 / hs,
            1.0 / (kappa + w2),
            1.0 / (kappa + aw2),
            1.0 / n as f64,
        ];
        fits &= all_fit(&row, max) && kappa.is_finite() && row[6] > 0.0 && row[7] > 0.0;
        let mut k = 0;
        while k < 9 {
            out.c[k][p] = row[k];
            k += 1;
        }
        out.n[p] = n;
        p += 1;
    }
    if !(alpha.is_finite() && alpha >= 0.0 && alpha < 1.0) {
        return Err(Error::InvalidMaterial(Param::PostYieldRatio));
    }
    if !fits {
        return Err(Error::OperatorOverflow);
    }
    Ok(out)
}

/// The `const fn` constructors of `Yielding<f32, P>` and `Yielding<f64, P>`.
macro_rules! yielding_ctor {
    ($t:ident, $new:ident, $with:ident) => {
        impl<const P: usize> Yielding<$t, P> {
            /// `const fn` twin of [`Yielding::new`] (same arguments, checks and errors),
            /// bit-identical to it: in a `static`, the compiler computes the coefficients.
            ///
            /// Errors: as [`Yielding::new`].
            pub const fn $new(
                period: [f64; P],
                damping: [f64; P],
                alpha: f64,
                h: f64,
            ) -> Result<Self, Error> {
                Self::$with(period, damping, alpha, h, Yielding::<$t, P>::SUBSTEPS)
            }

            /// `const fn` twin of [`Yielding::with`], bit-identical to it.
            ///
            /// Errors: as [`Yielding::with`].
            pub const fn $with(
                period: [f64; P],
                damping: [f64; P],
                alpha: f64,
                h: f64,
                substeps: Substeps,
            ) -> Result<Self, Error> {
                let o = const_try!(coeffs(
                    &period,
                    &damping,
                    alpha,
                    h,
                    substeps,
                    $t::MAX as f64
                ));
                let mut c = [[0.0 as $t; P]; 9];
                let mut k = 0;
                while k < 9 {
                    let mut p = 0;
                    while p < P {
                        c[k][p] = o.c[k][p] as $t;
                        p += 1;
                    }
                    k += 1;
                }
                Ok(Yielding {
                    w2: c[0],
                    inv_w2: c[1],
                    aw2: c[2],
                    hard: c[3],
                    four_h: c[4],
                    two_h: c[5],
                    inv_de: c[6],
                    inv_dp: c[7],
                    inv_n: c[8],
                    one_minus_alpha: (1.0 - alpha) as $t,
                    n: o.n,
                    period,
                    damping,
                    alpha,
                    time_step: h,
                    non_finite: NonFinite::Refuse,
                })
            }
        }
    };
}
yielding_ctor!(f32, new_f32, with_f32);
yielding_ctor!(f64, new_f64, with_f64);

/// The running response of a [`Yielding`] bank: each oscillator's state, its strength and
/// its peaks so far. Start with [`Yielding::at_rest`]; feed samples with
/// [`Yielding::step`].
///
/// Units follow the samples (m/s² in, m out). Size: `9P + 1` values of `T`, `P` `u32` and
/// two counters.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct YieldResponse<T, const P: usize> {
    u: [T; P],
    v: [T; P],
    /// Restoring force per unit mass `f(u)` (m/s²).
    f: [T; P],
    /// Yield strength per unit mass `a_y = f_y/m` (m/s²).
    ay: [T; P],
    /// `(1 − α) a_y`: the half-width of the elastic band.
    lim: [T; P],
    sd: [T; P],
    /// Plastic work per unit mass `∫ f dd_p` (m²/s²).
    work: [T; P],
    /// Accumulated plastic deformation `Σ |Δd_p|` (m).
    plastic: [T; P],
    /// Yield displacement `u_y = a_y/ω²` (m).
    uy: [T; P],
    /// Sub-steps on which each oscillator yielded.
    yielding: [u32; P],
    last: T,
    samples: u64,
    skipped: u64,
}

impl<T: Real, const P: usize> YieldResponse<T, P> {
    /// Peak relative displacement `max |u|` of each oscillator so far (m). Cost: none.
    pub fn sd(&self) -> &[T; P] {
        &self.sd
    }
    /// Peak ductility `μ = max|u| / u_y` of each oscillator so far, `u_y = a_y/ω²` (`0`
    /// for `a_y = +∞`). Cost: `P` divisions.
    pub fn ductility(&self) -> [T; P] {
        let mut out = self.sd;
        for (o, &uy) in out.iter_mut().zip(self.uy.iter()) {
            *o /= uy;
        }
        out
    }
    /// Yield displacement `u_y = a_y/ω²` of each oscillator (m). Cost: none.
    pub fn yield_displacement(&self) -> &[T; P] {
        &self.uy
    }
    /// Relative displacement of each oscillator now (m); after the record, the residual
    /// (permanent) displacement once the motion has died out. Cost: none.
    pub fn displacement(&self) -> &[T; P] {
        &self.u
    }
    /// Relative velocity of each oscillator now (m/s). Cost: none.
    pub fn velocity(&self) -> &[T; P] {
        &self.v
    }
    /// Restoring force per unit mass `f(u)` of each oscillator now (m/s²). Cost: none.
    pub fn force(&self) -> &[T; P] {
        &self.f
    }
    /// Yield strength per unit mass `a_y = f_y/m` of each oscillator (m/s²), as given to
    /// [`Yielding::at_rest`]. Cost: none.
    pub fn yield_acceleration(&self) -> &[T; P] {
        &self.ay
    }
    /// Plastic work per unit mass so far, `∫ f dd_p` (m²/s²; times the mass: J), the
    /// hysteretic energy: exact for the stepped path (each yielding sub-step's path is an
    /// elastic segment then a segment on the band's edge, integrated in closed form:
    /// `Δd_p (f₁ − H Δd_p / 2)`). Cost: none.
    pub fn plastic_work(&self) -> &[T; P] {
        &self.work
    }
    /// Accumulated plastic deformation `Σ |Δd_p|` so far (m); divided by `u_y`, the
    /// cumulative ductility. Cost: none.
    pub fn plastic_deformation(&self) -> &[T; P] {
        &self.plastic
    }
    /// Sub-steps on which each oscillator yielded so far. Cost: none.
    pub fn yielding_substeps(&self) -> &[u32; P] {
        &self.yielding
    }
    /// Samples fed so far, the skipped ones included, not counting free vibration. Cost:
    /// none.
    pub fn samples(&self) -> u64 {
        self.samples
    }
    /// Non-finite samples skipped so far (see [`Yielding::step`]). Cost: none.
    pub fn skipped(&self) -> u64 {
        self.skipped
    }
    /// Every state, peak and energy is finite (`u`, `v`, `f`, `Sd`, the plastic work and
    /// deformation): what [`Yielding::try_step`] checks. Cost: a scan of `6P` values.
    pub fn is_finite(&self) -> bool {
        use super::all_finite;
        all_finite(&self.u)
            & all_finite(&self.v)
            & all_finite(&self.f)
            & all_finite(&self.sd)
            & all_finite(&self.work)
            & all_finite(&self.plastic)
    }
}

impl<T: Real, const P: usize> Yielding<T, P> {
    /// The default sub-step rule: at least 40 points per initial period (chosen by
    /// measurement, see the [module](self) documentation).
    pub const SUBSTEPS: Substeps = Substeps::PointsPerPeriod(40);

    /// A bank of yielding oscillators with initial periods `period` (s, finite, at least
    /// `1e-150`, in non-decreasing order), damping ratios `damping` (in `[0, 1)`, on the
    /// initial stiffness), post-yield stiffness ratio `alpha` (in `[0, 1)`; `0` is
    /// elastic–perfectly plastic), sample interval `h` (s, finite, `> 0`) and the sub-step
    /// rule [`Yielding::SUBSTEPS`]. Run time, for either scalar; in a `static` use the
    /// `const fn` [`Yielding::new_f32`] / [`Yielding::new_f64`], bit-identical to it.
    ///
    /// Cost: about 30 `f64` flops per oscillator, once.
    ///
    /// Errors: [`Error::InvalidPeriod`], [`Error::InvalidDamping`] (checked first, period
    /// by period), [`Error::InvalidMaterial`] (`alpha`), [`Error::InvalidTimeStep`],
    /// [`Error::OperatorOverflow`] (a coefficient such as `ω²` or `4/h²` does not fit `T`).
    pub fn new(period: [f64; P], damping: [f64; P], alpha: f64, h: f64) -> Result<Self, Error> {
        Self::with(period, damping, alpha, h, Self::SUBSTEPS)
    }

    /// As [`Yielding::new`] with the sub-step rule chosen (`const fn` twins:
    /// [`Yielding::with_f32`] / [`Yielding::with_f64`]).
    ///
    /// Errors: as [`Yielding::new`], and [`Error::InvalidParameter`] for
    /// `Substeps::Fixed(0)`, `Substeps::Fixed(n > MAX_SUBSTEPS)` or
    /// `Substeps::PointsPerPeriod(0)`.
    pub fn with(
        period: [f64; P],
        damping: [f64; P],
        alpha: f64,
        h: f64,
        substeps: Substeps,
    ) -> Result<Self, Error> {
        let o = coeffs(&period, &damping, alpha, h, substeps, T::MAX)?;
        let r = |a: &[f64; P]| a.map(T::from_f64_rounded);
        Ok(Yielding {
            w2: r(&o.c[0]),
            inv_w2: r(&o.c[1]),
            aw2: r(&o.c[2]),
            hard: r(&o.c[3]),
            four_h: r(&o.c[4]),
            two_h: r(&o.c[5]),
            inv_de: r(&o.c[6]),
            inv_dp: r(&o.c[7]),
            inv_n: r(&o.c[8]),
            one_minus_alpha: T::from_f64_rounded(1.0 - alpha),
            n: o.n,
            period,
            damping,
            alpha,
            time_step: h,
            non_finite: NonFinite::Refuse,
        })
    }

    /// A response at rest, before the first sample, with yield strengths per unit mass
    /// `yield_acceleration` (`a_y = f_y/m`, m/s²; `f_y/(m g)` is the strength ratio `η`).
    /// `+∞` is allowed: that oscillator never yields (its ductility reads `0`).
    ///
    /// Errors: [`Error::InvalidMaterial`] if a strength is NaN or not `> 0`, or so small
    /// that it, its yield displacement `a_y/ω²` or its band `(1 − α) a_y` is subnormal
    /// or zero in `T` (below `MIN_POSITIVE`: the ductility `max|u|/u_y` of a subnormal
    /// `u_y` overflows for any motion, and has lost its precision).
    /// Cost: `2P` multiplications.
    pub fn at_rest(&self, yield_acceleration: &[T; P]) -> Result<YieldResponse<T, P>, Error> {
        let zero = T::from_f64_rounded(0.0);
        let (lim, uy) = self
            .bands(yield_acceleration)
            .ok_or(Error::InvalidMaterial(Param::YieldForce))?;
        Ok(YieldResponse {
            u: [zero; P],
            v: [zero; P],
            f: [zero; P],
            ay: *yield_acceleration,
            lim,
            sd: [zero; P],
            work: [zero; P],
            plastic: [zero; P],
            uy,
            yielding: [0; P],
            last: zero,
            samples: 0,
            skipped: 0,
        })
    }

    /// The bands `(1 − α) a_y` and yield displacements `a_y/ω²` of the strengths `ay`, or
    /// `None` if a strength, band or yield displacement is NaN or below `MIN_POSITIVE` of
    /// `T` (`+∞` passes: that oscillator never yields).
    fn bands(&self, ay: &[T; P]) -> Option<([T; P], [T; P])> {
        let zero = T::from_f64_rounded(0.0);
        let tiny = T::from_f64_rounded(super::min_normal::<T>());
        let mut lim = [zero; P];
        let mut uy = [zero; P];
        for p in 0..P {
            let a = ay[p];
            lim[p] = self.one_minus_alpha * a;
            uy[p] = a * self.inv_w2[p];
            // `!(x >= tiny)` is true for NaN too
            if !(a >= tiny && lim[p] >= tiny && uy[p] >= tiny) {
                return None;
            }
        }
        Some((lim, uy))
    }

    /// Feed the next ground-acceleration sample `ag` (m/s²). Sample 0 is the ground
    /// acceleration at `t = 0` with every oscillator at rest; each later sample advances
    /// time by `h`, the load linear between samples, oscillator `p` in `n_p` sub-steps,
    /// its peak taken at their ends.
    ///
    /// Unchecked: a non-finite sample (NaN, ±∞) is skipped and counted
    /// ([`YieldResponse::skipped`]) whatever the bank's [`NonFinite`] policy
    /// ([`Yielding::try_step`] applies it): time still advances by `h` with the last finite
    /// sample held in its place, as in [`Bank::step`](super::Bank::step).
    ///
    /// Cost: `Σ_p n_p` sub-steps ([`Yielding::substeps_per_sample`]) of about 30 flops and
    /// 4 comparisons each, whatever the branch; no allocation, no panic.
    pub fn step(&self, r: &mut YieldResponse<T, P>, ag: T) {
        if let Some((a0, a1)) = super::take_sample(&mut r.last, &mut r.samples, &mut r.skipped, ag)
        {
            self.advance(r, a0, a1);
        }
    }

    /// [`Yielding::step`], checked: the sample is taken on a copy of `r`, committed only if
    /// every state, peak and energy of the copy is finite ([`YieldResponse::is_finite`]).
    /// A non-finite sample is refused under [`NonFinite::Refuse`] (the default) and
    /// skipped and counted (`Ok`) under [`NonFinite::Skip`]; a *finite* sample so large
    /// that the response overflows (one sample of `5e307` m/s² turns the state to NaN) is
    /// an error under either policy.
    ///
    /// Errors, each with `r` unchanged (so [`YieldResponse::samples`] is the index of the
    /// sample refused): [`Error::NonFiniteInput`] (a non-finite sample, refused);
    /// [`Error::NonFiniteState`]. Cost: one comparison, one [`Yielding::step`], a copy of
    /// `r` and a scan of `6P` values.
    pub fn try_step(&self, r: &mut YieldResponse<T, P>, ag: T) -> Result<(), Error> {
        super::check_sample(self.non_finite, ag)?;
        let mut next = *r;
        self.step(&mut next, ag);
        if next.is_finite() {
            *r = next;
            Ok(())
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// Continue after the record in free vibration: the ground acceleration returns
    /// linearly to zero over one `h` and stays zero for `samples − 1` more intervals
    /// (as [`Bank::free_vibration`](super::Bank::free_vibration)).
    ///
    /// Cost: `samples` times that of [`Yielding::step`].
    pub fn free_vibration(&self, r: &mut YieldResponse<T, P>, samples: u32) {
        if r.samples == 0 {
            return;
        }
        let zero = T::from_f64_rounded(0.0);
        for _ in 0..samples {
            let a0 = r.last;
            r.last = zero;
            self.advance(r, a0, zero);
        }
    }

    /// What the checked and record-level calls do with a non-finite sample
    /// ([`NonFinite::Refuse`] unless [`Yielding::with_non_finite`] chose otherwise). Cost:
    /// none.
    pub fn non_finite(&self) -> NonFinite {
        self.non_finite
    }

    /// The same bank with the non-finite-sample policy `policy` (`const fn`, as
    /// [`Bank::with_non_finite`](super::Bank::with_non_finite)). The coefficients are
    /// unchanged, so the responses to finite records are the same bits. Cost: a copy of
    /// the bank.
    pub const fn with_non_finite(self, policy: NonFinite) -> Self {
        Yielding {
            non_finite: policy,
            ..self
        }
    }

    /// One initial period of the longest oscillator, in samples (`⌈T_max/h⌉`, saturating
    /// at `u32::MAX`): the free vibration the record-level functions append to the record
    /// (they refuse more than
    /// [`MAX_FREE_VIBRATION_SAMPLES`](super::MAX_FREE_VIBRATION_SAMPLES)). Cost: a scan of
    /// the periods.
    pub fn free_vibration_samples(&self) -> u32 {
        super::longest_period_samples(&self.period, self.time_step)
    }

    /// One sample interval `a0 → a1`: `n_p` sub-steps of every oscillator.
    #[inline(always)]
    fn advance(&self, r: &mut YieldResponse<T, P>, a0: T, a1: T) {
        let d = a1 - a0;
        let zero = T::from_f64_rounded(0.0);
        let half = T::from_f64_rounded(0.5);
        for p in 0..P {
            let (w2, inv_w2, aw2, hard) = (self.w2[p], self.inv_w2[p], self.aw2[p], self.hard[p]);
            let (four_h, two_h) = (self.four_h[p], self.two_h[p]);
            let (inv_de, inv_dp) = (self.inv_de[p], self.inv_dp[p]);
            let lim = r.lim[p];
            let n = self.n[p];
            let dl = d * self.inv_n[p];
            let (mut u, mut v, mut f, mut g) = (r.u[p], r.v[p], r.f[p], a0);
            let (mut sd, mut work, mut plastic, mut count) =
                (r.sd[p], r.work[p], r.plastic[p], r.yielding[p]);
            for k in 1..=n {
                let g1 = if k == n { a1 } else { g + dl };
                // κ Δu + f(u + Δu) = b
                let b = four_h * v - f - (g + g1);
                // elastic trial
                let du_e = (b - f) * inv_de;
                let u_e = u + du_e;
                let f_e = f + w2 * du_e;
                let q = f_e - aw2 * u_e;
                // plastic re-solve on the edge left, `f = αω²u + s(1 − α)a_y`
                let slim = if q > zero { lim } else { -lim };
                let u_p = u + (b - aw2 * u - slim) * inv_dp;
                let f_p = aw2 * u_p + slim;
                let yields = q > lim || -q > lim;
                let (u1, f1) = if yields { (u_p, f_p) } else { (u_e, f_e) };
                v = two_h * (u1 - u) - v;
                // plastic increment Δd_p = Δu − Δf/ω² (zero, not rounding, when elastic)
                let ddp = (u1 - u) - (f1 - f) * inv_w2;
                let ddp = if yields { ddp } else { zero };
                work += ddp * (f1 - half * hard * ddp);
                plastic += if ddp > zero { ddp } else { -ddp };
                count = count.saturating_add(u32::from(yields));
                u = u1;
                f = f1;
                g = g1;
                let au = if u > zero { u } else { -u };
                sd = if au > sd { au } else { sd };
            }
            r.u[p] = u;
            r.v[p] = v;
            r.f[p] = f;
            r.sd[p] = sd;
            r.work[p] = work;
            r.plastic[p] = plastic;
            r.yielding[p] = count;
        }
    }

    /// One record pass of the oscillators `live[p]` from `r` (at rest): every sample of
    /// `record` as [`Yielding::step`] then `tail` samples of free vibration as
    /// [`Yielding::free_vibration`], the live oscillators packed [`LANES`] to a group and
    /// each group stepped over the whole record side by side, through the crate's run-time
    /// AVX choice (`linalg::wide`: `f64 × 4` with AVX, `× 2` on SSE2). Bit-identical to
    /// the scalar step (see [`Group::advance`]); the oscillators not live stay at rest
    /// and `r`'s sample counters advance as [`Yielding::step`]'s.
    fn pass(&self, r: &mut YieldResponse<T, P>, record: &[T], tail: u32, live: &[bool; P]) {
        crate::linalg::wide(|| self.pass_lanes::<LANES>(r, record, tail, live));
    }

    #[inline(always)]
    fn pass_lanes<const L: usize>(
        &self,
        r: &mut YieldResponse<T, P>,
        record: &[T],
        tail: u32,
        live: &[bool; P],
    ) {
        let mut idx = [0usize; P];
        let mut m = 0;
        for p in 0..P {
            if live[p] {
                idx[m] = p;
                m += 1;
            }
        }
        let mut start = 0;
        while start < m {
            let end = if start + L < m { start + L } else { m };
            // A group short of `L` fills its lanes with copies of its last oscillator,
            // stepped and not written back.
            let lane: [usize; L] = core::array::from_fn(|l| idx[(start + l).min(end - 1)]);
            let mut g = Group::gather(self, r, &lane);
            let (mut last, mut samples, mut skipped) = (r.last, r.samples, r.skipped);
            for &a in record {
                if let Some((a0, a1)) = super::take_sample(&mut last, &mut samples, &mut skipped, a)
                {
                    g.advance(a0, a1);
                }
            }
            if samples != 0 {
                let zero = T::from_f64_rounded(0.0);
                for _ in 0..tail {
                    let a0 = last;
                    last = zero;
                    g.advance(a0, zero);
                }
            }
            g.scatter(r, &lane[..end - start]);
            start = end;
        }
        // The sample counters, as the scalar steps leave them.
        for &a in record {
            let _ = super::take_sample(&mut r.last, &mut r.samples, &mut r.skipped, a);
        }
        if r.samples != 0 && tail > 0 {
            r.last = T::from_f64_rounded(0.0);
        }
    }

    /// The response to a whole record: every sample of `record` (m/s², sample interval
    /// [`Yielding::time_step`]) then [`Yielding::free_vibration_samples`] of free
    /// vibration, from rest, with strengths `yield_acceleration` (m/s², as
    /// [`Yielding::at_rest`]). One *record pass*. A non-finite sample is refused
    /// ([`NonFinite::Refuse`], the default: the record is checked before it is stepped) or
    /// skipped and counted ([`NonFinite::Skip`], as in [`Yielding::step`]).
    ///
    /// Every field of the result is finite, its [ductility](YieldResponse::ductility)
    /// included, or the call is an error. The samples are stepped unchecked and the
    /// response checked once at the end: a NaN or `±∞` state never turns finite again (it
    /// propagates through the step, and the peak, work and deformation are running
    /// maxima and sums), so the end check sees every overflow.
    ///
    /// Errors: as [`Yielding::at_rest`]; [`Error::InvalidTimeStep`] if the free-vibration
    /// tail exceeds [`MAX_FREE_VIBRATION_SAMPLES`](super::MAX_FREE_VIBRATION_SAMPLES);
    /// [`Error::NonFiniteInput`] if a sample is not finite and the policy refuses it
    /// ([`first_non_finite`](super::first_non_finite) gives its index);
    /// [`Error::NonFiniteState`] if a finite sample made the response overflow;
    /// [`Error::OperatorOverflow`] if a ductility overflows. Cost: `N + ⌈T_max/h⌉` steps,
    /// the oscillators stepped 4 at a time in SIMD lanes, each group `max n_p` sub-steps a
    /// sample (the module's **Cost**); the result is the bits of [`Yielding::step`] and
    /// [`Yielding::free_vibration`] sample by sample.
    pub fn response(
        &self,
        record: &[T],
        yield_acceleration: &[T; P],
    ) -> Result<YieldResponse<T, P>, Error> {
        self.response_of(record, yield_acceleration, &[true; P])
    }

    /// [`Yielding::response`] of the oscillators `live[p]` only, the others left at rest
    /// (their trial finished: the constant-ductility search steps only the unfinished ones).
    /// The live oscillators are stepped in lanes ([`Yielding::pass`]): the bits of
    /// [`Yielding::step`].
    fn response_of(
        &self,
        record: &[T],
        yield_acceleration: &[T; P],
        live: &[bool; P],
    ) -> Result<YieldResponse<T, P>, Error> {
        let mut r = self.at_rest(yield_acceleration)?;
        let tail = super::checked_tail(&self.period, self.time_step)?;
        super::check_record(self.non_finite, record)?;
        self.pass(&mut r, record, tail, live);
        if !r.is_finite() {
            return Err(Error::NonFiniteState);
        }
        if !super::all_finite(&r.ductility()) {
            return Err(Error::OperatorOverflow);
        }
        Ok(r)
    }

    /// The elastic strength per unit mass `a_y0 = ω² u_o` of each oscillator (m/s²): its
    /// pseudo-spectral acceleration, `u_o` the peak of the same oscillator that never
    /// yields, stepped the same way (one record pass, as [`Yielding::response`], with
    /// `a_y = +∞`). `f_o = m a_y0` is Chopra's elastic strength.
    ///
    /// Errors: as [`Yielding::response`]; [`Error::OperatorOverflow`] if `ω² u_o`
    /// overflows. Cost: one record pass.
    pub fn elastic_strength(&self, record: &[T]) -> Result<[T; P], Error> {
        let inf = [T::from_f64_rounded(f64::INFINITY); P];
        // `+∞` passes `at_rest`'s checks (it is `> 0`, and so are `(1 − α)∞` and `∞/ω²`).
        let r = self.response(record, &inf)?;
        let mut out = r.sd;
        for (o, &w2) in out.iter_mut().zip(self.w2.iter()) {
            *o *= w2;
        }
        if super::all_finite(&out) {
            Ok(out)
        } else {
            Err(Error::OperatorOverflow)
        }
    }

    /// The constant-strength spectrum: the ductility demand of each oscillator with
    /// strength `a_y = a_y0 / R_p` (`a_y0` its [elastic strength](Yielding::elastic_strength),
    /// `R_p = reduction[p]` the strength-reduction factor, `f_y = f_o/R_y` in Chopra's
    /// notation) over the record (`N` samples, m/s²) and one longest period of free
    /// vibration.
    ///
    /// Errors: [`Error::InvalidParameter`] if a factor is not finite and `> 0`, or if the
    /// record leaves an oscillator at rest (elastic strength `0`: no ductility to speak of);
    /// [`Error::OperatorOverflow`] if a strength `a_y0/R` overflows `T` (a tiny `R`, e.g.
    /// `4e-44` in `f32`), [`Error::OperatorUnderflow`] if it (or its yield displacement)
    /// is subnormal in `T` (e.g. `R = 1e308`; see [`Yielding::at_rest`]); otherwise as
    /// [`Yielding::response`] (a record so large that the response or the ductility
    /// overflows: [`Error::NonFiniteState`], [`Error::OperatorOverflow`]). Every field of
    /// the result is finite.
    /// Cost: two record passes ([`Yielding::response`]).
    pub fn constant_strength(
        &self,
        record: &[T],
        reduction: &[T; P],
    ) -> Result<ConstantStrength<T, P>, Error> {
        let zero = T::from_f64_rounded(0.0);
        if reduction.iter().any(|&x| !(super::finite(x) && x > zero)) {
            return Err(Error::InvalidParameter(Param::StrengthReduction));
        }
        let elastic = self.elastic_strength(record)?;
        let mut ay = elastic;
        for p in 0..P {
            ay[p] /= reduction[p];
            if !(elastic[p] > zero && super::finite(elastic[p])) {
                return Err(Error::InvalidParameter(Param::ElasticStrength));
            }
        }
        // `a_y0 / R` beyond the range of `T` (a tiny `R`, found by fuzzing: `f32`, R = 4e-44)
        // or below its normal range (a huge `R`).
        if ay.iter().any(|&a| !super::finite(a)) {
            return Err(Error::OperatorOverflow);
        }
        if self.bands(&ay).is_none() {
            return Err(Error::OperatorUnderflow);
        }
        let r = self.response(record, &ay)?;
        Ok(ConstantStrength {
            elastic,
            yield_acceleration: ay,
            ductility: r.ductility(),
            plastic_work: r.work,
            response: r,
        })
    }

    /// The constant-ductility spectrum: for each oscillator, the **largest** strength per
    /// unit mass `a_y` (m/s²) whose ductility demand over the record (and one longest
    /// period of free vibration) is the target `target` (`μ_t > 1`).
    ///
    /// `μ(a_y)` need not be monotonic: several strengths can give `μ_t`. The convention is
    /// Chopra's (Dynamics of Structures, §7.5): the largest. It is found honestly:
    ///
    /// 1. one elastic pass gives `a_y0` ([`Yielding::elastic_strength`]); at `a_y0` the
    ///    oscillator does not yield, `μ ≤ 1 < μ_t`;
    /// 2. *bracketing*: strengths `a_y0 · lowest^{k/(points − 1)}`, `k = 1, 2, …` (a
    ///    geometric grid from the elastic strength downward, ratio
    ///    `lowest^{1/(points − 1)}`), one pass each, until the first with `μ ≥ μ_t`; with
    ///    the previous grid point it brackets the largest crossing the grid resolves (a pair
    ///    of crossings between two grid points, where `μ` rises to `μ_t` and falls back,
    ///    can be missed: refine the grid to see it). No crossing down to
    ///    `a_y0 · lowest`: [`Outcome::NoCrossing`];
    /// 3. *refinement* of `[lo, hi]` (`μ(lo) ≥ μ_t > μ(hi)`), which it keeps: the Illinois
    ///    variant of false position, safeguarded by bisection whenever a step would leave
    ///    the bracket or two steps have not halved its width. It stops when
    ///    `hi − lo ≤ tol · hi`; the strength returned is the secant point of the final
    ///    bracket. The tolerance is on the strength: the crossing found is within
    ///    `tol · a_y` of the value returned (relative). A crossing inside the bracket that
    ///    is not its largest can be found only if `μ` crosses `μ_t` three times between two
    ///    grid points.
    ///
    /// The oscillators search in lockstep: each pass steps every oscillator whose search is
    /// not finished, with its own trial strength, packed into SIMD lanes (4 trials a
    /// group; [`Yielding::response`]), so the number of passes is the slowest one's and
    /// their cost falls as the searches finish. The result is the bits of stepping every
    /// trial alone with [`Yielding::step`].
    ///
    /// Errors: [`Error::InvalidParameter`] if `target` is not finite and `> 1`, a setting of
    /// `search` is out of range ([`Search`]; its `tol` below `4 ε` of `T`), or the record
    /// leaves an oscillator at rest; [`Error::OperatorUnderflow`] if a strength of the
    /// grid, `a_y0 · lowest`, is subnormal in `T` (see [`Yielding::at_rest`]); otherwise as
    /// [`Yielding::response`] (a pass whose response or ductility overflows). Cost: `1 + (k_max) + refinement` record passes,
    /// `k_max ≤ points − 1` the grid index of the slowest bracket; refinement at most
    /// `2 ⌈log₂((1 − ρ)/tol)⌉ + 2`, typically 5 to 10 ([`ConstantDuctility::passes`];
    /// measured with [`Search::DEFAULT`] on El Centro, 10 periods 0.1–3 s, `μ_t = 2, 4`:
    /// 22 to 44 passes in all).
    pub fn constant_ductility(
        &self,
        record: &[T],
        target: T,
        search: &Search,
    ) -> Result<ConstantDuctility<T, P>, Error> {
        self.constant_ductility_while(record, target, search, &mut || true)
    }

    /// [`Yielding::constant_ductility`], asking `go_on()` before each record pass after
    /// the elastic one: when it returns `false` the search stops there, and every
    /// oscillator not finished reports [`Outcome::NotConverged`] with the bracket reached
    /// (as when the pass budget runs out). For a caller that must stop a long search: a
    /// time budget, or an interrupt from the user (the Python package answers Ctrl-C this
    /// way). With `go_on` always `true`, the same result, bit for bit.
    ///
    /// Errors: as [`Yielding::constant_ductility`]. Cost: as it, plus one call of `go_on`
    /// a pass.
    ///
    /// ```
    /// use aemstep::spectrum::inelastic::{Outcome, Search, Yielding};
    /// let y = Yielding::<f64, 2>::new([0.3, 1.0], [0.05; 2], 0.0, 0.01)?;
    /// let rec: Vec<f64> = (0..500).map(|n| 3.0 * (5.0 * n as f64 * 0.01).sin()).collect();
    /// // stop after 3 passes: the elastic one and 2 of the search
    /// let mut left = 2;
    /// let cd = y.constant_ductility_while(&rec, 4.0, &Search::DEFAULT, &mut || {
    ///     left -= 1;
    ///     left >= 0
    /// })?;
    /// assert_eq!(cd.passes, 3);
    /// assert!(cd.outcome.iter().all(|&o| o == Outcome::NotConverged));
    /// # Ok::<(), aemstep::Error>(())
    /// ```
    pub fn constant_ductility_while(
        &self,
        record: &[T],
        target: T,
        search: &Search,
        go_on: &mut dyn FnMut() -> bool,
    ) -> Result<ConstantDuctility<T, P>, Error> {
        let eps = T::default_epsilon().as_f64();
        let mu_t = target.as_f64();
        if !(mu_t.is_finite() && mu_t > 1.0) {
            return Err(Error::InvalidParameter(Param::TargetDuctility));
        }
        if !(search.valid() && search.tol >= 4.0 * eps) {
            return Err(Error::InvalidParameter(Param::Search));
        }
        let elastic = self.elastic_strength(record)?;
        let zero = T::from_f64_rounded(0.0);
        if elastic.iter().any(|&x| !(x > zero && super::finite(x))) {
            return Err(Error::InvalidParameter(Param::ElasticStrength));
        }
        // The weakest strength the search can try (the refinement stays above it).
        let weakest = elastic.map(|x| T::from_f64_rounded(x.as_f64() * search.lowest));
        if self.bands(&weakest).is_none() {
            return Err(Error::OperatorUnderflow);
        }
        let a0 = elastic.map(|x| x.as_f64());
        let ratio = libm_pow(search.lowest, 1.0 / (search.points - 1) as f64);
        let round = |x: f64| T::from_f64_rounded(x).as_f64();
        let mut s: [Root; P] = core::array::from_fn(|p| Root::start(a0[p], 1.0 - mu_t));
        for p in 0..P {
            s[p].x = round(a0[p] * ratio);
        }
        let mut passes = 1u32;
        let max_passes = search.points as u32 + 2 * 64;
        while s.iter().any(|r| r.outcome.is_none()) && passes < max_passes && go_on() {
            let trial: [T; P] = core::array::from_fn(|p| {
                if s[p].outcome.is_none() {
                    T::from_f64_rounded(s[p].x)
                } else {
                    T::from_f64_rounded(f64::INFINITY)
                }
            });
            // Only the unfinished trials are stepped: a finished one would step with
            // `a_y = +∞`, the elastic pass again, whose response is finite (it was checked).
            let live: [bool; P] = core::array::from_fn(|p| s[p].outcome.is_none());
            let mu = self.response_of(record, &trial, &live)?.ductility();
            passes += 1;
            for p in 0..P {
                if s[p].outcome.is_none() {
                    let f = mu[p].as_f64() - mu_t;
                    s[p].update(f, a0[p], ratio, search, round);
                }
            }
        }
        let t = |x: f64| T::from_f64_rounded(x);
        Ok(ConstantDuctility {
            yield_acceleration: core::array::from_fn(|p| t(s[p].answer())),
            elastic,
            bracket: core::array::from_fn(|p| [t(s[p].lo), t(s[p].hi)]),
            ductility: core::array::from_fn(|p| [t(s[p].flo + mu_t), t(s[p].fhi + mu_t)]),
            outcome: s.map(|r| r.outcome.unwrap_or(Outcome::NotConverged)),
            passes,
            skipped: super::non_finite_count(record),
        })
    }

    /// Periods (s), as given. Cost: none.
    pub fn periods(&self) -> &[f64; P] {
        &self.period
    }
    /// Damping ratios, as given. Cost: none.
    pub fn damping(&self) -> &[f64; P] {
        &self.damping
    }
    /// Post-yield stiffness ratio `α`, as given. Cost: none.
    pub fn post_yield_ratio(&self) -> f64 {
        self.alpha
    }
    /// The sample interval `h` (s). Cost: none.
    pub fn time_step(&self) -> f64 {
        self.time_step
    }
    /// Sub-steps per sample of each oscillator. Cost: none.
    pub fn substeps(&self) -> &[u16; P] {
        &self.n
    }
    /// Oscillator sub-steps per sample, `Σ_p n_p` (the cost unit of [`Yielding::step`]).
    /// Cost: a sum over the bank.
    pub fn substeps_per_sample(&self) -> u32 {
        self.n.iter().map(|&n| n as u32).sum()
    }
}

/// Oscillators a group of the record pass steps side by side ([`Yielding::pass`]): 4, one
/// AVX register of `f64` (two of SSE2). Measured against 8 (two chains overlapping, but
/// more lanes frozen while the group's shortest periods finish their sub-steps): the
/// 240-search constant-ductility benchmark took 0.55 s with 4 and 0.81 s with 8 (host
/// timing, load 6–7 on 2 cores: `cargo bench -p xtask --bench inelastic`).
const LANES: usize = 4;

/// `L` oscillators of a [`Yielding`] bank and their responses, structure-of-arrays: each
/// quantity `[T; L]`, the sub-step counts as `T` (exact: at most
/// [`MAX_SUBSTEPS`](super::MAX_SUBSTEPS)) so that every per-lane choice is a select
/// between two values of `T`.
struct Group<T, const L: usize> {
    w2: [T; L],
    inv_w2: [T; L],
    aw2: [T; L],
    hard: [T; L],
    four_h: [T; L],
    two_h: [T; L],
    inv_de: [T; L],
    inv_dp: [T; L],
    inv_n: [T; L],
    lim: [T; L],
    n: [T; L],
    /// The most sub-steps of a lane.
    most: u16,
    u: [T; L],
    v: [T; L],
    f: [T; L],
    sd: [T; L],
    work: [T; L],
    plastic: [T; L],
    yielding: [u32; L],
}

impl<T: Real, const L: usize> Group<T, L> {
    /// The coefficients and states of the oscillators `lane` (indices into the bank).
    #[inline(always)]
    fn gather<const P: usize>(
        y: &Yielding<T, P>,
        r: &YieldResponse<T, P>,
        lane: &[usize; L],
    ) -> Self {
        let of = |a: &[T; P]| -> [T; L] { core::array::from_fn(|l| a[lane[l]]) };
        let mut most = 0;
        for &p in lane {
            most = most.max(y.n[p]);
        }
        Group {
            w2: of(&y.w2),
            inv_w2: of(&y.inv_w2),
            aw2: of(&y.aw2),
            hard: of(&y.hard),
            four_h: of(&y.four_h),
            two_h: of(&y.two_h),
            inv_de: of(&y.inv_de),
            inv_dp: of(&y.inv_dp),
            inv_n: of(&y.inv_n),
            lim: of(&r.lim),
            n: core::array::from_fn(|l| T::from_f64_rounded(y.n[lane[l]] as f64)),
            most,
            u: of(&r.u),
            v: of(&r.v),
            f: of(&r.f),
            sd: of(&r.sd),
            work: of(&r.work),
            plastic: of(&r.plastic),
            yielding: core::array::from_fn(|l| r.yielding[lane[l]]),
        }
    }

    /// Write lanes `0..lane.len()` back to the oscillators `lane`.
    #[inline(always)]
    fn scatter<const P: usize>(&self, r: &mut YieldResponse<T, P>, lane: &[usize]) {
        for (l, &p) in lane.iter().enumerate() {
            r.u[p] = self.u[l];
            r.v[p] = self.v[l];
            r.f[p] = self.f[l];
            r.sd[p] = self.sd[l];
            r.work[p] = self.work[l];
            r.plastic[p] = self.plastic[l];
            r.yielding[p] = self.yielding[l];
        }
    }

    /// One sample interval `a0 → a1` of every lane: [`Yielding`]'s private `advance`,
    /// the same operations in the same order on each lane, its branches as selects, for
    /// `most` sub-steps; a lane past its own `n_p` computes and keeps its state (a select
    /// of the old values), so each lane's result is the scalar one bit for bit (packed
    /// `add`/`mul`/compare round each lane as the scalar instruction does; Rust fuses
    /// nothing). The sub-steps on which a lane yielded are summed in `T` over the
    /// sample (exact: at most `MAX_SUBSTEPS`) and added to its `u32` count saturating,
    /// as the scalar step's one at a time.
    #[inline(always)]
    fn advance(&mut self, a0: T, a1: T) {
        let d = a1 - a0;
        let zero = T::from_f64_rounded(0.0);
        let one = T::from_f64_rounded(1.0);
        let half = T::from_f64_rounded(0.5);
        let dl: [T; L] = core::array::from_fn(|l| d * self.inv_n[l]);
        let mut g = [a0; L];
        let mut count = [zero; L];
        for k in 1..=self.most {
            let kt = T::from_f64_rounded(k as f64);
            for l in 0..L {
                let (u, v, f) = (self.u[l], self.v[l], self.f[l]);
                let (lim, aw2) = (self.lim[l], self.aw2[l]);
                let live = kt <= self.n[l];
                let g1 = if kt == self.n[l] { a1 } else { g[l] + dl[l] };
                let b = self.four_h[l] * v - f - (g[l] + g1);
                let du_e = (b - f) * self.inv_de[l];
                let u_e = u + du_e;
                let f_e = f + self.w2[l] * du_e;
                let q = f_e - aw2 * u_e;
                let slim = if q > zero { lim } else { -lim };
                let u_p = u + (b - aw2 * u - slim) * self.inv_dp[l];
                let f_p = aw2 * u_p + slim;
                let yields = q > lim || -q > lim;
                let u1 = if yields { u_p } else { u_e };
                let f1 = if yields { f_p } else { f_e };
                let v1 = self.two_h[l] * (u1 - u) - v;
                let ddp = (u1 - u) - (f1 - f) * self.inv_w2[l];
                let ddp = if yields { ddp } else { zero };
                let work = self.work[l] + ddp * (f1 - half * self.hard[l] * ddp);
                let plastic = self.plastic[l] + if ddp > zero { ddp } else { -ddp };
                let au = if u1 > zero { u1 } else { -u1 };
                let sd = self.sd[l];
                let sd = if au > sd { au } else { sd };
                self.u[l] = if live { u1 } else { u };
                self.v[l] = if live { v1 } else { v };
                self.f[l] = if live { f1 } else { f };
                g[l] = if live { g1 } else { g[l] };
                self.work[l] = if live { work } else { self.work[l] };
                self.plastic[l] = if live { plastic } else { self.plastic[l] };
                self.sd[l] = if live { sd } else { self.sd[l] };
                count[l] += if live && yields { one } else { zero };
            }
        }
        for l in 0..L {
            self.yielding[l] = self.yielding[l].saturating_add(count[l].as_f64() as u32);
        }
    }
}

/// `x^y` for `0 < x < 1`, `0 < y ≤ 1`, by `exp(y ln x)` from `core`-free series: `ln` by
/// `atanh` (argument reduced by powers of two), `exp` by squaring a Taylor series. Good to
/// a few ulps of `f64`, which is all the grid needs.
fn libm_pow(x: f64, y: f64) -> f64 {
    // ln x = k ln 2 + ln m, m in [1, 2)
    let (mut m, mut k) = (x, 0i32);
    while m < 1.0 {
        m *= 2.0;
        k -= 1;
    }
    let z = (m - 1.0) / (m + 1.0);
    let z2 = z * z;
    let (mut term, mut sum, mut j) = (z, 0.0, 1.0);
    while j < 80.0 {
        sum += term / j;
        term *= z2;
        j += 2.0;
    }
    let ln = k as f64 * core::f64::consts::LN_2 + 2.0 * sum;
    // exp(t), t ≤ 0: exp(t/2^s)^(2^s)
    let t = y * ln;
    let mut s = 0;
    let mut r = t;
    while r < -0.5 {
        r *= 0.5;
        s += 1;
    }
    let (mut e, mut term, mut i) = (1.0, 1.0, 1.0);
    while i < 30.0 {
        term *= r / i;
        e += term;
        i += 1.0;
    }
    for _ in 0..s {
        e *= e;
    }
    e
}

/// The state of one oscillator's root find (strengths in `f64`, rounded to `T` values).
#[derive(Clone, Copy)]
struct Root {
    /// The strength being tried.
    x: f64,
    /// Grid index of `x` while bracketing; `None` once bracketed.
    k: Option<u16>,
    /// `μ(lo) − μ_t ≥ 0` (weaker end).
    lo: f64,
    flo: f64,
    /// `μ(hi) − μ_t < 0` (stronger end).
    hi: f64,
    fhi: f64,
    /// Illinois-weighted `f` at the ends.
    mlo: f64,
    mhi: f64,
    /// Which end the last update kept: `1` hi, `−1` lo, `0` none yet.
    kept: i8,
    /// Bracket widths after the last two updates.
    w1: f64,
    w2: f64,
    outcome: Option<Outcome>,
}

impl Root {
    fn start(a0: f64, f_elastic: f64) -> Self {
        Root {
            x: a0,
            k: Some(1),
            lo: a0,
            flo: f_elastic,
            hi: a0,
            fhi: f_elastic,
            mlo: f_elastic,
            mhi: f_elastic,
            kept: 0,
            w1: f64::INFINITY,
            w2: f64::INFINITY,
            outcome: None,
        }
    }

    fn update(&mut self, f: f64, a0: f64, ratio: f64, search: &Search, round: impl Fn(f64) -> f64) {
        if let Some(k) = self.k {
            if f >= 0.0 {
                self.lo = self.x;
                self.flo = f;
                self.mlo = f;
                self.mhi = self.fhi;
                self.k = None;
            } else {
                self.hi = self.x;
                self.fhi = f;
                if k + 1 >= search.points {
                    self.lo = self.x;
                    self.flo = f;
                    self.outcome = Some(Outcome::NoCrossing);
                    return;
                }
                let mut x = a0;
                for _ in 0..=k {
                    x *= ratio;
                }
                self.x = round(x);
                self.k = Some(k + 1);
                return;
            }
        } else if f >= 0.0 {
            self.lo = self.x;
            self.flo = f;
            self.mlo = f;
            if self.kept == 1 {
                self.mhi *= 0.5;
            }
            self.kept = 1;
        } else {
            self.hi = self.x;
            self.fhi = f;
            self.mhi = f;
            if self.kept == -1 {
                self.mlo *= 0.5;
            }
            self.kept = -1;
        }
        let w = self.hi - self.lo;
        if w <= search.tol * self.hi {
            self.outcome = Some(Outcome::Converged);
            return;
        }
        let mut x = self.lo + w * (self.mlo / (self.mlo - self.mhi));
        if !(x > self.lo && x < self.hi) || w > 0.5 * self.w2 {
            x = self.lo + 0.5 * w;
        }
        self.w2 = self.w1;
        self.w1 = w;
        let xr = round(x);
        self.x = if xr > self.lo && xr < self.hi { xr } else { x };
    }

    /// The secant point of the final bracket (in it), or `lo` without one.
    fn answer(&self) -> f64 {
        let d = self.flo - self.fhi;
        if self.outcome != Some(Outcome::NoCrossing)
            && self.hi > self.lo
            && self.flo >= 0.0
            && d > 0.0
        {
            self.lo + (self.hi - self.lo) * (self.flo / d)
        } else {
            self.lo
        }
    }
}

/// How the constant-ductility search is run ([`Yielding::constant_ductility`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Search {
    /// Grid points from the elastic strength down to `lowest` times it, both included
    /// (`≥ 2`, at most `u16::MAX`); also the most bracketing passes, `points − 1`.
    pub points: u16,
    /// The weakest strength tried, as a fraction of the elastic strength (in `(0, 1)`;
    /// `1/lowest` is the largest strength-reduction factor `R_y` searched).
    pub lowest: f64,
    /// Relative tolerance on the strength (finite, in `[4 ε_T, 0.1]`).
    pub tol: f64,
}

impl Search {
    /// 60 points down to `R_y = 100` (grid ratio 0.925: neighbouring strengths 7.5 %
    /// apart), strengths to `10⁻⁶` relative.
    pub const DEFAULT: Search = Search {
        points: 60,
        lowest: 0.01,
        tol: 1e-6,
    };

    fn valid(&self) -> bool {
        self.points >= 2
            && self.lowest.is_finite()
            && self.lowest > 0.0
            && self.lowest < 1.0
            && self.tol.is_finite()
            && self.tol <= 0.1
    }
}

impl Default for Search {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// How one oscillator's constant-ductility search ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Outcome {
    /// The largest crossing was bracketed and refined to the tolerance.
    Converged,
    /// Even the weakest strength of the grid gives `μ < μ_t`; the strength reported is
    /// that weakest one.
    NoCrossing,
    /// The pass budget (`points + 128`) ran out before the bracket reached the tolerance
    /// (not seen in practice: the bisection safeguard halves it every two passes); the
    /// strength reported is the secant point of the bracket reached.
    NotConverged,
}

/// A constant-strength spectrum ([`Yielding::constant_strength`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ConstantStrength<T, const P: usize> {
    /// Elastic strength per unit mass `a_y0 = ω² u_o` (m/s²).
    pub elastic: [T; P],
    /// Yield strength per unit mass `a_y = a_y0 / R` (m/s²).
    pub yield_acceleration: [T; P],
    /// Ductility demand `μ = max|u| / u_y`.
    pub ductility: [T; P],
    /// Plastic (hysteretic) work per unit mass (m²/s²).
    pub plastic_work: [T; P],
    /// The whole inelastic response (peaks, residual displacement, …; its
    /// [`skipped`](YieldResponse::skipped) counts the non-finite samples skipped under
    /// [`NonFinite::Skip`]).
    pub response: YieldResponse<T, P>,
}

/// A constant-ductility spectrum ([`Yielding::constant_ductility`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ConstantDuctility<T, const P: usize> {
    /// The largest yield strength per unit mass `a_y = f_y/m` giving the target ductility
    /// (m/s²; divided by `g`, the strength ratio `η`; divided by [`elastic`](Self::elastic),
    /// the normalized strength `f̄_y = 1/R_y`).
    pub yield_acceleration: [T; P],
    /// Elastic strength per unit mass `a_y0 = ω² u_o` (m/s²).
    pub elastic: [T; P],
    /// The final bracket `[lo, hi]` (m/s²): `μ(lo) ≥ μ_t > μ(hi)`.
    pub bracket: [[T; 2]; P],
    /// The ductility at the ends of the bracket, `[μ(lo), μ(hi)]`.
    pub ductility: [[T; 2]; P],
    /// How each search ended.
    pub outcome: [Outcome; P],
    /// Record passes taken, the elastic one included.
    pub passes: u32,
    /// Non-finite samples of the record skipped in every pass (under
    /// [`NonFinite::Skip`]; `0` under [`NonFinite::Refuse`], which refuses such a record).
    pub skipped: u64,
}
