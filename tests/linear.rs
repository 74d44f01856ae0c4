//! The linear AEM kernel (issue 2) against exact solutions, the paper's literal A-form,
//! and an independent Newmark average-acceleration loop.

#[path = "support/checks.rs"]
mod checks;
#[path = "support/runs.rs"]
mod runs;
mod support;

use aemstep::{Error, Linear, State, Stepper};
use checks::bits;
use nalgebra::{SMatrix, SVector, matrix, vector};
use runs::{
    CrossCheck, dm, example1_period, example2_error, example2_run, example4_error, free_vibration,
    rel_diff, sdof,
};
use support::*;

#[test]
fn example1_period_matches_theory_and_paper() {
    for (h, paper_pe) in [(0.01, 0.02e-2), (0.001, 0.00021e-2)] {
        let s: f64 = 5.0 * h;
        // Spec §4: the numerical phase per step is 2·atan(s/2) exactly for ξ = 0.
        let t_theory = 2.0 * std::f64::consts::PI * h / (2.0 * (s / 2.0).atan());
        let t_num = example1_period(h, 60.0);
        let rel = (t_num - t_theory).abs() / t_theory;
        let pe = t_num / (2.0 * std::f64::consts::PI / 5.0) - 1.0;
        eprintln!(
            "h = {h}: period {t_num:.12} vs theory {t_theory:.12}, rel {rel:.2e}, PE {pe:.3e}"
        );
        // The issue asks for 1 %; the interpolated crossings are far better than that.
        assert!(rel < 0.01);
        assert!(rel < 1e-7, "period off by {rel:e}");
        // The paper's PE (0.02 %, 0.00021 %) is s²/12 to the digits it prints.
        assert!(
            (pe - paper_pe).abs() < 0.05 * paper_pe,
            "PE {pe:e} vs paper {paper_pe:e}"
        );
    }
}

#[test]
fn example1_no_amplitude_decay_over_1e5_steps() {
    // Undamped trapezoidal rule = Cayley transform of a generator that is skew in the energy
    // norm: ω²u² + v² is conserved exactly; only rounding (~√n·ε) can move it.
    let h = 0.01;
    let s = free_vibration::<f64>(5.0, h, 100_000);
    let amp = (s.u()[0].powi(2) + (s.v()[0] / 5.0).powi(2)).sqrt();
    eprintln!("amplitude after 1e5 steps: 1 + {:.3e}", amp - 1.0);
    assert!((amp - 1.0).abs() < 1e-9);
    assert_eq!(s.steps(), 100_000);
    assert_eq!(s.time(h), 1000.0);
}

#[test]
fn example2_error_and_second_order_f64() {
    // We reproduce the trapezoidal rule's true error, 7.09e-5 (i) and 7.00e-5 (ii): the
    // AEM step IS the trapezoidal rule (spec §3), and an independent trapezoidal code gives
    // the same numbers. The paper's Fig. 7 (≈ 2e-5) cannot be reproduced by this scheme.
    for (case, p, expect) in [("(i)", 0.0, 7.09e-5), ("(ii)", 10.0, 7.00e-5)] {
        let e: Vec<f64> = [1, 2, 4, 8]
            .iter()
            .map(|&k| example2_error(&example2_run::<f64>(p, k), p, k))
            .collect();
        let orders: Vec<f64> = (1..4).map(|i| order(e[i - 1], 2.0, e[i], 1.0)).collect();
        let overall = order(e[0], 8.0, e[3], 1.0);
        eprintln!("Example 2 {case}: errors {e:?}, orders {orders:?}, overall {overall:.4}");
        assert!(e[0] <= 7.5e-5, "max error {:e}", e[0]);
        assert!(
            (e[0] - expect).abs() < 0.01 * expect,
            "{:e} vs {expect:e}",
            e[0]
        );
        assert!((overall - 2.0).abs() <= 0.05, "order {overall}");
        for o in orders {
            assert!((o - 2.0).abs() <= 0.05, "order {o}");
        }
    }
}

#[test]
fn example2_f32() {
    // f32 adds rounding on top of the O(h²) error: per step ≈ ε₃₂·|u| (≈ 6e-7 for
    // |u| ≤ 10), accumulating like a random walk over 12,500 steps (×√n ≈ 112) → ≈ 7e-5 at
    // worst. Measured: the f32 trajectory stays within 1e-5 of the f64 one.
    for p in [0.0, 10.0] {
        let (u32s, u64s) = (example2_run::<f32>(p, 1), example2_run::<f64>(p, 1));
        let e32 = example2_error(&u32s, p, 1);
        let e64 = example2_error(&u64s, p, 1);
        // max |u_f32 − u_f64| over Example 2 at h = 1/500.
        let d = max_diff(&u32s, &u64s);
        eprintln!(
            "Example 2 p = {p}: f32 max error {e32:.3e} (f64 {e64:.3e}), max |u32 − u64| {d:.3e}"
        );
        assert!(d < 7e-5, "f32 rounding {d:e}");
        assert!(e32 < e64 + 7e-5, "f32 error {e32:e}");
    }
}

