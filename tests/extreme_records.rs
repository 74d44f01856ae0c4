//! Issue 31: extreme records and unchecked arithmetic give a typed error, never `Ok` with
//! ±∞/NaN or a wrapped count. Each test names the defect it pins (each failed before its
//! fix: the old call returned `Ok` with a non-finite field, accepted, or wrapped).

use aemstep::spectrum::Bank;
use aemstep::spectrum::inelastic::Yielding;
use aemstep::{Error, Linear, Param, State, Stepper};
use nalgebra::{matrix, vector};

const H: f64 = 0.01;

/// 2 s of a 3 m/s² sine at 1.1 Hz (m/s²).
fn sine() -> Vec<f64> {
    (0..200)
        .map(|n| 3.0 * (std::f64::consts::TAU * 1.1 * n as f64 * H).sin())
        .collect()
}

fn yielding() -> Yielding<f64, 3> {
    Yielding::new([0.2, 0.5, 1.0], [0.05; 3], 0.05, H).unwrap()
}

/// The sine with one finite but enormous sample at `t = 1 s`.
fn spiked(spike: f64) -> Vec<f64> {
    let mut r = sine();
    r[100] = spike;
    r
}

#[test]
fn yielding_response_to_a_5e307_sample_is_non_finite_state() {
    // Before: Ok with displacement [NaN, NaN, NaN].
    let r = yielding().response(&spiked(5e307), &[1.0; 3]);
    assert_eq!(r.map(|r| *r.displacement()), Err(Error::NonFiniteState));
}

#[test]
fn constant_strength_r_1e308_is_an_error_not_infinite_ductility() {
    let cs = yielding().constant_strength(&sine(), &[1e308; 3]);
    // Before: Ok with ductility [∞, ∞, 8.9e307] (a_y0/R subnormal, u_y too).
    assert_eq!(cs.map(|c| c.ductility), Err(Error::OperatorUnderflow));
    let cd = yielding().constant_ductility(&sine(), 2.0, &Default::default());
    assert!(cd.is_ok());
}

#[test]
fn constant_strength_tiny_reduction_overflowing_f32_is_an_error() {
    // Found by fuzzing (fuzz/regressions/spectrum/constant-strength-f32-tiny-reduction-
    // overflows): in f32, R = 4.2e-44 (subnormal) makes a_y0/R ≈ 2e44 = +∞, which was
    // taken as "never yields" and returned Ok with an infinite yield acceleration.
    let y = Yielding::<f32, 3>::new([0.2, 0.5, 1.0], [0.05; 3], 0.0, H).unwrap();
    let rec: Vec<f32> = sine().iter().map(|&a| a as f32).collect();
    let cs = y.constant_strength(&rec, &[4.2e-44, 4.0, 4.0]);
    assert_eq!(cs.map(|_| ()), Err(Error::OperatorOverflow));
    assert!(y.constant_strength(&rec, &[4.0; 3]).is_ok());
}

#[test]
fn constant_strength_record_times_1e290_is_an_error_not_infinite_work() {
    let big: Vec<f64> = sine().iter().map(|a| a * 1e290).collect();
    let cs = yielding().constant_strength(&big, &[4.0; 3]);
    // Before: Ok with plastic work [NaN, ∞, ∞] (work ~ a_y·u ~ 1e293·1e290 overflows).
    assert_eq!(
        cs.map(|c| (c.ductility, c.plastic_work)),
        Err(Error::NonFiniteState)
    );
}

#[test]
fn at_rest_refuses_a_subnormal_yield_displacement() {
    // a_y = 1e-300 m/s² at T = 0.2 s: u_y = a_y/ω² ≈ 1e-303, normal; 1e-306: u_y ≈ 1e-309,
    // subnormal (below f64::MIN_POSITIVE ≈ 2.2e-308): its ductility overflows.
    let b = yielding();
    assert!(b.at_rest(&[1e-300; 3]).is_ok());
    assert_eq!(
        b.at_rest(&[1e-306; 3]).map(|_| ()),
        Err(Error::InvalidMaterial(Param::YieldForce))
    );
}

/// The sine with two finite samples whose difference overflows (`−3e308 = −∞`).
fn paired() -> Vec<f64> {
    let mut r = sine();
    r[100] = 1.5e308;
    r[101] = -1.5e308;
    r
}

fn bank() -> Bank<f64, 3> {
    Bank::<f64, 3>::new([0.2, 0.5, 1.0], [0.05; 3], H).unwrap()
}

#[cfg(feature = "std")]
#[test]
fn elastic_bank_over_overflowing_samples_is_non_finite_state() {
    // Before: `batch::spectra` returned a response with Sd = ∞ (no checked path at all).
    let rec = paired();
    let out = aemstep::spectrum::batch::spectra(&bank(), &[&rec[..], &sine()[..]], 10, 1);
    assert_eq!(
        out[0].as_ref().map(|r| *r.sd()),
        Err(&Error::NonFiniteState)
    );
    assert!(out[1].as_ref().unwrap().is_finite());
    assert_eq!(
        bank().response(&rec).map(|_| ()),
        Err(Error::NonFiniteState)
    );
}

#[test]
fn bank_try_step_leaves_the_response_unchanged_on_overflow() {
    let b = bank();
    let mut r = b.at_rest();
    let rec = paired();
    for &a in &rec[..101] {
        b.try_step(&mut r, a).unwrap();
    }
    let before = r;
    assert_eq!(b.try_step(&mut r, rec[101]), Err(Error::NonFiniteState));
    assert_eq!(r, before);
    // a non-finite sample is refused by default, the response unchanged; skipped and
    // counted when the bank is asked to skip
    assert_eq!(b.try_step(&mut r, f64::NAN), Err(Error::NonFiniteInput));
    assert_eq!(r, before);
    let skipping = b.with_non_finite(aemstep::spectrum::NonFinite::Skip);
    assert_eq!(skipping.try_step(&mut r, f64::NAN), Ok(()));
    assert_eq!(r.skipped(), 1);
}

