//! Firmware: the nonlinear stepper on a Cortex-M4F (QEMU `mps2-an386`), checked against
//! the exact solution, with the Newton report checked every step.
//!
//! Paper Example 5, the Duffing oscillator `u'' + 0.2 u' + u + u³ = p(t)`, u0 = 0,
//! v0 = 1, `p(t)` chosen so that `u = e^{−0.1t} sin t` exactly; h = 0.01 s, 2000 steps
//! (t ≤ 20 s), `f32`, exactly 2 Newton iterations a step (constant work, as a hard
//! real-time loop needs). The firmware fails if any step's report is not (converged, 2
//! iterations) or if |u_n − u(t_n)| exceeds `BOUND`, measured and derived on the host
//! first (`tests/firmware_duffing.rs`, same data, same bound).
//!
//! Run: `cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_nonlinear`
//! (or `bash scripts/qemu.sh`). Broken variant that must fail: `--cfg aemstep_broken="inject-nan"`
//! (a NaN load sample at step 1000).
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;

use aemstep::models::Duffing;
use aemstep::{Error, NewtonReport, NewtonSettings, Nonlinear, State};
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use nalgebra::{SVector, vector};

const H: f32 = 0.01;
const STEPS: u32 = 2000;
/// `NewtonSettings::default_tolerance()` for f32 (1.5e-5), as in the host twin.
const TOL: f32 = 1.5e-5;
/// `FIRMWARE_BOUND` of `tests/firmware_duffing.rs` (f32 error measured there: 1.622e-5).
const BOUND: f64 = 1.85e-5;

/// The exact solution `e^{−0.1t} sin t` (f64, libm).
fn exact(t: f64) -> f64 {
    libm::exp(-0.1 * t) * libm::sin(t)
}

/// The load sample `p(t_n)` for the exact solution (the sensor in a real system).
fn load_sample(n: u32) -> f32 {
    if cfg!(aemstep_broken = "inject-nan") && n == 1000 {
        return f32::NAN;
    }
    let t = n as f64 * H as f64;
    let s = libm::sin(t);
    (-0.01 * libm::exp(-0.1 * t) * s + libm::exp(-0.3 * t) * s * s * s) as f32
}

/// The step, out of line so its code size (symbol `qemu_nonlinear_step`, read by
/// `scripts/qemu.sh`) and stack can be measured alone.
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_nonlinear_step(
    stepper: &Nonlinear<f32, 1>,
    s: &mut State<f32, 1>,
    p: &SVector<f32, 1>,
) -> Result<NewtonReport<f32>, Error> {
    stepper.try_step(&Duffing, s, p)
}

#[entry]
fn main() -> ! {
    let stepper = match Nonlinear::<f32, 1>::new(H as f64, NewtonSettings::exactly(2, TOL)) {
        Ok(s) => s,
        Err(e) => fail!("settings: {}", e.as_str()),
    };
    let p0 = vector![load_sample(0)];
    let mut s = match stepper.start(&Duffing, &vector![0.0], &vector![1.0], &p0) {
        Ok(s) => s,
        Err(e) => fail!("start: {}", e.as_str()),
    };
    let mut probe = s;
    let step_stack = fw::stack_used_by(|| {
        let _ = core::hint::black_box(qemu_nonlinear_step(&stepper, &mut probe, &p0));
    });

    let mut max_err: f64 = 0.0;
    let mut max_residual: f32 = 0.0;
    for n in 1..=STEPS {
        let p = vector![load_sample(n)];
        let report = match qemu_nonlinear_step(&stepper, &mut s, &p) {
            Ok(r) => r,
            Err(e) => fail!("step {} refused: {}", n, e.as_str()),
        };
        if !report.converged || report.iterations != 2 {
            fail!(
                "step {}: Newton report converged = {}, iterations = {} (want true, 2)",
                n,
                report.converged,
                report.iterations
            );
        }
        max_residual = max_residual.max(report.residual);
        let err = libm::fabs(s.u()[0] as f64 - exact(n as f64 * H as f64));
        if err.is_nan() || err > BOUND {
            fail!("step {}: |u − exact| = {:e} > bound {:e}", n, err, BOUND);
        }
        max_err = max_err.max(err);
    }
    hprintln!(
        "qemu_nonlinear: {} Duffing steps (h = 0.01 s, f32, 2 Newton iterations each, all converged, max residual {:e}), max |u - exact| = {:e} <= bound {:e}",
        STEPS,
        max_residual,
        max_err,
        BOUND
    );
    hprintln!("MEM qemu_nonlinear step_stack_bytes {}", step_stack);
    fw::report_stack("qemu_nonlinear");
    fw::exit_success()
}
