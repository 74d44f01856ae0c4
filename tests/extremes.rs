//! Stability and accuracy at the extremes: s = ωh over twelve decades, 10⁶ and 10⁷ steps,
//! stiff systems, an ill-conditioned mass matrix, a tiny step and a huge time.
//!
//! Every bound is derived in a comment from the scheme's known error (spec §4) and the
//! rounding unit; the measured values are printed (`--nocapture`) and quoted.

#[path = "support/runs.rs"]
mod runs;
mod support;

use aemstep::analysis::{Scheme, sdof};
use aemstep::{Exact, GeneralizedAlpha, Linear, Newmark, State, Stepper};
use nalgebra::{SMatrix, SVector, matrix, vector};
use runs::{free_vibration, undamped_drift};

const EPS: f64 = f64::EPSILON;
const EPS32: f64 = f32::EPSILON as f64;

fn s_grid() -> Vec<f64> {
    (-24..=24).map(|i| 10f64.powf(i as f64 / 4.0)).collect()
}

#[test]
fn spectral_radius_at_most_one_plus_ulps_from_1e_minus6_to_1e6() {
    // Unconditionally stable schemes: ρ(A) ≤ 1 in exact arithmetic (= 1 for the AEM at
    // ξ = 0). The computed A (entries O(1) in (u, hv, h²a)) and its characteristic
    // polynomial carry a few ulps: bound 1 + 4ε (measured: 1 + 1ε). The exact scheme's Φ
    // comes from a Taylor polynomial (error ~ε) squared k = ⌈log₂ 2s⌉ times, and each
    // squaring doubles the relative error: ~2^k ε ≈ 2s ε. It is not norm-preserving by
    // construction, so its bound is 1 + 8 max(1, s) ε (measured: 1 + 150ε at s = 178,
    // below 1 at s = 1e6).
    let schemes = [
        Scheme::Aem,
        Scheme::AemAForm,
        Scheme::Newmark {
            beta: 0.25,
            gamma: 0.5,
        },
        Scheme::GeneralizedAlpha { rho_inf: 0.0 },
        Scheme::GeneralizedAlpha { rho_inf: 0.8 },
        Scheme::Hht { alpha: -0.1 },
        Scheme::Exact,
    ];
    for sch in schemes {
        let mut worst = f64::NEG_INFINITY;
        for &xi in &[0.0, 0.05] {
            for s in s_grid() {
                let bound = if sch == Scheme::Exact {
                    8.0 * s.max(1.0) * EPS
                } else {
                    4.0 * EPS
                };
                let r = sdof(sch, s, xi).unwrap().spectral_radius;
                assert!(
                    r <= 1.0 + bound,
                    "{sch:?} s={s:e} ξ={xi}: ρ−1 = {:e}",
                    r - 1.0
                );
                worst = worst.max(r - 1.0);
            }
        }
        println!(
            "{sch:?}: max ρ − 1 over s ∈ [1e-6, 1e6] = {worst:e} ({:.1} ε)",
            worst / EPS
        );
    }
}

/// Energy `u² + v²` (ω = 1) over `n` steps from u0 = 1, v0 = 0 (E0 = 1): returns
/// (max over all steps of E − 1, max over the first 1000 steps of E, max over the second
/// half of the run of E).
fn growth<S: Stepper<f64, 1, Input = SVector<f64, 1>, State = State<f64, 1>>>(
    sys: &S,
    n: usize,
) -> (f64, f64, f64) {
    let z = vector![0.0];
    let mut s = sys.start(&vector![1.0], &vector![0.0], &z).unwrap();
    let (mut worst, mut early, mut late) = (f64::NEG_INFINITY, 0.0f64, 0.0f64);
    for i in 0..n {
        sys.step(&mut s, &z);
        let e = s.u()[0] * s.u()[0] + s.v()[0] * s.v()[0];
        worst = worst.max(e - 1.0);
        if i < 1000 {
            early = early.max(e);
        }
        if i >= n / 2 {
            late = late.max(e);
        }
    }
    (worst, early, late)
}

