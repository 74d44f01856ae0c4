//! Change detection with the load unknown: the residual of the joint input–state estimator
//! (`InputStateObserver::step_innovation`) whitened by `R̃` (`InputStateGains::
//! innovation_covariance`) is `χ²` with `O − I` degrees of freedom while the structure
//! matches the model, whatever the force; a storey that loses stiffness makes it large.
//!
//! The checks are against distribution theory, not the crate's numbers: the truth
//! (`scenes/detection/unknown_load.rs`) is simulated with process noise drawn from `Q` and sensor noise from `R` (the noises
//! the gains were solved for), and a force the filter knows nothing of; the residual's
//! sample covariance is compared with `R̃ − D̃ Pʷ D̃ᵀ` (the projection of `R̃` that removes
//! the input's directions), its whitened mean with `O − I`, its autocorrelation with zero.
//! The residual itself is recomputed from the standard form's equations.

use aemstep::detection::{ChiSquareTest, Detector, Dof, Innovations, Whitener, Window};
use aemstep::estimation::{InputModel, InputStateGains, InputStateObserver};
use aemstep::observer::Outputs;
use nalgebra::{SMatrix, SVector};

#[path = "../scenes/detection/gauss.rs"]
mod gauss;
#[path = "../scenes/estimator/scene.rs"]
mod scene;
#[path = "../scenes/detection/unknown_load.rs"]
mod unknown_load;
use scene as estimator;

use unknown_load::{DOF, Truth, damaged};

#[path = "../scenes/detection/chi2.rs"]
mod chi2;

type V4 = SVector<f64, 4>;

fn observer() -> InputStateObserver<f64, 10, 1, 4> {
    InputStateObserver::new(&scene::MODEL, &scene::GAINS).unwrap()
}

#[test]
fn the_residual_is_the_standard_forms_residual() {
    let f = observer();
    let m = &scene::MODEL;
    let (a, b, c, d) = (m.a_matrix(), m.b_matrix(), m.c_matrix(), m.d_matrix());
    let gm = scene::GAINS.input_gain_matrix();
    let mut truth = Truth::new(7);
    let mut e = f.start_at_rest();
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for _ in 0..2000 {
        let y = truth.next(m);
        let (xi0, w0) = (*e.xi(), *e.input());
        let nu = f.step_innovation(&mut e, &y);
        // From the equations: ξ⁻ = A ξ̂ + B ŵ, ŵ_n = M (y − C ξ⁻), ν = y − C ξ⁻ − D̃ ŵ_n.
        let xp = a * xi0 + b * w0;
        let what = gm * (y - c * xp);
        let nu_ref = y - c * xp - d * what;
        worst = worst.max((nu - nu_ref).amax());
        scale = scale.max(y.amax());
    }
    // Rounding: each entry is a dot product of ≤ S + I + O terms of size ≤ max|y|
    // (the prediction cancels the measurement to the residual's size).
    let bound = 16.0 * 15.0 * f64::EPSILON * scale;
    println!("residual vs equations: {worst:.2e} (bound {bound:.2e})");
    assert!(worst <= bound, "{worst:e} > {bound:e}");
}