#[test]
fn example4_caughey_damping_matches_paper_matrix() {
    let (m, k, xi, u0, v0, p) = example4();
    let exact = ModalExact::new(&m, &k, xi, &u0, &v0, &p);
    let d = (exact.c - example4_printed_c()).abs().max();
    eprintln!(
        "Caughey C vs printed C: max abs difference {d:.2e}; ω = {:?}",
        exact.w
    );
    assert!(d < 5e-5, "{d:e}"); // the paper prints 4 decimals
}

#[test]
fn example4_against_exact_modal_solution() {
    // O(h²): the phase error of mode r after time t is ≈ ω_r³ h² t / 12. The stiffest mode
    // (ω ≈ 10.5 rad/s, ξ = 0.09) dominates the early error and has decayed by t = 5.
    let (e1, umax) = example4_error::<f64>(0.01);
    let (e2, _) = example4_error::<f64>(0.005);
    let (e3, _) = example4_error::<f64>(0.0025);
    let o1 = order(e1, 0.01, e2, 0.005);
    let o2 = order(e2, 0.005, e3, 0.0025);
    eprintln!(
        "Example 4: max |u| {umax:.3}, errors {e1:.3e} {e2:.3e} {e3:.3e}, orders {o1:.3} {o2:.3}"
    );
    assert!(
        (o1 - 2.0).abs() < 0.05 && (o2 - 2.0).abs() < 0.05,
        "orders {o1} {o2}"
    );
    assert!(e1 < 1e-2 * umax);
    // f32: rounding (≈ ε₃₂·|u|·√n ≈ 6e-8·17·22 ≈ 2e-5) is three orders below the O(h²)
    // error at h = 0.01, so the f32 error equals the f64 one to within that.
    let (e32, _) = example4_error::<f32>(0.01);
    eprintln!("Example 4 f32, h = 0.01: {e32:.6e} (f64 {e1:.6e})");
    assert!((e32 - e1).abs() < 1e-4, "f32 {e32:e} vs f64 {e1:e}");
}

/// Random system N (seed N): fast form, A-form and the independent Newmark-AA
/// (displacement form, dense LU each step) over 10⁴ steps, and the A-form's blocks against
/// the literal 3N×3N operators.
fn cross_check<const N: usize>() {
    let CrossCheck {
        m,
        c,
        k,
        h,
        aform,
        tf,
        ta,
        tn,
        t32,
    } = runs::cross_check::<N>();
    let d_fa = rel_diff(&tf, &ta);
    let d_fn = rel_diff(&tf, &tn);
    let d_an = rel_diff(&ta, &tn);

    // The literal 3N×3N A = L⁻¹R, b = L⁻¹E against the A-form's blocks.
    let (a_lit, b_lit) = literal_a_b(&dm(&m), &dm(&c), &dm(&k), h);
    let mut d_blocks: f64 = 0.0;
    for r in 0..3 {
        for cc in 0..3 {
            let lit = a_lit.view((r * N, cc * N), (N, N));
            d_blocks = d_blocks.max((dm(&aform.a_block(r, cc).unwrap()) - lit).abs().max());
        }
        let lit = b_lit.view((r * N, 0), (N, N));
        d_blocks = d_blocks.max((dm(&aform.b_block(r).unwrap()) - lit).abs().max());
    }
    eprintln!(
        "N = {N:2}: fast vs A-form {d_fa:.2e}, fast vs Newmark {d_fn:.2e}, A-form vs Newmark {d_an:.2e}, A blocks vs literal L⁻¹R {d_blocks:.2e}"
    );
    assert!(d_fa < 1e-12, "fast vs A-form {d_fa:e}");
    // The displacement form recovers a_n = (u_n − u)/(βh²) − …, which turns a rounding of
    // ε|u| into 4ε|u|/h² ≈ 4e-12·|u| of acceleration per step (h = 0.01); over 10⁴ steps
    // that stays below 1e-11 relative.
    assert!(d_fn < 1e-11 && d_an < 1e-11, "Newmark {d_fn:e} {d_an:e}");

    // f32 against f64: the operators rounded to f32 shift each frequency by ≈ ε₃₂ ≈ 6e-8
    // relative, i.e. a phase drift ω·t·ε₃₂ ≤ 9·100·6e-8 ≈ 5e-5 over the 100 s run (ω ≤ 9 rad/s
    // for these systems), plus per-step rounding; 1e-4 covers that, measured ≤ 4e-6.
    let d_32 = rel_diff(&t32, &tf);
    eprintln!("N = {N:2}: f32 vs f64 fast form {d_32:.2e}");
    assert!(d_32 < 1e-4, "f32 {d_32:e}");
    assert!(d_blocks < 1e-12, "A blocks {d_blocks:e}");
}