#[test]
#[ignore = "long: run in release by scripts/test.sh"]
fn no_growth_over_a_million_steps() {
    // ω = 1, h = s, u0 = 1, v0 = 0, energy E = u² + v² (E0 = 1), 10⁶ steps.
    //
    // Noise floor: the eliminated step forms u_n = û + (h²/4) q_n with û and (h²/4) q_n of
    // size ~s²/4 that cancel to O(1), so each step injects a rounding error ~ε s²/4 into
    // u: the energy of the first steps may differ from 1 by 2 · 2ε(1 + s²/4) (measured
    // 6.4e-5 at s = 1e6, 1.6e-10 at s = 1e3, ≤ 5e-13 for s ≤ 1).
    //
    // No growth: ρ(A) ≤ 1 + ε (AEM, Newmark-AA; previous test) so beyond that floor the
    // energy can rise by at most 2ε a step: E − 1 ≤ floor + n · 2ε over the whole run.
    // For the other schemes: the second half of the run may not exceed the first 1000
    // steps by more than floor + n · 2ε; for the exact scheme ρ − 1 ≤ 8 s ε adds
    // n · 16 s ε (vacuous for s ≥ 1e3, where its measured E nevertheless decreases).
    //
    // Generalized-α (ρ∞ = 0.8): ρ(A) < 1, but A is not normal and for s ≫ 1 the velocity
    // overshoots in the first steps (measured peak E ≈ 420 at s = 1e3); the same
    // no-growth criterion applies.
    let n = 1_000_000;
    let drift = n as f64 * 2.0 * EPS;
    for &xi in &[0.0, 0.05] {
        for s in [1e-6, 1e-3, 1.0, 1e3, 1e6] {
            let (m, c, k) = (matrix![1.0], matrix![2.0 * xi], matrix![1.0]);
            let floor = 4.0 * EPS * (1.0 + s * s / 4.0);
            let runs = [
                (
                    "aem",
                    growth(&Linear::<f64, _>::new(&m, &c, &k, s).unwrap(), n),
                    0.0,
                ),
                (
                    "newmark-aa",
                    growth(
                        &Newmark::<f64, _>::average_acceleration(&m, &c, &k, s).unwrap(),
                        n,
                    ),
                    0.0,
                ),
                (
                    "exact",
                    growth(&Exact::<f64, _>::new(&m, &c, &k, s).unwrap(), n),
                    n as f64 * 16.0 * s.max(1.0) * EPS,
                ),
                (
                    "gen-α 0.8",
                    growth(
                        &GeneralizedAlpha::<f64, _>::new(&m, &c, &k, s, 0.8).unwrap(),
                        n,
                    ),
                    0.0,
                ),
            ];
            for (name, (worst, early, late), extra) in runs {
                println!(
                    "ξ={xi} s={s:e} {name}: max E−1 {worst:e}, early max E {early:e}, late max E {late:e}"
                );
                assert!(
                    late <= early + floor + drift + extra,
                    "{name} ξ={xi} s={s:e}: grew"
                );
                if name != "gen-α 0.8" && name != "exact" {
                    assert!(worst <= floor + drift, "{name} ξ={xi} s={s:e}: {worst:e}");
                }
            }
        }
    }
}

