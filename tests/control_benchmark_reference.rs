//! The independent reference of the MR-damper benchmark of Dyke, Spencer, Sain & Carlson
//! (1996) (`tests/support/dyke1996.rs`): its pieces checked against closed forms (fast),
//! and its peak-response table (an `#[ignore]`d release run, printed beside what the
//! paper's table holds — which the stored text did not give: see
//! `docs/control-benchmark-data.md`).
//!
//! Nothing here calls `aemstep`'s control or device code: a later scene compares the
//! crate's simulation with [`dyke1996::simulate`].

#[path = "support/dyke1996.rs"]
mod dyke1996;
#[path = "../scenes/modal/elcentro.rs"]
mod elcentro;

use dyke1996::{Attached, DAMPER, Peaks, Record, STRUCTURE, damper_rates, rates, rk4, simulate};
use nalgebra::{SMatrix, SVector};

/// The damper driven at constant velocity `ẋ = v₀ > 0` from `z = 0`, `u = 0` under a held
/// command `V`: with `n = 1` and `γ = β` the Bouc–Wen equation is `ż = v₀ (A − (β+γ) z)`
/// for `z ≥ 0`, so `z(t) = z_u (1 − e^{−(β+γ) v₀ t})`, `z_u = A/(β+γ)`; the filter gives
/// `u(t) = V (1 − e^{−ηt})`. RK4 with `h = 1e-5` s against these: the fastest rate is
/// `(β+γ) v₀ = 120 s⁻¹` at `v₀ = 0.2 m/s`, `λh ≈ 1.2e-3`, so RK4's global error is of
/// order `λt (λh)⁴/120 ≈ 4e-14` of the transient's scale; rounding over 2000 steps adds at
/// most about `2000 ε ≈ 4e-13`. Bound 1e-12 (measured 6.4e-15 for `z`, 1.7e-14 for `f`).
#[test]
fn damper_at_constant_velocity_matches_the_closed_form() {
    let d = DAMPER;
    assert_eq!(
        (d.n, d.gamma),
        (1.0, d.beta),
        "the closed form needs n = 1, γ = β"
    );
    let v0 = 0.2; // m/s
    let vcmd = d.v_max;
    let h = 1e-5;
    let zu = d.a / (d.beta + d.gamma);
    let rate = v0 * (d.beta + d.gamma);
    let mut y = [0.0_f64; 2]; // [z, u]
    let mut worst = [0.0_f64; 3];
    for n in 0..2000 {
        y = rk4(n as f64 * h, &y, h, |_, yy| {
            let (_, zd, ud) = damper_rates(&d, v0, yy[0], yy[1], vcmd);
            [zd, ud]
        });
        let t = (n + 1) as f64 * h;
        let z = zu * (1.0 - (-rate * t).exp());
        let u = vcmd * (1.0 - (-d.eta * t).exp());
        let f = (d.c0a + d.c0b * u) * v0 + (d.alpha_a + d.alpha_b * u) * z;
        let (fy, _, _) = damper_rates(&d, v0, y[0], y[1], vcmd);
        worst[0] = worst[0].max((y[0] - z).abs() / zu);
        worst[1] = worst[1].max((y[1] - u).abs() / vcmd);
        worst[2] = worst[2].max((fy - f).abs() / f.abs().max(1.0));
    }
    println!(
        "constant velocity: max rel. error z {:.2e}, u {:.2e}, f {:.2e}",
        worst[0], worst[1], worst[2]
    );
    assert!(worst.iter().all(|&e| e < 1e-12), "{worst:?}");
}

