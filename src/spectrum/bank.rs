//! The oscillator bank and its per-sample step.

use super::operators::{self, SdofOps};
use super::{MAX_SUBSTEPS, NonFinite, Scheme, Substeps};
use crate::linalg::{all_fit, fits_value};
use crate::macros::const_try;
use crate::{Error, Param, Real};
use core::f64::consts::TAU;

/// A bank of `P` damped single-degree-of-freedom oscillators (the response-spectrum
/// computation), fed one ground-acceleration sample at a time.
///
/// Oscillator `p` obeys `u'' + 2ζ_p ω_p u' + ω_p² u = −a_g(t)` with `ω_p = 2π/T_p`;
/// `u` is the displacement relative to the ground (m when `a_g` is in m/s²). Periods and
/// damping ratios are fixed when the bank is built ([`Bank::new`], a `const fn`: in a
/// `static`, the compiler computes the operators into flash).
///
/// Each sample interval is one step of every oscillator by its whole-interval operator
/// (for the exact scheme the exact map over `h`; for the AEM the composition of its `n_p`
/// sub-steps), a loop over `p` on a structure of arrays (one `[T; P]` per coefficient) that
/// the compiler vectorizes. The sub-steps only locate peaks between samples: they are
/// walked, from the interval's start, only for the oscillators whose peak could rise inside
/// the interval (see [`Bank::step`]). Periods must be given in non-decreasing order
/// (oscillators with sub-steps are then a prefix of the bank).
///
/// Non-finite samples follow the bank's [`NonFinite`] policy ([`Bank::with_non_finite`];
/// by default refused by the checked and record-level calls).
///
/// Size: `24P` values of `T`, `2P` bytes, `2P + 3` `f64` and the policy byte.
#[derive(Clone, Copy, Debug, PartialEq)]
// `repr(C)`: the fields in the order written, the step's maps first and the values it never
// reads (periods, damping, the policy) last, so the step addresses its operators as small
// offsets from `self` (Thumb-2 `vldr` reaches ±1020 bytes). Left to rustc, adding the
// one-byte policy moved `period` and `damping` (1600 bytes for `P = 100`) in front of the
// sub-step maps: `Bank<f32, 100>`'s step rose from 10284 to 10498 instructions a sample
// (`docs/cortex-m4-cost.md`).
#[repr(C)]
pub struct Bank<T, const P: usize> {
    /// Whole-interval map, on `(u0, v0, a0, d = a1 − a0)`.
    pub(super) su: [[T; P]; 4],
    pub(super) sv: [[T; P]; 4],
    /// Sub-step map, on `(u, v, g, δ = d/n)`.
    pub(super) uu: [T; P],
    pub(super) uv: [T; P],
    pub(super) ug: [T; P],
    pub(super) ud: [T; P],
    pub(super) vu: [T; P],
    pub(super) vv: [T; P],
    pub(super) vg: [T; P],
    pub(super) vd: [T; P],
    /// `ω²` (1/s²).
    pub(super) w2: [T; P],
    /// `2ζω` (1/s).
    pub(super) c2: [T; P],
    /// `ω` (1/s).
    pub(super) w: [T; P],
    /// `1/(ω √(1 + 4ζ²))` (s): `|ω²u + 2ζωv| ≤ √(ω²u² + v²) / ka`.
    pub(super) ka: [T; P],
    /// `1/ω²` (s²).
    pub(super) inv_w2: [T; P],
    /// `1/ω` (s).
    pub(super) inv_w: [T; P],
    /// `2ζ/ω²` (s²).
    pub(super) k2: [T; P],
    /// `1/n_p`.
    pub(super) inv_n: [T; P],
    /// Sub-steps per sample `n_p` (non-increasing along the bank).
    pub(super) n: [u16; P],
    /// Oscillators with `n_p > 1` (a prefix).
    pub(super) m1: usize,
    /// Periods (s), as given.
    pub(super) period: [f64; P],
    /// Damping ratios, as given.
    pub(super) damping: [f64; P],
    /// Sample interval `h` (s).
    pub(super) time_step: f64,
    /// `1/h` (1/s).
    pub(super) inv_h: T,
    pub(super) scheme: Scheme,
    /// What the checked calls do with a non-finite sample.
    pub(super) non_finite: NonFinite,
}

/// The validated `f64` operators of a bank, before rounding to `T`.
pub(super) struct OpsF64<const P: usize> {
    pub ops: [SdofOps; P],
    pub whole: [SdofOps; P],
    pub ka: [f64; P],
    pub w2: [f64; P],
    pub c2: [f64; P],
    pub n: [u16; P],
}

/// Sub-steps per sample for period `t` under `rule` (`h`, `t` validated).
pub(super) const fn substeps_for(rule: Substeps, h: f64, t: f64) -> u16 {
    match rule {
        Substeps::Fixed(n) => n,
        Substeps::PointsPerPeriod(r) => {
            // n = ceil(r·h/T), clamped to [1, MAX_SUBSTEPS]
            let x = r as f64 * h / t;
            if x >= MAX_SUBSTEPS as f64 {
                MAX_SUBSTEPS
            } else {
                let f = x as u16; // x < MAX_SUBSTEPS: no overflow
                let n = if (f as f64) < x { f + 1 } else { f };
                if n == 0 { 1 } else { n }
            }
        }
    }
}

