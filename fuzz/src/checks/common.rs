//! What the fuzz targets share: the current input's context for the messages of broken
//! properties, the counters, the decoder from raw bytes to inputs biased to the extremes
//! (`Bytes`), the independent references (nalgebra, f64), and the property checks and
//! helpers several targets use (the data rule, the checked-step contract, the energy check).

use std::collections::BTreeMap;
use std::fmt::Debug;
use std::sync::Mutex;

use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::{Damping, Error, Real, StepState, Stepper};

thread_local! {
    static CONTEXT: std::cell::RefCell<String> = const { std::cell::RefCell::new(String::new()) };
}

/// Note the decoded data of the current input, for the message of a broken property.
pub(super) fn set_context(s: String) {
    CONTEXT.with(|c| *c.borrow_mut() = s);
}

/// The decoded data of the current input.
pub fn context() -> String {
    CONTEXT.with(|c| c.borrow().clone())
}

// ---------------------------------------------------------------------------------------
// Counters: what the inputs were and what happened (printed per target by the fuzz
// script, tabulated in docs/robustness.md).

static COUNTS: Mutex<BTreeMap<(&'static str, &'static str), u64>> = Mutex::new(BTreeMap::new());

/// Count one `what` for `target`.
pub fn count(target: &'static str, what: &'static str) {
    let mut c = COUNTS.lock().unwrap_or_else(|e| e.into_inner());
    *c.entry((target, what)).or_default() += 1;
}

/// The counters so far, `(target, what, n)`.
pub fn counts() -> Vec<(&'static str, &'static str, u64)> {
    let c = COUNTS.lock().unwrap_or_else(|e| e.into_inner());
    c.iter().map(|(&(t, w), &n)| (t, w, n)).collect()
}

/// The counters as `COUNT <target> <what> <n>` lines.
pub fn count_lines() -> String {
    counts()
        .iter()
        .map(|(t, w, n)| format!("COUNT {t} {w} {n}\n"))
        .collect()
}

pub(super) fn outcome<X>(t: &'static str, r: &Result<X, Error>) {
    count(t, if r.is_ok() { "built" } else { "rejected" });
}

// ---------------------------------------------------------------------------------------
// The decoder: raw bytes to numbers biased to the extremes. Past the end of the data every
// byte reads 0 (so every input decodes to something, and short inputs are ordinary).

/// A cursor over the fuzzer's bytes that also notes what kind of numbers it produced.
pub struct Bytes<'a> {
    data: &'a [u8],
    pub(super) pos: usize,
    extreme: bool,
    nonfinite: bool,
}

/// `M, C, K` and `h` of one linear system.
#[derive(Clone, Copy, Debug)]
pub struct System<const N: usize> {
    /// Mass.
    pub m: SMatrix<f64, N, N>,
    /// Damping.
    pub c: SMatrix<f64, N, N>,
    /// Stiffness.
    pub k: SMatrix<f64, N, N>,
    /// Time step.
    pub h: f64,
}