#[test]
fn the_residual_is_white_chi_square_with_o_minus_i_dof_whatever_the_force() {
    const N: usize = 40_000;
    const BURN: usize = 500;
    let f = observer();
    let wh = Whitener::<f64, 4>::new(&scene::GAINS.innovation_covariance).unwrap();
    let rt = SMatrix::<f64, 4, 4>::from_fn(|i, j| scene::GAINS.innovation_covariance[i][j]);
    let l_inv = rt.cholesky().unwrap().l().try_inverse().unwrap();
    let mut truth = Truth::new(2026);
    let mut e = f.start_at_rest();
    let mut zs: Vec<V4> = Vec::with_capacity(N);
    let mut qs = Vec::with_capacity(N);
    let mut cov = SMatrix::<f64, 4, 4>::zeros();
    for n in 0..BURN + N {
        let y = truth.next(&scene::MODEL);
        let nu = f.step_innovation(&mut e, &y);
        if n >= BURN {
            qs.push(wh.nis(&nu));
            zs.push(l_inv * nu);
            cov += nu * nu.transpose() / N as f64;
        }
    }
    // Mean of q: O − I = 3; a white χ²₃ sequence has variance 6, so the mean of N samples
    // has standard deviation √(6/N) = 0.012; allowed 5 of them.
    let mean = qs.iter().sum::<f64>() / N as f64;
    let band = 5.0 * (2.0 * DOF as f64 / N as f64).sqrt();
    println!("mean νᵀR̃⁻¹ν = {mean:.4} (expected {DOF} ± {band:.4})");
    assert!((mean - DOF as f64).abs() <= band, "mean {mean}");
    // The covariance of ν: R̃ − D̃ Pʷ D̃ᵀ (rank O − I). Compared whitened: L⁻¹ (·) L⁻ᵀ is
    // the projector I − G(GᵀG)⁻¹Gᵀ, G = L⁻¹D̃; each entry of the sample covariance of
    // white unit-variance data has standard deviation ≤ √(2/N) = 0.007; allowed 5.
    let d = scene::MODEL.d_matrix();
    let pw = scene::GAINS.input_covariance_matrix();
    let expected = rt - d * pw * d.transpose();
    let dev = (l_inv * (cov - expected) * l_inv.transpose()).amax();
    let band_cov = 5.0 * (2.0 / N as f64).sqrt();
    println!("whitened covariance vs R̃ − D̃PʷD̃ᵀ: {dev:.4} (≤ {band_cov:.4})");
    assert!(dev <= band_cov, "covariance off by {dev}");
    // White: the lag-k cross-covariances of the whitened residual, each entry of standard
    // deviation ≤ 1/√N = 0.005 if independent; allowed 5 (48 entries).
    let mut worst = 0.0f64;
    for lag in 1..=3 {
        let mut c = SMatrix::<f64, 4, 4>::zeros();
        for n in lag..N {
            c += zs[n] * zs[n - lag].transpose();
        }
        worst = worst.max((c / N as f64).amax());
    }
    let band_lag = 5.0 / (N as f64).sqrt();
    println!("largest lag-1..3 covariance {worst:.4} (≤ {band_lag:.4})");
    assert!(worst <= band_lag, "not white: {worst}");
    // The χ² test of O − I outputs over disjoint 1 s windows: false alarms at α.
    let det = Detector::<f64, 4, 50>::from_parts(wh, ChiSquareTest::new(&f, scene::ALPHA).unwrap());
    assert_eq!(det.test.dof(), 50 * DOF as u64);
    let mut win = Window::<f64, 50>::at_rest();
    let (mut alarms, mut windows) = (0u32, 0u32);
    for (k, q) in qs.iter().enumerate() {
        win.push(*q);
        if (k + 1) % 50 == 0 {
            windows += 1;
            alarms += u32::from(det.test.alarm(&win));
        }
    }
    // 800 windows at α = 1e-3: 0.8 expected; P(≥ 6) = 1.6e-4.
    println!(
        "false alarms: {alarms} in {windows} windows (α = {})",
        scene::ALPHA
    );
    assert!(alarms <= 5, "{alarms} false alarms in {windows} windows");
}

#[test]
fn a_storey_losing_stiffness_is_detected_with_the_load_unknown() {
    const DAMAGE_AT: usize = 1000; // 20 s
    const START_UP: usize = 250;
    let f = observer();
    let wh = Whitener::<f64, 4>::new(&scene::GAINS.innovation_covariance).unwrap();
    let det = Detector::<f64, 4, 250>::from_parts(wh, ChiSquareTest::new(&f, 1e-6).unwrap());
    let hurt = damaged(0.7);
    let mut delays = Vec::new();
    for seed in 0..6u64 {
        let mut truth = Truth::new(100 + seed);
        let mut e = f.start_at_rest();
        let mut win = Window::<f64, 250>::at_rest();
        let mut first = None;
        for n in 1..=3000usize {
            if n == DAMAGE_AT + 1 {
                truth.switch(&scene::MODEL, &hurt);
            }
            let model = if n > DAMAGE_AT { &hurt } else { &scene::MODEL };
            let y = truth.next(model);
            let nu = f.step_innovation(&mut e, &y);
            // The first 5 s are the estimator's start-up transient (it starts at rest, the
            // building under a 200 kN static force): not tested.
            if n > START_UP && det.update(&mut win, &nu) && first.is_none() {
                first = Some(n);
            }
        }
        let n = first.expect("the damage was not detected in 40 s");
        assert!(
            n > DAMAGE_AT,
            "seed {seed}: alarm at step {n}, before the damage"
        );
        delays.push((n - DAMAGE_AT) as f64 * scene::H);
    }
    println!("detection delays (s): {delays:?}");
    // Regression pin (measured 0.4–1.0 s on these seeds): within 3 s of the damage.
    assert!(delays.iter().all(|&d| d <= 3.0), "{delays:?}");
}

