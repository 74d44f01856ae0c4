//! Bad input found by trying the crate as a new user would (issue 10): each case is a named
//! regression test. Every one got `Ok` with garbage before; each now gets a typed error, or
//! the right answer where the input was in fact fine.

use aemstep::nalgebra::{SMatrix, matrix, vector};
use aemstep::{
    Coefficients, Damping, Error, Exact, GeneralizedAlpha, Linear, LinearInput, Modal, Newmark,
    Stepper, Varying,
};

type M2 = SMatrix<f64, 2, 2>;

/// An effective matrix that is zero up to rounding: `K = −4M/h²` cancels `M` in
/// `M + (h²/4) K`. Judged against the size of its terms, not of the cancelled result, it
/// is singular for every constant-coefficient scheme (as `Varying` already judged it).
#[test]
fn effective_matrix_cancelled_to_rounding_is_singular() {
    let m = matrix![2.0, 0.3; 0.3, 1.0];
    let h = 0.011;
    let k = m * (-4.0 / (h * h));
    let c = M2::zeros();
    let want: Result<(), _> = Err(Error::SingularEffectiveMatrix);
    assert_eq!(Linear::<f64, 2>::new(&m, &c, &k, h).err(), want.err());
    assert_eq!(Linear::<f32, 2>::new(&m, &c, &k, h).err(), want.err());
    assert_eq!(
        Newmark::<f64, 2>::average_acceleration(&m, &c, &k, h).err(),
        want.err()
    );
    assert_eq!(
        GeneralizedAlpha::<f64, 2>::new(&m, &c, &k, h, 1.0).err(),
        want.err()
    );
    assert_eq!(
        LinearInput::<f64, 2, 2>::new(&m, &c, &k, &M2::identity(), h).err(),
        want.err()
    );
    let rows = |a: M2| [[a[(0, 0)], a[(0, 1)]], [a[(1, 0)], a[(1, 1)]]];
    assert_eq!(
        Linear::<f64, 2>::from_rows_f64(rows(m), rows(c), rows(k), h).err(),
        want.err()
    );
}

/// The eigen-solver with very large and very small stiffness: `K = s [[2, −1], [−1, 2]]`,
/// `M = I` has `ω² = (s, 3s)` for every `s`; at `s = 1e160` the sums of squares overflowed
/// and at `s = 1e-165` they underflowed, and the solver returned `(2s, 2s)` with identity
/// modes. With power-of-two scaling every finite SPD pair gets its modes (to a few ulps)
/// or a typed error.
#[test]
fn eigen_solver_scales_large_and_small_stiffness() {
    for s in [1e160, 1e-165, 1e300, 1e-300, 1.0] {
        let k = matrix![2.0, -1.0; -1.0, 2.0] * s;
        let sys = Modal::<f64, 2, 2, 1, 1>::new(
            &M2::identity(),
            &k,
            &Damping::None,
            &SMatrix::repeat(1.0),
            &SMatrix::repeat(1.0),
            0.01,
        )
        .unwrap();
        let w2 = sys.frequencies().map(|w| w * w / s);
        assert!(
            (w2[0] - 1.0).abs() < 8.0 * f64::EPSILON,
            "s = {s:e}: {w2:?}"
        );
        assert!(
            (w2[1] - 3.0).abs() < 24.0 * f64::EPSILON,
            "s = {s:e}: {w2:?}"
        );
        // The modes are (1, 1)/√2 and (1, −1)/√2, not the identity.
        let phi = sys.mode_shapes();
        let r = core::f64::consts::FRAC_1_SQRT_2;
        assert!((phi[(0, 0)].abs() - r).abs() < 4.0 * f64::EPSILON, "{phi}");
        assert!((phi[(1, 1)].abs() - r).abs() < 4.0 * f64::EPSILON, "{phi}");
    }
    // In f32, ω² = 3e160 does not fit: a typed error, not ∞.
    let k = matrix![2.0, -1.0; -1.0, 2.0] * 1e160;
    assert_eq!(
        Modal::<f32, 2, 2, 1, 1>::new(
            &M2::identity(),
            &k,
            &Damping::None,
            &SMatrix::repeat(1.0),
            &SMatrix::repeat(1.0),
            0.01
        )
        .err(),
        Some(Error::OperatorOverflow)
    );
}

/// Operators that overflow when rounded to `f32`: `M = 1e-39` gives `G = 1e39 > f32::MAX`.
/// Checked after rounding to `T`, in every constructor.
#[test]
fn f32_operators_that_overflow_are_rejected() {
    let (m, z) = (matrix![1e-39], matrix![0.0]);
    let want = Some(Error::OperatorOverflow);
    assert_eq!(Linear::<f32, 1>::new(&m, &z, &z, 0.01).err(), want);
    assert_eq!(
        Linear::<f32, 1>::from_rows_f32([[1e-39]], [[0.0]], [[0.0]], 0.01).err(),
        want
    );
    assert_eq!(
        LinearInput::<f32, 1, 1>::new(&m, &z, &z, &matrix![1.0], 0.01).err(),
        want
    );
    assert_eq!(
        Newmark::<f32, 1>::average_acceleration(&m, &z, &z, 0.01).err(),
        want
    );
    assert_eq!(
        GeneralizedAlpha::<f32, 1>::new(&m, &z, &z, 0.01, 0.8).err(),
        want
    );
    // `Exact` reports its overflow as overflow (it used to say NonFiniteInput).
    assert_eq!(
        Exact::<f32, 1>::new(&m, &z, &matrix![1.0], 0.01).err(),
        want
    );
    // The same data is fine in f64.
    assert!(Linear::<f64, 1>::new(&m, &z, &z, 0.01).is_ok());
}

/// An exactly invertible but badly scaled `M = diag(1e16, 1)` is not singular: pivots are
/// judged row by row against the terms of the row.
#[test]
fn badly_scaled_but_regular_mass_is_not_singular() {
    let m = matrix![1e16, 0.0; 0.0, 1.0];
    let (c, k) = (M2::zeros(), M2::identity());
    let sys = Linear::<f64, 2>::new(&m, &c, &k, 0.01).unwrap();
    // Row-equilibrated: perfectly conditioned.
    assert!(sys.condition() < 1.0 + 1e-12, "{}", sys.condition());
    let s = sys
        .start(&vector![0.0, 0.0], &vector![0.0, 0.0], &vector![1.0, 1.0])
        .unwrap();
    assert_eq!(*s.a(), vector![1e-16, 1.0]);
    // The time-varying stepper judges its per-step matrix the same way.
    let coeffs = move |_t: f64| Coefficients {
        mass: m,
        damping: c,
        stiffness: k,
    };
    let st = Varying::<f64, 2>::new(0.01).unwrap();
    let mut s = st
        .start(
            &coeffs,
            &vector![0.0, 0.0],
            &vector![0.0, 0.0],
            &vector![1.0, 1.0],
        )
        .unwrap();
    st.try_step(&coeffs, &mut s, &vector![1.0, 1.0]).unwrap();
    // …and a cancelled one as singular, at the step it happens.
    let h = 0.011;
    let mm = matrix![2.0, 0.3; 0.3, 1.0];
    let cancel = move |_t: f64| Coefficients {
        mass: mm,
        damping: M2::zeros(),
        stiffness: mm * (-4.0 / (h * h)),
    };
    let st = Varying::<f64, 2>::new(h).unwrap();
    let mut s = st
        .start(
            &cancel,
            &vector![0.0, 0.0],
            &vector![0.0, 0.0],
            &vector![1.0, 1.0],
        )
        .unwrap();
    assert_eq!(
        st.try_step(&cancel, &mut s, &vector![1.0, 1.0]),
        Err(Error::SingularEffectiveMatrixAtStep { step: 1 })
    );
}