impl<'a> Bytes<'a> {
    /// A cursor at the start of `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Self {
            data,
            pos: 0,
            extreme: false,
            nonfinite: false,
        }
    }

    /// The next byte (0 past the end).
    pub fn byte(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos = self.pos.saturating_add(1);
        b
    }

    /// A choice among `n` (`n ≥ 1`).
    pub fn pick(&mut self, n: u8) -> u8 {
        self.byte() % n
    }

    pub(super) fn u16(&mut self) -> u16 {
        u16::from(self.byte()) << 8 | u16::from(self.byte())
    }

    /// Uniform in `[0, 1)`.
    pub(super) fn unit(&mut self) -> f64 {
        f64::from(self.u16()) / 65536.0
    }

    /// Note a produced number's kind (for the input category).
    pub fn note(&mut self, x: f64) -> f64 {
        if !x.is_finite() {
            self.nonfinite = true;
        } else if x != 0.0 && !(1e-100..=1e100).contains(&x.abs()) {
            self.extreme = true;
        }
        x
    }

    /// The input's category so far: non-finite, extreme (outside 1e-100 … 1e100, or
    /// subnormal) or finite.
    pub fn category(&self) -> &'static str {
        if self.nonfinite {
            "input: non-finite"
        } else if self.extreme {
            "input: extreme"
        } else {
            "input: finite"
        }
    }

    /// Any `f64`, biased to ordinary sizes and to the extremes: ±0, ±1e-320 … ±1e308,
    /// powers of two over the whole range, subnormals, `MAX`, NaN, ±∞, raw bit patterns.
    pub fn value(&mut self) -> f64 {
        let x = match self.byte() % 16 {
            0..=3 => -10.0 + 20.0 * self.unit(),
            4 => {
                if self.byte().is_multiple_of(2) {
                    0.0
                } else {
                    -0.0
                }
            }
            5..=7 => {
                let m = -9.9 + 19.8 * self.unit();
                let e = i32::from(self.u16() % 629) - 320;
                m * 10f64.powi(e)
            }
            8 => {
                let e = i32::from(self.u16() % 2098) - 1074;
                let s = if self.byte().is_multiple_of(2) {
                    1.0
                } else {
                    -1.0
                };
                s * pow2(e)
            }
            9 => [
                5e-324,
                1e-310,
                f64::MIN_POSITIVE,
                f64::EPSILON,
                f64::MAX,
                -f64::MAX,
                1.0,
                -1.0,
            ][usize::from(self.byte() % 8)],
            10 => [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -f64::NAN]
                [usize::from(self.byte() % 4)],
            11 => {
                let mut b = [0u8; 8];
                for x in &mut b {
                    *x = self.byte();
                }
                f64::from_le_bytes(b)
            }
            12 | 13 => f64::from(i32::from(self.byte() % 9) - 4),
            _ => 10f64.powf(-3.0 + 6.0 * self.unit()),
        };
        self.note(x)
    }

    /// Ordinary: in `[-10, 10)`.
    pub fn ordinary(&mut self) -> f64 {
        -10.0 + 20.0 * self.unit()
    }

    /// A scale factor: 1 (half of the time) or `10^e`, `e` in −300 … 300.
    pub fn scale(&mut self) -> f64 {
        let x = if self.byte().is_multiple_of(2) {
            1.0
        } else {
            10f64.powi(i32::from(self.u16() % 601) - 300)
        };
        self.note(x)
    }

    /// A parameter meant to lie in `[lo, hi]`: mostly inside, sometimes at an end, sometimes
    /// anything.
    pub fn param(&mut self, lo: f64, hi: f64) -> f64 {
        let x = match self.byte() % 8 {
            0..=4 => lo + (hi - lo) * self.unit(),
            5 => lo,
            6 => hi,
            _ => self.value(),
        };
        self.note(x)
    }

    /// A time step: ordinary (1e-4 … 1), extreme (1e-324 … 1e300), invalid (0, −0, < 0,
    /// NaN, ∞, `h²` underflowing or overflowing), or any value.
    pub fn time_step(&mut self) -> f64 {
        let h = match self.byte() % 8 {
            0..=3 => 10f64.powf(-4.0 + 4.0 * self.unit()),
            4 | 5 => 10f64.powi(i32::from(self.u16() % 625) - 324),
            6 => [
                0.0,
                -0.0,
                -0.01,
                f64::NAN,
                f64::INFINITY,
                5e-324,
                1e-160,
                1e155,
                f64::MIN_POSITIVE,
            ][usize::from(self.byte() % 9)],
            _ => self.value(),
        };
        self.note(h)
    }

    /// Entries from [`Bytes::value`].
    pub fn vector<const N: usize>(&mut self) -> SVector<f64, N> {
        SVector::from_fn(|_, _| self.value())
    }

    /// Ordinary entries.
    pub fn small_vector<const N: usize>(&mut self) -> SVector<f64, N> {
        SVector::from_fn(|_, _| self.ordinary())
    }

    /// A rectangular matrix: entries from [`Bytes::value`], ordinary entries at a scale, the
    /// identity (where square), or zero.
    pub fn matrix<const R: usize, const C: usize>(&mut self) -> SMatrix<f64, R, C> {
        let a: SMatrix<f64, R, C> = match self.byte() % 6 {
            0 | 1 => SMatrix::from_fn(|_, _| self.value()),
            2 | 3 => {
                let s = self.scale();
                SMatrix::from_fn(|_, _| self.ordinary()) * s
            }
            4 => SMatrix::from_fn(|i, j| if i == j { 1.0 } else { 0.0 }),
            _ => SMatrix::zeros(),
        };
        self.note_all(a.as_slice());
        a
    }

    /// A symmetric positive definite matrix `A Aᵀ + d I` of ordinary entries, at a scale.
    pub fn spd<const N: usize>(&mut self) -> SMatrix<f64, N, N> {
        let a = SMatrix::<f64, N, N>::from_fn(|_, _| self.ordinary() / 10.0);
        let d = 0.05 + self.unit();
        let s = self.scale();
        let mut m = (a * a.transpose() + SMatrix::identity() * d) * s;
        // exactly symmetric (the product is, to rounding)
        m = (m + m.transpose()) * 0.5;
        self.note_all(m.as_slice());
        m
    }

    /// A square matrix of a structure chosen by the data: any entries, symmetric positive
    /// definite, singular or near-singular (`v vᵀ + δ I`), non-symmetric (SPD plus a skew
    /// part), diagonal, zero or a multiple of the identity.
    pub fn square<const N: usize>(&mut self) -> SMatrix<f64, N, N> {
        let a = match self.byte() % 10 {
            0..=2 => SMatrix::from_fn(|_, _| self.value()),
            3 | 4 => self.spd(),
            5 => {
                let v = self.small_vector::<N>();
                let d = [0.0, 1e-17, 1e-15, 1e-12, 1e-8, 5e-324][usize::from(self.byte() % 6)];
                let s = self.scale();
                (v * v.transpose() + SMatrix::identity() * d) * s
            }
            6 => {
                let s = self.spd::<N>();
                let w = SMatrix::<f64, N, N>::from_fn(|_, _| self.ordinary());
                s + (w - w.transpose()) * (s.amax() / 10.0)
            }
            7 => SMatrix::from_diagonal(&self.vector::<N>()),
            8 => SMatrix::zeros(),
            _ => SMatrix::identity() * self.value(),
        };
        self.note_all(a.as_slice());
        a
    }

    /// `M, C, K, h` of a structure chosen by the data: independent matrices, effective
    /// matrices cancelled to rounding (`K = −4M/h²`, `C = −2M/h`, and near it), symmetric
    /// positive definite `M, K` with `C = 0` and `h` from `ω_max` (for the energy check),
    /// or with Rayleigh damping.
    pub fn system<const N: usize>(&mut self) -> System<N> {
        let kind = self.byte() % 10;
        let mut s: System<N> = System {
            m: self.square(),
            c: self.square(),
            k: self.square(),
            h: self.time_step(),
        };
        match kind {
            5 => {
                s.k = s.m * (-4.0 / (s.h * s.h));
                if self.byte().is_multiple_of(2) {
                    s.c = SMatrix::zeros();
                }
            }
            6 => {
                s.c = s.m * (-2.0 / s.h);
                s.k = SMatrix::zeros();
            }
            7 => {
                let d = [1e-16, 1e-12, 1e-8][usize::from(self.byte() % 3)];
                s.k = s.m * (-4.0 * (1.0 + d) / (s.h * s.h));
            }
            8 | 9 => {
                s.m = self.spd();
                s.k = self.spd();
                s.c = if kind == 8 {
                    SMatrix::zeros()
                } else {
                    s.m * self.unit() + s.k * (self.unit() * 1e-2)
                };
                if let Some(info) = spd_info(&s.m, &s.k) {
                    let wh = 10f64.powf(-4.0 + 6.0 * self.unit());
                    s.h = wh / info.omega_max;
                }
            }
            _ => {}
        }
        self.note_all(s.m.as_slice());
        self.note_all(s.c.as_slice());
        self.note_all(s.k.as_slice());
        self.note(s.h);
        s
    }

    pub(super) fn note_all(&mut self, xs: &[f64]) {
        for &x in xs {
            self.note(x);
        }
    }
}

