//! Property-based tests (issue 10) over every constructor and checked step of every
//! stepper, with random finite, non-finite and extreme data: entries from 1e-300 to 1e300
//! (and subnormal, `f64::MAX`, NaN, ±∞), `h` from subnormal to 1e300, singular and
//! near-singular matrices, non-symmetric matrices where symmetry is required.
//!
//! Properties:
//! - never a panic (proptest fails the test on one);
//! - `Ok` from a constructor ⇒ its operators are finite: a start from a unit state and a
//!   few checked steps under a unit load either succeed with a finite state or fail;
//! - `Err` from a checked step ⇒ the state is bit-identical (compared by bits, so `−0.0`
//!   and `0.0` differ);
//! - for the unconditionally stable schemes (AEM `Linear`, `AForm`, `CompensatedLinear`,
//!   Newmark average acceleration) with symmetric positive definite `M, K`, `C = 0`, zero
//!   load: the energy `½ vᵀMv + ½ uᵀKu` after 300 steps does not exceed its start beyond
//!   rounding (these schemes conserve it exactly in exact arithmetic); nor does
//!   generalized-α's (dissipative).
//!
//! Each test prints `COUNT <test> <category> <n>` lines (run with `--nocapture`):
//! `scripts/robustness.sh` collects them into `docs/robustness.md`.

use std::collections::BTreeMap;
use std::sync::Mutex;

use aemstep::nalgebra::{SMatrix, SVector, matrix, vector};
use aemstep::{
    AlphaParameters, Coefficients, CompensatedLinear, Damping, Error, Exact, GeneralizedAlpha,
    Linear, LinearInput, Modal, Model, Newmark, NewtonSettings, Nonlinear, StepState, Stepper,
    Tangent, Varying,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

type M2 = SMatrix<f64, 2, 2>;
type V2 = SVector<f64, 2>;

/// Cases per test: 1500 (debug build: the file runs in well under a minute), or
/// `AEMSTEP_PROP_CASES` (`scripts/robustness.sh` runs more in release).
fn config(cases: u32) -> Config {
    // A fixed seed: the counts in docs/robustness.md are reproducible; another seed
    // (`AEMSTEP_PROP_SEED`) explores other inputs.
    let seed = std::env::var("AEMSTEP_PROP_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10);
    Config {
        cases,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(seed),
        ..Config::default()
    }
}

fn cases() -> u32 {
    std::env::var("AEMSTEP_PROP_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1500)
}

/// One matrix entry: ordinary, extreme (1e-300 … 1e300, subnormal, `f64::MAX`) or not finite.
fn entry() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0f64..10.0,
        1 => Just(0.0),
        3 => (-300i32..=300, -9.9f64..9.9).prop_map(|(e, m)| m * 10f64.powi(e)),
        1 => prop_oneof![Just(5e-324), Just(1e-310), Just(f64::MAX), Just(-f64::MAX)],
        1 => prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
    ]
}

/// A time step: ordinary, extreme (subnormal … 1e300) or invalid.
fn time_step() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => 1e-4f64..1.0,
        3 => (-324i32..=300).prop_map(|e| 10f64.powi(e)),
        1 => prop_oneof![Just(0.0), Just(-0.01), Just(f64::NAN), Just(f64::INFINITY), Just(5e-324)],
    ]
}

/// A 2×2 matrix: random entries, or a structured one (SPD, singular, near-singular,
/// non-symmetric) at a random scale.
fn matrix2() -> impl Strategy<Value = M2> {
    let scale = (-300i32..=300).prop_map(|e| 10f64.powi(e));
    prop_oneof![
        3 => [entry(), entry(), entry(), entry()].prop_map(|[a, b, c, d]| matrix![a, b; c, d]),
        2 => [-10.0f64..10.0, -10.0f64..10.0, -10.0f64..10.0, -10.0f64..10.0]
            .prop_map(|[a, b, c, d]| matrix![a, b; c, d]),
        1 => (scale.clone(), 0.0f64..1.0, -0.9f64..0.9, 0.0f64..1.0)
            .prop_map(|(s, a, b, c)| matrix![2.0 + a, b; b, 1.0 + c] * s),
        1 => (scale.clone(), prop_oneof![Just(0.0), Just(1e-17), Just(1e-15), Just(1e-8)])
            .prop_map(|(s, d)| matrix![1.0, 1.0; 1.0, 1.0 + d] * s),
        1 => (scale, -5.0f64..5.0).prop_map(|(s, b)| matrix![2.0, b; -b, 1.0] * s),
    ]
}