/// The condition number the stepper reports grows as the effective matrix nears
/// singularity: for `M = [[1, 1], [1, 1 + δ]]`, `C = K = 0`, `κ₁ = 4(1 + δ)/δ` of the
/// row-equilibrated matrix; it is rejected once `δ` reaches rounding.
#[test]
fn condition_estimate_tracks_the_distance_to_singularity() {
    let z = M2::zeros();
    for d in [1e-2, 1e-6, 1e-10, 1e-14] {
        let m = matrix![1.0, 1.0; 1.0, 1.0 + d];
        let sys = Linear::<f64, 2>::new(&m, &z, &z, 0.01).unwrap();
        let k = sys.condition();
        // Exact, with D = diag(1, 1 + δ) (the row scales): ‖D⁻¹A‖₁ = 2 and
        // A⁻¹D = [[1 + δ, −(1 + δ)], [−1, 1 + δ]]/δ, ‖A⁻¹D‖₁ = (2 + 2δ)/δ: κ = 4(1 + δ)/δ.
        let exact = 4.0 * (1.0 + d) / d;
        // The computed inverse is accurate to about κ ε relative, so κ is too.
        let rel = (k / exact - 1.0).abs();
        eprintln!("δ = {d:e}: κ {k:e}, relative error {rel:e}");
        assert!(
            rel < 4.0 * f64::EPSILON * exact,
            "δ = {d:e}: {k:e} vs {exact:e}"
        );
    }
    let m = matrix![1.0, 1.0; 1.0, 1.0 + 1e-17];
    assert_eq!(
        Linear::<f64, 2>::new(&m, &z, &z, 0.01).err(),
        Some(Error::SingularEffectiveMatrix)
    );
}

/// A NaN load is `NonFiniteInput` from every stepper's checked step, and the state is
/// kept bit for bit.
#[test]
fn nan_load_is_the_same_error_everywhere() {
    let (m, c, k, h) = (matrix![1.0], matrix![0.1], matrix![4.0], 0.01);
    let nan = vector![f64::NAN];
    fn check<S: Stepper<f64, 1>>(sys: &S, w0: S::Input, bad: S::Input) {
        let z = vector![0.0];
        let mut s = sys.start(&vector![1.0], &z, &w0).unwrap();
        let before = format!("{:?}", sys.full_state(&s));
        assert_eq!(sys.try_step(&mut s, &bad), Err(Error::NonFiniteInput));
        assert_eq!(format!("{:?}", sys.full_state(&s)), before);
    }
    check(
        &Linear::<f64, 1>::new(&m, &c, &k, h).unwrap(),
        vector![0.0],
        nan,
    );
    check(
        &Linear::<f64, 1>::new(&m, &c, &k, h).unwrap().a_form(),
        vector![0.0],
        nan,
    );
    check(
        &Newmark::<f64, 1>::average_acceleration(&m, &c, &k, h).unwrap(),
        vector![0.0],
        nan,
    );
    check(
        &GeneralizedAlpha::<f64, 1>::new(&m, &c, &k, h, 0.8).unwrap(),
        vector![0.0],
        nan,
    );
    check(
        &Exact::<f64, 1>::new(&m, &c, &k, h).unwrap(),
        vector![0.0],
        nan,
    );
    check(
        &LinearInput::<f64, 1, 1>::new(&m, &c, &k, &matrix![1.0], h).unwrap(),
        vector![0.0],
        nan,
    );
    check(
        &Modal::<f64, 1, 1, 1, 1>::new(&m, &k, &Damping::None, &matrix![1.0], &matrix![1.0], h)
            .unwrap(),
        vector![0.0],
        nan,
    );
}

/// Operators that underflow (found by the property tests of `tests/properties.rs`): with
/// `M = 1e212`, `K = 1e-112`, `h = 1e99`, `G K = M_eff⁻¹ K ≈ 1e-324` rounds to zero in
/// `f64`, and a stepper built from it returned `q = 0` instead of `−G K û ≈ −1e-225`. Now
/// `OperatorUnderflow` from every Newmark-family build, in `f64` and, for an operator
/// subnormal in `f32`, in `f32`; ordinary data still build and step right. (In `f32` the
/// first data are refused earlier: `M = 1e212` does not fit `f32`.)
#[test]
fn operators_that_underflow_are_rejected() {
    let (m, c, k, h) = (matrix![1e212], matrix![0.0], matrix![1e-112], 1e99);
    let want = Some(Error::OperatorUnderflow);
    assert_eq!(Linear::<f64, 1>::new(&m, &c, &k, h).err(), want);
    assert_eq!(
        Newmark::<f64, 1>::average_acceleration(&m, &c, &k, h).err(),
        want
    );
    let b = matrix![1.0];
    assert_eq!(LinearInput::<f64, 1, 1>::new(&m, &c, &k, &b, h).err(), want);
    // f32: G = 1/M_eff with M_eff = 1e39 rounds to a subnormal f32 (1e-39 < 1.2e-38).
    let m32 = matrix![1e39];
    assert_eq!(
        Linear::<f32, 1>::new(&m32, &matrix![0.0], &matrix![1.0], 0.01).err(),
        Some(Error::OperatorUnderflow)
    );
    // Ordinary data: accepted, and the step agrees with the closed form of the undamped
    // oscillator.
    let sys = Linear::<f64, 1>::new(&matrix![1.0], &matrix![0.0], &matrix![1.0], 0.01)
        .expect("ordinary data");
    let mut s = sys
        .start(&vector![1.0], &vector![0.0], &vector![0.0])
        .expect("start");
    sys.try_step(&mut s, &vector![0.0]).expect("step");
    // One AEM step of u'' + u = 0: u1 = (1 − h²/4)/(1 + h²/4).
    let u1 = (1.0 - 0.25e-4) / (1.0 + 0.25e-4);
    assert!((s.u()[0] - u1).abs() <= 4.0 * f64::EPSILON);
}

// Found by fuzzing (`scripts/fuzz.sh`; the inputs in `fuzz/regressions/`): each got `Ok`
// with non-finite or vanishing operators before.

/// A time step that is fine in `f64` but not in `f32`: `h = 1e58` overflows `f32` and
/// `h = 1e-30` has `h²/4` round to zero. An `f32` stepper built from either had infinite or
/// vanishing kinematics (the fuzzer found `AForm` blocks of `∞`); now every `f32`
/// constructor says `InvalidTimeStep`, the `f64` ones keep them.
#[test]
fn f32_time_step_that_does_not_fit_is_invalid() {
    use aemstep::{CompensatedLinear, NewtonSettings, Nonlinear};
    let (m, z, k) = (matrix![1.0], matrix![0.0], matrix![1.0]);
    let want = Some(Error::InvalidTimeStep);
    for h in [1e58, 1e-30] {
        assert_eq!(
            Linear::<f32, 1>::new(&m, &z, &k, h).err(),
            want,
            "h = {h:e}"
        );
        assert_eq!(
            Linear::<f32, 1>::from_rows_f32([[1.0]], [[0.0]], [[1.0]], h).err(),
            want
        );
        assert_eq!(CompensatedLinear::<f32, 1>::new(&m, &z, &k, h).err(), want);
        assert_eq!(
            LinearInput::<f32, 1, 1>::new(&m, &z, &k, &matrix![1.0], h).err(),
            want
        );
        assert_eq!(
            Newmark::<f32, 1>::average_acceleration(&m, &z, &k, h).err(),
            want
        );
        assert_eq!(
            GeneralizedAlpha::<f32, 1>::new(&m, &z, &k, h, 0.8).err(),
            want
        );
        assert_eq!(Exact::<f32, 1>::new(&m, &z, &k, h).err(), want);
        assert_eq!(
            Modal::<f32, 1, 1, 1, 1>::new(&m, &k, &Damping::None, &m, &m, h).err(),
            want
        );
        assert_eq!(
            Nonlinear::<f32, 1>::new(h, NewtonSettings::default()).err(),
            want
        );
        assert_eq!(Varying::<f32, 1>::new(h).err(), want);
        // The same h in f64: a valid step.
        let sys = Linear::<f64, 1>::new(&m, &z, &k, h).unwrap();
        assert_eq!(sys.time_step(), h);
        assert!(Varying::<f64, 1>::new(h).is_ok());
    }
}