/// The bare structure in free vibration from a displaced shape, RK4 (`h = 1e-4` s) against
/// the exact solution `y(t) = e^{At} y₀` of the 6-state linear system (nalgebra's matrix
/// exponential). The highest natural frequency is `ω₃ ≈ 149 rad/s`, `ω₃h ≈ 0.015`: RK4's
/// relative error is at most `≈ ω₃ t (ω₃h)⁴/120 ≈ 3e-8` at `t = 0.5` s, less where the
/// lower modes carry the motion; measured 2.5e-10 of the largest state entry (the
/// velocities, m/s) at `t = 0.5` s: 1.1e-9, bound 3e-9.
#[test]
fn structure_free_vibration_matches_the_matrix_exponential() {
    let s = STRUCTURE;
    let mut a = SMatrix::<f64, 6, 6>::zeros();
    for i in 0..3 {
        a[(i, 3 + i)] = 1.0;
        for j in 0..3 {
            a[(3 + i, j)] = -s.k[i][j] / s.m[i];
            a[(3 + i, 3 + j)] = -s.c[i][j] / s.m[i];
        }
    }
    let omega_max = {
        let mk = SMatrix::<f64, 3, 3>::from_fn(|i, j| s.k[i][j] / (s.m[i] * s.m[j]).sqrt());
        mk.symmetric_eigenvalues().max().sqrt()
    };
    let h = 1e-4;
    assert!(omega_max * h < 0.02, "ω₃ = {omega_max}");
    let y0 = [0.01, 0.02, 0.03, 0.0, 0.0, 0.0, 0.0, 0.0];
    let mut y = y0;
    let steps = 5000;
    for n in 0..steps {
        y = rk4(n as f64 * h, &y, h, |_, yy| {
            rates(&s, &DAMPER, Attached::No, 0.0, yy, 0.0).0
        });
    }
    let exact = (a * (steps as f64 * h)).exp() * SVector::<f64, 6>::from_fn(|i, _| y0[i]);
    let err = (0..6).map(|i| (y[i] - exact[i]).abs()).fold(0.0, f64::max);
    let scale = exact.abs().max();
    println!("free vibration: ω₃ = {omega_max:.1} rad/s, max error {err:.2e} of {scale:.2}");
    assert!(err < 3e-9 * scale, "{err} of {scale}");
}

#[test]
fn record_is_linear_between_samples_and_zero_after() {
    let ag = [1.0, 3.0, -1.0];
    let r = Record {
        ag: &ag,
        dt: 0.02,
        time_scale: 0.2,
        amplitude: 2.0,
    };
    assert!((r.model_dt() - 0.004).abs() < 1e-18);
    assert_eq!(r.at(0.0), 2.0);
    assert!((r.at(0.002) - 4.0).abs() < 1e-12); // midway 1 → 3, ×2
    assert!((r.at(0.006) - 2.0).abs() < 1e-12); // midway 3 → −1, ×2
    assert!((r.at(0.008) + 2.0).abs() < 1e-12);
    assert_eq!(r.at(0.0081), 0.0);
    assert_eq!(r.at(-1.0), 0.0);
}

/// The El Centro record of the repository (`data/elcentro-ns-1940.txt`, dt 0.02 s, in g →
/// m/s²) played at five times the recorded rate, full amplitude — the reading of the
/// benchmark this reference assumes (UNVERIFIED against the paper's text: see
/// `docs/control-benchmark-data.md`).
fn benchmark_record() -> Record<'static> {
    Record {
        ag: &elcentro::AG_F64,
        dt: elcentro::DT,
        time_scale: 0.2,
        amplitude: 1.0,
    }
}

/// The three passive configurations: uncontrolled (no damper), passive-off (0 V),
/// passive-on (`V_max`), with RK4 of step `h` and 1 s of free vibration after the record.
pub fn passive_peaks(h: f64) -> [Peaks; 3] {
    let rec = benchmark_record();
    [
        simulate(
            &STRUCTURE,
            &DAMPER,
            &rec,
            Attached::No,
            h,
            1.0,
            |_, _, _| 0.0,
        ),
        simulate(
            &STRUCTURE,
            &DAMPER,
            &rec,
            Attached::Yes,
            h,
            1.0,
            |_, _, _| 0.0,
        ),
        simulate(
            &STRUCTURE,
            &DAMPER,
            &rec,
            Attached::Yes,
            h,
            1.0,
            |_, _, _| DAMPER.v_max,
        ),
    ]
}

fn row(name: &str, p: &Peaks) -> String {
    format!(
        "| {name} | {:.4} {:.4} {:.4} | {:.4} {:.4} {:.4} | {:.1} {:.1} {:.1} | {:.1} |",
        p.displacement[0] * 100.0,
        p.displacement[1] * 100.0,
        p.displacement[2] * 100.0,
        p.drift[0] * 100.0,
        p.drift[1] * 100.0,
        p.drift[2] * 100.0,
        p.acceleration[0],
        p.acceleration[1],
        p.acceleration[2],
        p.force
    )
}