/// `2^e` for any `e` in −1074 … 1023 (subnormal at the low end).
pub(super) fn pow2(e: i32) -> f64 {
    if e < -1022 {
        f64::from_bits(1u64 << (e + 1074))
    } else {
        f64::from_bits(((e + 1023) as u64) << 52)
    }
}

// ---------------------------------------------------------------------------------------
// Independent references (nalgebra, f64): nothing here calls the code under test.

/// Condition numbers of SPD `M`, `K` and the highest natural frequency of `M⁻¹K`.
#[derive(Clone, Copy, Debug)]
pub struct SpdInfo {
    /// `λmax/λmin` of `M`.
    pub kappa_m: f64,
    /// `λmax/λmin` of `K`.
    pub kappa_k: f64,
    /// `√λmax(M⁻¹K)` (rad/s).
    pub omega_max: f64,
}

/// `M`, `K` exactly symmetric and positive definite (eigenvalues of the scaled matrices),
/// finite: their condition numbers and `ω_max`; else `None`.
pub fn spd_info<const N: usize>(m: &SMatrix<f64, N, N>, k: &SMatrix<f64, N, N>) -> Option<SpdInfo> {
    let spd = |a: &SMatrix<f64, N, N>| -> Option<(f64, f64, nalgebra::DMatrix<f64>)> {
        if !a.iter().all(|x| x.is_finite()) || *a != a.transpose() {
            return None;
        }
        let s = a.amax();
        if !(s > 0.0 && s.is_normal()) {
            return None;
        }
        let d = nalgebra::DMatrix::from_fn(N, N, |i, j| a[(i, j)] / s);
        let ev = d.clone().symmetric_eigen().eigenvalues;
        let (lo, hi) = (ev.min(), ev.max());
        (lo > 0.0 && lo.is_normal()).then_some((hi / lo, s, d))
    };
    let (kappa_m, sm, dm) = spd(m)?;
    let (kappa_k, sk, dk) = spd(k)?;
    let l = dm.cholesky()?.l();
    let li = l.clone().try_inverse()?;
    let a = &li * dk * li.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let lmax = a.symmetric_eigen().eigenvalues.max();
    let omega_max = (lmax * (sk / sm)).sqrt();
    (omega_max.is_finite() && omega_max > 0.0).then_some(SpdInfo {
        kappa_m,
        kappa_k,
        omega_max,
    })
}