/// The sample interval `h` (s, finite, `> 0`: else [`Error::InvalidTimeStep`]) and the
/// sub-step rule ([`Error::InvalidParameter`] for `Fixed(0)`, `Fixed(n > MAX_SUBSTEPS)`,
/// `PointsPerPeriod(0)`), checked in that order: the first checks of both banks (the
/// elastic [`Bank`] and the yielding [`Yielding`](super::inelastic::Yielding)).
pub(super) const fn check_interval(h: f64, rule: Substeps) -> Result<(), Error> {
    if !(h.is_finite() && h > 0.0) {
        return Err(Error::InvalidTimeStep);
    }
    match rule {
        Substeps::Fixed(n) if n == 0 || n > MAX_SUBSTEPS => {
            Err(Error::InvalidParameter(Param::Substeps))
        }
        Substeps::PointsPerPeriod(0) => Err(Error::InvalidParameter(Param::Substeps)),
        _ => Ok(()),
    }
}

/// One oscillator of a bank, set up from its period and damping ratio.
pub(super) struct Oscillator {
    /// `ω = 2π/T` (1/s).
    pub w: f64,
    /// Damping ratio `ζ`, as given.
    pub z: f64,
    /// Sub-steps per sample `n`.
    pub n: u16,
    /// Sub-step `h/n` (s).
    pub hs: f64,
}

/// Oscillator `p`'s set-up, shared by both banks: its period checked (finite, at least
/// `1e-150` — periods so short that `ω²` overflows are rejected with the non-positive
/// ones — and not below the previous one: else [`Error::InvalidPeriod`]), then its damping
/// ratio (in `[0, 1)`: else [`Error::InvalidDamping`]); `ω = 2π/T`, `n` by
/// [`substeps_for`], `h/n`. `h` and `rule` checked by [`check_interval`]. Cost: a few
/// flops.
pub(super) const fn oscillator<const P: usize>(
    period: &[f64; P],
    damping: &[f64; P],
    p: usize,
    h: f64,
    rule: Substeps,
) -> Result<Oscillator, Error> {
    let t = period[p];
    let z = damping[p];
    if !(t.is_finite() && t >= 1e-150) || (p > 0 && t < period[p - 1]) {
        return Err(Error::InvalidPeriod);
    }
    if !(z >= 0.0 && z < 1.0) {
        return Err(Error::InvalidDamping);
    }
    let n = substeps_for(rule, h, t);
    Ok(Oscillator {
        w: TAU / t,
        z,
        n,
        hs: h / n as f64,
    })
}

/// The homogeneous part of a map is bounded as a damped oscillator's must be: the energy
/// `(ω²u² + v²)/2` never grows, so `|uu|, |vv|, ω|uv|, |vu|/ω ≤ 1` (exactly for both
/// schemes; here within `1e-6`). The exact scheme's matrix exponential loses that, and all
/// accuracy, far beyond `ω h ≈ 1e10` (its squarings amplify rounding by about `ω h`):
/// the fuzzer found a whole-interval `uu = 6e134` at `ω h ≈ 3e18`.
const fn contractive(m: &SdofOps, w: f64) -> bool {
    let b = 1.0 + 1e-6;
    m.uu.abs() <= b && m.vv.abs() <= b && (m.uv * w).abs() <= b && (m.vu / w).abs() <= b
}

/// Every operator of one oscillator, and `1/h`, fits the scalar type (largest finite value
/// `max`), the coefficients the bank derives from `ω` and `ζ` included, and both maps are
/// [`contractive`].
const fn oscillator_fits(op: &SdofOps, whole: &SdofOps, w: f64, z: f64, ka: f64, max: f64) -> bool {
    if !(contractive(op, w) && contractive(whole, w)) {
        return false;
    }
    let xs = [
        op.uu,
        op.uv,
        op.ug,
        op.ud,
        op.vu,
        op.vv,
        op.vg,
        op.vd,
        whole.uu,
        whole.uv,
        whole.ug,
        whole.ud,
        whole.vu,
        whole.vv,
        whole.vg,
        whole.vd,
        w,
        w * w,
        2.0 * z * w,
        ka,
        1.0 / (w * w),
        1.0 / w,
        2.0 * z * w / (w * w * w),
    ];
    all_fit(&xs, max)
}

