//! Fuzz target `detection` (`fuzz_targets/detection.rs`): checks chi_square_quantile,
//! normal_quantile, innovation_covariance, Whitener (new, from_rows_f32/_f64), Window,
//! ChiSquareTest, Detector, Cusum, ModelBank (from_parts, start, try_step, ranking,
//! clear_windows), Observer::step_innovation and Kalman::try_step_innovation; S = 2,
//! I = 1, O = 1 … 3, W = 1, 4, 8; f32, f64.
//!
//! The decoder and the checks every target shares are in `common.rs`.

use aemstep::detection::{
    ChiSquareTest, Cusum, CusumState, Detector, Dof, ModelBank, NIS_FRACTION_BITS, Whitener,
    Window, chi_square_quantile, innovation_covariance, normal_quantile,
};
use aemstep::nalgebra::{SMatrix, SVector};
use aemstep::observer::{Kalman, Measurement, Observer, StateSpace, SteadyState};
use aemstep::{Error, Param, Real, StepState};

use super::common::*;
use super::estimation::debug_finite;

const DE: &str = "detection";

/// Target `detection`.
pub fn detection(data: &[u8]) {
    let mut b = Bytes::new(data);
    match b.pick(3) {
        0 => sized::<1, 1>(&mut b),
        1 => sized::<2, 4>(&mut b),
        _ => sized::<3, 8>(&mut b),
    }
    count(DE, b.category());
}

fn err<X>(r: &Result<X, Error>) -> Option<Error> {
    r.as_ref().err().copied()
}

/// A probability: inside `(0, 1)` mostly (uniform, or 10^-e), at the ends, or any value.
fn probability(b: &mut Bytes) -> f64 {
    let p = match b.pick(4) {
        0 => b.unit(),
        1 => 10f64.powf(-20.0 * b.unit()),
        2 => [
            0.0,
            1.0,
            -0.0,
            1e-300,
            1.0 - f64::EPSILON,
            0.02425,
            0.97575,
            0.5,
        ][usize::from(b.pick(8))],
        _ => b.value(),
    };
    b.note(p)
}

/// The degrees of freedom or outputs: 0, small, large, or the extremes.
fn how_many(b: &mut Bytes) -> u64 {
    match b.pick(4) {
        0 => u64::from(b.pick(4)),
        1 => u64::from(b.u16()),
        2 => [0, 1, 1 << 20, 1 << 40, u64::MAX / 2, u64::MAX][usize::from(b.pick(6))],
        _ => u64::from(b.byte()) + 1,
    }
}

/// The stored term of `q` as the window's documentation defines it: `round(q·2²⁴)`,
/// 0 below 0, capped at `⌊(2⁶⁴ − 1)/W⌋`.
fn term<const W: usize>(q: f64) -> u64 {
    let cap = u64::MAX / W as u64;
    let x = q * (1u64 << NIS_FRACTION_BITS) as f64;
    if !(x > 0.0) {
        0
    } else if x >= cap as f64 {
        cap
    } else {
        ((x + 0.5) as u64).min(cap)
    }
}