pub(super) fn energy<const N: usize>(
    m: &SMatrix<f64, N, N>,
    k: &SMatrix<f64, N, N>,
    u: &SVector<f64, N>,
    v: &SVector<f64, N>,
) -> f64 {
    0.5 * (v.dot(&(m * v)) + u.dot(&(k * u)))
}

// ---------------------------------------------------------------------------------------
// Shared helpers.

pub(super) fn bits<S: Debug>(s: &S) -> String {
    // `{:?}` of a float is its shortest round-trip form: equal strings ⇔ equal bits (for
    // all but NaN payloads, and a committed state is finite).
    format!("{s:?}")
}

pub(super) fn eps<T: Real>() -> f64 {
    if core::mem::size_of::<T>() == 4 {
        f64::from(f32::EPSILON)
    } else {
        f64::EPSILON
    }
}

pub(super) fn to_t<T: Real, const R: usize, const C: usize>(
    x: &SMatrix<f64, R, C>,
) -> SMatrix<T, R, C> {
    x.map(T::from_f64_rounded)
}

pub(super) fn to_f64<T: Real, const R: usize, const C: usize>(
    x: &SMatrix<T, R, C>,
) -> SMatrix<f64, R, C> {
    x.map(|v| v.as_f64())
}

pub(super) fn finite<T: Real, const R: usize, const C: usize>(x: &SMatrix<T, R, C>) -> bool {
    x.iter().all(|v| v.is_finite())
}

pub(super) fn all_finite(xs: &[f64]) -> bool {
    xs.iter().all(|x| x.is_finite())
}

/// `h` passes the crate's one time-step rule (finite, `> 0`, `h²` normal-range nonzero
/// and finite).
pub(super) fn valid_h(h: f64) -> bool {
    h.is_finite() && h > 0.0 && (h * h).is_finite() && h * h > 0.0
}

/// `h` passes the time-step rule in `T`: in `f64`, and `h`, `h/2`, `h²/4` finite and
/// nonzero once rounded to `T` (an `f32` stepper cannot step with `h = 1e58`).
pub(super) fn valid_h_as<T: Real>(h: f64) -> bool {
    valid_h(h)
        && [h, 0.5 * h, 0.25 * h * h].iter().all(|&x| {
            let r = T::from_f64_rounded(x);
            r.is_finite() && r != T::zero()
        })
}

/// The error the shared data must give every constructor in `T`, whatever the scheme: a
/// non-finite entry first, then a bad `h`; `None` when neither.
pub(super) fn data_error_as<T: Real>(matrices: &[&[f64]], h: f64) -> Option<Error> {
    if !matrices.iter().all(|m| all_finite(m)) {
        Some(Error::NonFiniteInput)
    } else if !valid_h_as::<T>(h) {
        Some(Error::InvalidTimeStep)
    } else {
        None
    }
}