#[test]
#[ignore = "long: run in release by scripts/test.sh"]
fn ten_million_undamped_steps_f64_and_f32() {
    let n = 10_000_000;
    // 10⁷ undamped steps, ω = 2π, h = 0.01: (max |E/E0 − 1|, final |E/E0 − 1|, max
    // |u − cos(nφ)|) with φ the operators' own phase per step (tests/support/runs.rs).
    let (e64, f64_final, u64) = undamped_drift::<f64>(n);
    let (e32, f32_final, u32_) = undamped_drift::<f32>(n);
    println!("f64: max |ΔE/E| {e64:e}, final {f64_final:e}, max |u − cos(nφ)| {u64:e}");
    println!("f32: max |ΔE/E| {e32:e}, final {f32_final:e}, max |u − cos(nφ)| {u32_:e}");
    // f64: per step the energy picks up ≲ 2ε relative rounding; worst case linear growth
    // 10⁷·2ε = 4.4e-9. The phase against the operators' own φ drifts by ≲ 2ε per step:
    // 4.4e-9 rad, plus the f64 phase φ itself from the analysis (≤ 16ε/s relative, times
    // n·φ ≈ 6e5 rad → 6e5 · 16ε/… ≈ 1e-7·…): bound 1e-6 on u.
    assert!(e64 <= n as f64 * 2.0 * EPS, "{e64:e}");
    assert!(u64 <= 1e-6, "{u64:e}");
    // f32: the same reasoning with ε₃₂: energy ≤ 10⁷ · 2 ε₃₂ = 2.4 (vacuous) in the worst
    // case; unbiased roundings make a random walk, √n · 2ε₃₂ ≈ 7.5e-4 (measured 1.2e-4).
    // The phase is not a random walk: the f32 rounding of the state is biased and the
    // phase drifts systematically (measured |Δu| 9.4e-3 after 10⁷ steps; issue 10's
    // drift study measures it per 10⁸ steps). Its worst-case bound is vacuous, so the
    // check is a regression pin at twice the measured value.
    assert!(e32 <= (n as f64).sqrt() * 2.0 * EPS32, "{e32:e}");
    assert!(u32_ <= 2e-2, "{u32_:e} (regression pin)");
}

/// Rotation by θ: the modal matrix used to make the extreme systems fully populated.
fn rot(t: f64) -> SMatrix<f64, 2, 2> {
    matrix![t.cos(), -t.sin(); t.sin(), t.cos()]
}

/// Run a 2-DOF stepper from u0 (v0 = 0, p = 0) for `n` steps; returns the final state
/// as (u, v).
fn run2<S: Stepper<f64, 2, Input = SVector<f64, 2>, State = State<f64, 2>>>(
    sys: &S,
    u0: SVector<f64, 2>,
    n: usize,
) -> (SVector<f64, 2>, SVector<f64, 2>) {
    let z = SVector::<f64, 2>::zeros();
    let mut s = sys.start(&u0, &z, &z).unwrap();
    for _ in 0..n {
        sys.step(&mut s, &z);
        assert!(s.is_finite());
    }
    (*s.u(), *s.v())
}