#[test]
fn fast_form_a_form_and_newmark_agree() {
    cross_check::<1>();
    cross_check::<2>();
    cross_check::<3>();
    cross_check::<6>();
    cross_check::<12>();
}

// ---------------------------------------------------------------- errors, bad input

#[test]
fn new_rejects_non_finite_entries() {
    let ok = matrix![1.0, 0.0; 0.0, 1.0];
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let b = matrix![1.0, bad; 0.0, 1.0];
        assert_eq!(
            Linear::<f64, _>::new(&b, &ok, &ok, 0.1),
            Err(Error::NonFiniteInput)
        );
        assert_eq!(
            Linear::<f64, _>::new(&ok, &b, &ok, 0.1),
            Err(Error::NonFiniteInput)
        );
        assert_eq!(
            Linear::<f64, _>::new(&ok, &ok, &b, 0.1),
            Err(Error::NonFiniteInput)
        );
    }
}

#[test]
fn new_rejects_bad_time_steps() {
    let one = matrix![1.0];
    for h in [0.0, -0.01, -0.0, f64::NAN, f64::INFINITY] {
        assert_eq!(
            Linear::<f64, _>::new(&one, &one, &one, h),
            Err(Error::InvalidTimeStep),
            "h = {h}"
        );
    }
    // A step whose square underflows to zero is refused (the kinematics would lose the
    // acceleration terms); the smallest step with a normal square is valid.
    assert_eq!(
        Linear::<f64, _>::new(&one, &one, &one, f64::MIN_POSITIVE),
        Err(Error::InvalidTimeStep)
    );
    assert!(Linear::<f64, _>::new(&one, &one, &one, 1.5e-154).is_ok());
}

#[test]
fn new_rejects_singular_effective_matrix() {
    let z = matrix![0.0, 0.0; 0.0, 0.0];
    assert_eq!(
        Linear::<f64, _>::new(&z, &z, &z, 0.01),
        Err(Error::SingularEffectiveMatrix)
    );
    // Rank one in every term: M_eff = (1 + h/2 + h²/4)·[[1, 1], [1, 1]].
    let r1 = matrix![1.0, 1.0; 1.0, 1.0];
    assert_eq!(
        Linear::<f64, _>::new(&r1, &r1, &r1, 0.01),
        Err(Error::SingularEffectiveMatrix)
    );
    // M = −(h²/4) K cancels exactly.
    let h = 0.5;
    assert_eq!(
        Linear::<f64, _>::new(&matrix![-0.0625], &matrix![0.0], &matrix![1.0], h),
        Err(Error::SingularEffectiveMatrix)
    );
}

#[test]
fn singular_mass_needs_a_known_initial_acceleration() {
    // Second DOF massless: u2 is a static (quasi-static) DOF, M_eff regular.
    let m = matrix![1.0, 0.0; 0.0, 0.0];
    let k = matrix![2.0, -1.0; -1.0, 2.0];
    let c = matrix![0.0, 0.0; 0.0, 0.1];
    let sys = Linear::<f64, _>::new(&m, &c, &k, 0.01).unwrap();
    let (u0, v0, p0) = (vector![1.0, 0.5], vector![0.0, 0.0], vector![0.0, 0.0]);
    assert_eq!(sys.start(&u0, &v0, &p0), Err(Error::SingularMass));
    let mut s = sys
        .start_with_acceleration(&u0, &v0, &vector![-1.5, 0.0])
        .unwrap();
    for _ in 0..100 {
        sys.try_step(&mut s, &vector![0.0, 0.0]).unwrap();
    }
    // Equilibrium of the massless DOF holds at every step: −u1 + 2u2 + 0.1 v2 = 0.
    let r: f64 = -s.u()[0] + 2.0 * s.u()[1] + 0.1 * s.v()[1];
    assert!(r.abs() < 1e-12, "{r:e}");
    assert_eq!(
        sys.start_with_acceleration(&u0, &vector![f64::NAN, 0.0], &vector![0.0, 0.0]),
        Err(Error::NonFiniteInput)
    );
}