fn vec2() -> impl Strategy<Value = V2> {
    [entry(), entry()].prop_map(|[a, b]| vector![a, b])
}

/// The category of a case, for the counts: non-finite data, extreme data (an entry or `h`
/// outside 1e-100 … 1e100, or subnormal), or ordinary finite data.
fn category(values: &[f64]) -> &'static str {
    if values.iter().any(|x| !x.is_finite()) {
        "non-finite"
    } else if values
        .iter()
        .any(|&x| x != 0.0 && !(1e-100..=1e100).contains(&x.abs()))
    {
        "extreme"
    } else {
        "finite"
    }
}

static COUNTS: Mutex<BTreeMap<(String, String), u64>> = Mutex::new(BTreeMap::new());

fn count(test: &str, what: &str) {
    *COUNTS
        .lock()
        .unwrap()
        .entry((test.into(), what.into()))
        .or_default() += 1;
}

fn print_counts(test: &str) {
    for ((t, what), n) in COUNTS.lock().unwrap().iter() {
        if t == test {
            println!("COUNT {t} {what} {n}");
        }
    }
}

fn flat(ms: &[&M2], h: f64) -> Vec<f64> {
    ms.iter()
        .flat_map(|m| m.iter().copied())
        .chain([h])
        .collect()
}

fn bits<S: std::fmt::Debug>(s: &S) -> String {
    format!("{s:?}")
}

/// The checked-step contract on a built stepper: a start from a unit state, then checked
/// steps under `load` (and a NaN load): every `Ok` leaves a finite state, every `Err` the
/// state bit-identical. Returns whether every step succeeded.
fn drive<S: Stepper<f64, 2, Input = V2, State: std::fmt::Debug>>(
    test: &str,
    sys: &S,
    load: &V2,
) -> Result<bool, TestCaseError> {
    let one = vector![1.0, -0.5];
    let s0 = match sys.start(&one, &one, load) {
        Ok(s) => s,
        Err(_) => match sys.start_with_acceleration(&one, &one, &V2::zeros()) {
            Ok(s) => s,
            Err(e) => {
                return Err(TestCaseError::fail(format!(
                    "start_with_acceleration: {e:?}"
                )));
            }
        },
    };
    prop_assert!(s0.is_finite());
    let mut s = s0;
    let mut all_ok = true;
    for w in [*load, vector![f64::NAN, 0.0], *load, V2::zeros(), *load] {
        let before = bits(&s);
        match sys.try_step(&mut s, &w) {
            Ok(()) => prop_assert!(s.is_finite()),
            Err(e) => {
                count(test, "failed step");
                prop_assert_eq!(bits(&s), before, "{:?} changed the state", e);
                if w.iter().all(|x| x.is_finite()) {
                    all_ok = false;
                }
            }
        }
        let before = bits(&s);
        if let Err(e) = sys.try_step_with_previous_input(&mut s, &w, &w) {
            count(test, "failed step");
            prop_assert_eq!(bits(&s), before, "{:?} changed the state", e);
        }
    }
    Ok(all_ok)
}

/// `drive` in f64 and counts the outcome.
fn check<S: Stepper<f64, 2, Input = V2, State: std::fmt::Debug>>(
    test: &str,
    built: Result<S, Error>,
    load: &V2,
    data: &[f64],
) -> Result<(), TestCaseError> {
    count(test, category(data));
    match built {
        Ok(sys) => {
            count(test, "built");
            if !drive(test, &sys, load)? {
                count(test, "step rejected");
            }
        }
        Err(_) => count(test, "rejected"),
    }
    Ok(())
}