/// Newmark coefficients that overflow although `h²` does not: `β = 1e300`, `h = 1e10` has
/// `β h² = ∞`. With `K = 0` no operator showed it and the stepper was built; now it is an
/// overflow (and `β = 1e30` fits `f64` but not `f32`).
#[test]
fn newmark_coefficients_that_overflow_are_rejected() {
    let (m, z) = (matrix![1.0], matrix![0.0]);
    assert_eq!(
        Newmark::<f64, 1>::new(&m, &z, &z, 1e10, 1e300, 0.5).err(),
        Some(Error::OperatorOverflow)
    );
    assert_eq!(
        Newmark::<f32, 1>::new(&m, &z, &z, 1.0, 1e39, 0.5).err(),
        Some(Error::OperatorOverflow)
    );
    assert!(Newmark::<f64, 1>::new(&m, &z, &z, 1.0, 1e39, 0.5).is_ok());
}

/// Hysteretic laws and buildings whose coefficients do not fit `f32`: `Bilinear::<f32>`
/// with `k = 1.6e293` had an infinite stiffness; now an overflow, as a Bouc–Wen `k/f_y` of
/// `1e41`, a `1/v_r` of `1e40` and a floor mass of `1e39` are.
#[test]
fn hysteresis_coefficients_that_overflow_f32_are_rejected() {
    use aemstep::hysteresis::{Bilinear, BoucWen, Friction, ShearBuilding};
    let want = Some(Error::OperatorOverflow);
    assert_eq!(Bilinear::<f32>::new(1.6e293, 1e2, 0.0).err(), want);
    assert!(Bilinear::<f64>::new(1.6e293, 1e2, 0.0).is_ok());
    assert_eq!(
        BoucWen::<f32>::new(1e39, 1e-2, 0.05, 0.5, 0.5, 1.0).err(),
        want
    );
    assert_eq!(Friction::<f32>::new(1.0, 1e-40).err(), want);
    let law = Bilinear::<f32>::new(1e8, 1e5, 0.05).unwrap();
    assert_eq!(
        ShearBuilding::<f32, _, 2>::new([1e39, 1.0], [law; 2], &[[0.0; 2]; 2]).err(),
        want
    );
    // f64: huge but finite coefficients, and a coefficient that overflows f64 itself.
    let law64 = Bilinear::<f64>::new(1e8, 1e5, 0.05).unwrap();
    assert!(ShearBuilding::<f64, _, 2>::new([1e39, 1.0], [law64; 2], &[[0.0; 2]; 2]).is_ok());
    assert_eq!(Bilinear::<f64>::new(1e308, 1.0, 0.99).err(), want);
}

/// A reduced stepper's start from known values can overflow in `f32`: the projection
/// `Φᵀ M u` of `u = (100, 100)` with `M = K = 1e74 I` is about `1.4e39`. That is
/// `NonFiniteState` (documented now), and a start from rest still works. (The data first
/// found, `M = 1e76 I`, `K = I`, has `ω² = 1e-76`, which flushes to zero in `f32`: that
/// build is `OperatorUnderflow` now, as `Linear<f32>`'s.)
#[test]
fn modal_f32_projection_overflow_is_non_finite_state() {
    let m = SMatrix::<f64, 2, 2>::identity() * 1e74;
    let k = m;
    let sys = Modal::<f32, 2, 2, 1, 1>::new(
        &m,
        &k,
        &Damping::None,
        &SMatrix::repeat(1.0),
        &SMatrix::repeat(1.0),
        0.01,
    )
    .unwrap();
    let (hundred, z) = (vector![100.0f32, 100.0], vector![0.0f32, 0.0]);
    assert_eq!(
        sys.start_with_acceleration(&hundred, &z, &z).err(),
        Some(Error::NonFiniteState)
    );
    assert!(sys.start_with_acceleration(&z, &z, &z).is_ok());
    let m = SMatrix::<f64, 2, 2>::identity() * 1e76;
    let k = SMatrix::<f64, 2, 2>::identity();
    let (b, y) = (SMatrix::repeat(1.0), SMatrix::repeat(1.0));
    assert_eq!(
        Modal::<f32, 2, 2, 1, 1>::new(&m, &k, &Damping::None, &b, &y, 0.01).err(),
        Some(Error::OperatorUnderflow)
    );
}

/// Bouc–Wen with a large exponent (`n = 951`, β = 1, γ = 0.5) at a step of 3 `u_y` from
/// rest: the unsafeguarded Newton's first iterate had `|z|ⁿ = ∞` and the force came out
/// NaN (the stepper then refused every such step). Newton safeguarded by bisection on its
/// bracket converges: the force is finite and the hysteretic variable solves its update.
#[test]
fn bouc_wen_large_exponent_converges() {
    use aemstep::hysteresis::{BoucWen, Law};
    let (k, fy, alpha, n) = (1e9, 1e7, 0.99, 951.2660600471733);
    let law = BoucWen::<f64>::new(k, fy, alpha, 1.0, 0.5, n).unwrap();
    let uy = fy / k;
    for d in [2.98797607421875 * uy, -4.9493408203125 * uy, 0.5 * uy] {
        let t = law.trial(&law.initial_history(), d, 1.0);
        assert!(t.force.is_finite() && t.stiffness.is_finite(), "{t:?}");
        // z solves z = (Δ/2u_y)(g(0) + g(z)), g(z) = 1 − |z|ⁿ (β + γ) loading.
        let z = t.history.z;
        // Judged as the solve stops: the Newton correction `r/r'` within `4ε |z|` (its
        // tolerance), plus the rounding of `r` itself (`z ≈ 1`, `|c| ≤ 2.5`, `|g| ≤ 2`: a
        // few ε) over the slope `r' ≥ 1` — 8ε |z| in all. (The slope is ~3500 here, so
        // `r` itself is ~1e-12 at the root's neighbouring numbers.)
        let c = 0.5 * (d / uy);
        let g = |z: f64| 1.0 - z.abs().powf(n) * 1.5;
        let r = z - c * (1.0 + g(z));
        let slope = 1.0 + c * n * z.abs().powf(n - 1.0) * z.signum() * 1.5;
        assert!(
            (r / slope).abs() <= 8.0 * f64::EPSILON * z.abs(),
            "d = {d:e}: z = {z}, residual {r:e}, slope {slope:e}"
        );
    }
}

/// A response-spectrum bank whose operators are not finite: period `1.06e-109` s at
/// `dt = 1e-4` (`ω dt ≈ 6e105`) gave NaN in the exact map over `dt`, and the bank stepped
/// every sample to NaN; in `f32`, period `1e-20` s gives `ω² ≈ 4e41`, beyond `f32`. Both
/// are `OperatorOverflow` now.
#[test]
fn spectrum_bank_operators_that_are_not_finite_are_rejected() {
    use aemstep::spectrum::Bank;
    let periods = [
        1.0644899600020377e-109,
        5.232991146814947,
        999.7892142570423,
    ];
    assert_eq!(
        Bank::<f64, 3>::new(periods, [0.0; 3], 1e-4).err(),
        Some(Error::OperatorOverflow)
    );
    assert_eq!(
        Bank::<f32, 1>::new([1e-20], [0.05], 0.01).err(),
        Some(Error::OperatorOverflow)
    );
    // The AEM's sub-step in closed form stays finite and bounded there (formed from unit
    // inputs it was NaN, and at ωh ≈ 5e14 finite but off by 1e13: 10 m/s² stepped to a
    // displacement of 1e98).
    let aem = Bank::<f64, 3>::with(
        periods,
        [0.0; 3],
        1e-4,
        aemstep::spectrum::Scheme::Aem,
        aemstep::spectrum::Substeps::AUTO,
    )
    .unwrap();
    let mut r = aem.at_rest();
    for _ in 0..12 {
        aem.step(&mut r, -10.0);
    }
    assert!(
        r.sd().iter().all(|x| x.is_finite() && *x < 1e3),
        "{:?}",
        r.sd()
    );
    let stiff = Bank::<f64, 3>::with(
        [
            2.220446049250313e-16,
            0.6660419550143868,
            0.6660419550143868,
        ],
        [0.18235015869140625; 3],
        1.643114108127686e-2,
        aemstep::spectrum::Scheme::Aem,
        aemstep::spectrum::Substeps::Fixed(1),
    )
    .unwrap();
    let mut r = stiff.at_rest();
    for a in [2.15667724609375, -10.0, -10.0, -10.0, -10.0] {
        stiff.step(&mut r, a);
    }
    assert!(
        r.sd()[0] < 1e-20 && r.sa().iter().all(|x| *x < 1e3),
        "{r:?}"
    );
    // f64 holds ω² = 4e41.
    assert!(
        Bank::<f64, 1>::with(
            [1e-20],
            [0.05],
            0.01,
            aemstep::spectrum::Scheme::Aem,
            aemstep::spectrum::Substeps::Fixed(1)
        )
        .is_ok()
    );
}