/// Check the inputs and compute the `f64` operators (shared by the `f32` and `f64`
/// constructors; `max`: the largest finite value of the scalar type they are rounded to).
pub(super) const fn build_f64<const P: usize>(
    period: &[f64; P],
    damping: &[f64; P],
    h: f64,
    scheme: Scheme,
    rule: Substeps,
    max: f64,
) -> Result<OpsF64<P>, Error> {
    const_try!(check_interval(h, rule));
    let zero = SdofOps {
        uu: 0.0,
        uv: 0.0,
        ug: 0.0,
        ud: 0.0,
        vu: 0.0,
        vv: 0.0,
        vg: 0.0,
        vd: 0.0,
    };
    let mut out = OpsF64 {
        ops: [zero; P],
        whole: [zero; P],
        ka: [0.0; P],
        w2: [0.0; P],
        c2: [0.0; P],
        n: [1; P],
    };
    let mut fits_all = true;
    let mut p = 0;
    while p < P {
        let Oscillator { w, z, n, hs } = const_try!(oscillator(period, damping, p, h, rule));
        out.w2[p] = w * w;
        out.c2[p] = 2.0 * z * w;
        out.n[p] = n;
        out.ops[p] = match scheme {
            Scheme::Exact => operators::exact(w, 2.0 * z * w, hs),
            Scheme::Aem => operators::aem(w * w, 2.0 * z * w, hs),
        };
        out.whole[p] = match scheme {
            // exact over h directly (composing n exact sub-steps agrees to rounding)
            Scheme::Exact => operators::exact(w, 2.0 * z * w, h),
            Scheme::Aem => operators::compose(&out.ops[p], n),
        };
        // 1/(ω√(1 + 4ζ²)) without a square root: √(1 + x) by 6 Newton steps from 1 + x/2
        // (x = 4ζ² < 4; converged to rounding)
        let x = 4.0 * z * z;
        let mut r = 1.0 + 0.5 * x;
        let mut it = 0;
        while it < 6 {
            r = 0.5 * (r + (1.0 + x) / r);
            it += 1;
        }
        out.ka[p] = 1.0 / (w * r);
        // Operators that overflow (or come out NaN: the exact map over `ω h ≈ 1e106` was
        // NaN, found by fuzzing) are an error, not a bank that steps to NaN — reported
        // after every period and damping ratio has been checked (bad data first).
        fits_all &= oscillator_fits(&out.ops[p], &out.whole[p], w, z, out.ka[p], max);
        p += 1;
    }
    if !(fits_all && fits_value(1.0 / h, max)) {
        return Err(Error::OperatorOverflow);
    }
    Ok(out)
}

impl<T: Real, const P: usize> Bank<T, P> {
    /// A bank of oscillators with periods `period` (s, finite, at least `1e-150` — shorter
    /// ones, whose `ω²` overflows, are `InvalidPeriod` too — in non-decreasing order),
    /// damping ratios `damping` (in `[0, 1)`), sample interval `h` (s, finite, `> 0`), the
    /// exact scheme, and the sub-step rule [`Substeps::AUTO`]. Run time, for either scalar
    /// (generic code, `T` inferred); in a `static` use the `const fn`
    /// [`Bank::new_f32`] / [`Bank::new_f64`], bit-identical to it.
    ///
    /// Cost: about 1 000 `f64` flops per oscillator, once.
    ///
    /// Errors: [`Error::InvalidPeriod`], [`Error::InvalidDamping`],
    /// [`Error::InvalidTimeStep`], [`Error::OperatorOverflow`] (an operator is not finite
    /// in `T`, e.g. `ω²` beyond `f32`, or not bounded as an oscillator's map must be: `T/h`
    /// so small that the exact map over `h` cannot be formed, `ω h` far beyond `1e10`).
    pub fn new(period: [f64; P], damping: [f64; P], h: f64) -> Result<Self, Error> {
        Self::with(period, damping, h, Scheme::Exact, Substeps::AUTO)
    }

    /// As [`Bank::new`] with the scheme and the sub-step rule chosen (run time; the
    /// `const fn` twins are [`Bank::with_f32`] / [`Bank::with_f64`]).
    ///
    /// Errors: as [`Bank::new`], and [`Error::InvalidParameter`] for `Substeps::Fixed(0)`,
    /// `Substeps::Fixed(n > MAX_SUBSTEPS)` or `Substeps::PointsPerPeriod(0)`.
    pub fn with(
        period: [f64; P],
        damping: [f64; P],
        h: f64,
        scheme: Scheme,
        substeps: Substeps,
    ) -> Result<Self, Error> {
        // The `f64` bank with every operator checked against `T`'s range, then each value
        // rounded once: what the `const fn` of `T` computes, value for value.
        Bank::<f64, P>::checked_for(period, damping, h, scheme, substeps, T::MAX)
            .map(|b| b.rounded())
    }
}

impl<const P: usize> Bank<f64, P> {
    /// Every stored value rounded once to `T` (each was computed in `f64`, as the `const`
    /// constructors round it).
    fn rounded<T: Real>(&self) -> Bank<T, P> {
        let r = |a: &[f64; P]| a.map(T::from_f64_rounded);
        Bank {
            su: self.su.map(|row| r(&row)),
            sv: self.sv.map(|row| r(&row)),
            uu: r(&self.uu),
            uv: r(&self.uv),
            ug: r(&self.ug),
            ud: r(&self.ud),
            vu: r(&self.vu),
            vv: r(&self.vv),
            vg: r(&self.vg),
            vd: r(&self.vd),
            w2: r(&self.w2),
            c2: r(&self.c2),
            w: r(&self.w),
            ka: r(&self.ka),
            inv_w2: r(&self.inv_w2),
            inv_w: r(&self.inv_w),
            k2: r(&self.k2),
            inv_n: r(&self.inv_n),
            n: self.n,
            m1: self.m1,
            period: self.period,
            damping: self.damping,
            time_step: self.time_step,
            inv_h: T::from_f64_rounded(self.inv_h),
            scheme: self.scheme,
            non_finite: self.non_finite,
        }
    }
}