/// The benchmark's passive rows by the reference, RK4 at `h = 1e-4` s (40 steps per model
/// sample of the record, so its kinks fall on step boundaries) and at `h/2`. The peaks are
/// read on the step grid, so beside RK4's `O(h⁴)` state error they carry a sampling error
/// `O(h²)`: at most `(ω h)²/8` relative for a component of frequency `ω`, `2.8e-5` for
/// the structure's highest mode (`ω₃ = 148.5 rad/s`) — the bound on displacements and
/// drifts (measured 2.6e-6). Accelerations and the force also follow the damper's
/// Bouc–Wen transitions at velocity reversals (time scale `1/((β+γ)|ẋ|) ≈ 3e-2` s at
/// 5 cm/s) and the force jumps of `c₀ ẋ`: their bounds, 1e-5 (measured 4.3e-6) and 1e-6
/// (measured 5.1e-7), are regression pins, not derived.
///
/// The paper's table is not in the stored text (docs/control-benchmark-data.md), so there
/// is no side-by-side comparison to assert: the paper's column prints "n/a". The paper's
/// clipped-optimal row needs its H2/LQG weights and noise intensities, also not in the
/// stored text: `benchmark_clipped_optimal_row` runs the controller with assumed ones.
///
/// `cargo test --release --features std --test control_benchmark_reference -- --ignored --nocapture`
#[test]
#[ignore = "release stage: three 17 s model-time runs at two steps (~1-2 s in release)"]
fn benchmark_passive_table() {
    let coarse = passive_peaks(1e-4);
    let fine = passive_peaks(5e-5);
    // Largest relative difference per quantity: displacements and drifts, accelerations,
    // force.
    let mut worst = [0.0_f64; 3];
    let rel = |a: f64, b: f64| if b > 0.0 { (a - b).abs() / b } else { 0.0 };
    for (c, f) in coarse.iter().zip(&fine) {
        for i in 0..3 {
            worst[0] = worst[0].max(rel(c.displacement[i], f.displacement[i]));
            worst[0] = worst[0].max(rel(c.drift[i], f.drift[i]));
            worst[1] = worst[1].max(rel(c.acceleration[i], f.acceleration[i]));
        }
        worst[2] = worst[2].max(rel(c.force, f.force));
    }
    println!(
        "| case | displacement x1 x2 x3 (cm) | drift d1 d2 d3 (cm) | abs. acceleration a1 a2 a3 (m/s²) | damper force (N) |"
    );
    println!("|---|---|---|---|---|");
    for (name, p) in ["uncontrolled", "passive-off (0 V)", "passive-on (V_max)"]
        .iter()
        .zip(&fine)
    {
        println!("{}", row(name, p));
    }
    println!("paper (Dyke et al. 1996, its table of peak responses): n/a — not in the stored text");
    println!(
        "h = 1e-4 s against h = 5e-5 s: largest relative difference of a peak: displacement/drift {:.2e}, acceleration {:.2e}, force {:.2e}",
        worst[0], worst[1], worst[2]
    );
    assert!(worst[0] < 2.8e-5, "{worst:?}");
    assert!(worst[1] < 1e-5, "{worst:?} (regression pin)");
    assert!(worst[2] < 1e-6, "{worst:?} (regression pin)");
    // The uncontrolled run has no damper force; the damper runs do.
    assert_eq!(fine[0].force, 0.0);
    assert!(fine[1].force > 0.0 && fine[2].force > fine[1].force);
}

/// The scalar CARE `2a p − p² b²/r + q = 0` has the stabilizing root
/// `p = r (a + √(a² + b² q / r)) / b²`; Newton–Kleinman from `K₀ = 0` (needs `a < 0`)
/// reaches it to its stopping rule (relative change `< 1e-13`, quadratic convergence).
#[test]
fn care_scalar_closed_form() {
    use nalgebra::DMatrix;
    let (a, b, q, r): (f64, f64, f64, f64) = (-0.7, 2.0, 3.0, 0.5);
    let exact = r * (a + (a * a + b * b * q / r).sqrt()) / (b * b);
    let one = |x: f64| DMatrix::from_element(1, 1, x);
    let (p, k) = dyke1996::lqg::care(&one(a), &one(b), &one(q), &one(r));
    println!(
        "scalar CARE: p = {}, exact {exact}, rel. error {:.1e}",
        p[(0, 0)],
        (p[(0, 0)] - exact).abs() / exact
    );
    assert!((p[(0, 0)] - exact).abs() < 1e-14 * exact);
    assert!((k[(0, 0)] - b * exact / r).abs() < 1e-13 * k[(0, 0)]);
}