/// The paper's literal form can overflow where the stepper does not: `M = −9.7e-252`,
/// `C = K = 0`, `h = 1e147` give `G = −1e251` (finite) but the block `(h/2) G = ∞`.
/// `try_a_form` reports it; `a_form` documents it.
#[test]
fn a_form_blocks_that_overflow_are_reported() {
    let z = matrix![0.0];
    let sys = Linear::<f64, 1>::new(&matrix![-9.715100097656247e-252], &z, &z, 1e147).unwrap();
    assert!(sys.effective_inverse()[(0, 0)].is_finite());
    assert_eq!(sys.try_a_form().err(), Some(Error::OperatorOverflow));
    assert!(!sys.a_form().b_block(1).unwrap()[(0, 0)].is_finite());
    let ok = Linear::<f64, 1>::new(&matrix![1.0], &z, &matrix![4.0], 0.01).unwrap();
    assert_eq!(
        format!("{:?}", ok.try_a_form().unwrap()),
        format!("{:?}", ok.a_form())
    );
}

/// Bouc–Wen in `f32` with `n = 984`: the Newton slope `1 − c ∂g/∂z` overflowed to `∞`, the
/// step `r/∞ = 0` looked converged at `z = −1.09` (not the root near `−1.003`), and the next
/// trial's stiffness was `−∞`. A slope that overflows is now a bisection step.
#[test]
fn bouc_wen_overflowing_slope_is_not_convergence() {
    use aemstep::hysteresis::{BoucWen, Law};
    let law =
        BoucWen::<f32>::new(1e9, 1e2, 0.0, 0.1, 9.796142578125e-3, 983.8988194023956).unwrap();
    let t = law.trial(&law.initial_history(), -1e-6, -10.0);
    let z = t.history.z;
    assert!(t.force.is_finite() && z > -1.01 && z < -1.0, "{t:?}");
    let again = law.trial(&t.history, -1e-6, -10.0);
    assert!(
        again.force.is_finite() && again.stiffness.is_finite(),
        "{again:?}"
    );
}

/// An observer in `f32` of a model whose time step does not fit `f32` (`h = 1e147`): its
/// `time_step()` was `∞`; now `InvalidTimeStep`, as for every `f32` stepper.
#[test]
fn f32_observer_of_a_model_with_an_f64_only_time_step_is_invalid() {
    use aemstep::observer::{Observer, Outputs, StateSpace};
    let m = SMatrix::<f64, 2, 2>::identity();
    let k = m * 4.0;
    for h in [1e147, 0.01] {
        let ss =
            StateSpace::<2, 4, 1>::aem(&m, &M2::zeros(), &k, &SMatrix::repeat(1.0), h).unwrap();
        let meas = ss
            .outputs(&Outputs::displacements(Outputs::<2, 1, 1>::select([0])))
            .unwrap();
        let r32 = Observer::<f32, 4, 1, 1>::new(&ss, &meas, &SMatrix::zeros());
        let r64 = Observer::<f64, 4, 1, 1>::new(&ss, &meas, &SMatrix::zeros());
        if h > 1.0 {
            assert_eq!(r32.err(), Some(Error::InvalidTimeStep));
        } else {
            assert!(r32.is_ok());
        }
        assert!(r64.is_ok());
    }
}

/// Bouc–Wen with a huge `β` (`3e94`, so `z_max = 6e-48`): the inner solve's tolerance was
/// absolute (`4ε`), it stopped at `z = 3e-16`, 1e31 times `z_max`, and the next trial
/// overflowed to a NaN force. The tolerance is now relative to `min(1, z_max)`.
#[test]
fn bouc_wen_tiny_z_max_is_resolved() {
    use aemstep::hysteresis::{BoucWen, Law};
    let (beta, gamma) = (2.989215087890625e94, -0.5);
    let law = BoucWen::<f64>::new(1e9, 1e7, 0.99, beta, gamma, 2.0).unwrap();
    let uy = 1e-2;
    let t1 = law.trial(&law.initial_history(), 2.9290771484375 * uy, -10.0);
    // The trapezoidal update saturates at √2 z_max for n = 2 (z = c (g(0) + g(z)), c ≫ 1):
    // z solves it to rounding, on z's own scale.
    let (z, z_max) = (t1.history.z, (beta + gamma).powf(-0.5));
    let c = 0.5 * 2.9290771484375;
    let r = z - c * (2.0 - z * z * (beta + gamma));
    let slope = 1.0 + 2.0 * c * z * (beta + gamma);
    assert!(
        z > 0.0 && z <= 1.4143 * z_max && (r / slope).abs() <= 1e-12 * z,
        "{t1:?}, r = {r:e}"
    );
    let t2 = law.trial(&t1.history, 2.98736572265625 * uy, -10.0);
    assert!(t2.force.is_finite() && t2.stiffness.is_finite(), "{t2:?}");
}

/// A start with a non-finite initial value is `NonFiniteInput` from every stepper: the
/// full-order ones said `SingularMass` first when `M` was singular too (`Nonlinear`,
/// `Modal`, `Varying` checked the input first).
#[test]
fn non_finite_start_is_non_finite_input_before_singular_mass() {
    let (m, z, k) = (M2::zeros(), M2::zeros(), M2::identity());
    let sys = Linear::<f64, 2>::new(&m, &z, &k, 0.01).unwrap();
    let nan = vector![f64::NAN, 0.0];
    let zero = vector![0.0, 0.0];
    assert_eq!(
        sys.start(&nan, &zero, &zero).err(),
        Some(Error::NonFiniteInput)
    );
    assert_eq!(
        sys.start(&zero, &zero, &zero).err(),
        Some(Error::SingularMass)
    );
}

/// The exact response-spectrum map over `dt` for a period of `2e-22` s at `dt = 1e-4`
/// (`ω dt ≈ 3e18`): finite, but `uu = 6e134` where an oscillator's map is bounded by 1 —
/// the matrix exponential's squarings amplified rounding by `ω dt`. Rejected now
/// (`OperatorOverflow`); the AEM's closed form is bounded there.
#[test]
fn spectrum_exact_map_that_is_not_bounded_is_rejected() {
    use aemstep::spectrum::{Bank, Scheme, Substeps};
    let periods = [2.117582368135751e-22, 6.94091796875, 7.602937936467169];
    assert_eq!(
        Bank::<f64, 3>::new(periods, [0.0; 3], 1e-4).err(),
        Some(Error::OperatorOverflow)
    );
    assert!(Bank::<f64, 3>::with(periods, [0.0; 3], 1e-4, Scheme::Aem, Substeps::AUTO).is_ok());
    // Ordinary banks are untouched.
    assert!(Bank::<f64, 3>::new([0.02, 1.0, 10.0], [0.05; 3], 0.02).is_ok());
}

/// A steady-state Kalman gain for a model with an unobservable marginal mode (two free
/// masses, only the sum of their displacements measured, process noise on every state):
/// the covariance grows without bound, yet the doubling algorithm stopped at a "solution"
/// with diagonal entries of `−4e10` and returned it. Not a covariance: now
/// `RiccatiNotConverged`, as documented for an undetectable model.
#[test]
fn riccati_solution_that_is_not_a_covariance_is_rejected() {
    use aemstep::observer::{Outputs, StateSpace, SteadyState};
    let m = matrix![1.7976931348623157e308, 0.0; 0.0, -2.1559570312499998e-48];
    let ss = StateSpace::<2, 4, 1>::exact(
        &m,
        &M2::zeros(),
        &M2::zeros(),
        &matrix![1.0; 0.0],
        1.4508452551555398e-1,
    )
    .unwrap();
    let mut out = Outputs::<2, 1, 2>::zero();
    out.u = [[-10.0, -10.0], [-10.0, -10.0]];
    let meas = ss.outputs(&out).unwrap();
    let q = SMatrix::<f64, 4, 4>::identity() * 1e-6;
    let r = SMatrix::<f64, 2, 2>::identity() * 1e-6;
    assert_eq!(
        SteadyState::new(&ss, &meas, &q, &r).err(),
        Some(Error::RiccatiNotConverged)
    );
}

