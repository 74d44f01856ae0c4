//! What the nonlinear AEM stepper does to energy, measured (README, "Nonlinear and
//! time-varying systems"). The paper claims energy conservation; this prints what the
//! scheme actually does on its own conservative examples:
//!
//! - Example 6, the pendulum `θ'' + sin θ = 0` (l = g = 9.81, θ0 = 0.4π, E0 = −29.74);
//! - Example 7, the elastic pendulum with gravity, h = 0.01 s to t = 1000 s, in f64 and f32;
//! - Example 7 without gravity: the step sweep where the energy stops being bounded.
//!
//! Run: `cargo run --release -p xtask --bin energy`

#[path = "../../../tests/support/pendulums.rs"]
mod pendulums;

use aemstep::Real;
use nalgebra::vector;
use pendulums::{
    EL_EA, EL_KE0, EL_L, EL_M, EL_SPEED, Elastic, G, THETA0, elastic_energy, elastic_run,
    max_and_first_tenth, pendulum_energy, pendulum_run,
};

/// Max |E − E0| (J) in each of `windows` equal windows of the run, or the step at which
/// the run failed; and the first time the stretch |r − L| exceeds L.
struct Run {
    window_max: Vec<f64>,
    failed: Option<(u64, aemstep::Error)>,
    blow_up: Option<f64>,
    max_iterations: u32,
}

fn elastic<T: Real>(h: f64, t_end: f64, g: f64, windows: usize) -> Run {
    let run = elastic_run::<T>(&Elastic { analytic: true }, h, t_end, g);
    let mut window_max = vec![0.0f64; windows];
    for (i, de) in run.energy_error.iter().enumerate() {
        let w = (i as u64 * windows as u64 / run.steps) as usize;
        window_max[w] = window_max[w].max(*de);
    }
    Run {
        window_max,
        failed: run.failed,
        blow_up: run.blow_up(h),
        max_iterations: run.max_iterations,
    }
}

fn main() {
    println!("Energy behaviour of the nonlinear AEM step (measured, not claimed)\n");

    // Example 6: the pendulum.
    let e0 = pendulum_energy(THETA0, 0.0);
    println!("Example 6, pendulum (l = g, θ0 = 0.4π), E0 = {e0:.4} (paper: −29.74), t ≤ 100 s:");
    for h in [0.1, 0.01, 0.001] {
        let de: Vec<f64> = pendulum_run(h, 100.0)
            .iter()
            .map(|&(th, w)| (pendulum_energy(th, w) - e0).abs())
            .collect();
        let (all, first) = max_and_first_tenth(&de, de.len() as u64);
        println!(
            "  h = {h:<5}: max |E − E0| = {all:.3e} ({:.2e} of |E0|); first 10 s: {first:.3e}",
            all / e0.abs()
        );
    }

    // Example 7 with gravity, the paper's run.
    let ke0 = EL_KE0;
    let e0 = elastic_energy(&vector![0.0, EL_L], &vector![EL_SPEED, 0.0], G);
    println!(
        "\nExample 7, elastic pendulum with gravity, h = 0.01 s, t ≤ 1000 s \
         (E0 = {e0:.3} J, initial kinetic energy KE0 = {ke0:.1} J):"
    );
    for (name, run) in [
        ("f64", elastic::<f64>(0.01, 1000.0, G, 10)),
        ("f32", elastic::<f32>(0.01, 1000.0, G, 10)),
    ] {
        let max = run.window_max.iter().cloned().fold(0.0, f64::max);
        let w: Vec<String> = run.window_max.iter().map(|x| format!("{x:.4}")).collect();
        println!(
            "  {name}: max |E − E0| = {max:.4} J ({:.2e} of KE0); per 100 s window: [{}] J; \
             Newton ≤ {} iterations{}",
            max / ke0,
            w.join(", "),
            run.max_iterations,
            run.failed
                .map_or(String::new(), |(n, e)| format!("; FAILED at step {n}: {e}"))
        );
    }

    // Example 7 without gravity: where does the energy stop being bounded?
    println!(
        "\nExample 7 without gravity, t ≤ 100 s (axial period 2π√(mL/EA) = {:.3} s); \
         bounded = max |E − E0| ≤ KE0:",
        2.0 * std::f64::consts::PI * (EL_M * EL_L / EL_EA).sqrt()
    );
    let mut first_unbounded: Option<f64> = None;
    let mut always_unbounded_from: Option<f64> = None;
    let mut late_blow_ups = Vec::new();
    for i in 1..=80 {
        let h = 0.005 * i as f64;
        let run = elastic::<f64>(h, 100.0, 0.0, 10);
        let max = run.window_max.iter().cloned().fold(0.0, f64::max);
        let bounded = max <= ke0 && run.failed.is_none();
        if bounded {
            always_unbounded_from = None;
        } else {
            first_unbounded.get_or_insert(h);
            always_unbounded_from.get_or_insert(h);
            late_blow_ups.push((h, run.blow_up));
        }
        if h <= 0.2851 && (i % 10 == 0 || !bounded || h >= 0.2399) {
            println!(
                "  h = {h:.3}: max |E − E0| = {:.3e} KE0{}{}",
                max / ke0,
                run.blow_up
                    .map_or(String::new(), |t| format!(", stretch > L at t = {t:.1} s")),
                run.failed
                    .map_or(String::new(), |(n, e)| format!(", failed at step {n}: {e}"))
            );
        }
    }
    let from = always_unbounded_from.unwrap_or(f64::NAN);
    let times: Vec<f64> = late_blow_ups
        .iter()
        .filter(|(h, _)| *h >= from - 1e-9)
        .filter_map(|(_, t)| *t)
        .collect();
    println!(
        "  every h from {from:.3} to 0.400 s: stretch > L within {:.1}–{:.1} s",
        times.iter().cloned().fold(f64::INFINITY, f64::min),
        times.iter().cloned().fold(0.0, f64::max)
    );
    println!(
        "  first unbounded step on the 0.005 s grid: {:.3} s; unbounded for every step from {from:.3} s",
        first_unbounded.unwrap_or(f64::NAN)
    );
}