#[test]
fn start_rejects_non_finite_initial_values() {
    let sys = sdof::<f64>(2.0, 0.05, 0.01);
    let (one, bad) = (vector![1.0], vector![f64::NAN]);
    assert_eq!(sys.start(&bad, &one, &one), Err(Error::NonFiniteInput));
    assert_eq!(sys.start(&one, &bad, &one), Err(Error::NonFiniteInput));
    assert_eq!(
        sys.start(&one, &one, &vector![f64::INFINITY]),
        Err(Error::NonFiniteInput)
    );
    // Finite inputs whose acceleration overflows.
    assert_eq!(
        sys.start(&vector![1e308], &one, &one),
        Err(Error::NonFiniteState)
    );
}

#[test]
fn checked_step_keeps_state_bit_identical_on_bad_load() {
    let (m, k, xi, u0, v0, p) = example4();
    let c = ModalExact::new(&m, &k, xi, &u0, &v0, &p).c;
    for (name, sys) in [("fast", Linear::<f64, _>::new(&m, &c, &k, 0.01).unwrap())] {
        let aform = sys.a_form();
        let steppers: [&dyn Stepper<f64, 3, Input = SVector<f64, 3>, State = State<f64, 3>>; 2] =
            [&sys, &aform];
        for st in steppers {
            let mut s = st.start(&u0, &v0, &p).unwrap();
            for _ in 0..10 {
                st.try_step(&mut s, &p).unwrap();
            }
            let before = s;
            // A non-finite load is refused as input (the same variant in every stepper).
            for bad in [
                vector![f64::NAN, 0.0, 0.0],
                vector![0.0, f64::INFINITY, 0.0],
                vector![0.0, 0.0, 1e308 * 10.0],
            ] {
                assert_eq!(
                    st.try_step(&mut s, &bad),
                    Err(Error::NonFiniteInput),
                    "{name}"
                );
                assert_eq!(bits(&s), bits(&before));
                assert_eq!(s.steps(), before.steps());
            }
            // A finite load whose step overflows: the result is refused as state.
            let m = SVector::repeat(f64::MAX);
            let mut huge = State::restore(m, m, m, s.steps()).unwrap();
            let kept = huge;
            assert_eq!(
                st.try_step(&mut huge, &vector![f64::MAX, f64::MAX, f64::MAX]),
                Err(Error::NonFiniteState),
                "{name}"
            );
            assert_eq!(bits(&huge), bits(&kept));
            // The stepper goes on from the kept state.
            st.try_step(&mut s, &p).unwrap();
            assert_eq!(s.steps(), before.steps() + 1);
        }
    }
    // A finite load that overflows the state is refused the same way: G = 1e10 here.
    let light = Linear::<f64, _>::new(&matrix![1e-10], &matrix![0.0], &matrix![0.0], 1.0).unwrap();
    let mut s = light
        .start(&vector![0.0], &vector![0.0], &vector![0.0])
        .unwrap();
    assert_eq!(
        light.try_step(&mut s, &vector![1e300]),
        Err(Error::NonFiniteState)
    );
    assert_eq!(
        s,
        light
            .start(&vector![0.0], &vector![0.0], &vector![0.0])
            .unwrap()
    );
    light.try_step(&mut s, &vector![1e200]).unwrap();
    // f32 too.
    let sys = sdof::<f32>(2.0, 0.07, 0.002);
    let mut s = sys
        .start(&vector![1.0], &vector![20.0], &vector![10.0])
        .unwrap();
    sys.try_step(&mut s, &vector![10.0]).unwrap();
    let before = s;
    assert_eq!(
        sys.try_step(&mut s, &vector![f32::NAN]),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(s.u()[0].to_bits(), before.u()[0].to_bits());
    assert_eq!(s.v()[0].to_bits(), before.v()[0].to_bits());
    assert_eq!(s.a()[0].to_bits(), before.a()[0].to_bits());
}

#[test]
fn errors_display_and_const_path_errors() {
    assert_eq!(
        Error::SingularMass.to_string(),
        Error::SingularMass.as_str()
    );
    assert!(Error::InvalidTimeStep.to_string().contains("time step"));
    let e: &dyn std::error::Error = &Error::NonFiniteState;
    assert!(!e.to_string().is_empty());
    assert_eq!(
        Linear::<f64, 1>::from_rows_f64([[1.0]], [[0.0]], [[1.0]], 0.0),
        Err(Error::InvalidTimeStep)
    );
    assert_eq!(
        Linear::<f32, 1>::from_rows_f32([[f64::NAN]], [[0.0]], [[1.0]], 0.1),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        Linear::<f32, 2>::from_rows_f32([[0.0; 2]; 2], [[0.0; 2]; 2], [[0.0; 2]; 2], 0.1),
        Err(Error::SingularEffectiveMatrix)
    );
    let s = Linear::<f64, 2>::from_rows_f64(
        [[1.0, 0.0], [0.0, 0.0]],
        [[0.0; 2]; 2],
        [[1.0, 0.0], [0.0, 1.0]],
        0.1,
    )
    .unwrap();
    assert_eq!(
        s.start(&vector![0.0, 0.0], &vector![0.0, 0.0], &vector![0.0, 0.0]),
        Err(Error::SingularMass)
    );
}

// ---------------------------------------------------------------- compile-time operators

const EX4_M: [[f64; 3]; 3] = [[52.0, 10.0, 20.0], [10.0, 150.0, 30.0], [20.0, 30.0, 441.0]];
const EX4_C: [[f64; 3]; 3] = [
    [34.3199, 27.9975, 89.4615],
    [27.9975, 172.1296, 50.4249],
    [89.4615, 50.4249, 770.3077],
];
const EX4_K: [[f64; 3]; 3] = [
    [1472.0, 407.0, 5553.0],
    [407.0, 1001.0, 4154.0],
    [5553.0, 4154.0, 43516.0],
];

/// Evaluated by the compiler (a `static` initializer must be a constant).
static EX4_F64: Linear<f64, 3> = match Linear::from_rows_f64(EX4_M, EX4_C, EX4_K, 0.01) {
    Ok(s) => s,
    Err(e) => panic!("{}", e.as_str()),
};
static EX4_F32: Linear<f32, 3> = match Linear::from_rows_f32(EX4_M, EX4_C, EX4_K, 0.01) {
    Ok(s) => s,
    Err(e) => panic!("{}", e.as_str()),
};

#[test]
fn const_built_operators_equal_runtime_built_bit_for_bit() {
    let sm = |a: [[f64; 3]; 3]| SMatrix::<f64, 3, 3>::from_fn(|i, j| a[i][j]);
    let rt64 = Linear::<f64, _>::new(&sm(EX4_M), &sm(EX4_C), &sm(EX4_K), 0.01).unwrap();
    assert_eq!(rt64, EX4_F64); // PartialEq on every operator entry
    assert_eq!(
        rt64.effective_inverse().map(f64::to_bits),
        EX4_F64.effective_inverse().map(f64::to_bits)
    );
    // f32: computed in f64 from the same (f64) data and rounded once, in both paths.
    let from_rows = Linear::<f32, 3>::from_rows_f32(EX4_M, EX4_C, EX4_K, 0.01).unwrap();
    let rt32 = Linear::<f32, 3>::new(&sm(EX4_M), &sm(EX4_C), &sm(EX4_K), 0.01).unwrap();
    assert_eq!(rt32, from_rows);
    // The compile-time f32 static: `step` and `try_step` give the same bits.
    let p = vector![10.0f32, 10.0, 10.0];
    let mut a = EX4_F32
        .start(&vector![10.0, 1.0, 5.0], &vector![0.0, 50.0, 20.0], &p)
        .unwrap();
    let mut b = a;
    for _ in 0..100 {
        EX4_F32.step(&mut a, &p);
        EX4_F32.try_step(&mut b, &p).unwrap();
    }
    assert_eq!(a, b);
    // The f32 static is the f64 one rounded once.
    let g64 = EX4_F64.effective_inverse();
    let g32 = EX4_F32.effective_inverse();
    assert_eq!(g64.map(|x| x as f32), g32);
}

#[test]
fn time_is_computed_from_the_step_count() {
    let h = 0.1f32; // not exact in binary: accumulating t += h would drift
    let sys = sdof::<f32>(1.0, 0.0, h as f64);
    let mut s = sys
        .start(&vector![0.0], &vector![0.0], &vector![0.0])
        .unwrap();
    let mut acc = 0.0f32;
    for _ in 0..1_000_000 {
        sys.step(&mut s, &vector![0.0]);
        acc += h;
    }
    assert_eq!(s.time(h), (1_000_000.0f64 * h as f64) as f32);
    assert!((s.time(h) - 100_000.0).abs() < 0.01);
    assert!(
        (acc - 100_000.0).abs() > 100.0,
        "accumulation drifts: {acc}"
    ); // why we don't
}