fn sized<const O: usize, const W: usize>(b: &mut Bytes) {
    // Quantiles and tests.
    let (a1, a2) = (probability(b), probability(b));
    let k = how_many(b);
    let outputs = how_many(b);
    let lambda = b.param(1.0, 10.0);
    let qs: [f64; 12] = core::array::from_fn(|_| b.value());
    // A model of the bank: S = 2, I = 1, two hypotheses.
    let sys = b.system::<1>();
    let stiffer = b.param(0.5, 2.0);
    let bm: SMatrix<f64, 1, 1> = b.matrix();
    let h: SMatrix<f64, O, 2> = b.matrix();
    let d: SMatrix<f64, O, 1> = b.matrix();
    let q = covariance::<2>(b);
    let r = covariance::<O>(b);
    let s_raw = covariance::<O>(b);
    let gain_from_riccati = b.pick(4) != 0;
    let gain: SMatrix<f64, 2, O> = b.matrix();
    let x0 = b.vector::<2>();
    let ws = [b.vector::<1>(), b.vector::<1>(), b.vector::<1>()];
    let ys = [
        b.vector::<O>(),
        SVector::from_element(f64::NAN),
        b.vector::<O>(),
        b.vector::<O>(),
    ];
    count(DE, "inputs");
    set_context(format!(
        "O = {O}, W = {W}, alpha = {a1:e}, {a2:e}, k = {k}, outputs = {outputs}, lambda = {lambda:e}, q = {qs:?}, M = {:?}, C = {:?}, K = {:?}, h = {:e}, stiffer = {stiffer:e}, B = {:?}, H = {:?}, D = {:?}, Q = {:?}, R = {:?}, S = {:?}, riccati gain = {gain_from_riccati}, gain = {:?}, x0 = {:?}, w = {ws:?}, y = {ys:?}",
        sys.m.as_slice(),
        sys.c.as_slice(),
        sys.k.as_slice(),
        sys.h,
        bm.as_slice(),
        h.as_slice(),
        d.as_slice(),
        q.as_slice(),
        r.as_slice(),
        s_raw.as_slice(),
        gain.as_slice(),
        x0.as_slice()
    ));

    quantiles(a1, a2, k);
    let test64 = chi_square_test::<f64, W>(outputs, a1);
    let test32 = chi_square_test::<f32, W>(outputs, a1);
    cusum::<f64>(outputs, lambda, a1, &qs);
    cusum::<f32>(outputs, lambda, a1, &qs);
    let window64 = window::<f64, W>(&qs);
    let window32 = window::<f32, W>(&qs);
    check!(
        err(&ChiSquareTest::<f64, 0>::new(&Dof::<1>, 0.5))
            == Some(Error::InvalidParameter(Param::Window))
            && err(&Whitener::<f64, 0>::new(&[])) == Some(Error::InvalidParameter(Param::Outputs))
            && err(&ModelBank::<f64, 2, 1, O, 0>::from_parts([], []))
                == Some(Error::InvalidParameter(Param::BankSize)),
        "{DE}: W = 0, O = 0 or M = 0 accepted"
    );

    // The bank's models: the data's, and one with its stiffness scaled.
    let meas = Measurement::<2, 1, O> {
        h: rows(&h),
        d: rows(&d),
    };
    let mut models = [None, None];
    for (i, kk) in [sys.k, sys.k * stiffer].iter().enumerate() {
        let ss = StateSpace::<1, 2, 1>::aem(&sys.m, &sys.c, kk, &bm, sys.h);
        outcome(DE, &ss);
        let Ok(ss) = ss else { continue };
        let st = SteadyState::new(&ss, &meas, &q, &r);
        outcome(DE, &st);
        let cov = match &st {
            Ok(st) => {
                let s = innovation_covariance(st, &meas, &rows(&r));
                outcome(DE, &s);
                check!(
                    all_finite(r.as_slice()) != (err(&s) == Some(Error::InvalidCovariance)),
                    "{DE}: innovation_covariance gave {:?}",
                    err(&s)
                );
                if let Ok(s) = &s {
                    let m = SMatrix::<f64, O, O>::from_fn(|i, j| s[i][j]);
                    check!(
                        all_finite(m.as_slice()) && m == m.transpose(),
                        "{DE}: innovation_covariance Ok, not finite or not symmetric: {s:?}"
                    );
                }
                s.ok()
            }
            Err(_) => None,
        };
        let s = cov.unwrap_or(rows(&s_raw));
        let g = match (&st, gain_from_riccati) {
            (Ok(st), true) => st.gain_matrix(),
            _ => gain,
        };
        models[i] = Some((ss, g, s));
    }
    // The whiteners of S (the Riccati one, else the decoded).
    let (s0, wh64, wh32) = {
        let s = models[0].map(|m| m.2).unwrap_or(rows(&s_raw));
        (s, whitener::<f64, O>(&s), whitener::<f32, O>(&s))
    };
    let e64 = err(&wh64);
    let e32 = err(&wh32);
    check!(
        e32 == e64
            || (e32 == Some(Error::OperatorOverflow)
                && (e64.is_none() || e64 == Some(Error::OperatorOverflow))),
        "{DE}: Whitener: f64 gave {e64:?}, f32 gave {e32:?} (S = {s0:?})"
    );
    if let (Ok(wh), Some(test)) = (&wh64, &test64) {
        detector(wh, test, &window64, &ys);
    }
    if let (Ok(wh), Some(test)) = (&wh32, &test32) {
        detector(wh, test, &window32, &ys);
    }
    if let [Some(m0), Some(m1)] = models {
        bank::<f64, O, W>(&meas, &[m0, m1], &x0, &ws, &ys);
        bank::<f32, O, W>(&meas, &[m0, m1], &x0, &ws, &ys);
        kalman::<f64, O>(&m0.0, &meas, &q, &r, &x0, &ws, &ys);
        kalman::<f32, O>(&m0.0, &meas, &q, &r, &x0, &ws, &ys);
    }
}