/// The `const fn` constructors of `Bank<f32, P>` and `Bank<f64, P>`: the scalar is in
/// the name (`new_f32`, `with_f64`, …), so a typed `static` needs no turbofish.
macro_rules! bank_ctor {
    ($t:ident, $new:ident, $with:ident) => {
        impl<const P: usize> Bank<$t, P> {
            /// `const fn` twin of [`Bank::new`] (same arguments, checks and errors; `h`
            /// the sample interval in s), bit-identical to it: in a `static`, the compiler
            /// computes the operators (flash). Cost: about 1 000 `f64` flops per
            /// oscillator, once.
            ///
            /// Errors: as [`Bank::new`].
            pub const fn $new(period: [f64; P], damping: [f64; P], h: f64) -> Result<Self, Error> {
                Self::$with(period, damping, h, Scheme::Exact, Substeps::AUTO)
            }

            /// `const fn` twin of [`Bank::with`], bit-identical to it.
            ///
            /// Errors: as [`Bank::with`].
            pub const fn $with(
                period: [f64; P],
                damping: [f64; P],
                h: f64,
                scheme: Scheme,
                substeps: Substeps,
            ) -> Result<Self, Error> {
                Self::checked_for(period, damping, h, scheme, substeps, $t::MAX as f64)
            }

            /// The bank with its operators checked against `max`, the largest finite
            /// value of the scalar type the values end in (`$t`'s own, or a narrower one
            /// the `f64` bank is rounded to by [`Bank::with`]).
            const fn checked_for(
                period: [f64; P],
                damping: [f64; P],
                h: f64,
                scheme: Scheme,
                substeps: Substeps,
                max: f64,
            ) -> Result<Self, Error> {
                let o = const_try!(build_f64(&period, &damping, h, scheme, substeps, max));
                let mut b = Bank {
                    su: [[0.0; P]; 4],
                    sv: [[0.0; P]; 4],
                    uu: [0.0; P],
                    uv: [0.0; P],
                    ug: [0.0; P],
                    ud: [0.0; P],
                    vu: [0.0; P],
                    vv: [0.0; P],
                    vg: [0.0; P],
                    vd: [0.0; P],
                    w2: [0.0; P],
                    c2: [0.0; P],
                    w: [0.0; P],
                    ka: [0.0; P],
                    inv_w2: [0.0; P],
                    inv_w: [0.0; P],
                    k2: [0.0; P],
                    inv_n: [0.0; P],
                    n: o.n,
                    m1: 0,
                    period,
                    damping,
                    time_step: h,
                    inv_h: (1.0 / h) as $t,
                    scheme,
                    non_finite: NonFinite::Refuse,
                };
                let mut p = 0;
                while p < P {
                    let op = &o.ops[p];
                    b.uu[p] = op.uu as $t;
                    b.uv[p] = op.uv as $t;
                    b.ug[p] = op.ug as $t;
                    b.ud[p] = op.ud as $t;
                    b.vu[p] = op.vu as $t;
                    b.vv[p] = op.vv as $t;
                    b.vg[p] = op.vg as $t;
                    b.vd[p] = op.vd as $t;
                    let wh = &o.whole[p];
                    b.su[0][p] = wh.uu as $t;
                    b.su[1][p] = wh.uv as $t;
                    b.su[2][p] = wh.ug as $t;
                    b.su[3][p] = wh.ud as $t;
                    b.sv[0][p] = wh.vu as $t;
                    b.sv[1][p] = wh.vv as $t;
                    b.sv[2][p] = wh.vg as $t;
                    b.sv[3][p] = wh.vd as $t;
                    b.w2[p] = o.w2[p] as $t;
                    b.c2[p] = o.c2[p] as $t;
                    b.w[p] = (core::f64::consts::TAU / period[p]) as $t;
                    b.ka[p] = o.ka[p] as $t;
                    let w = core::f64::consts::TAU / period[p];
                    b.inv_w2[p] = (1.0 / o.w2[p]) as $t;
                    b.inv_w[p] = (1.0 / w) as $t;
                    b.k2[p] = (o.c2[p] / (o.w2[p] * w)) as $t;
                    b.inv_n[p] = (1.0 / o.n[p] as f64) as $t;
                    if o.n[p] > 1 {
                        b.m1 = p + 1;
                    }
                    p += 1;
                }
                Ok(b)
            }

            /// A response at rest, before the first sample (`const fn`; cost: zeroing
            /// `5P` values).
            pub const fn at_rest(&self) -> Response<$t, P> {
                Response {
                    u: [0.0; P],
                    v: [0.0; P],
                    sd: [0.0; P],
                    sv: [0.0; P],
                    sa: [0.0; P],
                    last: 0.0,
                    samples: 0,
                    skipped: 0,
                    walks: 0,
                }
            }
        }
    };
}
bank_ctor!(f32, new_f32, with_f32);
bank_ctor!(f64, new_f64, with_f64);

/// The running response of a [`Bank`]: the state of every oscillator and the peaks so
/// far. Start with [`Bank::at_rest`]; feed samples with [`Bank::step`].
///
/// Units follow the samples: with `a_g` in m/s², displacements are m, velocities m/s and
/// accelerations m/s². Size: `5P + 1` values of `T` and two counters.
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response<T, const P: usize> {
    pub(super) u: [T; P],
    pub(super) v: [T; P],
    pub(super) sd: [T; P],
    pub(super) sv: [T; P],
    pub(super) sa: [T; P],
    /// The last finite sample (the load at the start of the next step).
    pub(super) last: T,
    pub(super) samples: u64,
    pub(super) skipped: u64,
    pub(super) walks: u64,
}