/// `Ok` is not garbage: the step's new acceleration is the solution of its equation. From
/// `u = v = (1, −0.5)`, `a = 0` (so `v̂ = v`, `û = u + h v`), `q` must match the solution
/// `q_ref` of `A q = p − C v̂ − K û`, `A = M + (h/2) C + (h²/4) K`, by an independent LU
/// (nalgebra's), normwise: `‖q − q_ref‖∞ ≤ 64 ε κ∞(A) ‖q_ref‖∞` (the forward error of
/// both solves). Checked where `64 ε κ∞ < 0.1`.
///
/// (Row by row the residual of `q` is not small when the rows of `A` differ in size by
/// many orders: the operators `G C`, `G K` are precomputed, so `q` is accurate normwise,
/// not componentwise. Found by this test with rows 1e74 apart; documented in
/// `docs/robustness.md`.)
#[allow(clippy::too_many_arguments)]
fn eom_holds<S: Stepper<f64, 2, Input = V2>>(
    test: &str,
    sys: &S,
    m: &M2,
    c: &M2,
    k: &M2,
    h: f64,
    p: &V2,
) -> Result<(), TestCaseError> {
    if !p.iter().all(|x| x.is_finite()) {
        return Ok(());
    }
    let one = vector![1.0, -0.5];
    let Ok(mut s) = sys.start_with_acceleration(&one, &one, &V2::zeros()) else {
        return Ok(());
    };
    if sys.try_step(&mut s, p).is_err() {
        return Ok(());
    }
    let q = *sys.full_state(&s).a();
    let (vh, uh) = (one, one + one * h);
    let a = m + c * (0.5 * h) + k * (0.25 * h * h);
    let rhs = p - c * vh - k * uh;
    // Scaled first: nalgebra's 2×2 inverse forms the determinant, which over/underflows.
    let sc = a.amax();
    let (Some(ainv), true) = (
        (a / sc).try_inverse().map(|x| x / sc),
        rhs.iter().all(|x| x.is_finite()),
    ) else {
        return Ok(());
    };
    let norm_inf = |x: &M2| {
        (0..2)
            .map(|i| x[(i, 0)].abs() + x[(i, 1)].abs())
            .fold(0.0, f64::max)
    };
    let kappa = norm_inf(&a) * norm_inf(&ainv);
    let tol = 64.0 * f64::EPSILON * kappa;
    let Some(q_ref) = a.lu().solve(&rhs) else {
        return Ok(());
    };
    if !(tol < 0.1 && tol > 0.0 && q_ref.iter().all(|x| x.is_finite())) {
        return Ok(());
    }
    // Operators with entries below `MIN_POSITIVE / ε` (subnormal or nearly) have lost
    // relative precision: a known limit, not checked here (see docs/robustness.md).
    // (Judged by logarithms: the products themselves may underflow to zero.)
    let floor = (f64::MIN_POSITIVE / f64::EPSILON).log2();
    let thin = |x: &M2| x.amax() != 0.0 && x.amax().log2() + ainv.amax().log2() < floor + 2.0;
    if ainv.amax().log2() < floor || thin(c) || thin(k) {
        count(test, "acceleration not checked: operators below 1e-292");
        return Ok(());
    }
    count(test, "acceleration checked against an independent solve");
    prop_assert!(
        (q - q_ref).amax() <= tol * q_ref.amax() + 4.0e-323,
        "{}: q = {:?}, reference {:?}, κ∞ = {:e}; M = {:?}, C = {:?}, K = {:?}, h = {:e}, p = {:?}",
        test,
        q.as_slice(),
        q_ref.as_slice(),
        kappa,
        m.as_slice(),
        c.as_slice(),
        k.as_slice(),
        h,
        p.as_slice()
    );
    Ok(())
}

