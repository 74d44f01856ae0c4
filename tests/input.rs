//! `LinearInput` (loads through an influence matrix, `p = B w`) against `Linear` fed
//! `p = B w` directly, which is itself checked against exact solutions elsewhere.
//!
//! The two compute the same recurrence; the only difference is where `G B w` is rounded:
//! `LinearInput` forms `G B` once in `f64` and rounds it to `T`, `Linear` rounds `G` and
//! multiplies by `B w` in `T` each step. Each step therefore differs by a few units of
//! rounding in `q`, `O(N ε |G||B||w|)`, and the scheme neither amplifies nor damps
//! perturbations faster than the system itself (unconditionally stable, `|λ| ≤ 1`), so the
//! difference can grow at most linearly with the step count `n`. The bounds below are
//! `n · N · ε` times a factor 8 for the constant in front (measured ratios are quoted at
//! each assertion).

#[path = "support/checks.rs"]
mod checks;
/// El Centro NS 1940 ground acceleration (m/s²) at dt = 0.02 s.
#[path = "../scenes/modal/elcentro.rs"]
mod elcentro;
mod support;

use aemstep::models::base_excitation;
use aemstep::{Error, Linear, LinearInput, Stepper, models};
use nalgebra::{SMatrix, SVector};
use support::Rng;

/// A random well-conditioned system (not symmetric: `Linear` does not need it) and a
/// random influence matrix.
#[allow(clippy::type_complexity)]
fn random_system<const N: usize, const I: usize>(
    rng: &mut Rng,
) -> (
    SMatrix<f64, N, N>,
    SMatrix<f64, N, N>,
    SMatrix<f64, N, N>,
    SMatrix<f64, N, I>,
) {
    let r = |rng: &mut Rng| SMatrix::<f64, N, N>::from_fn(|_, _| rng.uniform());
    let a = r(rng);
    let m = a * a.transpose() + SMatrix::identity() * N as f64;
    let bk = r(rng);
    let k = (bk * bk.transpose() + SMatrix::identity()) * 40.0 + r(rng) * 0.5;
    let c = m * 0.3 + k * 0.01 + r(rng) * 0.05;
    let b = SMatrix::<f64, N, I>::from_fn(|_, _| rng.uniform());
    (m, c, k, b)
}

fn input_at<const I: usize>(n: usize, h: f64) -> SVector<f64, I> {
    let t = n as f64 * h;
    SVector::from_fn(|j, _| (1.7 * (j + 1) as f64 * t).sin() + 0.3 * (j as f64 - t).cos())
}

/// Max over the run of `‖u_input − u_linear‖∞`, relative to the max of `‖u_linear‖∞`.
fn compare<const N: usize, const I: usize>(seed: u64, steps: usize) -> f64 {
    let mut rng = Rng::from_state(seed);
    let (m, c, k, b) = random_system::<N, I>(&mut rng);
    let h = 0.01;
    let lin = Linear::<f64, _>::new(&m, &c, &k, h).unwrap();
    let inp = LinearInput::<f64, _, _>::new(&m, &c, &k, &b, h).unwrap();
    let u0 = SVector::<f64, N>::from_fn(|_, _| rng.uniform());
    let v0 = SVector::<f64, N>::from_fn(|_, _| rng.uniform());
    let w0 = input_at::<I>(0, h);
    let mut sl = lin.start(&u0, &v0, &(b * w0)).unwrap();
    let mut si = inp.start(&u0, &v0, &w0).unwrap();
    let (mut diff, mut peak) = (0.0f64, 0.0f64);
    for n in 1..=steps {
        let w = input_at::<I>(n, h);
        lin.step(&mut sl, &(b * w));
        inp.step(&mut si, &w);
        diff = diff.max((si.u() - sl.u()).amax());
        diff = diff.max((si.v() - sl.v()).amax() * h);
        peak = peak.max(sl.u().amax());
    }
    assert_eq!(si.steps(), steps as u64);
    diff / peak
}

#[test]
fn same_sequence_as_linear_fed_b_w() {
    let steps = 2000;
    let mut worst = 0.0f64;
    macro_rules! case {
        ($n:literal, $i:literal) => {
            for seed in 1..4u64 {
                let rel = compare::<$n, $i>(seed * 7919 + $n, steps);
                // Bound: 8 · n · N · ε, the worst case of linear growth (module docs).
                // Measured: worst 1.4e-15 over all cases (bound 4e-11 for N = 12): the
                // damped systems forget old rounding, so nothing accumulates.
                let bound = 8.0 * steps as f64 * $n as f64 * f64::EPSILON;
                assert!(
                    rel <= bound,
                    "N={} I={} seed {seed}: {rel:e} > {bound:e}",
                    $n,
                    $i
                );
                worst = worst.max(rel);
            }
        };
    }
    case!(2, 1);
    case!(3, 2);
    case!(5, 1);
    case!(6, 3);
    case!(8, 2);
    case!(12, 1);
    eprintln!("LinearInput vs Linear(p = B w), f64: worst relative difference {worst:e}");
}