#[test]
fn stiff_system_frequency_ratio_1e6() {
    // M = I, K = P diag(1, 1e12) Pᵀ with P = [[3, −4], [4, 3]] (PᵀP = 25 I): every entry
    // of K is an integer below 2⁵³, so K is exact and its eigenpairs are known exactly:
    // ω1 = 5, ω2 = 5e6 rad/s (ratio 1e6), modes Q = P/5. (A K rounded from Q D Qᵀ would
    // carry an error ε·1e12 on the soft eigenvalue, i.e. a problem error, not a scheme
    // error.) h = 0.002: s1 = 0.01, s2 = 1e4. Initial displacement η = (1, 1e-6) in modal
    // coordinates (equal energy in both modes), v0 = 0, 1000 steps (t = 2 s).
    let p = matrix![3.0, -4.0; 4.0, 3.0];
    let k = p * SMatrix::<f64, 2, 2>::from_diagonal(&vector![1.0, 1e12]) * p.transpose();
    assert_eq!(k[(0, 1)], -11999999999988.0);
    let q = p / 5.0;
    let (w1, w2) = (5.0f64, 5e6f64);
    let (m, c) = (
        SMatrix::<f64, 2, 2>::identity(),
        SMatrix::<f64, 2, 2>::zeros(),
    );
    let (h, n) = (0.002, 1000);
    let t = n as f64 * h;
    let u0 = q * vector![1.0, 1e-6];
    let modal = |u: SVector<f64, 2>| q.transpose() * u;
    let eta0 = modal(u0);
    // AEM: mode 1 has the phase φ1 = 2 atan(s1/2) per step exactly, so η1 = η1(0) cos(nφ1)
    // up to rounding. The rounding that matters: G·K is formed explicitly, and its entries
    // are sums of terms ~‖K‖·‖G‖ ≈ 1e13 that cancel to the soft eigenvalue 25: an absolute
    // error ~ε‖K‖ ≈ 4e-3 on it, i.e. a relative frequency error δω1/ω1 ≲ ε‖K‖/(2ω1²)
    // ≈ 7e-5, and a phase error ≤ ω1 t · 7e-5 = 7e-4 after 10 rad. (Any K with this
    // eigenvalue spread is known only to ε‖K‖ anyway; the kernel adds the same order.)
    let aem = Linear::<f64, _>::new(&m, &c, &k, h).unwrap();
    let (u, v) = run2(&aem, u0, n);
    let (eu, ev) = (modal(u), modal(v));
    let phi1 = 2.0 * (w1 * h / 2.0).atan();
    let e1 = (eu[0] - eta0[0] * (n as f64 * phi1).cos()).abs();
    let kn = 1.6e13 + 1.2e13;
    let bound1 = w1 * t * EPS * kn / (2.0 * w1 * w1);
    // The same rounding couples the modes: each step moves ~(h²/4) ε‖K‖ |η1| ≈ 6e-9 of
    // displacement into the stiff mode, whose own amplitude is only 1e-6; the modal
    // energy (ω1²η1² + η̇1² + ω2²η2² + η̇2²)/2 = 25 is conserved by the scheme, so its
    // relative error is bounded by n · ω2² · 1e-6 · 6e-9 / 25 ≈ 6e-2 (worst case linear
    // accumulation); measured below.
    let energy = |eu: SVector<f64, 2>, ev: SVector<f64, 2>| {
        0.5 * (w1 * w1 * eu[0] * eu[0] + ev[0] * ev[0] + w2 * w2 * eu[1] * eu[1] + ev[1] * ev[1])
    };
    let e0 = energy(eta0, SVector::zeros());
    let e2 = (energy(eu, ev) / e0 - 1.0).abs();
    println!(
        "stiff AEM: mode-1 error vs η1(0)cos(nφ) {e1:e} (bound {bound1:e}), modal energy error {e2:e}"
    );
    assert!(e1 < bound1, "{e1:e}");
    // Measured 8.7e-7 and 1.0e-8: both far inside the worst-case bounds above, which
    // assume every rounding adds up; regression pins at 10× the measured values catch a
    // change that lets the stiff mode's rounding leak into the soft one.
    assert!(e1 < 1e-5, "{e1:e} (regression pin)");
    assert!(e2 < 1e-7, "{e2:e} (regression pin)");
    // Against the true cos(ω1 t): the period error s1²/12 gives a phase lag ω1 t s1²/12.
    let lag = w1 * t * (w1 * h).powi(2) / 12.0;
    assert!((eu[0] - eta0[0] * (w1 * t).cos()).abs() <= lag * 1.01 + bound1);

    // Exact scheme: both modes exact up to rounding. Its folded operators contain
    // P0·K (P0 ≈ h²/2 M⁻¹), with the same ε‖K‖ cancellation on the soft mode as the AEM's
    // G·K: mode 1 has the same bound. Mode 2 (amplitude 1e-6): the exponential's
    // squaring error ~2^15 ε ≈ 7e-12 a step, plus the coupling from mode 1,
    // ≤ ε (h²/2)‖K‖ |η1| ≈ 1.2e-8 a step (1.2e-2 relative), unsigned; bound 1.2e-2.
    let ex = Exact::<f64, _>::new(&m, &c, &k, h).unwrap();
    let (u, _) = run2(&ex, u0, n);
    let eu = modal(u);
    let x1 = (eu[0] - eta0[0] * (w1 * t).cos()).abs();
    let x2 = (eu[1] - eta0[1] * (w2 * t).cos()).abs() / eta0[1];
    println!("stiff exact: mode-1 error {x1:e}, mode-2 relative error {x2:e}");
    assert!(x1 < bound1, "{x1:e}");
    assert!(x2 < 1.2e-2, "{x2:e}");

    // Generalized-α with ρ∞ = 0 annihilates the stiff mode (ρ ≈ 2e-3 at s = 1e4), down to
    // the rounding coupling from mode 1 that is re-injected every step, ≤ (h²/4) ε ‖K‖
    // |η1| ≈ 6e-9 (and damped at once): |η2| ≤ 1e-8 from 1e-6. Mode 1 keeps its
    // O(s1²) phase error (Chung–Hulbert's PE at ρ∞ = 0 is ≈ 3× the AEM's: measured).
    let ga = GeneralizedAlpha::<f64, _>::new(&m, &c, &k, h, 0.0).unwrap();
    let (u, _) = run2(&ga, u0, n);
    let eu = modal(u);
    let g1 = (eu[0] - eta0[0] * (w1 * t).cos()).abs();
    println!(
        "stiff gen-α ρ∞=0: mode-1 error {g1:e}, |η2| {:e}",
        eu[1].abs()
    );
    assert!(eu[1].abs() < 1e-8, "{:e}", eu[1]);
    assert!(g1 < 4.0 * lag, "{g1:e} vs lag {lag:e}");
}