/// A 2-DOF stepper's f32 twin: the same contract in the working precision of firmware.
fn check_f32<S: Stepper<f32, 2, Input = SVector<f32, 2>, State: std::fmt::Debug>>(
    built: Result<S, Error>,
    load: &V2,
) -> Result<(), TestCaseError> {
    if let Ok(sys) = built {
        let p = load.map(|x| x as f32);
        let one = vector![1.0f32, -0.5];
        let mut s = match sys.start(&one, &one, &p) {
            Ok(s) => s,
            Err(_) => match sys.start_with_acceleration(&one, &one, &SVector::zeros()) {
                Ok(s) => s,
                Err(e) => return Err(TestCaseError::fail(format!("f32 start: {e:?}"))),
            },
        };
        for w in [p, vector![f32::NAN, 0.0], p] {
            let before = bits(&s);
            match sys.try_step(&mut s, &w) {
                Ok(()) => prop_assert!(s.is_finite()),
                Err(_) => prop_assert_eq!(bits(&s), before),
            }
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(cases()))]

    #[test]
    fn linear_aform_compensated(m in matrix2(), c in matrix2(), k in matrix2(), h in time_step(), p in vec2()) {
        let d = flat(&[&m, &c, &k], h);
        let built = Linear::<f64, 2>::new(&m, &c, &k, h);
        if let Ok(sys) = &built {
            prop_assert!(sys.effective_inverse().iter().all(|x| x.is_finite()));
            prop_assert!(sys.condition().is_finite() || sys.condition() == f64::INFINITY);
            check("aform", Ok(sys.a_form()), &p, &d)?;
        }
        let rows = |a: M2| [[a[(0, 0)], a[(0, 1)]], [a[(1, 0)], a[(1, 1)]]];
        let from_rows = Linear::<f64, 2>::from_rows_f64(rows(m), rows(c), rows(k), h);
        prop_assert_eq!(bits(&from_rows), bits(&built));
        if let Ok(sys) = &built {
            eom_holds("linear", sys, &m, &c, &k, h, &p)?;
        }
        if let Ok(sys) = &CompensatedLinear::<f64, 2>::new(&m, &c, &k, h) {
            eom_holds("compensated", sys, &m, &c, &k, h, &p)?;
        }
        check("linear", built, &p, &d)?;
        check("compensated", CompensatedLinear::<f64, 2>::new(&m, &c, &k, h), &p, &d)?;
        check_f32(Linear::<f32, 2>::new(&m, &c, &k, h), &p)?;
        check_f32(CompensatedLinear::<f32, 2>::new(&m, &c, &k, h), &p)?;
    }

    #[test]
    fn newmark_family(m in matrix2(), c in matrix2(), k in matrix2(), h in time_step(), p in vec2(),
                      beta in prop_oneof![0.0f64..1.0, Just(f64::NAN), Just(-1.0)],
                      gamma in prop_oneof![0.0f64..1.0, Just(f64::INFINITY)],
                      rho in prop_oneof![0.0f64..1.0, Just(1.5), Just(f64::NAN)]) {
        let d = flat(&[&m, &c, &k], h);
        check("newmark", Newmark::<f64, 2>::new(&m, &c, &k, h, beta, gamma), &p, &d)?;
        check("newmark", Newmark::<f64, 2>::central_difference(&m, &c, &k, h), &p, &d)?;
        check("generalized_alpha", GeneralizedAlpha::<f64, 2>::new(&m, &c, &k, h, rho), &p, &d)?;
        check_f32(GeneralizedAlpha::<f32, 2>::new(&m, &c, &k, h, rho), &p)?;
        check_f32(Newmark::<f32, 2>::average_acceleration(&m, &c, &k, h), &p)?;
    }

    #[test]
    fn input_exact_modal(m in matrix2(), c in matrix2(), k in matrix2(), b in matrix2(), h in time_step(), p in vec2(),
                         xi in prop_oneof![0.0f64..0.5, Just(-0.1), Just(f64::NAN)]) {
        let d = flat(&[&m, &c, &k, &b], h);
        check("linear_input", LinearInput::<f64, 2, 2>::new(&m, &c, &k, &b, h), &p, &d)?;
        check_f32(LinearInput::<f32, 2, 2>::new(&m, &c, &k, &b, h), &p)?;
        check("exact", Exact::<f64, 2>::new(&m, &c, &k, h), &p, &d)?;
        let modal = Modal::<f64, 2, 2, 2, 2>::new(&m, &k, &Damping::Ratios([xi, xi]), &b, &M2::identity(), h);
        if let Ok(sys) = &modal {
            let s = sys.start_at_rest(&p);
            if let Ok(s) = s { prop_assert!(s.is_finite()); }
        }
        check("modal", modal, &p, &d)?;
        check_f32(Modal::<f32, 2, 2, 2, 2>::new(&m, &k, &Damping::None, &b, &M2::identity(), h), &p)?;
    }

    #[test]
    fn nonlinear_and_varying(m in entry(), k in entry(), k3 in entry(), h in time_step(), p in entry(),
                             mm in matrix2(), cc in matrix2(), kk in matrix2(), pv in vec2()) {
        let d = [m, k, k3, h, p];
        count("nonlinear", category(&d));
        match Nonlinear::<f64, 1>::new(h, NewtonSettings::up_to(20, 1e-10)) {
            Ok(stepper) => {
                count("nonlinear", "built");
                let model = Cubic { m, k, k3 };
                if let Ok(mut s) = stepper.start(&model, &vector![1.0], &vector![0.0], &vector![p]) {
                    for w in [p, f64::NAN, p, 0.0] {
                        let before = bits(&s);
                        match stepper.try_step(&model, &mut s, &vector![w]) {
                            Ok(_) => prop_assert!(s.is_finite()),
                            Err(e) => {
                                count("nonlinear", "failed step");
                                prop_assert_eq!(bits(&s), before, "{:?}", e)
                            }
                        }
                    }
                }
            }
            Err(_) => count("nonlinear", "rejected"),
        }
        let dv = flat(&[&mm, &cc, &kk], h);
        count("varying", category(&dv));
        match Varying::<f64, 2>::new(h) {
            Ok(stepper) => {
                count("varying", "built");
                let co = |t: f64| Coefficients { mass: mm, damping: cc * (1.0 + t.min(1.0)), stiffness: kk };
                let one = vector![1.0, -0.5];
                let s = stepper.start(&co, &one, &one, &pv)
                    .or_else(|_| stepper.start_with_acceleration(&one, &one, &V2::zeros()));
                let Ok(mut s) = s else { return Err(TestCaseError::fail("varying start")) };
                for w in [pv, vector![f64::NAN, 0.0], pv] {
                    let before = bits(&s);
                    match stepper.try_step(&co, &mut s, &w) {
                        Ok(()) => prop_assert!(s.is_finite()),
                        Err(e) => {
                            count("varying", "failed step");
                            prop_assert_eq!(bits(&s), before, "{:?}", e)
                        }
                    }
                }
            }
            Err(_) => count("varying", "rejected"),
        }
    }
}