impl<T: Real, const P: usize> Response<T, P> {
    /// Peak relative displacement `max |u|` of each oscillator so far, `Sd` (m). Cost: none.
    pub fn sd(&self) -> &[T; P] {
        &self.sd
    }
    /// Peak relative velocity `max |u'|` so far, `Sv` (m/s). Cost: none.
    pub fn sv(&self) -> &[T; P] {
        &self.sv
    }
    /// Peak absolute acceleration `max |u'' + a_g| = max |2ζω u' + ω² u|` so far, `Sa`
    /// (m/s²). Cost: none.
    pub fn sa(&self) -> &[T; P] {
        &self.sa
    }
    /// Relative displacement of each oscillator now (m). Cost: none.
    pub fn displacement(&self) -> &[T; P] {
        &self.u
    }
    /// Relative velocity of each oscillator now (m/s). Cost: none.
    pub fn velocity(&self) -> &[T; P] {
        &self.v
    }
    /// Samples fed so far, the skipped (non-finite) ones included, not counting free
    /// vibration. Cost: none.
    pub fn samples(&self) -> u64 {
        self.samples
    }
    /// Non-finite samples skipped so far (see [`Bank::step`]). Cost: none.
    pub fn skipped(&self) -> u64 {
        self.skipped
    }
    /// Sub-step walks taken so far (one per oscillator and interval whose peak could rise
    /// inside it; see [`Bank::step`]): the part of the cost that depends on the record.
    /// Cost: none.
    pub fn walks(&self) -> u64 {
        self.walks
    }
    /// Every state and peak is finite (`u`, `v`, `Sd`, `Sv`, `Sa`): what
    /// [`Bank::try_step`] checks. Cost: a scan of `5P` values.
    pub fn is_finite(&self) -> bool {
        use super::all_finite;
        all_finite(&self.u)
            & all_finite(&self.v)
            & all_finite(&self.sd)
            & all_finite(&self.sv)
            & all_finite(&self.sa)
    }
    /// A response at rest for any `T` (the `const` [`Bank::at_rest`] is per type).
    pub(super) fn rest() -> Self {
        let z = T::from_f64_rounded(0.0);
        Response {
            u: [z; P],
            v: [z; P],
            sd: [z; P],
            sv: [z; P],
            sa: [z; P],
            last: z,
            samples: 0,
            skipped: 0,
            walks: 0,
        }
    }
}

#[inline(always)]
fn abs<T: Real>(x: T) -> T {
    // max(x, −x): one sign flip and one `max` (vector max on the host); for finite x
    let n = -x;
    if x > n { x } else { n }
}

#[inline(always)]
fn keep_max<T: Real>(m: &mut T, x: T) {
    // an unconditional store of a select: vectorizes (a conditional store does not)
    let old = *m;
    // x86-64: LLVM folds `store(select(c, x, load p), p)` into a masked store when AVX is
    // on (`vmaskmovpd`, microcoded on AMD: the AVX bank ran 2× slower than SSE2 in f32).
    // `old + 0` is not a load, so the select stays a `vmaxpd`; it is `old` bit for bit,
    // since a peak is never −0 (it starts at +0 and only a larger value replaces it) and
    // `+ 0` keeps every other value, NaN and ±∞ included. Other targets: plain `old`.
    #[cfg(target_arch = "x86_64")]
    let old = old + T::from_f64_rounded(0.0);
    *m = if x > old { x } else { old };
}

impl<T: Real, const P: usize> Bank<T, P> {
    /// Feed the next ground-acceleration sample `ag` (m/s² or any unit; the response is in
    /// the same unit system). Sample 0 is the ground acceleration at `t = 0`, with every
    /// oscillator at rest; each later sample advances time by `h`, the load linear
    /// between samples. Peaks are taken at the samples and, for oscillator `p`, at the ends
    /// of its `n_p` sub-steps in between.
    ///
    /// The sub-steps are walked only where the peak could rise inside the interval. On the
    /// interval the motion is the quasi-static part `u_p(τ) = −a(τ)/ω² + 2ζs/ω³`
    /// (`v_p = −s/ω²`, `s` the load's slope; `ω²u_p + 2ζωv_p = −a`) plus a free vibration
    /// `w` whose `|z| = |(ωw, w')|` the damping can only lower. So inside the interval,
    /// with `A = max(|a₀|, |a₁|)`: `|u| ≤ 2ζ|s|/ω³ + A/ω² + |z₀|/ω`, `|v| ≤ |s|/ω² + |z₀|`,
    /// `|ω²u + 2ζωv| ≤ A + ω√(1 + 4ζ²)|z₀|`; when all three are below the peaks so far,
    /// nothing between the samples can raise them and the walk is skipped. The bound is
    /// that of the exact
    /// motion: with the exact scheme the peaks are those of walking every interval (to
    /// rounding); with the AEM its sub-step values may exceed the bound by the scheme's
    /// `O(h²)` error, and a peak may be missed by that much.
    ///
    /// Unchecked: a non-finite sample (NaN, ±∞) is skipped and counted
    /// ([`Response::skipped`]) whatever the bank's [`NonFinite`] policy (this step has no
    /// error to return; [`Bank::try_step`] applies the policy): time still advances by `h`,
    /// with the last finite sample held in its place, so later samples stay on their times;
    /// the peaks so far are kept.
    ///
    /// Cost: `P` whole-interval steps (10 multiply-adds, 3 absolute values and 3
    /// comparisons each), a bound check (about 20 flops) for each oscillator with
    /// `n_p > 1`, both vectorized over the oscillators, and `n_p − 1` sub-steps for each
    /// oscillator whose bound fails (about 2 % of the checks on El Centro,
    /// [`Response::walks`]); no allocation, no panic.
    pub fn step(&self, r: &mut Response<T, P>, ag: T) {
        // t = 0: at rest, u'' = −a_g, absolute acceleration 0; nothing to step.
        if let Some((a0, a1)) = super::take_sample(&mut r.last, &mut r.samples, &mut r.skipped, ag)
        {
            // On x86-64 with AVX, 4 `f64` or 8 `f32` oscillators a packed operation
            // instead of 2 or 4 (same bits, `linalg::wide`).
            crate::linalg::wide(|| self.advance(r, a0, a1));
        }
    }