#[test]
fn ill_conditioned_mass_condition_1e8() {
    // M = Q diag(1, 1e-8) Qᵀ (cond 1e8), K = I: modes are Q's columns with ω1 = 1,
    // ω2 = 1e4. h = 1e-3 (s1 = 1e-3, s2 = 10), 10 s, initial η = (1, 1e-4), v0 = 0.
    let q = rot(0.7);
    let m = q * SMatrix::<f64, 2, 2>::from_diagonal(&vector![1.0, 1e-8]) * q.transpose();
    let (c, k) = (
        SMatrix::<f64, 2, 2>::zeros(),
        SMatrix::<f64, 2, 2>::identity(),
    );
    let (h, n) = (1e-3, 10_000);
    let t = n as f64 * h;
    let u0 = q * vector![1.0, 1e-4];
    // Start-up: a0 = −M⁻¹ K u0 = −Q diag(1, 1e8) Qᵀ u0 = −Q (1, 1e4). M⁻¹ carries a
    // relative error ~cond(M) ε = 2e-8.
    let aem = Linear::<f64, _>::new(&m, &c, &k, h).unwrap();
    let z = SVector::<f64, 2>::zeros();
    let s0 = aem.start(&u0, &z, &z).unwrap();
    let a0 = -(q * vector![1.0, 1e4]);
    let rel = (s0.a() - a0).norm() / a0.norm();
    println!("ill-conditioned M: start-up a0 relative error {rel:e}");
    assert!(rel < 1e8 * EPS * 10.0, "{rel:e}");
    // Mode 1 against the AEM's own phase cos(nφ1), φ1 = 2 atan(s1/2): rounding only, but
    // amplified by cond(M) through G = M_eff⁻¹: ≲ n · 1e8 · ε ≈ 2e-4 worst case; the
    // measured error is far below; bound 2e-4.
    let (u, _) = run2(&aem, u0, n);
    let eta = q.transpose() * u;
    let phi1 = 2.0 * (h / 2.0f64).atan();
    let e1 = (eta[0] - (n as f64 * phi1).cos()).abs();
    // Mode 2 (s2 = 10, aliased, |λ| = 1): amplitude kept at 1e-4.
    println!(
        "ill-conditioned M: AEM mode-1 error vs cos(nφ) {e1:e}, |η2| {:e}",
        eta[1].abs()
    );
    assert!(e1 < 2e-4, "{e1:e}");
    assert!(eta[1].abs() <= 1e-4 * (1.0 + 1e-6));
    let _ = t;
}