/// [`data_error_as`] in `f64`.
pub(super) fn data_error(matrices: &[&[f64]], h: f64) -> Option<Error> {
    data_error_as::<f64>(matrices, h)
}

/// A constructor's result against the data rule: the expected error if there is one, and
/// neither `NonFiniteInput` nor `InvalidTimeStep` otherwise.
pub(super) fn expect_data<X>(t: &str, name: &str, r: &Result<X, Error>, want: Option<Error>) {
    let got = r.as_ref().err().copied();
    match want {
        Some(e) => check!(
            got == Some(e),
            "{t}: {name} gave {got:?}, the data calls for {e:?}"
        ),
        None => check!(
            !matches!(got, Some(Error::NonFiniteInput | Error::InvalidTimeStep)),
            "{t}: {name} gave {got:?} for finite data and a valid h"
        ),
    }
}

/// The `f32` twin of a constructor against the `f64` one: the operators are the same `f64`
/// numbers rounded, so they fail alike — the checks before `h` (data, parameters) the same,
/// then `InvalidTimeStep` where `h` does not fit `f32` — except that `f32` may be out of
/// its narrower range (overflow or underflow) where `f64` fits or is out of range.
pub(super) fn expect_twins<A, B>(
    t: &str,
    h: f64,
    name: &str,
    r64: &Result<A, Error>,
    r32: &Result<B, Error>,
) {
    let (e64, e32) = (r64.as_ref().err().copied(), r32.as_ref().err().copied());
    twins(t, h, name, e64, e32);
}

/// [`expect_twins`] on the errors.
pub(super) fn twins(t: &str, h: f64, name: &str, e64: Option<Error>, e32: Option<Error>) {
    let early = matches!(
        e64,
        Some(
            Error::NonFiniteInput
                | Error::InvalidTimeStep
                | Error::InvalidParameter(_)
                | Error::InvalidModeSelection
        )
    );
    let ok = if early {
        e32 == e64
    } else if !valid_h_as::<f32>(h) {
        e32 == Some(Error::InvalidTimeStep)
    } else {
        // Where f64 fits or is out of range itself, f32 may be out of its narrower range
        // (at the same or an earlier operator).
        let range = |e: Option<Error>| {
            matches!(e, Some(Error::OperatorOverflow | Error::OperatorUnderflow))
        };
        e32 == e64 || ((e64.is_none() || range(e64)) && range(e32))
    };
    check!(ok, "{t}: {name}: f64 gave {e64:?}, f32 gave {e32:?}");
}

pub(super) fn same_outcome<A, B>(t: &str, what: &str, a: &Result<A, Error>, b: &Result<B, Error>) {
    let (x, y) = (a.as_ref().err().copied(), b.as_ref().err().copied());
    check!(x == y, "{t}: {what}: {x:?} against {y:?}");
}

/// One checked step (and one with the previous input) against the unchecked step on a
/// copy: a non-finite input is `NonFiniteInput`; a finite one gives either the unchecked
/// step's state, finite, or `NonFiniteState` (the unchecked state not finite); a failed
/// step leaves the state bit-identical.
pub(super) fn checked_step<T, const N: usize, const I: usize, S>(
    t: &'static str,
    name: &str,
    sys: &S,
    s: &mut S::State,
    prev: &SVector<T, I>,
    w: &SVector<T, I>,
) where
    T: Real,
    S: Stepper<T, N, Input = SVector<T, I>, State: Debug>,
{
    for with_previous in [false, true] {
        let before = bits(s);
        let mut unchecked = *s;
        let r = if with_previous {
            sys.step_with_previous_input(&mut unchecked, prev, w);
            sys.try_step_with_previous_input(s, prev, w)
        } else {
            sys.step(&mut unchecked, w);
            sys.try_step(s, w)
        };
        let input_ok = finite(w) && (!with_previous || finite(prev));
        count(t, "checked steps");
        match r {
            Ok(()) => {
                check!(input_ok, "{t}: {name}: a non-finite input was accepted");
                check!(
                    s.is_finite(),
                    "{t}: {name}: Ok step left a non-finite state"
                );
                check!(
                    bits(s) == bits(&unchecked),
                    "{t}: {name}: the checked step differs from the unchecked one"
                );
            }
            Err(e) => {
                count(t, "failed checked steps");
                check!(
                    bits(s) == before,
                    "{t}: {name}: failed step ({e:?}) changed the state"
                );
                if input_ok {
                    check!(
                        e == Error::NonFiniteState && !unchecked.is_finite(),
                        "{t}: {name}: finite input gave {e:?} (unchecked state finite: {})",
                        unchecked.is_finite()
                    );
                } else {
                    check!(
                        e == Error::NonFiniteInput,
                        "{t}: {name}: a non-finite input gave {e:?}"
                    );
                }
            }
        }
    }
}