/// `chi_square_quantile` and `normal_quantile`: NaN exactly outside their domain, finite
/// (and `≥ 0`) inside, monotone in the probability.
fn quantiles(a1: f64, a2: f64, k: u64) {
    let valid = |a: f64| a > 0.0 && a < 1.0;
    for a in [a1, a2] {
        let z = normal_quantile(a);
        check!(
            valid(a) == z.is_finite() && (valid(a) || z.is_nan()),
            "{DE}: normal_quantile({a:e}) = {z:e}"
        );
        let x = chi_square_quantile(k, a);
        check!(
            if valid(a) && k > 0 {
                x.is_finite() && x >= 0.0
            } else {
                x.is_nan()
            },
            "{DE}: chi_square_quantile({k}, {a:e}) = {x:e}"
        );
    }
    if valid(a1) && valid(a2) && k > 0 {
        let (lo, hi) = if a1 <= a2 { (a1, a2) } else { (a2, a1) };
        let (zl, zh) = (normal_quantile(lo), normal_quantile(hi));
        let (xl, xh) = (chi_square_quantile(k, lo), chi_square_quantile(k, hi));
        check!(
            zl <= zh && xl >= xh,
            "{DE}: quantiles not monotone: Φ⁻¹({lo:e}) = {zl:e}, Φ⁻¹({hi:e}) = {zh:e}, χ²({k}, {lo:e}) = {xl:e}, χ²({k}, {hi:e}) = {xh:e}"
        );
        count(DE, "quantiles compared");
    }
}

/// The degrees of freedom a sample the tests are built for, picked by `outputs` (the
/// count is a type, `Dof::<k>`): 0 … 3, 1000 or 10⁶.
fn dof_of(outputs: u64) -> u64 {
    [0, 1, 2, 3, 1000, 1_000_000][(outputs % 6) as usize]
}

/// `ChiSquareTest::new(&Dof::<o>, alpha)` for `o` from [`dof_of`].
fn chi_new<T: Real, const W: usize>(o: u64, alpha: f64) -> Result<ChiSquareTest<T, W>, Error> {
    match o {
        0 => ChiSquareTest::new(&Dof::<0>, alpha),
        1 => ChiSquareTest::new(&Dof::<1>, alpha),
        2 => ChiSquareTest::new(&Dof::<2>, alpha),
        3 => ChiSquareTest::new(&Dof::<3>, alpha),
        1000 => ChiSquareTest::new(&Dof::<1000>, alpha),
        _ => ChiSquareTest::new(&Dof::<1_000_000>, alpha),
    }
}

/// `Cusum::new(&Dof::<o>, lambda, alpha)` for `o` from [`dof_of`].
fn cusum_new<T: Real>(o: u64, lambda: f64, alpha: f64) -> Result<Cusum<T>, Error> {
    match o {
        0 => Cusum::new(&Dof::<0>, lambda, alpha),
        1 => Cusum::new(&Dof::<1>, lambda, alpha),
        2 => Cusum::new(&Dof::<2>, lambda, alpha),
        3 => Cusum::new(&Dof::<3>, lambda, alpha),
        1000 => Cusum::new(&Dof::<1000>, lambda, alpha),
        _ => Cusum::new(&Dof::<1_000_000>, lambda, alpha),
    }
}

/// `ChiSquareTest::new`: `InvalidParameter` for no degree of freedom or a bad `alpha`;
/// `Ok` with the quantile of `W·k` degrees of freedom as its threshold, rounded to `T`.
fn chi_square_test<T: Real, const W: usize>(
    outputs: u64,
    alpha: f64,
) -> Option<ChiSquareTest<T, W>> {
    let o = dof_of(outputs);
    let t = chi_new::<T, W>(o, alpha);
    outcome(DE, &t);
    if o == 0 || !(alpha > 0.0 && alpha < 1.0) {
        check!(
            err(&t)
                == Some(Error::InvalidParameter(if o == 0 {
                    Param::Outputs
                } else {
                    Param::FalseAlarm
                })),
            "{DE}: ChiSquareTest::new({o}, {alpha:e}) gave {:?}",
            err(&t)
        );
    } else {
        check!(
            err(&t).is_none() || err(&t) == Some(Error::InvalidParameter(Param::Threshold)),
            "{DE}: ChiSquareTest::new gave {:?}",
            err(&t)
        );
    }
    let t = t.ok()?;
    let dof = (W as u64).saturating_mul(o);
    check!(
        t.dof() == dof
            && t.false_alarm() == T::from_f64_rounded(alpha)
            && t.threshold().is_finite()
            && t.threshold() >= T::zero()
            && t.threshold() == T::from_f64_rounded(chi_square_quantile(dof, alpha)),
        "{DE}: ChiSquareTest Ok: {t:?}"
    );
    Some(t)
}

