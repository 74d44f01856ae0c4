//! Issue 34: one policy for non-finite ground-acceleration samples (NaN, ±∞) in records,
//! across the spectrum banks (`Bank`, `RotD`, `Yielding`, the host batch) and
//! `ida::spectral_acceleration`: refused by default (`Error::NonFiniteInput`, the checked
//! step leaving the response unchanged at the refused sample's index, the record-level
//! calls refusing the whole record, `first_non_finite` naming the sample), skipped only
//! when asked (`NonFinite::Skip`: the last finite sample held in its place, `0` before
//! any, counted).
//!
//! The reference for skipping is written here, independently of the crate's bookkeeping:
//! the record with each non-finite sample replaced by the last finite one before it
//! (`held`), run under the default policy; and a closed form (the undamped oscillator
//! under a ramp then a constant held by NaNs).
#![allow(clippy::needless_range_loop)]

#[path = "../scenes/modal/elcentro.rs"]
mod elcentro;

use aemstep::Error;
use aemstep::spectrum::inelastic::{Search, Yielding};
use aemstep::spectrum::{Bank, NonFinite, RotD, first_non_finite};

const DT: f64 = 0.02;
const PER: [f64; 4] = [0.05, 0.3, 1.0, 3.0];

fn bank() -> Bank<f64, 4> {
    Bank::new(PER, [0.05; 4], DT).unwrap()
}

fn yielding() -> Yielding<f64, 3> {
    Yielding::new([0.2, 0.5, 1.0], [0.05; 3], 0.0, DT).unwrap()
}

/// The first `n` samples of El Centro (m/s²) with `bad` written at the given indices.
fn record(n: usize, bad: &[(usize, f64)]) -> Vec<f64> {
    let mut r = elcentro::AG_F64[..n].to_vec();
    for &(k, x) in bad {
        r[k] = x;
    }
    r
}

/// The documented meaning of skipping, written independently: every non-finite sample
/// replaced by the last finite sample before it, `0` (at rest) if none.
fn held(rec: &[f64]) -> Vec<f64> {
    let mut last = 0.0;
    rec.iter()
        .map(|&a| {
            if a.is_nan() || a.is_infinite() {
                last
            } else {
                last = a;
                a
            }
        })
        .collect()
}

const BAD: [(usize, f64); 4] = [
    (0, f64::NAN),
    (700, f64::NAN),
    (701, f64::INFINITY),
    (1500, f64::NEG_INFINITY),
];

#[test]
fn default_policy_is_refuse() {
    assert_eq!(NonFinite::default(), NonFinite::Refuse);
    assert_eq!(bank().non_finite(), NonFinite::Refuse);
    assert_eq!(yielding().non_finite(), NonFinite::Refuse);
    let static_bank = const {
        match Bank::new_f64([0.5], [0.05], 0.01) {
            Ok(b) => b.with_non_finite(NonFinite::Skip),
            Err(_) => panic!(),
        }
    };
    assert_eq!(static_bank.non_finite(), NonFinite::Skip);
}

/// A non-finite sample at `k` is refused at `k`: the record-level calls return
/// `NonFiniteInput` (and `first_non_finite` is `k`), the checked steps fail exactly at
/// sample `k` with the response unchanged (`samples() == k`).
#[test]
fn non_finite_sample_at_k_is_refused_at_k() {
    let (b, y, rot) = (bank(), yielding(), RotD::<f64, 8>::new());
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for k in [0usize, 1, 333, 1999] {
            let rec = record(2000, &[(k, bad)]);
            assert_eq!(first_non_finite(&rec), Some(k));
            assert_eq!(b.response(&rec), Err(Error::NonFiniteInput));
            assert_eq!(
                y.response(&rec, &[1.0; 3]).map(|_| ()),
                Err(Error::NonFiniteInput)
            );
            // streaming, checked: fails at k, nothing committed
            let mut r = b.at_rest();
            let mut ry = y.at_rest(&[1.0; 3]).unwrap();
            let mut rr = rot.at_rest(&b);
            let mut failed = None;
            for (n, &a) in rec.iter().enumerate() {
                let (before, before_y, before_r) = (r, ry, rr);
                let e = b.try_step(&mut r, a);
                let ey = y.try_step(&mut ry, a);
                // the bad sample on the second component only
                let er = rot.try_step(&b, &mut rr, elcentro::AG_F64[n], a);
                if e.is_err() {
                    let refused = Err(Error::NonFiniteInput);
                    assert_eq!((e, ey, er), (refused, refused, refused));
                    assert_eq!((r, ry, rr), (before, before_y, before_r));
                    assert_eq!(
                        (r.samples(), ry.samples(), rr.y().samples()),
                        (n as u64, n as u64, n as u64)
                    );
                    failed = Some(n);
                    break;
                }
                assert_eq!((ey, er), (Ok(()), Ok(())));
            }
            assert_eq!(failed, Some(k));
        }
    }
    // the first component refused too
    let mut rr = rot.at_rest(&b);
    assert_eq!(
        rot.try_step(&b, &mut rr, f64::NAN, 0.0),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(rr, rot.at_rest(&b));
}