/// A measurement-noise covariance singular to rounding (relative determinant `−3e-21`,
/// entries near 1e-272; found by fuzzing) passed `Kalman::new`'s Cholesky test and failed
/// `SteadyState`'s LU: the same `R` got `Ok` from one and `InvalidCovariance` from the
/// other. Definiteness needs both factorizations now: `InvalidCovariance` from each, and a
/// well-conditioned `R` at that scale still passes both.
#[test]
fn covariance_singular_to_rounding_is_invalid_for_every_observer() {
    use aemstep::observer::{Kalman, Outputs, StateSpace, SteadyState};
    let ss = StateSpace::<2, 4, 1>::aem(
        &(M2::identity() * 2.0),
        &M2::zeros(),
        &(M2::identity() * 3.0),
        &matrix![1.0; 0.0],
        0.1,
    )
    .unwrap();
    let meas = ss
        .outputs(&Outputs::displacements(Outputs::<2, 1, 2>::select([0, 1])))
        .unwrap();
    let q = SMatrix::<f64, 4, 4>::zeros();
    let r = matrix![9.95123147964477e-273, 9.975281506776804e-273;
                    9.975281506776804e-273, 9.99938965775072e-273];
    assert_eq!(
        Kalman::<f64, 4, 1, 2>::new(&ss, &meas, &q, &r).err(),
        Some(Error::InvalidCovariance)
    );
    assert_eq!(
        SteadyState::new(&ss, &meas, &q, &r).err(),
        Some(Error::InvalidCovariance)
    );
    let well = M2::identity() * 1e-272;
    assert!(Kalman::<f64, 4, 1, 2>::new(&ss, &meas, &q, &well).is_ok());
}

/// Friction with `v_r = 1.25e-308`: `1/v_r` fits `f64` but `f_s/v_r` does not, and the
/// trial's damping `(f_s/v_r)(1 − tanh²)` was `∞ · 0 = NaN`. Now `OperatorOverflow`.
#[test]
fn friction_damping_coefficient_that_overflows_is_rejected() {
    use aemstep::hysteresis::Friction;
    assert_eq!(
        Friction::<f64>::new(143777.64739990234, 1.2510781e-308).err(),
        Some(Error::OperatorOverflow)
    );
    assert!(Friction::<f64>::new(1e5, 1e-3).is_ok());
}

/// One range check for every build (`linalg::fits`, issue 10's review): generalized-α, the
/// exact scheme and modal reduction checked only for overflow, so an operator flushed to
/// zero or subnormal in `T` was accepted where the Newmark family says `OperatorUnderflow`.
/// Each case is derived by hand: the operator's size against `MIN_POSITIVE` of the type.
#[test]
fn every_build_rejects_operators_that_underflow() {
    let want = Some(Error::OperatorUnderflow);
    // f64: G K = K / ((1 − α_m) M + …) ≈ 1e-112 / 1e212 = 1e-324, below f64's subnormals.
    let (m, c, k, h) = (matrix![1e212], matrix![0.0], matrix![1e-112], 1e99);
    assert_eq!(
        GeneralizedAlpha::<f64, 1>::new(&m, &c, &k, h, 0.8).err(),
        want
    );
    assert_eq!(
        GeneralizedAlpha::<f64, 1>::hht(&m, &c, &k, h, -0.1).err(),
        want
    );
    // Exact, f32: M = 1e30, h = 1e-10: the load reaches v through Γ₂/h ≈ h/(2M) = 5e-41,
    // subnormal in f32 (1.18e-38); in f64 it is normal and the build succeeds.
    let (m, z, k) = (matrix![1e30], matrix![0.0], matrix![1.0]);
    assert_eq!(Exact::<f32, 1>::new(&m, &z, &k, 1e-10).err(), want);
    assert!(Exact::<f64, 1>::new(&m, &z, &k, 1e-10).is_ok());
    // Modal, f32: M = 1, K = 1e-40: ω² = 1e-40 is subnormal in f32 (as `Linear<f32>`'s
    // G K); in f64 it is normal.
    let (one, k) = (matrix![1.0], matrix![1e-40]);
    let modal32 = Modal::<f32, 1, 1, 1, 1>::new(&one, &k, &Damping::None, &one, &one, 0.01);
    assert_eq!(modal32.err(), want);
    assert_eq!(
        Linear::<f32, 1>::new(&one, &matrix![0.0], &k, 0.01).err(),
        want
    );
    assert!(Modal::<f64, 1, 1, 1, 1>::new(&one, &k, &Damping::None, &one, &one, 0.01).is_ok());
    // Ordinary data still build in every scheme.
    let k = matrix![4.0];
    assert!(GeneralizedAlpha::<f32, 1>::new(&one, &z, &k, 0.01, 0.8).is_ok());
    assert!(Exact::<f32, 1>::new(&one, &z, &k, 0.01).is_ok());
    assert!(Modal::<f32, 1, 1, 1, 1>::new(&one, &k, &Damping::None, &one, &one, 0.01).is_ok());
}

/// Bouc–Wen with `β = 8.5e199`, `γ = 1/2`, `n = 2` (`z_max = 1.1e-100`) at a step of
/// `−3.18 u_y` from rest: the root `z ≈ −√2 z_max` lies 1e100 below the predictor `−3.18`,
/// and bisection in value needed about 380 halvings to reach it to `4ε` — beyond the
/// budget of 200: the force was NaN. Bisection in the ordering of the numbers reaches any
/// scale within 64 halvings: `z` solves its update to the solve's tolerance.
#[test]
fn bouc_wen_root_100_orders_below_its_bracket_is_resolved() {
    use aemstep::hysteresis::{BoucWen, Law};
    let (k, fy, alpha, beta, gamma) = (8.050498138213321, 1e7, 0.99, 8.48062133789063e199, 0.5);
    let law = BoucWen::<f64>::new(k, fy, alpha, beta, gamma, 2.0).unwrap();
    let uy = fy / k;
    let x = -3.17657470703125;
    let t = law.trial(&law.initial_history(), x * uy, -10.0);
    assert!(t.force.is_finite() && t.stiffness.is_finite(), "{t:?}");
    // z = c (g(0) + g(z)), g(z) = 1 − z² (β + γ) on the loading branch (z < 0, step < 0);
    // judged as the solve stops: the Newton correction r/r′ within 4ε |z| (its tolerance)
    // plus the rounding of r (a few ε |z| over the slope r′ ≥ 1): 8ε |z|.
    let (z, c, bg) = (t.history.z, 0.5 * x, beta + gamma);
    let r = z - c * (2.0 - z * z * bg);
    let slope = 1.0 + 2.0 * c * z * bg;
    let z_max = bg.powf(-0.5);
    assert!(
        z < 0.0 && z.abs() <= 2f64.sqrt() * z_max * (1.0 + 4.0 * f64::EPSILON),
        "z = {z:e}, z_max = {z_max:e}"
    );
    assert!((r / slope).abs() <= 8.0 * f64::EPSILON * z.abs(), "{r:e}");
    // The path goes on (the fuzzer's next deformations, −10 u_y): finite.
    let t2 = law.trial(&t.history, -10.0 * uy, -10.0);
    assert!(t2.force.is_finite() && t2.stiffness.is_finite(), "{t2:?}");
}

