//! The time-varying stepper against paper Example 3's exact solution, against `Linear`
//! for constant coefficients, and on its failure paths.

#[path = "support/checks.rs"]
mod checks;
#[path = "support/runs.rs"]
mod runs;
mod support;

use aemstep::{Coefficients, Error, Linear, Stepper, Varying, models};
use checks::bits;
use nalgebra::{SVector, matrix, vector};
use runs::{Example3, example3_exact, example3_load, example3_start};
use support::sm;

// ---------------------------------------------------------------- Example 3
// (`Example3`, `(1 + t²) u'' + t u' + e^{1/(1+t)} u = p(t)`, its exact solution and load:
// tests/support/runs.rs)

#[test]
fn example3_exact_solution_and_load_are_right() {
    let d = 1e-4;
    for i in 0..60 {
        let t = 0.33 * i as f64;
        let (um, vm, _) = example3_exact(t - d);
        let (_, v, a) = example3_exact(t);
        let (up, vp, _) = example3_exact(t + d);
        // central differences, truncation d²/6 |u'''| < 2e-9
        assert!(((up - um) / (2.0 * d) - v).abs() < 1e-8);
        assert!(((vp - vm) / (2.0 * d) - a).abs() < 1e-8);
        // the paper's printed load: 0.01 e^{−0.1t}[−(99 + 10t + 99t²) cos t
        //   + (20 − 100t + 20t²) sin t + 100 e^{1/(1+t)} cos t]
        let (s, c) = t.sin_cos();
        let paper = 0.01
            * (-0.1 * t).exp()
            * (-(99.0 + 10.0 * t + 99.0 * t * t) * c
                + (20.0 - 100.0 * t + 20.0 * t * t) * s
                + 100.0 * (1.0 / (1.0 + t)).exp() * c);
        assert!((example3_load(t) - paper).abs() < 1e-12 * (1.0 + t * t));
    }
}

#[test]
fn example3_error_and_order() {
    let e1 = runs::example3_error::<f64>(0.01, 20.0);
    let e2 = runs::example3_error::<f64>(0.005, 20.0);
    let order = (e1 / e2).log2();
    println!("Example 3 (T = 20): max error h=0.01: {e1:.3e}, h=0.005: {e2:.3e}, order {order:.3}");
    // Measured 3.132e-5 and 7.831e-6, order 2.000: error = C h² with C = 0.313 at both
    // steps. Verification: order within ±0.05 of 2 against the exact solution. Regression
    // pin: C at most 10 % above the measured one.
    assert!((order - 2.0).abs() < 0.05, "{order}");
    assert!(e1 < 0.345 * 0.01 * 0.01, "{e1}");
    assert!(e2 < 0.345 * 0.005 * 0.005, "{e2}");
}

#[test]
fn example3_in_f32() {
    let h = 0.01f32;
    let coeffs = |t: f32| Coefficients {
        mass: matrix![1.0 + t * t],
        damping: matrix![t],
        stiffness: matrix![(1.0 / (1.0 + t)).exp()],
    };
    let st = Varying::<f32, 1>::new(h as f64).unwrap();
    let p = |n: u64| vector![example3_load(n as f64 * 0.01) as f32];
    let mut s = st
        .start(&coeffs, &vector![1.0], &vector![-0.1], &p(0))
        .unwrap();
    let mut err = 0.0f64;
    for n in 1..=2000 {
        st.try_step(&coeffs, &mut s, &p(n)).unwrap();
        err = err.max((s.u()[0] as f64 - example3_exact(n as f64 * 0.01).0).abs());
    }
    println!("Example 3 in f32 (h = 0.01, T = 20): max error {err:.3e}");
    // f64 bound 0.345 h² = 3.45e-5 plus f32 rounding: ε_f32 ≈ 6e-8 per step as a random
    // walk over 2000 steps ≈ 3e-6; allowed 5e-6.
    assert!(err < 3.45e-5 + 5e-6, "{err}");
}