/// The spectra built on the yielding bank refuse the record, before any pass.
#[test]
fn inelastic_spectra_refuse_a_non_finite_record() {
    let y = yielding();
    let rec = record(1000, &[(400, f64::NAN)]);
    assert_eq!(y.elastic_strength(&rec), Err(Error::NonFiniteInput));
    assert_eq!(
        y.constant_strength(&rec, &[2.0; 3]).map(|_| ()),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        y.constant_ductility(&rec, 2.0, &Search::DEFAULT)
            .map(|_| ()),
        Err(Error::NonFiniteInput)
    );
}

/// With `Skip`, the response is that of the held record under the default policy, bit for
/// bit (states and peaks), and the count is the number of non-finite samples.
#[test]
fn skip_equals_the_held_record() {
    let rec = record(2000, &BAD);
    let reference = held(&rec);
    assert!(reference.iter().all(|a| a.is_finite()));
    let b = bank();
    let s = b.with_non_finite(NonFinite::Skip);
    let (got, want) = (s.response(&rec).unwrap(), b.response(&reference).unwrap());
    assert_eq!(got.skipped(), 4);
    assert_eq!(want.skipped(), 0);
    assert_eq!(got.samples(), want.samples());
    assert_eq!(
        (
            got.sd(),
            got.sv(),
            got.sa(),
            got.displacement(),
            got.velocity()
        ),
        (
            want.sd(),
            want.sv(),
            want.sa(),
            want.displacement(),
            want.velocity()
        )
    );
    // the checked step under Skip: Ok, the same response
    let mut r = s.at_rest();
    for &a in &rec {
        s.try_step(&mut r, a).unwrap();
    }
    s.free_vibration(&mut r, s.free_vibration_samples());
    assert_eq!(r, got);

    // RotD: a gap in one component is held in that component only
    let rot = RotD::<f64, 8>::new();
    let ay: Vec<f64> = elcentro::AG_F64[1000..3000].to_vec();
    let mut ay_bad = ay.clone();
    ay_bad[10] = f64::NAN;
    let (mut got, mut want) = (rot.at_rest(&s), rot.at_rest(&b));
    let held_y = held(&ay_bad);
    for n in 0..rec.len() {
        rot.try_step(&s, &mut got, rec[n], ay_bad[n]).unwrap();
        rot.try_step(&b, &mut want, reference[n], held_y[n])
            .unwrap();
    }
    assert_eq!((got.x().skipped(), got.y().skipped()), (4, 1));
    assert_eq!(
        (got.rotd50(), got.rotd100()),
        (want.rotd50(), want.rotd100())
    );

    // the yielding bank and its spectra
    let y = yielding();
    let ys = y.with_non_finite(NonFinite::Skip);
    let rec = record(1000, &BAD[..3]);
    let reference = held(&rec);
    let (got, want) = (
        ys.response(&rec, &[1.0; 3]).unwrap(),
        y.response(&reference, &[1.0; 3]).unwrap(),
    );
    assert_eq!(got.skipped(), 3);
    assert_eq!(
        (got.sd(), got.displacement(), got.plastic_work()),
        (want.sd(), want.displacement(), want.plastic_work())
    );
    let (cs, cs_ref) = (
        ys.constant_strength(&rec, &[2.0; 3]).unwrap(),
        y.constant_strength(&reference, &[2.0; 3]).unwrap(),
    );
    assert_eq!(cs.response.skipped(), 3);
    assert_eq!(
        (cs.ductility, cs.elastic),
        (cs_ref.ductility, cs_ref.elastic)
    );
    let (cd, cd_ref) = (
        constant_ductility(&ys, &rec),
        constant_ductility(&y, &reference),
    );
    assert_eq!((cd.skipped, cd_ref.skipped), (3, 0));
    assert_eq!(cd.yield_acceleration, cd_ref.yield_acceleration);
}