/// The benchmark building under El Centro, both in `f32`: the same bound argument with
/// `ε = ε_f32`.
#[test]
fn base_excitation_f32_matches_linear() {
    let (m, c, k) = models::five_storey_building();
    let b = base_excitation(&m);
    let h = 0.02;
    let lin = Linear::<f32, 5>::from_rows_f32(m, c, k, h).unwrap();
    let inp = LinearInput::<f32, 5, 1>::from_rows_f32(m, c, k, b, h).unwrap();
    let bv = SVector::<f32, 5>::from_fn(|i, _| b[i][0] as f32);
    let ag = elcentro::AG_F32;
    let z = SVector::<f32, 5>::zeros();
    let mut sl = lin.start(&z, &z, &(bv * ag[0])).unwrap();
    let mut si = inp.start(&z, &z, &SVector::from([ag[0]])).unwrap();
    let (mut diff, mut peak) = (0.0f32, 0.0f32);
    for &a in &ag[1..] {
        lin.step(&mut sl, &(bv * a));
        inp.step(&mut si, &SVector::from([a]));
        diff = diff.max((si.u() - sl.u()).amax());
        peak = peak.max(sl.u().amax());
    }
    let rel = (diff / peak) as f64;
    // The two f32 steppers differ by the rounding of their operators (`G B` formed once vs
    // `G·(B a_g)` each step: a few ε_f32 relative) and of each step. The building is damped
    // (ξ = 5 %): a rounding error fades within about 1/(ξ ω₁ h) = 1/(0.05 · 9 · 0.02) ≈ 111
    // steps, so at most ~111 steps of rounding (each ≤ N ε for the N = 5 terms of a row)
    // accumulate: bound 111 · 5 · ε_f32 = 6.6e-5. Measured 4.0e-7.
    let bound = 111.0 * 5.0 * f32::EPSILON as f64;
    eprintln!("El Centro, f32: relative difference {rel:e} (bound {bound:e})");
    assert!(rel <= bound, "{rel:e} > {bound:e}");
    // …and the f32 run is a real run: peak roof drift of order centimetres.
    assert!(peak > 0.01 && peak < 1.0, "{peak}");
}

#[test]
fn const_and_runtime_constructors_agree_bit_for_bit() {
    let (m, c, k) = models::five_storey_building();
    let b = base_excitation(&m);
    static SYS: LinearInput<f32, 5, 1> = match LinearInput::from_rows_f32(
        models::five_storey_building().0,
        models::five_storey_building().1,
        models::five_storey_building().2,
        base_excitation(&models::five_storey_building().0),
        0.02,
    ) {
        Ok(s) => s,
        Err(e) => panic!("{}", e.as_str()),
    };
    // Both constructors take the f64 data (C is not f32-exact) and round once.
    let f = |a: [[f64; 5]; 5]| SMatrix::<f64, 5, 5>::from_fn(|i, j| a[i][j]);
    let c32 = c.map(|r| r.map(|x| x as f32 as f64));
    let rt = LinearInput::<f32, 5, 1>::new(
        &f(m),
        &f(c32),
        &f(k),
        &SMatrix::<f64, 5, 1>::from_fn(|i, _| b[i][0]),
        0.02,
    )
    .unwrap();
    let ct = LinearInput::<f32, 5, 1>::from_rows_f32(m, c32, k, b, 0.02).unwrap();
    assert_eq!(rt, ct);
    // The static one used the exact C; it differs from the rounded-C one, and equals a
    // fresh const evaluation.
    assert_eq!(
        SYS,
        LinearInput::<f32, 5, 1>::from_rows_f32(m, c, k, b, 0.02).unwrap()
    );
    // G·B really is G times B.
    let g = Linear::<f64, 5>::from_rows_f64(m, c, k, 0.02)
        .unwrap()
        .effective_inverse();
    let gb = LinearInput::<f64, 5, 1>::from_rows_f64(m, c, k, b, 0.02)
        .unwrap()
        .input_operator();
    let bm = SMatrix::<f64, 5, 1>::from_fn(|i, _| b[i][0]);
    assert!((g * bm - gb).amax() <= 1e-15 * gb.amax());
}

#[test]
fn errors_and_failed_step_leaves_state_unchanged() {
    let (m, c, k) = models::five_storey_building();
    let b = base_excitation(&m);
    let mut bad = b;
    bad[2][0] = f64::NAN;
    assert_eq!(
        LinearInput::<f64, 5, 1>::from_rows_f64(m, c, k, bad, 0.02),
        Err(Error::NonFiniteInput)
    );
    assert_eq!(
        LinearInput::<f64, 5, 1>::from_rows_f64(m, c, k, b, 0.0),
        Err(Error::InvalidTimeStep)
    );
    // Singular M with nonsingular M_eff: steps fine, start needs the acceleration.
    let z = [[0.0; 2]; 2];
    let sys = LinearInput::<f64, 2, 1>::from_rows_f64(
        z,
        z,
        [[2.0, -1.0], [-1.0, 1.0]],
        [[1.0], [0.0]],
        0.1,
    )
    .unwrap();
    let zero = SVector::<f64, 2>::zeros();
    assert_eq!(
        sys.start(&zero, &zero, &SVector::from([1.0])),
        Err(Error::SingularMass)
    );
    let sys = LinearInput::<f64, 5, 1>::from_rows_f64(m, c, k, b, 0.02).unwrap();
    let z5 = SVector::<f64, 5>::zeros();
    assert_eq!(
        sys.start(&z5, &z5, &SVector::from([f64::INFINITY])),
        Err(Error::NonFiniteInput)
    );
    let s = sys.start(&z5, &z5, &SVector::from([1.0])).unwrap();
    let w = |x: f64| SVector::from([x]);
    checks::refuses_non_finite_input(&sys, s, &w(2.0), &w(f64::NAN), &w(1.0));
}