/// `m u'' + k u + k3 u³ = p` (any signs and sizes: the property is no panic and no
/// changed state on error, not convergence).
struct Cubic {
    m: f64,
    k: f64,
    k3: f64,
}

impl Model<f64, 1> for Cubic {
    fn mass(&self) -> SMatrix<f64, 1, 1> {
        matrix![self.m]
    }
    fn force(&self, u: &SVector<f64, 1>, _v: &SVector<f64, 1>) -> SVector<f64, 1> {
        vector![self.k * u[0] + self.k3 * u[0] * u[0] * u[0]]
    }
    fn tangent(&self, u: &SVector<f64, 1>, _v: &SVector<f64, 1>) -> Option<Tangent<f64, 1>> {
        Some(Tangent {
            stiffness: matrix![self.k + 3.0 * self.k3 * u[0] * u[0]],
            damping: matrix![0.0],
        })
    }
}

/// SPD `M`, `K` at scales 1e-100 … 1e100 (`κ ≤ 10` each; then `h` from `ω_max` keeps `h²`
/// normal), `C = 0`: the energy norm does not grow.
fn spd() -> impl Strategy<Value = M2> {
    ((-100i32..=100), 0.0f64..1.0, -0.9f64..0.9, 0.0f64..1.0)
        .prop_map(|(e, a, b, c)| matrix![2.0 + a, b; b, 1.0 + c] * 10f64.powi(e))
}

fn energy(m: &M2, k: &M2, u: &V2, v: &V2) -> f64 {
    0.5 * (v.dot(&(m * v)) + u.dot(&(k * u)))
}

/// Energy after `steps` zero-load steps over the energy at the start (`None` if not built).
fn energy_ratio<S: Stepper<f64, 2, Input = V2>>(
    sys: Result<S, Error>,
    m: &M2,
    k: &M2,
    u0: &V2,
    v0: &V2,
    steps: usize,
) -> Result<f64, Error> {
    let sys = sys?;
    let mut s = sys.start(u0, v0, &V2::zeros())?;
    for _ in 0..steps {
        sys.step(&mut s, &V2::zeros());
    }
    let f = sys.full_state(&s);
    Ok(energy(m, k, f.u(), f.v()) / energy(m, k, u0, v0))
}