/// The checked-step contract on a built stepper: start (a non-finite initial value is
/// `NonFiniteInput`; else `Ok` and finite, or `SingularMass`/`NonFiniteState` and then a
/// start from a known acceleration must succeed), then checked steps under `loads`.
pub(super) fn drive<T, const N: usize, const I: usize, S>(
    t: &'static str,
    name: &str,
    sys: &S,
    u0: &SVector<T, N>,
    v0: &SVector<T, N>,
    loads: &[SVector<T, I>],
) where
    T: Real,
    S: Stepper<T, N, Input = SVector<T, I>, State: Debug>,
{
    let w0 = loads.first().copied().unwrap_or_else(SVector::zeros);
    let inputs_finite = finite(u0) && finite(v0) && finite(&w0);
    let one = SVector::<T, N>::from_element(T::one());
    let zero = SVector::<T, N>::zeros();
    let mut s = match sys.start(u0, v0, &w0) {
        Ok(s) => {
            check!(
                inputs_finite,
                "{t}: {name}: start accepted a non-finite input"
            );
            check!(s.is_finite(), "{t}: {name}: start gave a non-finite state");
            s
        }
        Err(e) => {
            if inputs_finite {
                check!(
                    matches!(e, Error::SingularMass | Error::NonFiniteState),
                    "{t}: {name}: start with finite input gave {e:?}"
                );
            } else {
                check!(
                    e == Error::NonFiniteInput,
                    "{t}: {name}: start with a non-finite input gave {e:?}"
                );
            }
            // From unit values (a reduced stepper's projection may overflow: then from
            // rest, which cannot).
            match sys
                .start_with_acceleration(&one, &one, &zero)
                .or_else(|_| sys.start_with_acceleration(&zero, &zero, &zero))
            {
                Ok(s) => s,
                Err(e) => panic!(
                    "property broken: {t}: {name}: start_with_acceleration: {e:?}\n  data: {}",
                    context()
                ),
            }
        }
    };
    let h = sys.time_step();
    check!(
        h.is_finite() && h > T::zero(),
        "{t}: {name}: Ok with time step {h:?}"
    );
    let mut nan = one;
    nan[0] = T::from_f64_rounded(f64::NAN);
    check!(
        sys.start_with_acceleration(&nan, &one, &zero).err() == Some(Error::NonFiniteInput)
            && sys.start_with_acceleration(&one, &one, &nan).err() == Some(Error::NonFiniteInput),
        "{t}: {name}: start_with_acceleration accepted NaN, or another error"
    );
    let mut prev = w0;
    for w in loads {
        checked_step::<T, N, I, S>(t, name, sys, &mut s, &prev, w);
        if finite(w) {
            prev = *w;
        }
    }
}

/// Loads for `drive`: the decoded `p`, a NaN, `p` again, zero, a second decoded load.
pub(super) fn loads<T: Real, const I: usize>(
    p: &SVector<f64, I>,
    q: &SVector<f64, I>,
) -> [SVector<T, I>; 5] {
    let mut nan = SVector::<T, I>::zeros();
    nan[0] = T::from_f64_rounded(f64::NAN);
    [to_t(p), nan, to_t(p), SVector::zeros(), to_t(q)]
}

/// Relative energy growth allowed after `steps` steps: rounding, a few ulps a step,
/// amplified by the conditioning of `M` and `K` (a rounding error of the state in a stiff
/// or heavy direction) and by the cancellation in `u_n = û + (h²/4) q` at large `ωh`.
pub(super) fn energy_tol<T: Real>(info: &SpdInfo, wh: f64, steps: usize) -> f64 {
    steps as f64
        * 16.0
        * eps::<T>()
        * (1.0 + info.kappa_m)
        * (1.0 + info.kappa_k)
        * (wh * wh / 4.0).max(1.0)
}

