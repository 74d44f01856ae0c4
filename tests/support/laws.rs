//! The law-level figures of `docs/hysteresis_figures.md`: each law driven along prescribed
//! deformations and compared with a closed form or an independent implementation written
//! here. Shared by `tests/hysteresis.rs` (which asserts on them) and
//! `xtask/src/bin/hysteresis_report.rs` (which prints them).
#![allow(dead_code)]

use std::f64::consts::PI;

use aemstep::hysteresis::{Bilinear, BoucWen, Friction, Law};

/// The laws' parameters of these figures: `k` (N/m), `f_y` (N), `α`.
pub const K: f64 = 1e8;
pub const FY: f64 = 5e5;
pub const ALPHA: f64 = 0.05;
pub const UY: f64 = FY / K;
/// Steps per cycle of the loop figures.
pub const LOOP_STEPS: [usize; 4] = [64, 128, 256, 512];
/// Steps per cycle of the RK4 comparison.
pub const RK4_STEPS: [usize; 3] = [64, 128, 256];
/// Bouc–Wen shapes (β, γ, n) of the RK4 comparison.
pub const RK4_SHAPES: [(f64, f64, f64); 3] = [(0.5, 0.5, 1.0), (0.7, 0.3, 2.0), (0.6, -0.2, 1.5)];
/// Steps per cycle of the friction figure.
pub const FRICTION_STEPS: [usize; 3] = [1000, 2000, 4000];

/// Drive a law along prescribed deformations (rates given, or 0), committing every trial:
/// `(d, force, stiffness)` at each point.
pub fn drive<L: Law<f64>>(law: &L, path: &[f64], rates: Option<&[f64]>) -> Vec<(f64, f64, f64)> {
    let mut h = law.initial_history();
    path.iter()
        .enumerate()
        .map(|(i, &d)| {
            let r = rates.map_or(0.0, |r| r[i]);
            let t = law.trial(&h, d, r);
            h = t.history;
            (d, t.force, t.stiffness)
        })
        .collect()
}

/// `∮ f dd` of a sampled loop by the trapezoidal rule in the deformation.
pub fn work(points: &[(f64, f64, f64)]) -> f64 {
    points
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum()
}

/// `U sin(2π j / m)` for `j = 0..=cycles·m`.
pub fn sine_path(u: f64, m: usize, cycles: usize) -> Vec<f64> {
    (0..=cycles * m)
        .map(|j| u * (2.0 * PI * j as f64 / m as f64).sin())
        .collect()
}

/// The amplitudes of the loop figures: 16 in `[3u_y, 4u_y)`. Where a yield point or a kink
/// falls inside a step decides the error of that step, so one amplitude gives an erratic
/// sequence; the worst over these shows the order.
pub fn amplitudes() -> impl Iterator<Item = f64> {
    (0..16).map(|j| (3.0 + j as f64 / 16.0) * UY)
}

/// Bilinear cycle work (second cycle) against the parallelogram `4 f_y (1 − α)(U − u_y)`,
/// for each of [`LOOP_STEPS`]: the worst relative error over [`amplitudes`], and the worst
/// ratio of the error to its derived bound — only the trapezoid of the (four) steps holding
/// an elastic–plastic transition errs, each by at most `(1 − α) k Δ²/8`, `Δ ≤ 2πU/m`.
pub fn bilinear_loop() -> (Vec<f64>, f64) {
    let law = Bilinear::<f64>::new(K, FY, ALPHA).unwrap();
    let mut ratio: f64 = 0.0;
    let worst = LOOP_STEPS
        .iter()
        .map(|&m| {
            amplitudes().fold(0.0f64, |w, u| {
                let area = 4.0 * FY * (1.0 - ALPHA) * (u - UY);
                let pts = drive(&law, &sine_path(u, m, 2), None);
                let e = (work(&pts[m..]) - area).abs();
                let delta = 2.0 * PI * u / m as f64;
                ratio = ratio.max(e / (4.0 * (1.0 - ALPHA) * K * delta * delta / 8.0));
                w.max(e / area)
            })
        })
        .collect();
    (worst, ratio)
}

/// The steady loop of Bouc–Wen with β = γ = 1/2, n = 1 (unloading linear with slope 1/u_y,
/// loading `z = 1 − e^{−(d − d₀)/u_y}`): `z_m = 1 − e^{−2U/u_y} e^{z_m}` and the loop area
/// `(1 − α) f_y · 2 (2U − 2 z_m u_y − z_m² u_y / 2)`.
pub fn bouc_wen_loop_area(u: f64) -> f64 {
    let mut zm: f64 = 1.0;
    for _ in 0..200 {
        zm = 1.0 - (-2.0 * u / UY).exp() * zm.exp();
    }
    (1.0 - ALPHA) * FY * 2.0 * (2.0 * u - 2.0 * zm * UY - zm * zm * UY / 2.0)
}