static GROWTH: Mutex<BTreeMap<String, f64>> = Mutex::new(BTreeMap::new());

/// The largest relative energy change seen per scheme (printed by `zz_counts`).
fn note_growth(name: &str, g: f64) {
    let mut t = GROWTH.lock().unwrap();
    let e = t.entry(name.into()).or_insert(f64::NEG_INFINITY);
    *e = e.max(g);
}

/// Relative growth allowed after 300 steps at `ω_max h`: 300 steps × a few ulps per step,
/// times the condition number of `M⁻¹K` (≤ 100 here), times the cancellation in
/// `u_n = û + (h²/4) q` at large `ωh` (`max(1, (ωh)²/4)`): `300 · 8 · 100 · 1.1e-16 ≈
/// 2.7e-11` per unit of cancellation. Measured: up to 4.2e-10 at ωh = 1000 (2.5e5 units),
/// 1e-11 at ωh ≤ 1 (see `GROWTH` lines).
fn energy_tol(wh: f64) -> f64 {
    3e-11 * (wh * wh / 4.0).max(1.0)
}

proptest! {
    #![proptest_config(config(cases() / 5))]

    #[test]
    fn energy_does_not_grow(m in spd(), k in spd(), wh in -4i32..=2, u0 in [-1.0f64..1.0, -1.0f64..1.0],
                            v0 in [-1.0f64..1.0, -1.0f64..1.0], rho in 0.0f64..1.0) {
        // h from the highest natural frequency: ω_max h = 10^wh.
        // ω_max² of M⁻¹K, scaled so the 2×2 characteristic polynomial does not overflow.
        let a = m.try_inverse().unwrap() * k;
        let sc = a.amax();
        let b = a / sc;
        let (tr, det) = (b.trace(), b.determinant());
        let wmax = (sc * 0.5 * (tr + (tr * tr - 4.0 * det).max(0.0).sqrt())).sqrt();
        let h = 10f64.powi(wh) / wmax;
        let (u0, v0) = (vector![u0[0], u0[1]], vector![v0[0], v0[1]] * wmax);
        prop_assume!(energy(&m, &k, &u0, &v0) > 0.0);
        let c = M2::zeros();
        count("energy", "cases");
        for (name, r) in [
            ("linear", energy_ratio(Linear::<f64, 2>::new(&m, &c, &k, h), &m, &k, &u0, &v0, 300)),
            ("aform", energy_ratio(Linear::<f64, 2>::new(&m, &c, &k, h).map(|s| s.a_form()), &m, &k, &u0, &v0, 300)),
            ("compensated", energy_ratio(CompensatedLinear::<f64, 2>::new(&m, &c, &k, h), &m, &k, &u0, &v0, 300)),
            ("newmark", energy_ratio(Newmark::<f64, 2>::average_acceleration(&m, &c, &k, h), &m, &k, &u0, &v0, 300)),
        ] {
            let r = r.map_err(|e| TestCaseError::fail(format!("{name}: {e:?}, h = {h:e}")))?;
            note_growth(name, r - 1.0);
            prop_assert!(r < 1.0 + energy_tol(10f64.powi(wh)), "{}: energy ratio {}", name, r);
        }
        // Generalized-α dissipates; it must not add energy beyond the same rounding.
        let ga = GeneralizedAlpha::<f64, 2>::with_parameters(&m, &c, &k, h, AlphaParameters::chung_hulbert(rho).unwrap());
        if let Ok(r) = energy_ratio(ga, &m, &k, &u0, &v0, 300) {
            count("energy", "generalized_alpha");
            note_growth("generalized_alpha", r - 1.0);
            prop_assert!(r < 1.0 + energy_tol(10f64.powi(wh)), "generalized-α: energy ratio {}", r);
        }
    }
}

/// Prints the counts (run last: `cargo test --test properties -- --nocapture
/// --test-threads 1` runs the tests in name order).
#[test]
fn zz_counts() {
    for t in [
        "aform",
        "linear",
        "compensated",
        "newmark",
        "generalized_alpha",
        "linear_input",
        "exact",
        "modal",
        "nonlinear",
        "varying",
        "energy",
    ] {
        print_counts(t);
    }
    for (name, g) in GROWTH.lock().unwrap().iter() {
        println!("GROWTH {name} {g:.1e}");
    }
}