// ---------------------------------------------------------------- constant coefficients

#[test]
fn constant_coefficients_reproduce_linear() {
    let (m, c, k) = models::five_storey_building();
    let (m, c, k) = (sm(&m), sm(&c), sm(&k));
    let h = 0.01;
    let lin = Linear::<f64, _>::new(&m, &c, &k, h).unwrap();
    let var = Varying::<f64, 5>::new(h).unwrap();
    let coeffs = |_t: f64| Coefficients {
        mass: m,
        damping: c,
        stiffness: k,
    };
    let p = |t: f64| SVector::<f64, 5>::from_fn(|i, _| 1e6 * (3.0 * t + i as f64).sin());
    let u0 = vector![0.002, 0.004, 0.006, 0.008, 0.01];
    let v0 = SVector::<f64, 5>::zeros();
    let mut a = lin.start(&u0, &v0, &p(0.0)).unwrap();
    let mut b = var.start(&coeffs, &u0, &v0, &p(0.0)).unwrap();
    let (mut dev, mut umax) = (0.0f64, 0.0f64);
    for n in 1..=2000 {
        let pn = p(n as f64 * h);
        lin.step(&mut a, &pn);
        var.try_step(&coeffs, &mut b, &pn).unwrap();
        dev = dev.max((a.u() - b.u()).amax());
        umax = umax.max(a.u().amax());
    }
    println!(
        "Varying (constant) vs Linear, 5 storeys, 2000 steps: max |Δu| / max |u| = {:.3e}",
        dev / umax
    );
    // Same recurrence; only rounding differs (precomputed inverse vs an LU per step).
    assert!(dev <= 1e-12 * umax, "{dev} vs {umax}");
    assert_eq!(a.steps(), b.steps());
}

// ---------------------------------------------------------------- failure paths

#[test]
fn singular_effective_matrix_names_the_step_and_keeps_the_state() {
    let h = 0.1;
    // M_eff = 1 + (h²/4) K(t) = 0 from t = 0.5 on (step 5), when K = −4/h².
    let coeffs = |t: f64| Coefficients {
        mass: matrix![1.0],
        damping: matrix![0.0],
        stiffness: matrix![if t > 0.45 { -4.0 / (h * h) } else { 1.0 }],
    };
    let st = Varying::<f64, 1>::new(h).unwrap();
    let mut s = st
        .start(&coeffs, &vector![1.0], &vector![0.0], &vector![0.0])
        .unwrap();
    for _ in 0..4 {
        st.try_step(&coeffs, &mut s, &vector![0.0]).unwrap();
    }
    let before = bits(&s);
    assert_eq!(
        st.try_step(&coeffs, &mut s, &vector![0.0]),
        Err(Error::SingularEffectiveMatrixAtStep { step: 5 })
    );
    assert_eq!(bits(&s), before);
    // Nothing lost: the caller can carry on with other coefficients.
    let soft = |_t: f64| Coefficients {
        mass: matrix![1.0],
        damping: matrix![0.0],
        stiffness: matrix![1.0],
    };
    st.try_step(&soft, &mut s, &vector![0.0]).unwrap();
    assert_eq!(s.steps(), 5);
    // A 2×2 case singular by a rank-one M_eff (rows proportional), not by a zero entry.
    let rank1 = |_t: f64| Coefficients {
        mass: matrix![1.0, 2.0; 2.0, 4.0],
        damping: matrix![0.0, 0.0; 0.0, 0.0],
        stiffness: matrix![0.0, 0.0; 0.0, 0.0],
    };
    let st2 = Varying::<f64, 2>::new(h).unwrap();
    let mut s2 = st2
        .start_with_acceleration(&vector![0.0, 0.0], &vector![1.0, 0.0], &vector![0.0, 0.0])
        .unwrap();
    let before = bits(&s2);
    assert_eq!(
        st2.try_step(&rank1, &mut s2, &vector![1.0, 1.0]),
        Err(Error::SingularEffectiveMatrixAtStep { step: 1 })
    );
    assert_eq!(bits(&s2), before);
}