#[test]
#[ignore = "long: run in release by scripts/test.sh"]
fn tiny_step_1e_minus9() {
    // u'' + ω² u = 0, ω = 2π, h = 1e-9 s (s = 6.3e-9), 10⁶ steps to t = 1e-3 s.
    let w = 2.0 * core::f64::consts::PI;
    let (h, n) = (1e-9, 1_000_000);
    let t = n as f64 * h;
    // f64: the period error s²/12 = 3e-18 is nothing; u ≈ 1 takes a rounding of ≤ ε/2 each
    // step (u + h v with |h v| ≤ 6e-9): ≤ n ε/2 = 1.1e-10 on u.
    let s = free_vibration::<f64>(w, h, n);
    let e = (s.u()[0] - (w * t).cos()).abs();
    let ev = (s.v()[0] + w * (w * t).sin()).abs();
    println!(
        "h = 1e-9, f64: |Δu| {e:e}, |Δv| {ev:e} (v = {:e})",
        s.v()[0]
    );
    assert!(e <= n as f64 * EPS / 2.0, "{e:e}");
    assert!((s.time(h) - t).abs() <= EPS * t);
    // f32: a displacement increment h v ≤ 2.5e-13 is far below half an ulp of u ≈ 1
    // (6e-8): u stagnates at exactly 1, so the error is |1 − cos(ωt)| = 2e-5. This is the
    // expected f32 limit (use f64, or a larger h, when h·v ≪ ε₃₂·|u|).
    let s = free_vibration::<f32>(w, h, n);
    let e32 = (s.u()[0] as f64 - (w * t).cos()).abs();
    println!(
        "h = 1e-9, f32: u = {} (stagnates), |Δu| {e32:e}, v = {:e}",
        s.u()[0],
        s.v()[0]
    );
    assert!(s.is_finite());
    assert_eq!(s.u()[0], 1.0);
    assert!(e32 <= (1.0 - (w * t).cos()) + 1e-12);
}

#[test]
#[ignore = "long: run in release by scripts/test.sh"]
fn huge_time_1e6_seconds() {
    // u'' + ω² u = 0, ω = 0.1, h = 1 s (s = 0.1), 10⁶ steps to t = 10⁶ s (≈ 16 000 periods).
    let (w, h, n) = (0.1f64, 1.0, 1_000_000usize);
    let t = n as f64 * h;
    let (m, c, k) = (matrix![1.0], matrix![0.0], matrix![w * w]);
    // AEM: exactly cos(nφ) with φ = 2 atan(s/2); rounding drifts the phase by ≲ 2ε a step
    // (relative to φ·n ≈ 1e5 rad): ≤ n · 2ε · … ≈ 4.4e-10 rad, plus the f64 evaluation
    // of cos(nφ) at 1e5 rad (≈ 1e5 ε): bound 1e-9.
    let aem = Linear::<f64, _>::new(&m, &c, &k, h).unwrap();
    let mut s = aem
        .start(&vector![1.0], &vector![0.0], &vector![0.0])
        .unwrap();
    for _ in 0..n {
        aem.step(&mut s, &vector![0.0]);
    }
    assert_eq!(s.time(h), 1e6);
    let phi = 2.0 * (0.1f64 / 2.0).atan();
    let e_disc = (s.u()[0] - (n as f64 * phi).cos()).abs();
    let e_true = (s.u()[0] - (w * t).cos()).abs();
    println!(
        "t = 1e6 s, AEM: |u − cos(nφ)| {e_disc:e}, |u − cos(ωt)| {e_true:e} (phase lag n(s − φ) = {:e} rad)",
        n as f64 * (0.1 - phi)
    );
    assert!(e_disc < 1e-9, "{e_disc:e}");
    // Exact scheme: against cos(ωt) itself. Its Φ has a phase error ≲ 2ε per step (no
    // squaring at s = 0.1): ≤ n · 2ε ≈ 4.4e-10 rad; bound 1e-9.
    let ex = Exact::<f64, _>::new(&m, &c, &k, h).unwrap();
    let mut s = ex
        .start(&vector![1.0], &vector![0.0], &vector![0.0])
        .unwrap();
    for _ in 0..n {
        ex.step(&mut s, &vector![0.0]);
    }
    let e_ex = (s.u()[0] - (w * t).cos()).abs();
    println!("t = 1e6 s, exact: |u − cos(ωt)| {e_ex:e}");
    assert!(e_ex < 1e-9, "{e_ex:e}");
}