/// `Cusum::new` errors, and its statistic: `≥ 0` (never NaN), NaN samples skipped and
/// counted with the statistic unchanged, alarm exactly above the threshold.
fn cusum<T: Real>(outputs: u64, lambda: f64, alpha: f64, qs: &[f64]) {
    let o = dof_of(outputs);
    let c = cusum_new::<T>(o, lambda, alpha);
    outcome(DE, &c);
    let which = if o == 0 {
        Some(Param::Outputs)
    } else if !(lambda > 1.0 && lambda.is_finite()) {
        Some(Param::CusumDrift)
    } else if !(alpha > 0.0 && alpha < 1.0) {
        Some(Param::FalseAlarm)
    } else {
        None
    };
    let bad = which.is_some();
    check!(
        err(&c) == which.map(Error::InvalidParameter) && (bad || c.is_ok()),
        "{DE}: Cusum::new({o}, {lambda:e}, {alpha:e}) gave {:?}",
        err(&c)
    );
    let Ok(c) = c else { return };
    check!(
        c.threshold().is_finite() && c.threshold() > T::zero(),
        "{DE}: Cusum threshold {:?}",
        c.threshold()
    );
    let mut s = CusumState::<T>::default();
    for &q in qs {
        let q = T::from_f64_rounded(q);
        let (g, skipped) = (s.statistic(), s.skipped());
        let alarm = c.update(&mut s, q);
        count(DE, "cusum updates");
        if q.as_f64().is_nan() {
            check!(
                !alarm
                    && s.skipped() == skipped + 1
                    && s.statistic().as_f64().to_bits() == g.as_f64().to_bits(),
                "{DE}: Cusum: a NaN sample not skipped"
            );
        } else {
            check!(
                s.skipped() == skipped
                    && s.statistic() >= T::zero()
                    && alarm == (s.statistic() > c.threshold()),
                "{DE}: Cusum: statistic {:?} after {q:?} (alarm {alarm})",
                s.statistic()
            );
        }
    }
    s.reset();
    check!(s.statistic() == T::zero(), "{DE}: Cusum reset");
}

/// The window's invariant: its fixed-point sum is the exact sum of its stored terms (the
/// last `W` non-NaN pushes), its length and skipped count those of the pushes.
fn window<T: Real, const W: usize>(qs: &[f64]) -> Window<T, W> {
    let mut win = Window::<T, W>::at_rest();
    let mut held: Vec<u64> = Vec::new();
    let mut skipped = 0;
    for &q in qs {
        let q = T::from_f64_rounded(q);
        win.push(q);
        let q = q.as_f64();
        if q.is_nan() {
            skipped += 1;
        } else {
            held.push(term::<W>(q));
            if held.len() > W {
                held.remove(0);
            }
        }
        let exact: u128 = held.iter().map(|&t| u128::from(t)).sum();
        check!(
            u128::from(win.sum_fixed()) == exact
                && win.len() == held.len()
                && win.skipped() == skipped
                && win.is_full() == (held.len() == W)
                && win.is_empty() == held.is_empty()
                && win.sum() >= T::zero()
                && win.sum().as_f64() == fixed_as::<T>(win.sum_fixed()),
            "{DE}: Window after {q:e}: {win:?}, want terms {held:?} (sum {exact})"
        );
        count(DE, "window pushes");
    }
    win
}

/// A fixed-point sum as `T` reads it: the integer rounded once to `T`, times `2⁻²⁴`.
fn fixed_as<T: Real>(sum: u64) -> f64 {
    let scale = (1u64 << NIS_FRACTION_BITS) as f64;
    if eps::<T>() > 1e-10 {
        (sum as f32) as f64 / scale
    } else {
        sum as f64 / scale
    }
}