    /// [`Bank::step`], checked: the sample is taken on a copy of `r`, committed only if
    /// every state and peak of the copy is finite ([`Response::is_finite`]). A non-finite
    /// sample is refused under [`NonFinite::Refuse`] (the default) and skipped and counted
    /// (`Ok`) under [`NonFinite::Skip`], as in [`Bank::step`]; a *finite* sample so large
    /// that the response overflows (e.g. `1.5e308` then `−1.5e308`, whose difference is
    /// `−∞`) is an error under either policy.
    ///
    /// Errors, each with `r` unchanged (so [`Response::samples`] is the index of the
    /// sample refused): [`Error::NonFiniteInput`] (a non-finite sample, refused);
    /// [`Error::NonFiniteState`]. Cost: one comparison, one [`Bank::step`], a copy of `r`
    /// and a scan of `5P` values.
    ///
    /// ```
    /// use aemstep::{Error, spectrum::{Bank, NonFinite}};
    /// let bank = Bank::<f64, 2>::new([0.2, 1.0], [0.05; 2], 0.01)?;
    /// let mut r = bank.at_rest();
    /// bank.try_step(&mut r, 1.0)?;
    /// assert_eq!(bank.try_step(&mut r, f64::NAN), Err(Error::NonFiniteInput));
    /// assert_eq!(r.samples(), 1); // unchanged: the refused sample is sample 1
    /// // Skipping, asked for explicitly: held and counted.
    /// let skipping = bank.with_non_finite(NonFinite::Skip);
    /// skipping.try_step(&mut r, f64::NAN)?;
    /// assert_eq!((r.samples(), r.skipped()), (2, 1));
    /// # Ok::<(), Error>(())
    /// ```
    pub fn try_step(&self, r: &mut Response<T, P>, ag: T) -> Result<(), Error> {
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

    /// The response to a whole record: from rest, every sample of `record` (sample
    /// interval [`Bank::time_step`]) then [`Bank::free_vibration_samples`] of free
    /// vibration. A non-finite sample is refused ([`NonFinite::Refuse`], the default: the
    /// record is checked before it is stepped) or skipped and counted
    /// ([`NonFinite::Skip`], as in [`Bank::step`]).
    ///
    /// The samples are stepped unchecked and the response checked once at the end: a
    /// non-finite state or peak never turns finite again under these linear maps (`∞` and
    /// NaN propagate, peaks are running maxima), so the end check sees every overflow.
    ///
    /// Errors: [`Error::InvalidTimeStep`] if the tail exceeds
    /// [`MAX_FREE_VIBRATION_SAMPLES`](super::MAX_FREE_VIBRATION_SAMPLES);
    /// [`Error::NonFiniteInput`] if a sample is not finite and the policy refuses it
    /// ([`first_non_finite`](super::first_non_finite) gives its index);
    /// [`Error::NonFiniteState`] if the response overflowed. Cost: `N + ⌈T_max/h⌉` steps,
    /// two scans.
    ///
    /// ```
    /// use aemstep::{Error, spectrum::{Bank, NonFinite}};
    /// let bank = Bank::<f64, 2>::new([0.2, 1.0], [0.05; 2], 0.01)?;
    /// let r = bank.response(&[0.0, 1.0, -1.0, 0.5])?; // m/s²
    /// assert!(r.sd()[1] > 0.0);
    /// // a NaN sample: refused by default, skipped (held, counted) if asked
    /// assert_eq!(bank.response(&[0.0, f64::NAN]), Err(Error::NonFiniteInput));
    /// let held = bank.with_non_finite(NonFinite::Skip).response(&[0.0, 1.0, f64::NAN])?;
    /// assert_eq!((held.sd(), held.skipped()), (bank.response(&[0.0, 1.0, 1.0])?.sd(), 1));
    /// // finite samples whose difference overflows: an error, not ±∞ in the spectrum
    /// assert_eq!(bank.response(&[0.0, 1.5e308, -1.5e308]), Err(Error::NonFiniteState));
    /// # Ok::<(), Error>(())
    /// ```
    pub fn response(&self, record: &[T]) -> Result<Response<T, P>, Error> {
        let tail = super::checked_tail(&self.period, self.time_step)?;
        self.record_pass(record, tail)
    }

    /// From rest, the record checked against the policy, every sample of `record` stepped
    /// unchecked, then `tail` samples of free vibration, the response checked once at the
    /// end (see [`Bank::response`]): the pass of [`Bank::response`] and of the host batch.
    ///
    /// Errors: [`Error::NonFiniteInput`], [`Error::NonFiniteState`]. Cost: `N + tail`
    /// steps, two scans.
    pub(super) fn record_pass(&self, record: &[T], tail: u32) -> Result<Response<T, P>, Error> {
        super::check_record(self.non_finite, record)?;
        let mut r = Response::rest();
        for &a in record {
            self.step(&mut r, a);
        }
        self.free_vibration(&mut r, tail);
        if r.is_finite() {
            Ok(r)
        } else {
            Err(Error::NonFiniteState)
        }
    }

    /// Continue after the record in free vibration: the ground acceleration returns
    /// linearly to zero over one `h` and stays zero for `samples − 1` more intervals;
    /// peaks keep updating ([`Response::samples`] does not count these).
    /// [`Bank::free_vibration_samples`] is long enough for every oscillator's peak.
    ///
    /// Cost: `samples` times that of [`Bank::step`].
    pub fn free_vibration(&self, r: &mut Response<T, P>, samples: u32) {
        if r.samples == 0 {
            return;
        }
        crate::linalg::wide(|| self.ring_out(r, samples));
    }

    /// The loop of [`Bank::free_vibration`] (inlined where it is called).
    #[inline(always)]
    fn ring_out(&self, r: &mut Response<T, P>, samples: u32) {
        let zero = T::from_f64_rounded(0.0);
        for _ in 0..samples {
            let a0 = r.last;
            r.last = zero;
            self.advance(r, a0, zero);
        }
    }

    /// One period of the longest oscillator, in samples (`⌈T_max/h⌉`, saturating at
    /// `u32::MAX`): after the record, a damped oscillator's free vibration decays, so its
    /// peak (displacement, velocity and absolute acceleration) comes within one period;
    /// stepping this long catches it. The record-level calls refuse a tail longer than
    /// [`MAX_FREE_VIBRATION_SAMPLES`](super::MAX_FREE_VIBRATION_SAMPLES).
    /// Cost: a scan of the periods.
    pub fn free_vibration_samples(&self) -> u32 {
        super::longest_period_samples(&self.period, self.time_step)
    }

    /// One sample interval `a0 → a1`: the peak search between the samples where needed,
    /// then the whole-interval step of every oscillator.
    #[inline(always)]
    fn advance(&self, r: &mut Response<T, P>, a0: T, a1: T) {
        let d = a1 - a0;
        let zero = T::from_f64_rounded(0.0);
        let slope = d * self.inv_h;
        let amax = if abs(a0) > abs(a1) { abs(a0) } else { abs(a1) };
        let m1 = if self.m1 < P { self.m1 } else { P };
        let mut need = [false; P];
        let aslope = abs(slope);
        for i in 0..m1 {
            // Room left for |z| of the free part under each peak, lowered by its
            // quasi-static share (|u_p| ≤ 2ζ|s|/ω³ + A/ω², |v_p| = |s|/ω², see `step`).
            let mut room = self.w[i] * r.sd[i] - (aslope * self.k2[i] + amax * self.inv_w[i]);
            let rv = r.sv[i] - aslope * self.inv_w2[i];
            if rv < room {
                room = rv;
            }
            let ra = self.ka[i] * (r.sa[i] - amax);
            if ra < room {
                room = ra;
            }
            // z of the free part at the start: (ω(u₀ − u_p(0)), v₀ − v_p)
            let fu = self.w[i] * r.u[i] - (slope * self.k2[i] - a0 * self.inv_w[i]);
            let fv = r.v[i] + slope * self.inv_w2[i];
            // (`|` of two comparisons, not `||`: no branch, so the loop vectorizes)
            need[i] = (room <= zero) | (fu * fu + fv * fv > room * room);
        }
        // Two passes: the bound above vectorizes; the walks (about 2 % of the checks on
        // El Centro) follow.
        for i in 0..m1 {
            if need[i] {
                self.walk(r, i, a0, d);
            }
        }
        let [su0, su1, su2, su3] = &self.su;
        let [sv0, sv1, sv2, sv3] = &self.sv;
        for i in 0..P {
            let (u0, v0) = (r.u[i], r.v[i]);
            let u1 = su0[i] * u0 + su1[i] * v0 + su2[i] * a0 + su3[i] * d;
            let v1 = sv0[i] * u0 + sv1[i] * v0 + sv2[i] * a0 + sv3[i] * d;
            r.u[i] = u1;
            r.v[i] = v1;
            let acc = self.w2[i] * u1 + self.c2[i] * v1;
            keep_max(&mut r.sd[i], abs(u1));
            keep_max(&mut r.sv[i], abs(v1));
            keep_max(&mut r.sa[i], abs(acc));
        }
    }

    /// The peaks of oscillator `i` at its `n − 1` sub-step ends inside the interval
    /// (the state is not changed: the whole-interval step follows).
    #[inline(never)]
    fn walk(&self, r: &mut Response<T, P>, i: usize, a0: T, d: T) {
        let (Some(&n), Some(&inv)) = (self.n.get(i), self.inv_n.get(i)) else {
            return;
        };
        let (uu, uv, ug, ud) = (self.uu[i], self.uv[i], self.ug[i], self.ud[i]);
        let (vu, vv, vg, vd) = (self.vu[i], self.vv[i], self.vg[i], self.vd[i]);
        let (w2, c2) = (self.w2[i], self.c2[i]);
        let dl = d * inv;
        let (mut u, mut v, mut g) = (r.u[i], r.v[i], a0);
        let (mut pd, mut pv, mut pa) = (r.sd[i], r.sv[i], r.sa[i]);
        for _ in 1..n {
            let u1 = uu * u + uv * v + ug * g + ud * dl;
            v = vu * u + vv * v + vg * g + vd * dl;
            u = u1;
            g += dl;
            keep_max(&mut pd, abs(u));
            keep_max(&mut pv, abs(v));
            keep_max(&mut pa, abs(w2 * u + c2 * v));
        }
        r.sd[i] = pd;
        r.sv[i] = pv;
        r.sa[i] = pa;
        r.walks += 1;
    }

    /// Periods (s), as given. Cost: none.
    pub fn periods(&self) -> &[f64; P] {
        &self.period
    }
    /// Damping ratios, as given. Cost: none.
    pub fn damping(&self) -> &[f64; P] {
        &self.damping
    }
    /// The sample interval `h` (s), the time step of every oscillator's whole-interval
    /// map. Cost: none.
    pub fn time_step(&self) -> f64 {
        self.time_step
    }
    /// The scheme the operators were built with. Cost: none.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }
    /// What the checked and record-level calls do with a non-finite sample
    /// ([`NonFinite::Refuse`] unless [`Bank::with_non_finite`] chose otherwise). Cost: none.
    pub fn non_finite(&self) -> NonFinite {
        self.non_finite
    }
    /// The same bank with the non-finite-sample policy `policy` (`const fn`: usable on a
    /// `static` bank's constructor result, e.g. `match Bank::new_f32(..) { Ok(b) =>
    /// b.with_non_finite(NonFinite::Skip), .. }`). The operators are unchanged, so the
    /// responses to finite records are the same bits. Cost: a copy of the bank.
    pub const fn with_non_finite(self, policy: NonFinite) -> Self {
        Bank {
            non_finite: policy,
            ..self
        }
    }
    /// Sub-steps per sample of each oscillator (`1 ..= MAX_SUBSTEPS`). Cost: none.
    pub fn substeps(&self) -> &[u16; P] {
        &self.n
    }
    /// Oscillator sub-steps per sample, `Σ_p n_p` (the cost unit of [`Bank::step`]).
    /// Cost: a sum over the bank.
    pub fn substeps_per_sample(&self) -> u32 {
        self.n.iter().map(|&n| n as u32).sum()
    }

    /// Pseudo-spectral velocity `PSV = ω Sd` (m/s) of each oscillator from its spectral
    /// displacement `sd` (m; [`Response::sd`] or a RotD spectrum).
    /// Cost: `P` divisions and multiplications.
    pub fn psv(&self, sd: &[T; P]) -> [T; P] {
        let mut out = *sd;
        for (o, t) in out.iter_mut().zip(self.period.iter()) {
            *o *= T::from_f64_rounded(TAU / *t);
        }
        out
    }

    /// Pseudo-spectral acceleration `PSA = ω² Sd` (m/s²) of each oscillator from its
    /// spectral displacement `sd` (m; [`Response::sd`] or a RotD spectrum).
    /// Cost: `P` multiplications.
    pub fn psa(&self, sd: &[T; P]) -> [T; P] {
        let mut out = *sd;
        for (o, w2) in out.iter_mut().zip(self.w2.iter()) {
            *o *= *w2;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bank stepped through `Bank::step` (on x86-64 with AVX, the `linalg::wide`
    /// path) and through the plain `advance` give the same bits: state, peaks, walks.
    fn same_bits<T: Real>(rest: fn(&Bank<T, 37>) -> Response<T, 37>) {
        let per: [f64; 37] = core::array::from_fn(|i| 0.01 * 1.2f64.powi(i as i32));
        let b = Bank::<T, 37>::new(per, [0.05; 37], 0.02).unwrap();
        let (mut wide, mut plain) = (rest(&b), rest(&b));
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut a0 = T::from_f64_rounded(0.0);
        for n in 0..2000 {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            let noise = (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            let a = T::from_f64_rounded(3.0 * (0.07 * n as f64).sin() + noise);
            b.step(&mut wide, a);
            if n > 0 {
                b.advance(&mut plain, a0, a);
            }
            a0 = a;
        }
        b.free_vibration(&mut wide, 100);
        let zero = T::from_f64_rounded(0.0);
        for _ in 0..100 {
            b.advance(&mut plain, a0, zero);
            a0 = zero;
        }
        assert!(wide.walks > 0 && wide.walks == plain.walks);
        for (x, y) in [
            (&wide.u, &plain.u),
            (&wide.v, &plain.v),
            (&wide.sd, &plain.sd),
            (&wide.sv, &plain.sv),
            (&wide.sa, &plain.sa),
        ] {
            for (p, q) in x.iter().zip(y) {
                assert_eq!(p.as_f64().to_bits(), q.as_f64().to_bits());
            }
        }
    }

    #[test]
    fn wide_path_is_bit_identical() {
        same_bits::<f64>(Bank::<f64, 37>::at_rest);
        same_bits::<f32>(Bank::<f32, 37>::at_rest);
    }
}