#[test]
fn rotd_try_step_leaves_the_response_unchanged_on_overflow() {
    let (b, rot) = (bank(), aemstep::spectrum::RotD::<f64, 4>::new_f64());
    let mut r = rot.at_rest(&b);
    let rec = paired();
    for &a in &rec[..101] {
        rot.try_step(&b, &mut r, a, 0.5 * a).unwrap();
    }
    let before = r;
    assert_eq!(
        rot.try_step(&b, &mut r, rec[101], 0.0),
        Err(Error::NonFiniteState)
    );
    assert_eq!(r, before);
    // the unchecked step overflows, and the end check says so
    rot.step(&b, &mut r, rec[101], 0.0);
    rot.free_vibration(&b, &mut r, 10);
    assert!(!r.is_finite());
}

#[test]
fn yielding_try_step_leaves_the_response_unchanged_on_overflow() {
    let b = yielding();
    let mut r = b.at_rest(&[1.0; 3]).unwrap();
    let rec = spiked(5e307);
    for &a in &rec[..100] {
        b.try_step(&mut r, a).unwrap();
    }
    let before = r;
    assert_eq!(b.try_step(&mut r, rec[100]), Err(Error::NonFiniteState));
    assert_eq!(r, before);
    assert_eq!(
        b.try_step(&mut r, f64::INFINITY),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(r, before);
    let skipping = b.with_non_finite(aemstep::spectrum::NonFinite::Skip);
    assert_eq!(skipping.try_step(&mut r, f64::INFINITY), Ok(()));
    assert_eq!(r.skipped(), 1);
}

#[cfg(feature = "std")]
#[test]
fn spectral_acceleration_of_overflowing_samples_is_an_error() {
    // Before: Ok(∞) (a finite 5e307 spike alone gives a finite, correct Sa ≈ 5.8e306).
    let sa = aemstep::ida::spectral_acceleration(&paired(), H, 0.5, 0.05);
    assert_eq!(sa, Err(Error::NonFiniteState));
}

#[test]
fn tiny_time_step_free_vibration_tail_is_refused() {
    // T = 1 s at h = 1e-9 s: a tail of 1e9 samples (hours of stepping) is refused.
    // Before: 181 s of stepping in debug, then Ok.
    let b = Yielding::<f64, 1>::new([1.0], [0.05], 0.0, 1e-9).unwrap();
    let r = b.response(&[0.0, 1.0, 0.0], &[1.0]);
    assert_eq!(r.map(|_| ()), Err(Error::InvalidTimeStep));
    let e = Bank::<f64, 1>::new([1.0], [0.05], 1e-9).unwrap();
    assert_eq!(
        e.response(&[0.0, 1.0]).map(|_| ()),
        Err(Error::InvalidTimeStep)
    );
    #[cfg(feature = "std")]
    assert_eq!(
        aemstep::ida::spectral_acceleration(&[0.0, 1.0], 1e-9, 1.0, 0.05),
        Err(Error::InvalidTimeStep)
    );
    // the cap itself: one period of exactly MAX samples is accepted, one more refused
    use aemstep::spectrum::MAX_FREE_VIBRATION_SAMPLES as MAX;
    let h = 1.0 / MAX as f64; // a power of two: T/h is exact
    let ok = Bank::<f64, 1>::new([1.0], [0.05], h).unwrap();
    assert_eq!(ok.free_vibration_samples(), MAX);
    let over = Bank::<f64, 1>::new([1.0 + 2.0 * h], [0.05], h).unwrap();
    assert_eq!(
        over.response(&[0.0]).map(|_| ()),
        Err(Error::InvalidTimeStep)
    );
}

#[test]
fn restore_refuses_a_step_count_that_would_wrap() {
    // Before: Ok with n = u64::MAX; the next step wrapped the count, and the time, to 0.
    let r = State::restore(vector![0.0], vector![0.0], vector![0.0], u64::MAX);
    assert_eq!(r, Err(Error::StepCountOverflow));
    let max = State::<f64, 1>::MAX_RESTORED_STEPS;
    let over = State::restore(vector![0.0], vector![0.0], vector![0.0], max + 1);
    assert_eq!(over, Err(Error::StepCountOverflow));
    // The largest accepted count steps on, its time finite and past the restored one.
    let h = 0.01;
    let lin = Linear::<f64, 1>::new(&matrix![1.0], &matrix![0.1], &matrix![4.0], h).unwrap();
    let mut s = State::restore(vector![0.1], vector![0.0], vector![-0.4], max).unwrap();
    for _ in 0..3 {
        lin.try_step(&mut s, &vector![0.0]).unwrap();
    }
    assert_eq!(s.steps(), max + 3);
    assert!(s.time(h) >= max as f64 * h);
}

#[cfg(feature = "std")]
#[test]
fn record_scaled_by_nan_is_refused() {
    let r = aemstep::records::Record::from_column("1\n2\n", 0.01).unwrap();
    // Before: a record of NaN.
    assert_eq!(r.scaled(f64::NAN), Err(Error::NonFiniteInput));
    assert_eq!(r.scaled(f64::INFINITY), Err(Error::NonFiniteInput));
    assert_eq!(r.scaled(1e308), Err(Error::OperatorOverflow));
    assert_eq!(r.scaled(-2.0), Ok(vec![-2.0, -4.0]));
}