/// `Whitener::new` against its `const fn` twin; `Ok` ⇒ finite; a non-finite `S` is
/// `InvalidCovariance`.
fn whitener<T: Real, const O: usize>(s: &[[f64; O]; O]) -> Result<Whitener<T, O>, Error> {
    let w = Whitener::<T, O>::new(s);
    outcome(DE, &w);
    let twin = if eps::<T>() > 1e-10 {
        bits(&Whitener::<f32, O>::from_rows_f32(s))
    } else {
        bits(&Whitener::<f64, O>::from_rows_f64(s))
    };
    check!(
        twin == bits(&w),
        "{DE}: Whitener::from_rows differs from new"
    );
    let finite_s = s.iter().flatten().all(|x| x.is_finite());
    let diag_bad = (0..O).any(|i| !(s[i][i] > 0.0));
    if !finite_s || diag_bad {
        check!(
            err(&w) == Some(Error::InvalidCovariance),
            "{DE}: Whitener of a non-finite or non-positive S gave {:?}",
            err(&w)
        );
    }
    if let Ok(w) = &w {
        check!(
            debug_finite(w) && w.log_det().is_finite(),
            "{DE}: Whitener Ok, not finite: {w:?}"
        );
    }
    w
}

/// `Detector::update` is a push of the normalized innovation squared and the test.
fn detector<T: Real, const O: usize, const W: usize>(
    wh: &Whitener<T, O>,
    test: &ChiSquareTest<T, W>,
    start: &Window<T, W>,
    ys: &[SVector<f64, O>],
) {
    let det = Detector::from_parts(*wh, *test);
    let mut win = *start;
    for y in ys {
        let nu = to_t::<T, O, 1>(y);
        let q = wh.nis(&nu);
        check!(!(q.as_f64() < 0.0), "{DE}: nis {q:?} < 0");
        if finite(&nu) {
            check!(
                !q.as_f64().is_nan(),
                "{DE}: nis of a finite innovation is NaN"
            );
        }
        let mut want = win;
        want.push(q);
        let alarm = det.update(&mut win, &nu);
        check!(
            win == want && alarm == test.alarm(&win),
            "{DE}: Detector::update is not a push and the test"
        );
    }
}

/// The bank: a failed step changes nothing and its error is the data's; an `Ok` one is
/// each observer's `step_innovation` (itself `Observer::step`) and a push of its normalized
/// innovation squared; the ranking a permutation ordered by the log-likelihoods.
fn bank<T: Real, const O: usize, const W: usize>(
    meas: &Measurement<2, 1, O>,
    models: &[(StateSpace<1, 2, 1>, SMatrix<f64, 2, O>, [[f64; O]; O]); 2],
    x0: &SVector<f64, 2>,
    ws: &[SVector<f64, 1>],
    ys: &[SVector<f64, O>],
) {
    let mut obs = Vec::new();
    let mut whs = Vec::new();
    for (ss, g, s) in models {
        let o = Observer::<T, 2, 1, O>::new(ss, meas, g);
        outcome(DE, &o);
        let Ok(o) = o else { return };
        let w = Whitener::<T, O>::new(s).or_else(|_| Whitener::<T, O>::new(&identity_rows()));
        let Ok(w) = w else { return };
        obs.push(o);
        whs.push(w);
    }
    let bank = ModelBank::<T, 2, 1, O, 2>::from_parts([obs[0], obs[1]], [whs[0], whs[1]]);
    let Ok(bank) = bank else {
        panic!(
            "property broken: {DE}: ModelBank::from_parts of two models failed\n  data: {}",
            context()
        );
    };
    let x = to_t::<T, 2, 1>(x0);
    let w0 = to_t::<T, 1, 1>(&ws[0]);
    let st = bank.start::<W>(&x, &w0);
    check!(
        st.is_ok() == (finite(&x) && finite(&w0))
            && (st.is_ok() || err(&st) == Some(Error::NonFiniteInput)),
        "{DE}: ModelBank::start gave {:?}",
        err(&st)
    );
    let Ok(mut st) = st.or_else(|_| bank.start::<W>(&SVector::zeros(), &SVector::zeros())) else {
        panic!(
            "property broken: {DE}: ModelBank could not start at rest\n  data: {}",
            context()
        );
    };
    for (k, y) in ys.iter().enumerate() {
        let w = to_t::<T, 1, 1>(&ws[k % ws.len()]);
        let y = to_t::<T, O, 1>(y);
        let before = bits(&st);
        // The reference: each observer's own step and innovation.
        let mut want = [*st.estimate(0), *st.estimate(1)];
        let mut wins = [*st.window(0), *st.window(1)];
        let mut next_finite = true;
        for m in 0..2 {
            let mut plain = want[m];
            bank.observer(m).step(&mut plain, &w, &y);
            let nu = bank.observer(m).step_innovation(&mut want[m], &w, &y);
            check!(
                bits(&plain) == bits(&want[m]),
                "{DE}: step_innovation differs from step"
            );
            if !finite(&y) {
                check!(
                    !finite(&nu),
                    "{DE}: the innovation of a missing sample is finite"
                );
            }
            next_finite &= want[m].is_finite();
            wins[m].push(whs[m].nis(&nu));
        }
        count(DE, "checked steps");
        match bank.try_step(&mut st, &w, &y) {
            Ok(()) => {
                check!(
                    finite(&w)
                        && next_finite
                        && (0..2).all(|m| {
                            bits(st.estimate(m)) == bits(&want[m]) && *st.window(m) == wins[m]
                        }),
                    "{DE}: ModelBank Ok step differs from its observers' steps"
                );
            }
            Err(e) => {
                count(DE, "failed checked steps");
                check!(
                    bits(&st) == before,
                    "{DE}: ModelBank failed step ({e:?}) changed the state"
                );
                let want_e = if finite(&w) {
                    Error::NonFiniteState
                } else {
                    Error::NonFiniteInput
                };
                check!(
                    e == want_e && (want_e == Error::NonFiniteInput || !next_finite),
                    "{DE}: ModelBank step gave {e:?}, want {want_e:?}"
                );
            }
        }
        let ll = bank.log_likelihoods(&st);
        let rank = bank.ranking(&st);
        let mut sorted = rank;
        sorted.sort_unstable();
        check!(
            sorted == [0, 1]
                && ll.iter().all(|x| x.is_finite())
                && (ll[rank[0]] > ll[rank[1]] || (ll[rank[0]] == ll[rank[1]] && rank[0] < rank[1])),
            "{DE}: ranking {rank:?} of log-likelihoods {ll:?}"
        );
    }
    let skipped = [st.window(0).skipped(), st.window(1).skipped()];
    st.clear_windows();
    check!(
        (0..2).all(|m| st.window(m).is_empty() && st.window(m).skipped() == skipped[m]),
        "{DE}: clear_windows"
    );
}