/// The benchmark-sized design (the weights of `benchmark_clipped_optimal_row`, NOT the
/// paper's): both Riccati residuals, relative to the largest term, at rounding level
/// (measured 7e-16 and 2e-14: the Kronecker solves of the 36×36 systems lose a few digits
/// to their conditioning; bound 1e-12); the closed loops `A − BK` and `A − LC` stable.
#[test]
fn benchmark_design_solves_its_riccati_equations() {
    let g = dyke1996::design(&STRUCTURE, Q_DISP, R_FORCE, GROUND, SENSOR);
    let bt = g.b.transpose();
    let res =
        g.a.transpose() * &g.p + &g.p * &g.a - &g.p * &g.b * &bt * &g.p / R_FORCE + q_matrix();
    let scale = (g.a.transpose() * &g.p).abs().max();
    let dual = &g.a * &g.sigma + &g.sigma * g.a.transpose()
        - &g.sigma * g.c.transpose() * &g.c * &g.sigma / SENSOR
        + e_matrix() * GROUND * e_matrix().transpose();
    let dscale = (&g.a * &g.sigma).abs().max();
    let closed = (&g.a - &g.b * &g.k).complex_eigenvalues();
    let observer = (&g.a - &g.l * &g.c).complex_eigenvalues();
    let worst = |e: &nalgebra::DVector<nalgebra::Complex<f64>>| {
        e.iter().map(|z| z.re).fold(f64::MIN, f64::max)
    };
    println!(
        "CARE residual {:.1e}, dual {:.1e}; slowest closed-loop pole re {:.3}, observer {:.3} (1/s)",
        res.abs().max() / scale,
        dual.abs().max() / dscale,
        worst(&closed),
        worst(&observer)
    );
    assert!(res.abs().max() < 1e-12 * scale);
    assert!(dual.abs().max() < 1e-12 * dscale);
    assert!(worst(&closed) < 0.0 && worst(&observer) < 0.0);
}

/// ASSUMED design weights (not the paper's, which the stored text does not give): `Q` on
/// the floor displacements (N²/m²), `R` on the force (1/N² scale), ground-acceleration
/// intensity ((m/s²)²·s) and accelerometer noise intensity ((m/s²)²·s).
const Q_DISP: f64 = 1e10;
const R_FORCE: f64 = 1.0;
const GROUND: f64 = 1.0;
const SENSOR: f64 = 1e-2;

fn q_matrix() -> nalgebra::DMatrix<f64> {
    let mut q = nalgebra::DMatrix::<f64>::zeros(6, 6);
    for i in 0..3 {
        q[(i, i)] = Q_DISP;
    }
    q
}

fn e_matrix() -> nalgebra::DMatrix<f64> {
    let mut e = nalgebra::DMatrix::<f64>::zeros(6, 1);
    for i in 3..6 {
        e[(i, 0)] = -1.0;
    }
    e
}

/// A clipped-optimal row with the ASSUMED weights above (controller at 5 kHz, `tc = 2e-4`
/// s, a multiple of both plant steps, so both runs have the same controller), RK4 at
/// `h = 1e-4` and `5e-5` s; the peaks of the two agree to 1e-5 relative (measured 8.4e-6; a regression pin:
/// a switching instant that moved by a controller sample between the runs would break it).
/// Not comparable with the paper's row (other weights); printed for the later scene, which
/// can run the crate's controller with the same weights against it. Asserted: the
/// controller lowers every drift below the uncontrolled run's.
#[test]
#[ignore = "release stage: two 17 s model-time runs with the observer (~1 s in release)"]
fn benchmark_clipped_optimal_row() {
    let g = dyke1996::design(&STRUCTURE, Q_DISP, R_FORCE, GROUND, SENSOR);
    let rec = benchmark_record();
    let coarse = dyke1996::clipped_optimal(&STRUCTURE, &DAMPER, &rec, 1e-4, 2e-4, &g);
    let fine = dyke1996::clipped_optimal(&STRUCTURE, &DAMPER, &rec, 5e-5, 2e-4, &g);
    println!("{}", row("clipped-optimal (ASSUMED weights)", &fine));
    println!("{}", row("  same, h = 1e-4 s", &coarse));
    let pairs = [
        (fine.displacement, coarse.displacement),
        (fine.drift, coarse.drift),
        (fine.acceleration, coarse.acceleration),
        ([fine.force; 3], [coarse.force; 3]),
    ];
    let worst = pairs
        .iter()
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs() / x))
        .fold(0.0, f64::max);
    println!("clipped-optimal, h = 1e-4 s against 5e-5 s: largest relative difference {worst:.2e}");
    assert!(worst < 1e-5, "{worst} (regression pin)");
    let uncontrolled = passive_peaks(5e-5)[0];
    for i in 0..3 {
        assert!(fine.drift[i] < uncontrolled.drift[i]);
    }
}