/// Bouc–Wen with `β = γ = 3e-310`, `n = 950`: `z_max = (β + γ)^{−1/n} = 2.11`, where
/// `|z|ⁿ = 1.6e309` overflows though `|z|ⁿ (β + γ) ≈ 1`: the slope `∂g/∂z` was `−∞` and the
/// tangent `∞/∞ = NaN` at every step that reached saturation. `g` is now evaluated in
/// `w = (β + |γ|)^{1/n} |z|`, about 1 at saturation at any scale.
#[test]
fn bouc_wen_saturation_where_z_to_the_n_overflows_has_a_finite_tangent() {
    use aemstep::hysteresis::{BoucWen, Law};
    let (k, fy) = (1e8, 1e5);
    let law = BoucWen::<f64>::new(k, fy, 0.05, 3e-310, 3e-310, 950.0).unwrap();
    let uy = fy / k;
    let mut h = law.initial_history();
    for x in [4.0, -2.8, 1e3, -7e2, 10.0] {
        let t = law.trial(&h, x * uy, x);
        assert!(t.force.is_finite() && t.stiffness.is_finite(), "{t:?}");
        // Saturation bound of the trapezoidal update, 2^{1/n} z_max.
        let z_max = (6e-310f64).powf(-1.0 / 950.0);
        assert!(t.history.z.abs() <= 2f64.powf(1.0 / 950.0) * z_max * (1.0 + 8.0 * f64::EPSILON));
        h = t.history;
    }
}

/// Bouc–Wen with `γ < 0` (`β = 1/2`, `γ = −0.4`, `n = 2`): unloading is steeper than
/// elastic (`g = 1 + 0.9 z²`), and the trapezoidal rule's explicit half took that slope over
/// a whole step that carried `z` through 0, overshooting `z_max` on the other side by up to
/// `ρ = (β − γ)/(β + γ) = 9`: under cyclic steps of `1.7 u_y`, `z` reached 5e8 in 26 steps and
/// the force overflowed later. Such a step is split at `z = 0` now, and `z` stays within
/// the trapezoidal update's saturation bound `2^{1/n} z_max` (`z_max = (β + γ)^{−1/n}`).
#[test]
fn bouc_wen_negative_gamma_stays_bounded_under_cyclic_steps() {
    use aemstep::hysteresis::{BoucWen, Law};
    let (k, fy, beta, gamma) = (1e8, 1e5, 0.5, -0.4);
    let law = BoucWen::<f64>::new(k, fy, 0.05, beta, gamma, 2.0).unwrap();
    let uy = fy / k;
    let bound = 2f64.sqrt() * (beta + gamma).powf(-0.5) * (1.0 + 8.0 * f64::EPSILON);
    for amp in [1.0, 4.0, 1e3, 1e10] {
        let mut h = law.initial_history();
        for i in 0..2000 {
            let x = if i % 2 == 0 { amp } else { -0.7 * amp };
            let t = law.trial(&h, x * uy, x);
            assert!(
                t.force.is_finite() && t.stiffness.is_finite() && t.history.z.abs() <= bound,
                "amplitude {amp} u_y, step {i}: {t:?}"
            );
            h = t.history;
        }
    }
}

/// Bouc–Wen at its saturation bound under huge steps (`β = γ = 1`, `n = 2`, from the test
/// command's fuzz stage): a step of `−1.4e144 u_y` ends at `g(z) = −g₀ = −1`, i.e. `z` at
/// the trapezoidal bound `2^{1/n} z_max = 1`, where rounding (`κ = √2` one ulp high) makes
/// the next loading slope `g₀ = −1 − 4e-16`. The next step (`c = 2.4e142`) then had no
/// bounded root — `g ≤ 1`, so `z − z₀ = c (g₀ + g) ≈ −c · 4e-16` — and `z = −1e127`, the
/// step after `z = −∞`. The loading slope is now taken as at least `−1` (its value at the
/// bound), and `z` stays within the bound under any path of huge steps, whatever `β, γ, n`.
#[test]
fn bouc_wen_huge_steps_at_the_saturation_bound_stay_bounded() {
    use aemstep::hysteresis::{BoucWen, Law};
    let uy = 0.1;
    let law = BoucWen::<f64>::new(1e3, 1e2, 0.0, 1.0, 1.0, 2.0).unwrap();
    let mut h = law.initial_history();
    let path = [
        -9.998,
        -6.17,
        -1.4497350084814718e144,
        7.29,
        4.877732109868738e142,
        -10.0,
    ];
    for x in path {
        let t = law.trial(&h, x * uy, -10.0);
        assert!(
            t.force.is_finite() && t.history.z.abs() <= 1.0 + 4.0 * f64::EPSILON,
            "step to {x} u_y: {t:?}"
        );
        h = t.history;
    }
    for (beta, gamma, n) in [
        (1.0, 1.0, 2.0),
        (0.5, 0.5, 1.0),
        (0.5, -0.25, 2.0),
        (2.0, 1.0, 3.5),
    ] {
        let law = BoucWen::<f64>::new(1e3, 1e2, 0.0, beta, gamma, n).unwrap();
        let bound = 2f64.powf(1.0 / n) * (beta + gamma).powf(-1.0 / n) * (1.0 + 8.0 * f64::EPSILON);
        for amp in [1e20, 1e143, 1e300] {
            let mut h = law.initial_history();
            for i in 0..200 {
                let x = [amp, -amp, 0.5 * amp, 1.0, -3.0 * amp][i % 5] * uy;
                let t = law.trial(&h, x, 1.0);
                assert!(
                    t.force.is_finite() && t.history.z.abs() <= bound,
                    "β = {beta}, γ = {gamma}, n = {n}, amplitude {amp}, step {i}: {t:?}"
                );
                h = t.history;
            }
        }
    }
}

/// Bouc–Wen in `f32` with `β = 8.5e229`, `n = 6` (`κ = 2e38`, `z_max` subnormal) at a
/// step of `2.8e-44` from saturation (found by fuzzing): `Δ/2u_y` underflows to 0, and
/// the tangent's `1 − c ∂g/∂z` was `1 − 0·∞ = NaN` (`∂g/∂z ≈ n κ` overflows `f32`). Such a
/// step does not move `z`, and its tangent is the limit `g₀/u_y`: the same as the `f64`
/// law's (where `c ∂g/∂z ≈ 1e-11`) to `f32` rounding.
#[test]
fn bouc_wen_f32_step_whose_increment_underflows_has_a_finite_tangent() {
    use aemstep::hysteresis::{BoucWen, BoucWenHistory, Law};
    let (k, fy, alpha, beta, gamma, n) = (
        8.050498138213321,
        1e7,
        0.99,
        8.462191772460943e229,
        0.5,
        6.0,
    );
    let l32 = BoucWen::<f32>::new(k, fy, alpha, beta, gamma, n).unwrap();
    let l64 = BoucWen::<f64>::new(k, fy, alpha, beta, gamma, n).unwrap();
    // The fuzz input's path: saturation at z < 0, at z > 0, then d = −0 (z < 0 again).
    let mut t0 = l32.trial(&l32.initial_history(), -8.914372e6, -1.0);
    for d in [2.0808334e4, -0.0] {
        t0 = l32.trial(&t0.history, d, 0.0);
    }
    assert!(t0.history.z < 0.0, "{t0:?}");
    let t32 = l32.trial(&t0.history, 2.8e-44, 0.0);
    let h64 = BoucWenHistory {
        deformation: f64::from(t0.history.deformation),
        z: f64::from(t0.history.z),
    };
    let t64 = l64.trial(&h64, f64::from(2.8e-44f32), 0.0);
    assert_eq!(t32.history.z, t0.history.z);
    let (s32, s64) = (f64::from(t32.stiffness), t64.stiffness);
    assert!(
        t32.force.is_finite() && (s32 - s64).abs() <= 4.0 * f64::from(f32::EPSILON) * s64.abs(),
        "f32 {t32:?}, f64 {t64:?}"
    );
}