/// A coarse constant-ductility search (`μ_t = 2`), fast in a debug build.
fn constant_ductility(
    y: &Yielding<f64, 3>,
    rec: &[f64],
) -> aemstep::spectrum::inelastic::ConstantDuctility<f64, 3> {
    let search = Search {
        points: 20,
        lowest: 0.05,
        tol: 1e-4,
    };
    y.constant_ductility(rec, 2.0, &search).unwrap()
}

/// An all-NaN record: refused by default; skipped, it is a record at rest (all held at
/// `0`), every sample counted.
#[test]
fn all_nan_record() {
    let rec = [f64::NAN; 50];
    let b = bank();
    assert_eq!(b.response(&rec), Err(Error::NonFiniteInput));
    let r = b.with_non_finite(NonFinite::Skip).response(&rec).unwrap();
    assert_eq!((r.skipped(), r.samples()), (50, 50));
    assert!(r.sd().iter().all(|&x| x == 0.0));
    let y = yielding();
    assert_eq!(y.elastic_strength(&rec), Err(Error::NonFiniteInput));
    // at rest: no elastic strength, so no inelastic spectrum (as for a zero record)
    assert_eq!(
        y.with_non_finite(NonFinite::Skip)
            .constant_strength(&rec, &[2.0; 3])
            .map(|_| ()),
        y.constant_strength(&[0.0; 50], &[2.0; 3]).map(|_| ())
    );
}

/// A closed form for the held value: an undamped oscillator (`ζ = 0`, `T = 101 h`) under
/// a ground acceleration ramping from `0` to `1` m/s² over the first interval, then held
/// at `1` by NaN samples. Exact: `u(t) = −1/ω² + (2 sin(ωh/2)/(hω³)) cos(ω(t − h/2))` for
/// `t ≥ h`, whose largest `|u|`, `1/ω² + 2 sin(ωh/2)/(hω³)`, falls on the sample
/// `t = h/2 + T/2 = 51 h`. The exact scheme is exact at the samples to rounding: 51 steps
/// of `O(1)` maps of `f64` lose at most about `51·4ε ≈ 5e-14` relative; tolerance `1e-13`
/// (measured: `2e-15`).
#[test]
fn held_tail_matches_the_exact_ramp_then_constant_response() {
    let h = 0.01;
    let t = 101.0 * h;
    let b = Bank::<f64, 1>::new([t], [0.0], h)
        .unwrap()
        .with_non_finite(NonFinite::Skip);
    let mut rec = vec![f64::NAN; 200];
    rec[0] = 0.0;
    rec[1] = 1.0;
    let mut r = b.at_rest();
    for &a in &rec {
        b.step(&mut r, a);
    }
    assert_eq!(r.skipped(), 198);
    let w = std::f64::consts::TAU / t;
    let exact = 1.0 / (w * w) + 2.0 * (w * h / 2.0).sin() / (h * w * w * w);
    let rel = (r.sd()[0] - exact).abs() / exact;
    println!(
        "held tail: Sd {:.15e}, exact {exact:.15e}, relative {rel:.1e}",
        r.sd()[0]
    );
    assert!(rel < 1e-13, "{rel}");
    // refused by default
    assert_eq!(
        Bank::<f64, 1>::new([t], [0.0], h).unwrap().response(&rec),
        Err(Error::NonFiniteInput)
    );
}

#[cfg(feature = "std")]
#[test]
fn batch_and_spectral_acceleration_follow_the_policy() {
    use aemstep::spectrum::batch;
    let good = record(1000, &[]);
    let bad = record(1000, &[(500, f64::NAN)]);
    let b = bank();
    let out = batch::spectra(&b, &[&good, &bad], 10, 2);
    assert!(out[0].is_ok());
    assert_eq!(out[1], Err(Error::NonFiniteInput));
    let s = b.with_non_finite(NonFinite::Skip);
    let out = batch::spectra(&s, &[&good, &bad], 10, 2);
    let held_bad = held(&bad);
    let want = batch::spectra(&b, &[&good, &held_bad], 10, 1);
    assert_eq!(out[1].as_ref().map(|r| r.skipped()), Ok(1));
    assert_eq!(
        out[1].as_ref().map(|r| *r.sd()),
        want[1].as_ref().map(|r| *r.sd())
    );
    assert_eq!(out[0], want[0]);
    assert_eq!(
        aemstep::ida::spectral_acceleration(&bad, DT, 0.5, 0.05),
        Err(Error::NonFiniteInput)
    );
}
