//! A day of real-time stepping in `f32`: the amplitude and phase drift of an undamped
//! oscillator over many steps, with the plain state update ([`Linear`]) and the
//! compensated one ([`CompensatedLinear`]), and `Linear<f64>` for scale.
//!
//! `u'' + ω² u = 0`, `u0 = 1`, `v0 = 0`, `h = 1e-3` s (10⁸ steps ≈ 28 h at 1 kHz), at
//! ωh = 1e-4, 1e-2, 1, 100. Measured, every run:
//!
//! - amplitude drift: `A_n / A_0 − 1` with `A = √(u² + (v/ω)²)` (the average-acceleration
//!   rule conserves `v² + ω² u²` exactly in exact arithmetic, so any change is rounding);
//! - phase error: the state's angle `atan2(−v/ω, u)` against the exact recurrence's phase
//!   `n·Φ`, `Φ = 2 atan(ωh/2)` computed in `f64` (independent of the stepper), tracked
//!   unwrapped every 64 steps.
//!
//! Run: `cargo run --release -p xtask --bin drift -- STEPS [DIR]` (STEPS defaults to 10⁸;
//! writes `DIR/drift.md`, DIR defaults to `docs`). The test command regenerates the page
//! with the page's own step count.

use std::f64::consts::PI;
use std::time::Instant;

use aemstep::{CompensatedLinear, Linear, Real, Stepper};
use nalgebra::{SVector, matrix, vector};

const H: f64 = 1e-3;
const OMEGA_H: [f64; 4] = [1e-4, 1e-2, 1.0, 1e2];
/// Phase tracked every this many steps (its change stays far below π).
const EVERY: u64 = 64;

struct Run {
    drift: f64,
    phase: f64,
    ns_per_step: f64,
}

fn wrap(x: f64) -> f64 {
    let y = x.rem_euclid(2.0 * PI);
    if y > PI { y - 2.0 * PI } else { y }
}

fn run<T: Real, S: Stepper<T, 1, Input = SVector<T, 1>>>(sys: &S, omega: f64, steps: u64) -> Run {
    let zero = vector![T::zero()];
    let mut s = sys
        .start(&vector![T::one()], &zero, &zero)
        .expect("finite start");
    let phi = 2.0 * (omega * H / 2.0).atan();
    let phi_every = (EVERY as f64 * phi).rem_euclid(2.0 * PI);
    let angle = |s: &S::State| {
        let st = sys.full_state(s);
        (-st.v()[0].as_f64() / omega).atan2(st.u()[0].as_f64())
    };
    let (mut theta, mut phase) = (angle(&s), 0.0f64);
    let t0 = Instant::now();
    let mut n = 0;
    while n < steps {
        let k = EVERY.min(steps - n);
        for _ in 0..k {
            sys.step(&mut s, &zero);
        }
        n += k;
        let th = angle(&s);
        let expect = if k == EVERY {
            phi_every
        } else {
            (k as f64 * phi).rem_euclid(2.0 * PI)
        };
        phase += wrap(th - theta - expect);
        theta = th;
    }
    let secs = t0.elapsed().as_secs_f64();
    let st = sys.full_state(&s);
    let (u, v) = (st.u()[0].as_f64(), st.v()[0].as_f64());
    Run {
        drift: (u * u + (v / omega) * (v / omega)).sqrt() - 1.0,
        phase,
        ns_per_step: secs * 1e9 / steps as f64,
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let steps: u64 = args.get(1).map_or(Ok(100_000_000), |s| s.parse())?;
    let dir = args.get(2).cloned().unwrap_or_else(|| "docs".into());
    let mut md = format!(
        "# A day of `f32` steps: amplitude and phase drift\n\n\
         Produced by `cargo run --release -p xtask --bin drift -- {steps}` (writes this page; \
         deterministic IEEE arithmetic except the columns headed \"host\", host timings of \
         the same run, not checked). The test command regenerates it and compares every \
         other number.\n\n\
         Undamped `u'' + ω² u = 0`, `u0 = 1`, `v0 = 0`, `h = 1e-3` s, {steps} steps \
         (10⁸ steps are about 28 hours at 1 kHz). Drift: `A_n / A_0 − 1`, \
         `A = √(u² + (v/ω)²)`, which the scheme conserves exactly in exact arithmetic. \
         Phase: the state's angle against the exact recurrence's `n·2 atan(ωh/2)` (rad, \
         positive = ahead). `Linear<f32>` is the plain update, `CompensatedLinear<f32>` \
         the two-sum update; `Linear<f64>` for scale.\n\n\
         | ωh | `Linear<f32>` drift | `CompensatedLinear<f32>` drift | `Linear<f64>` drift | `Linear<f32>` phase | `CompensatedLinear<f32>` phase | `Linear<f64>` phase | host ns/step f32 | host ns/step compensated |\n\
         |---|---|---|---|---|---|---|---|---|\n"
    );
    // Which update keeps |drift| under the 1e-4 at each ωh, and the better of the two.
    let (mut plain_ok, mut comp_ok, mut best) = (Vec::new(), Vec::new(), 0.0f64);
    for wh in OMEGA_H {
        let omega = wh / H;
        let (m, c, k) = (matrix![1.0], matrix![0.0], matrix![omega * omega]);
        let plain = run(&Linear::<f32, 1>::new(&m, &c, &k, H)?, omega, steps);
        let comp = run(
            &CompensatedLinear::<f32, 1>::new(&m, &c, &k, H)?,
            omega,
            steps,
        );
        let wide = run(&Linear::<f64, 1>::new(&m, &c, &k, H)?, omega, steps);
        md += &format!(
            "| {wh:.0e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.1} | {:.1} |\n",
            plain.drift,
            comp.drift,
            wide.drift,
            plain.phase,
            comp.phase,
            wide.phase,
            plain.ns_per_step,
            comp.ns_per_step
        );
        let label = format!("{wh:.0e}");
        if plain.drift.abs() < 1e-4 {
            plain_ok.push(label.clone());
        }
        if comp.drift.abs() < 1e-4 {
            comp_ok.push(label);
        }
        best = best.max(plain.drift.abs().min(comp.drift.abs()));
    }
    md += &format!(
        "\nUnder 1e-4 in 10⁸ steps: the plain update at ωh = {}; the compensated one at ωh = \
         {}. Taking the better of the two for each ωh, the largest drift is {best:.2e}.\n",
        list(&plain_ok),
        list(&comp_ok)
    );
    md += "\nReading: the plain `f32` update drifts systematically where the increments are \
           small against the state (many steps per period); the compensated update (two-sum on \
           every addition to `u` and `v`, the predictor's rounding errors fed through `GC`, \
           `GK`) removes most of it at ωh ≤ 1. At ωh = 100 (a mode far above what the step \
           resolves) it does not help: there the plain update drifts least, so a mode \
           above the step's resolution is better stepped plain. The phase error is the same with and without \
           compensation: it comes from rounding the operators to `f32` (a relative frequency \
           error of order 1e-7, times `n·Φ`), not from the state update; `f64` operators are \
           the remedy for phase. Cost per step on the Cortex-M4F: `docs/cortex-m4-cost.md` \
           (rows \"compensated\"); on the host: the last two columns.\n";
    std::fs::create_dir_all(&dir)?;
    std::fs::write(format!("{dir}/drift.md"), &md)?;
    print!("{md}");
    Ok(())
}

/// `a, b and c` (or `none`).
fn list(xs: &[String]) -> String {
    match xs {
        [] => "none".into(),
        [x] => x.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}