/// The undamped energy after a few zero-load steps from `u0, v0` does not exceed its start
/// beyond `tol`. Checked only where `tol` is below 1 % (else it says nothing), `M, K` SPD,
/// `C = 0` and the energies representable. Returns whether it was checked.
pub(super) fn energy_holds<T, const N: usize, const I: usize, S>(
    t: &'static str,
    name: &str,
    sys: &S,
    sysd: &System<N>,
    u0: &SVector<f64, N>,
    v0: &SVector<f64, N>,
) -> bool
where
    T: Real,
    S: Stepper<T, N, Input = SVector<T, I>>,
{
    const STEPS: usize = 8;
    if sysd.c.iter().any(|&x| x != 0.0) {
        return false;
    }
    let Some(info) = spd_info(&sysd.m, &sysd.k) else {
        return false;
    };
    let wh = info.omega_max * sysd.h;
    let tol = energy_tol::<T>(&info, wh, STEPS);
    if !(tol < 1e-2) {
        return false;
    }
    let (u, v) = (to_t::<T, N, 1>(u0), to_t::<T, N, 1>(v0));
    let Ok(mut s) = sys.start(&u, &v, &SVector::zeros()) else {
        return false;
    };
    let e0 = energy(&sysd.m, &sysd.k, &to_f64(&u), &to_f64(&v));
    if !(1e-250..=1e250).contains(&e0) {
        return false;
    }
    for n in 1..=STEPS {
        sys.step(&mut s, &SVector::zeros());
        if !s.is_finite() {
            // The representation overflowed (e.g. `h η'` beyond f32 with `M = 1e72`): not
            // an energy to judge (a checked step reports it as `NonFiniteState`).
            count(t, "energy not checked: state overflowed");
            return false;
        }
        let f = sys.full_state(&s);
        let e = energy(&sysd.m, &sysd.k, &to_f64(f.u()), &to_f64(f.v()));
        check!(
            e <= e0 * (1.0 + tol),
            "{t}: {name}: undamped energy grew by {:e} (allowed {tol:e}) after {n} steps; ωh = {wh:e}, κM = {:e}, κK = {:e}",
            e / e0 - 1.0,
            info.kappa_m,
            info.kappa_k
        );
    }
    count(t, "energy checked");
    true
}

// ---------------------------------------------------------------------------------------
// Decoding and helpers first written for one target and now used by several.

impl Bytes<'_> {
    /// A coin.
    pub fn flag(&mut self) -> bool {
        self.byte().is_multiple_of(2)
    }
}

pub(super) fn rows<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>) -> [[f64; C]; R] {
    core::array::from_fn(|i| core::array::from_fn(|j| a[(i, j)]))
}

pub(super) fn damping<const N: usize>(b: &mut Bytes, s: &System<N>) -> Damping<N> {
    match b.pick(5) {
        0 => Damping::None,
        1 => Damping::Rayleigh {
            a0: b.param(0.0, 1.0),
            a1: b.param(0.0, 1e-2),
        },
        2 => Damping::Ratios(core::array::from_fn(|_| b.param(0.0, 0.2))),
        3 => Damping::Matrix(rows(&s.c)),
        _ => Damping::Matrix(rows(&b.square::<N>())),
    }
}

pub(super) fn same_kind(t: &str, what: &str, a: &Option<Error>, b: &Option<Error>) {
    let ok = a == b || (a.is_none() && *b == Some(Error::OperatorOverflow));
    check!(ok, "{t}: {what}: {a:?} against {b:?}");
}

pub(super) fn damping_data<const N: usize>(d: &Damping<N>) -> Vec<f64> {
    match d {
        Damping::None => vec![],
        Damping::Rayleigh { a0, a1 } => vec![*a0, *a1],
        Damping::Ratios(x) => x.to_vec(),
        Damping::Matrix(c) => c.iter().flatten().copied().collect(),
    }
}

/// A covariance: `σ² I`, `L Lᵀ` of ordinary entries, singular, non-symmetric, negative, or
/// any entries.
pub(super) fn covariance<const N: usize>(b: &mut Bytes) -> SMatrix<f64, N, N> {
    let a = match b.pick(6) {
        0 | 1 => SMatrix::identity() * 10f64.powf(-6.0 + 6.0 * b.unit()),
        2 => {
            let l = SMatrix::<f64, N, N>::from_fn(|_, _| b.ordinary());
            let s = l * l.transpose();
            (s + s.transpose()) * 0.5
        }
        3 => {
            let v = b.small_vector::<N>();
            v * v.transpose()
        }
        4 => b.square(),
        _ => SMatrix::identity() * b.value(),
    };
    b.note_all(a.as_slice());
    a
}