#[test]
fn a_missing_sample_gives_a_non_finite_residual_and_is_skipped() {
    let f = observer();
    let wh = Whitener::<f64, 4>::new(&scene::GAINS.innovation_covariance).unwrap();
    let det = Detector::<f64, 4, 50>::from_parts(wh, ChiSquareTest::new(&f, 1e-3).unwrap());
    let mut e = f.start_at_rest();
    let mut win = Window::<f64, 50>::at_rest();
    let y = V4::new(0.1, f64::NAN, 0.2, 1e-4);
    let before = *e.input();
    let nu = f.step_innovation(&mut e, &y);
    assert!(nu[1].is_nan());
    assert_eq!(*e.input(), before, "the input estimate is held");
    assert_eq!(e.missing(), 1);
    assert!(!det.update(&mut win, &nu));
    assert_eq!((win.len(), win.skipped()), (0, 1));
    // Checked: a state that would overflow is an error and leaves everything as it was.
    let mut e2 = f.start_at_rest();
    let _ = f
        .try_step_innovation(&mut e2, &V4::new(0.1, 0.0, 0.0, 0.0))
        .unwrap();
    let snapshot = e2;
    let r = f.try_step_innovation(&mut e2, &V4::new(f64::MAX, f64::MAX, 0.0, 0.0));
    assert_eq!(r, Err(aemstep::Error::NonFiniteState));
    assert_eq!(e2, snapshot);
}

/// `Detector<f32, …>::update` rounds its terms to fixed point in `f32`; the window must
/// hold exactly what `Window::push` of the same term widened to `f64` holds. Half the
/// `f32` values in `[½, 1)` scale to a tie (`x.5`), so random terms test the rounding.
#[test]
fn the_f32_detectors_terms_are_the_f64_windows_terms() {
    let det = Detector::<f32, 1, 7>::from_parts(
        Whitener::<f32, 1>::new(&[[1.0]]).unwrap(),
        ChiSquareTest::new(&Dof::<1>, 1e-3).unwrap(),
    );
    let (mut a, mut b) = (Window::<f32, 7>::at_rest(), Window::<f64, 7>::at_rest());
    let mut g = gauss::Gauss::new(5);
    let mut specials = vec![0.0f32, -0.0, 1e-30, 2.9e-8, 3.0e-8, 0.5, 0.70710677, 1.0];
    specials.extend([
        4096.0,
        4096.001,
        1e12,
        1e19,
        f32::MAX.sqrt(),
        f32::MAX,
        f32::INFINITY,
    ]);
    specials.extend([
        f32::NAN,
        f32::MIN_POSITIVE,
        2.0f32.powi(-12),
        2.0f32.powi(-13),
    ]);
    let mut n = 0;
    for k in 0..400_000 {
        let nu = if k < specials.len() {
            specials[k]
        } else {
            // Magnitudes from 1e-6 to 1e6.
            (g.next() * 10f64.powf(6.0 * (2.0 * (k % 1000) as f64 / 1000.0 - 1.0))) as f32
        };
        let v = SVector::<f32, 1>::new(nu);
        det.update(&mut a, &v);
        b.push(det.whitener.nis(&v) as f64);
        assert_eq!(
            (a.sum_fixed(), a.skipped(), a.len()),
            (b.sum_fixed(), b.skipped(), b.len()),
            "term of ν = {nu:e}"
        );
        n += 1;
    }
    assert_eq!(n, 400_000);
}