/// Bouc–Wen (β = γ = 1/2, n = 1) cycle work (third cycle, converged) against
/// [`bouc_wen_loop_area`], for each of [`LOOP_STEPS`]: the worst relative error over
/// [`amplitudes`], and the worst ratio of the error to the scale of its leading term,
/// `(2πU/m)²/u_y · f_y`.
pub fn bouc_wen_loop() -> (Vec<f64>, f64) {
    let law = BoucWen::<f64>::new(K, FY, ALPHA, 0.5, 0.5, 1.0).unwrap();
    let mut ratio: f64 = 0.0;
    let worst = LOOP_STEPS
        .iter()
        .map(|&m| {
            amplitudes().fold(0.0f64, |w, u| {
                let area = bouc_wen_loop_area(u);
                let pts = drive(&law, &sine_path(u, m, 3), None);
                let e = (work(&pts[2 * m..]) - area).abs();
                let delta = 2.0 * PI * u / m as f64;
                ratio = ratio.max(e / (delta * delta / UY * FY));
                w.max(e / area)
            })
        })
        .collect();
    (worst, ratio)
}

/// `dz/dt` of the Bouc–Wen ODE in time (the textbook form, `A = 1`).
fn bouc_wen_rate(z: f64, du: f64, b: f64, g: f64, n: f64) -> f64 {
    let a = z.abs();
    (du - b * du.abs() * a.powf(n - 1.0) * z - g * du * a.powf(n)) / UY
}

/// Max |z_law − z_RK4| over two cycles of `d = 3u_y sin 2πt`, the law at each of
/// [`RK4_STEPS`] steps a cycle, RK4 of the ODE in time at 4096 steps a cycle.
pub fn bouc_wen_rk4(b: f64, g: f64, n: f64) -> Vec<f64> {
    let law = BoucWen::<f64>::new(K, FY, ALPHA, b, g, n).unwrap();
    let (amp, w) = (3.0 * UY, 2.0 * PI);
    let (sub, m_ref) = (16, 4096);
    let mut z: f64 = 0.0;
    let mut reference = vec![0.0];
    let dt = 1.0 / m_ref as f64;
    let du = |t: f64| amp * w * (w * t).cos();
    let f = |t: f64, z: f64| bouc_wen_rate(z, du(t), b, g, n);
    for j in 0..2 * m_ref {
        let t = j as f64 * dt;
        let k1 = f(t, z);
        let k2 = f(t + dt / 2.0, z + dt / 2.0 * k1);
        let k3 = f(t + dt / 2.0, z + dt / 2.0 * k2);
        let k4 = f(t + dt, z + dt * k3);
        z += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        if (j + 1) % sub == 0 {
            reference.push(z);
        }
    }
    RK4_STEPS
        .iter()
        .map(|&m| {
            let stride = m_ref / sub / m;
            drive(&law, &sine_path(amp, m, 2), None)
                .iter()
                .enumerate()
                .map(|(j, &(d, f, _))| {
                    let z_law = (f - ALPHA * K * d) / ((1.0 - ALPHA) * FY);
                    (z_law - reference[j * stride]).abs()
                })
                .fold(0.0, f64::max)
        })
        .collect()
}

/// Friction `f_s = 2e4 N`, `v_r = 1e-3 m/s`, one cycle of `d = U sin ωt` (U = 0.01 m,
/// ω = 2π): the closed form `4 f_s U (1 − π²/(24a²) − 7π⁴/(1920a⁴))`, `a = Uω/v_r`, and
/// |work − closed form| at each of [`FRICTION_STEPS`].
pub fn friction_cycle() -> (f64, Vec<f64>) {
    let (fs, vr) = (2e4, 1e-3);
    let law = Friction::<f64>::new(fs, vr).unwrap();
    let (u, w) = (0.01, 2.0 * PI);
    let a = u * w / vr;
    let closed =
        4.0 * fs * u * (1.0 - PI * PI / (24.0 * a * a) - 7.0 * PI.powi(4) / (1920.0 * a.powi(4)));
    let errors = FRICTION_STEPS
        .iter()
        .map(|&m| {
            let rates: Vec<f64> = (0..=m)
                .map(|j| u * w * (2.0 * PI * j as f64 / m as f64).cos())
                .collect();
            (work(&drive(&law, &sine_path(u, m, 1), Some(&rates))) - closed).abs()
        })
        .collect();
    (closed, errors)
}

/// `log2` of successive ratios.
pub fn orders(e: &[f64]) -> Vec<f64> {
    e.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}