/// Bouc–Wen with a subnormal `u_y` (`f_y = 1.1e-305`, `k = 1e3`; found by fuzzing): a
/// trial at the committed deformation (a rate reversal, `Δ = 0`) has the slope
/// `g₀/u_y = 2.3 × 8.8e307 = ∞`, and the tangent was `∞` where it is
/// `α k + (1 − α) k g₀ ≈ 2.2e3`. The slope is kept in units of `1/u_y` now: the tangent is
/// that closed form, `g₀ = 1 + (β − γ) z₀²` on unloading (`n = 2`).
#[test]
fn bouc_wen_tangent_with_a_subnormal_yield_deformation_is_finite() {
    use aemstep::hysteresis::{BoucWen, Law};
    let (k, fy, alpha, beta, gamma) = (
        1e3,
        1.1392378155556871e-305,
        0.09532012939453124,
        3.0194091796875,
        0.5,
    );
    let law = BoucWen::<f64>::new(k, fy, alpha, beta, gamma, 2.0).unwrap();
    let d = 9.99969482421875 * (fy / k);
    let t1 = law.trial(&law.initial_history(), d, 1.0);
    let z0 = t1.history.z;
    assert!(z0 > 0.5 && t1.stiffness.is_finite(), "{t1:?}");
    // Reversal at the same deformation: unloading (s z₀ < 0), g₀ = 1 + (β − γ) z₀².
    let t2 = law.trial(&t1.history, d, -10.0);
    let expected = alpha * k + (1.0 - alpha) * k * (1.0 + (beta - gamma) * z0 * z0);
    assert!(
        (t2.stiffness - expected).abs() <= 8.0 * f64::EPSILON * expected,
        "{t2:?}, expected {expected}"
    );
}

/// A steady-state Kalman gain whose closed loop has modes at `0.99988` (the fuzz input
/// `riccati-residual-3e-3`: an `exact` model of an indefinite `M`, `R = 1e-6`, `Q` of
/// rank ~1). The doubling stopped at iteration 2 — `X` had not moved by `4ε` yet, while
/// its slow part had still to accumulate — with `P` off by 6e-14 relative, and the gain of
/// that `P` (the innovation covariance has `κ = 3.5e13`, so the gain magnifies such
/// errors) made an observer with spectral radius 1.0000085: unstable. (The fuzz check's
/// residual of 3e-3 was its own rounding, in the textbook form.) The doubling now also
/// waits for `‖A_k‖∞ ≤ 2^-26`, and the solution is verified: its closed loop is certified
/// stable and its Joseph-form residual is within `RICCATI_RESIDUAL_UNITS` units of rounding.
#[test]
fn riccati_gain_of_a_slow_closed_loop_is_converged_and_verified() {
    use aemstep::observer::{Outputs, RICCATI_RESIDUAL_UNITS, StateSpace, SteadyState};
    let m = matrix![0.17854163271146717, 0.0; 0.0, -8.50982666015625];
    let c = M2::identity() * -8.50982666015625;
    let b = matrix![-8.50982666015625; -8.50982666015625];
    let ss = StateSpace::<2, 4, 1>::exact(&m, &c, &c, &b, 1.9862534655951106e-4).unwrap();
    let mut out = Outputs::<2, 1, 2>::zero();
    out.a = [
        [-8.50982666015625, 8.57208251953125],
        [-8.50982666015625, 0.001],
    ];
    out.w = [[-10.0], [9.99969482421875]];
    let meas = ss.outputs(&out).unwrap();
    // The fuzz input's Q: v vᵀ (rank one), v = (0.15625, 9.9871826171875, 10, 10).
    let q = SMatrix::<f64, 4, 4>::from_column_slice(&[
        0.0244140625,
        1.5604972839355469,
        1.5625,
        1.5625,
        1.5604972839355469,
        99.74381662905216,
        99.871826171875,
        99.871826171875,
        1.5625,
        99.871826171875,
        100.0,
        100.0,
        1.5625,
        99.871826171875,
        100.0,
        100.0,
    ]);
    let r = M2::identity() * 1e-6;
    let kf = SteadyState::new(&ss, &meas, &q, &r).unwrap();
    assert!(kf.iterations > 2, "{}", kf.iterations);
    let (phi, h, p, l) = (
        ss.phi_matrix(),
        meas.h_matrix(),
        kf.covariance_matrix(),
        kf.gain_matrix(),
    );
    let a = phi - phi * l * h;
    let rho = aemstep::nalgebra::DMatrix::from_fn(4, 4, |i, j| a[(i, j)])
        .complex_eigenvalues()
        .iter()
        .fold(0.0f64, |m, z| m.max(z.norm()));
    assert!(rho < 1.0, "closed-loop spectral radius {rho}");
    // The residual the library bounds, evaluated here in the same Joseph form (its own
    // rounding: about one more unit).
    let k = phi * l;
    let res = a * p * a.transpose() + k * r * k.transpose() + q - p;
    let bnd = a.abs() * p.abs() * a.abs().transpose()
        + k.abs() * r.abs() * k.abs().transpose()
        + q.abs()
        + p.abs();
    let unit = 13.0 * f64::EPSILON;
    for i in 0..4 {
        for j in 0..4 {
            let scale = (bnd[(i, i)] * bnd[(j, j)]).sqrt().max(bnd[(i, j)]);
            assert!(
                res[(i, j)].abs() <= (RICCATI_RESIDUAL_UNITS + 1.0) * unit * scale,
                "residual ({i}, {j}) {:e} of {scale:e}",
                res[(i, j)]
            );
        }
    }
}

/// A shear building with a floor mass of `6.2e-322` kg: positive, so accepted, but `0` in
/// `f32` (and subnormal in `f64`): the `f32` building's start failed with `SingularMass`.
/// A mass below the smallest normal number of the scalar type is `OperatorUnderflow` now.
#[test]
fn building_mass_below_the_smallest_normal_is_operator_underflow() {
    use aemstep::hysteresis::{Bilinear, ShearBuilding};
    let c = [[-10.0, -10.0], [-10.0, -10.0]];
    let l32 = Bilinear::<f32>::new(1e3, 1e7, 0.99).unwrap();
    assert_eq!(
        ShearBuilding::<f32, _, 2>::new([1000.0, 6.2e-322], [l32, l32], &c).err(),
        Some(Error::OperatorUnderflow)
    );
    assert_eq!(
        ShearBuilding::<f32, _, 2>::new([1000.0, 1e-39], [l32, l32], &c).err(),
        Some(Error::OperatorUnderflow)
    );
    let l64 = Bilinear::<f64>::new(1e3, 1e7, 0.99).unwrap();
    assert_eq!(
        ShearBuilding::<f64, _, 2>::new([1000.0, 6.2e-322], [l64, l64], &c).err(),
        Some(Error::OperatorUnderflow)
    );
    assert!(ShearBuilding::<f64, _, 2>::new([1000.0, 1e-39], [l64, l64], &c).is_ok());
    assert!(ShearBuilding::<f32, _, 2>::new([1000.0, 1e-37], [l32, l32], &c).is_ok());
}

/// Bouc–Wen with an exponent of `8.4e83` (the fuzzer's; here with `β = γ = 1/2`, so that
/// `z_max = 1` as in its input): `g = 1 − zⁿ` jumps from `0` to `−∞` within one ulp of `z = 1`, the solve
/// converged to `z = 1 + 2ε` where `zⁿ = ∞`, and the tangent was `∞/∞ = NaN`. A root
/// converged where `g` is not finite is moved to the nearest number within the tolerance
/// where it is (`z = 1`, the root to rounding).
#[test]
fn bouc_wen_huge_exponent_tangent_at_saturation_is_finite() {
    use aemstep::hysteresis::{BoucWen, Law};
    let (k, fy) = (8.050498138213321, 1e7);
    let law = BoucWen::<f64>::new(k, fy, 0.99, 0.5, 0.5, 8.430468750000003e83).unwrap();
    let uy = fy / k;
    let mut h = law.initial_history();
    for x in [0.5, 1.5, 3.0, 3.1, -2.0, 4.0, 4.0] {
        let t = law.trial(&h, x * uy, 1.0);
        assert!(
            t.force.is_finite() && t.stiffness.is_finite(),
            "x = {x}: {t:?}"
        );
        assert!(t.history.z.abs() <= 1.0, "{t:?}");
        h = t.history;
    }
}