#[test]
fn non_finite_inputs_keep_the_state() {
    let h = 0.1;
    let nan_at_3 = |t: f64| Coefficients {
        mass: matrix![1.0],
        damping: matrix![if t > 0.25 { f64::NAN } else { 0.1 }],
        stiffness: matrix![1.0],
    };
    let st = Varying::<f64, 1>::new(h).unwrap();
    let mut s = st
        .start(&nan_at_3, &vector![1.0], &vector![0.0], &vector![0.0])
        .unwrap();
    st.try_step(&nan_at_3, &mut s, &vector![0.0]).unwrap();
    st.try_step(&nan_at_3, &mut s, &vector![0.0]).unwrap();
    let before = bits(&s);
    assert_eq!(
        st.try_step(&nan_at_3, &mut s, &vector![0.0]),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(bits(&s), before);
    let ok = |_t: f64| Coefficients {
        mass: matrix![1.0],
        damping: matrix![0.0],
        stiffness: matrix![1.0],
    };
    for bad in [f64::NAN, f64::NEG_INFINITY] {
        assert_eq!(
            st.try_step(&ok, &mut s, &vector![bad]),
            Err(Error::NonFiniteInput)
        );
        assert_eq!(bits(&s), before);
    }
    // A tiny (but not singular) effective matrix that makes q overflow.
    let feather = |_t: f64| Coefficients {
        mass: matrix![1e-300],
        damping: matrix![0.0],
        stiffness: matrix![0.0],
    };
    assert_eq!(
        st.try_step(&feather, &mut s, &vector![1e10]),
        Err(Error::NonFiniteState)
    );
    assert_eq!(bits(&s), before);
}

#[test]
fn start_and_construction_errors() {
    assert_eq!(Varying::<f64, 1>::new(0.0), Err(Error::InvalidTimeStep));
    assert_eq!(Varying::<f64, 1>::new(-0.1), Err(Error::InvalidTimeStep));
    assert_eq!(
        Varying::<f64, 1>::new(f64::INFINITY),
        Err(Error::InvalidTimeStep)
    );
    let st = Varying::<f64, 1>::new(0.1).unwrap();
    let z = vector![0.0];
    let massless = |_t: f64| Coefficients {
        mass: matrix![0.0],
        damping: matrix![1.0],
        stiffness: matrix![1.0],
    };
    assert_eq!(st.start(&massless, &z, &z, &z), Err(Error::SingularMass));
    // ... but it can start from a known acceleration and step (M_eff = h/2 + h²/4 ≠ 0).
    let mut s = st
        .start_with_acceleration(&vector![1.0], &z, &vector![-1.0])
        .unwrap();
    st.try_step(&massless, &mut s, &z).unwrap();
    assert!(s.is_finite());
    assert_eq!(
        st.start_with_acceleration(&z, &vector![f64::NAN], &z),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        st.start(&Example3, &vector![f64::NAN], &z, &z),
        Err(Error::NonFiniteInput)
    );
    let nan_m = |_t: f64| Coefficients {
        mass: matrix![f64::NAN],
        damping: matrix![0.0],
        stiffness: matrix![1.0],
    };
    assert_eq!(st.start(&nan_m, &z, &z, &z), Err(Error::NonFiniteInput));
    // q0 = M(0)⁻¹ (p0 − C(0) v0 − K(0) u0): Example 3 at t = 0: M = 1, C = 0, K = e.
    let s = example3_start(&st);
    assert!((s.a()[0] - example3_exact(0.0).2).abs() < 1e-15);
}

#[test]
fn singular_step_error_names_the_step_when_displayed() {
    let e = aemstep::Error::SingularEffectiveMatrixAtStep { step: 5 };
    let text = e.to_string();
    assert!(
        text.starts_with(e.as_str()) && text.ends_with("(step 5)"),
        "{text}"
    );
}