/// Issue 31, "statistics not tied to types": three accelerometers, one unknown force, a
/// 100-sample window, α = 10⁻⁶. The joint estimator's residual carries `O − I = 2`
/// degrees of freedom a sample, so the window's sum is `χ²₂₀₀` and the threshold its upper
/// 10⁻⁶ quantile, about 310; `ChiSquareTest::new(outputs, α)` had to be told `O − I`, and
/// given `O = 3` it took `χ²₃₀₀`'s quantile, about 431, and the detector never alarmed.
/// Now the test takes the number from the estimator's type.
#[test]
fn chi_square_threshold_takes_o_minus_i_from_the_joint_estimator() {
    // The estimator scene's building and roof force, three of its sensors: the floor-1 and
    // roof accelerometers and the roof displacement (the accelerometers alone leave the
    // force's static part unidentifiable).
    let sensors = scene::SENSORS;
    let pick = [0, 2, 3];
    let three = Outputs::<5, 1, 3> {
        u: pick.map(|i| sensors.u[i]),
        v: pick.map(|i| sensors.v[i]),
        a: pick.map(|i| sensors.a[i]),
        w: pick.map(|i| sensors.w[i]),
    };
    let meas = scene::SS.outputs(&three).unwrap();
    let model = InputModel::from_parts(&scene::SS, &meas).unwrap();
    let r = [[9e-4, 0.0, 0.0], [0.0, 9e-4, 0.0], [0.0, 0.0, 1e-10]];
    let gains = InputStateGains::solve(&model, &scene::Q, &r).unwrap();
    let est = InputStateObserver::<f32, 10, 1, 3>::new(&model, &gains).unwrap();
    assert_eq!(<InputStateObserver<f32, 10, 1, 3> as Innovations>::DOF, 2);

    const ALPHA: f64 = 1e-6;
    let run = ChiSquareTest::<f64, 100>::new(&est, ALPHA).unwrap();
    let at_compile = ChiSquareTest::<f64, 100>::new_f64(&est, ALPHA).unwrap();
    assert_eq!(run, at_compile);
    assert_eq!(run.dof(), 200);
    // The exact quantiles of χ²₂₀₀ and χ²₃₀₀, by bisection of the regularized incomplete
    // gamma function (`scenes/detection/chi2.rs`, written from its series, not the crate's).
    let exact = |k: u64| {
        let (mut lo, mut hi) = (0.0f64, 2.0 * k as f64 + 200.0);
        while hi - lo > 1e-12 * hi {
            let mid = 0.5 * (lo + hi);
            if chi2::chi2_upper_tail(k, mid) > ALPHA {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    };
    let (x200, x300) = (exact(200), exact(300));
    println!(
        "α = 1e-6, W = 100: threshold {:.3} (exact χ²₂₀₀ quantile {x200:.3}; χ²₃₀₀'s, the \
         wrong count, {x300:.3})",
        run.threshold()
    );
    // Wilson–Hilferty's relative error is c(z)/k (Cornish–Fisher terms of order 1/k);
    // `tests/detection.rs` bounds c(z) by 0.01 (1 + z²) on α ∈ [1e-5, 0.05]; here z = 4.75
    // (α = 1e-6), the same form extrapolated: 0.01 · 23.6 / 200 = 1.2e-3.
    let z = 4.753_424_308_822_899; // Φ⁻¹(1 − 10⁻⁶), from tables
    let bound = 0.01 * (1.0 + z * z) / 200.0;
    let rel = (run.threshold() - x200).abs() / x200;
    assert!(rel <= bound, "relative error {rel:.2e} > {bound:.2e}");
    assert!((x200 - 310.0).abs() < 1.0 && (x300 - 431.0).abs() < 1.0);
    // The threshold the wrong count gave is nowhere near.
    assert!(run.threshold() < x300 - 100.0);
    // The CUSUM takes the same count: offset ½ (O − I) ln λ.
    let c = aemstep::detection::Cusum::<f64>::new(&est, 2.0, ALPHA).unwrap();
    let c2 = aemstep::detection::Cusum::<f64>::new(&Dof::<2>, 2.0, ALPHA).unwrap();
    assert_eq!(c, c2);
}