fn identity_rows<const O: usize>() -> [[f64; O]; O] {
    core::array::from_fn(|i| core::array::from_fn(|j| if i == j { 1.0 } else { 0.0 }))
}

/// `Kalman::try_step_innovation` is `Kalman::try_step` plus the innovation: the same result
/// and state; a failed step changes nothing; the innovation covariance symmetric.
fn kalman<T: Real, const O: usize>(
    ss: &StateSpace<1, 2, 1>,
    meas: &Measurement<2, 1, O>,
    q: &SMatrix<f64, 2, 2>,
    r: &SMatrix<f64, O, O>,
    x0: &SVector<f64, 2>,
    ws: &[SVector<f64, 1>],
    ys: &[SVector<f64, O>],
) {
    let kf = Kalman::<T, 2, 1, O>::new(ss, meas, q, r);
    outcome(DE, &kf);
    let Ok(kf) = kf else { return };
    let x = to_t::<T, 2, 1>(x0);
    let Ok(mut st) = kf
        .start(&x, &SMatrix::identity(), &SVector::zeros())
        .or_else(|_| kf.start(&SVector::zeros(), &SMatrix::identity(), &SVector::zeros()))
    else {
        panic!(
            "property broken: {DE}: Kalman could not start at rest\n  data: {}",
            context()
        );
    };
    for (k, y) in ys.iter().enumerate() {
        let w = to_t::<T, 1, 1>(&ws[k % ws.len()]);
        let y = to_t::<T, O, 1>(y);
        let before = bits(&st);
        let mut plain = st;
        let r_plain = kf.try_step(&mut plain, &w, &y);
        let r = kf.try_step_innovation(&mut st, &w, &y);
        count(DE, "checked steps");
        check!(
            err(&r) == err(&r_plain) && bits(&st) == bits(&plain),
            "{DE}: Kalman::try_step_innovation gave {:?}, try_step {:?}",
            err(&r),
            err(&r_plain)
        );
        match r {
            Ok((nu, s)) => {
                check!(
                    s == s.transpose() || !finite(&s),
                    "{DE}: innovation covariance not symmetric: {s:?}"
                );
                if !finite(&y) {
                    check!(
                        !finite(&nu),
                        "{DE}: Kalman: a missing sample's innovation finite"
                    );
                }
            }
            Err(e) => {
                count(DE, "failed checked steps");
                check!(
                    bits(&st) == before,
                    "{DE}: Kalman failed step ({e:?}) changed the state"
                );
            }
        }
    }
}