/// Bouc–Wen with `n = 2.9e17` and `u_y = 8e-265` (`k = 1.3e266`, `f_y = 100`): at a step
/// of `−10 u_y` the root is resolved to within `4ε` of saturation, where `wⁿ ≈ 1e250`, so
/// `g₀ + g ≈ −1e250` and the denominator `1 − c ∂g/∂z` is as large: their ratio is small,
/// but `(g₀ + g)/(2u_y)` was formed first and overflowed — a tangent of `−∞`. The ratio is
/// formed first where that product overflows.
#[test]
fn bouc_wen_tangent_ratio_is_formed_before_its_overflowing_scale() {
    use aemstep::hysteresis::{BoucWen, Law};
    let (k, fy) = (1.2897815701554327e266, 1e2);
    let law = BoucWen::<f64>::new(
        k,
        fy,
        1.4693801879882812e-1,
        5.324081420898438e-1,
        4.921722412109375e-1,
        2.8823037615171174e17,
    )
    .unwrap();
    let uy = fy / k;
    let mut h = law.initial_history();
    // (A further trial at the same deformation has the law's own slope `g₀/u_y ≈ −1e514`
    // at that state, beyond `f64`: not judged, as in the fuzz check.)
    for x in [5.883593420661338e-185, -10.0] {
        let t = law.trial(&h, x * uy, -10.0);
        // Finite, and no stiffer than elastic (|dz/dd| ≤ 1/u_y here: g₀ + g ≤ 2 over a
        // denominator ≥ 1), up to rounding.
        assert!(
            t.force.is_finite()
                && t.stiffness.is_finite()
                && t.stiffness.abs() <= k * (1.0 + 1e-12),
            "{t:?}"
        );
        h = t.history;
    }
}

/// Bouc–Wen with `n = 7.3e17` (`β = 1`, `γ = −1/2`): `g` changes by `e^(n δ)` over a
/// relative `δ` of `z`, so a `z` within the solve's `4ε` of the root had `g = −3e209`
/// where the root has `g ≈ −1`. Committed, that `g₀` drove the next loading step (further
/// negative) to `z = +1`, and the one after to a force of `−∞`. The solve now keeps, of the
/// numbers within its tolerance, the one with the smallest residual: `z` keeps its sign
/// along a monotonic path and stays within `2^(1/n) z_max` to rounding.
#[test]
fn bouc_wen_huge_exponent_root_is_the_smallest_residual() {
    use aemstep::hysteresis::{BoucWen, Law};
    let law = BoucWen::<f64>::new(1e9, 1e7, 0.0, 1.0, -0.5, 7.259738159179689e17).unwrap();
    let uy = 0.01;
    let mut h = law.initial_history();
    for x in [-5.75347900390625, -9.9835205078125, -20.0, -1e6] {
        let t = law.trial(&h, x * uy, -1.0);
        let z = t.history.z;
        // z_max = 0.5^(−1/n) = 1 + 1e-18: 1 to rounding; 4ε is the solve's tolerance.
        assert!(
            t.force.is_finite()
                && t.stiffness.is_finite()
                && (-(1.0 + 4.0 * f64::EPSILON)..0.0).contains(&z),
            "x = {x}: {t:?}"
        );
        h = t.history;
    }
}

/// `InputModel::zero_dynamics` returned `Ā = A − B M₀ C` unchecked: with `B`, `C` of
/// 1e300 it is `−∞` and was `Ok` (found by the `estimation` fuzz target,
/// `fuzz/regressions/estimation/zero-dynamics-not-finite-is-operator-overflow`). Now
/// `OperatorOverflow`, as its docs say.
#[test]
fn zero_dynamics_not_finite_is_operator_overflow() {
    use aemstep::estimation::InputModel;
    let model = InputModel::<2, 1, 1> {
        a: [[1.0, 0.0], [0.0, 1.0]],
        b: [[1e300], [1e300]],
        c: [[1e300, 0.0]],
        d: [[1.0]],
        gamma1: [[0.0], [0.0]],
        time_step: 0.01,
    };
    assert_eq!(
        model.zero_dynamics(&SMatrix::<f64, 1, 1>::identity()).err(),
        Some(Error::OperatorOverflow)
    );
}

/// `Whitener::nis` of a finite innovation whose whitened terms overflow (`∞ − ∞`) was NaN,
/// which a `Window` skips as a missing sample: the largest innovations were never an alarm
/// (found by the `detection` fuzz target,
/// `fuzz/regressions/detection/nis-of-finite-innovation-overflowing-is-infinite`). Now `+∞`,
/// an alarm; a NaN innovation stays NaN (missing).
#[test]
fn nis_of_finite_innovation_overflowing_is_infinite() {
    use aemstep::detection::{ChiSquareTest, Detector, Dof, Whitener, Window};
    let s = [[1.0, 0.99], [0.99, 1.0]];
    let w64 = Whitener::<f64, 2>::new(&s).unwrap();
    let nu = vector![f64::MAX / 2.0, f64::MAX / 2.0];
    assert_eq!(w64.nis(&nu), f64::INFINITY);
    assert!(w64.nis(&vector![f64::NAN, 0.0]).is_nan());
    let w32 = Whitener::<f32, 2>::new(&s).unwrap();
    assert_eq!(
        w32.nis(&vector![f32::MAX / 2.0, f32::MAX / 2.0]),
        f32::INFINITY
    );
    let det = Detector::from_parts(w64, ChiSquareTest::<f64, 1>::new(&Dof::<2>, 1e-3).unwrap());
    let mut win = Window::<f64, 1>::at_rest();
    assert!(
        det.update(&mut win, &nu),
        "an overflowing innovation is an alarm"
    );
    assert_eq!(win.skipped(), 0);
}

/// `innovation_covariance` checked `S = H P Hᵀ + R` finite before symmetrizing it, and
/// `(S + Sᵀ)/2` of entries near `f64::MAX` overflows: `R = f64::MAX` gave `Ok([[∞]])`
/// (found by the `detection` fuzz target,
/// `fuzz/regressions/detection/innovation-covariance-symmetrized-near-max-overflows`). Now
/// `OperatorOverflow`.
#[test]
fn innovation_covariance_symmetrized_near_max_overflows() {
    use aemstep::detection::innovation_covariance;
    use aemstep::observer::{Measurement, SteadyState};
    let kf = SteadyState::<2, 1> {
        covariance: [[1.0, 0.0], [0.0, 1.0]],
        gain: [[0.0], [0.0]],
        iterations: 1,
        cross: [[0.0], [0.0]],
    };
    let meas = Measurement::<2, 1, 1> {
        h: [[0.0, 0.0]],
        d: [[1.0]],
    };
    assert_eq!(
        innovation_covariance(&kf, &meas, &[[f64::MAX]]).err(),
        Some(Error::OperatorOverflow)
    );
    assert_eq!(innovation_covariance(&kf, &meas, &[[2.0]]), Ok([[2.0]]));
}

/// `KrAlpha` judged the range of its start-up operators (`M⁻¹`, `M⁻¹C`, `M⁻¹K`) before the
/// singularity of `M (I − α3)`, against its documented order (singularity, then range): an
/// `f32` build said `OperatorUnderflow` where the `f64` build of the same data said
/// `SingularEffectiveMatrix` (`M` with entries from 1e1 to 1.8e308, so `M⁻¹` is below
/// `f32`'s range; found by the `hybrid` fuzz target,
/// `fuzz/regressions/hybrid/f32-start-operators-range-after-singular-m-i-minus-alpha3`).
/// Now the start-up operators' range is judged with the other operators'.
#[test]
fn kr_alpha_start_operators_range_after_singular_m_i_minus_alpha3() {
    use aemstep::KrAlpha;
    use aemstep::hybrid::Split;
    let m = matrix![6.582018229284824e63, 1.201202692608752e257; f64::MAX, -10.0];
    let ck = M2::repeat(-10.0);
    let h = 1e-4;
    let want = Some(Error::SingularEffectiveMatrix);
    assert_eq!(KrAlpha::<f64, 2>::new(&m, &ck, &ck, h, 0.0).err(), want);
    assert_eq!(KrAlpha::<f32, 2>::new(&m, &ck, &ck, h, 0.0).err(), want);
    assert_eq!(Split::<f32, 2>::new(&m, &ck, &ck, &ck, h, 0.0).err(), want);
}
