//! Firmware: logging the crate's types through defmt on a Cortex-M4F (QEMU `mps2-an386`).
//!
//! With `aemstep`'s `defmt` feature, `State`, `Error`, `NewtonReport`… implement
//! `defmt::Format`: the firmware logs them with `defmt::info!("{}", x)`, defmt sends only an
//! index of the format string and the raw values (here over semihosting, `defmt-semihosting`),
//! and the host formats them (`defmt-print -e <elf>`). Logged:
//! - paper Example 2 (ii) stepped by a compile-time `Linear<f32, 1>` (as `qemu_timer`), its
//!   `State` after 0, 250 and 500 steps (t = 1 s), with the error against the closed form;
//! - the `Error` a NaN load sample gets, and the state it left unchanged;
//! - the Duffing oscillator (paper Example 5) stepped by `Nonlinear<f32, 1>` with exactly 2
//!   Newton iterations: the first step's `NewtonReport` and the `State` after it.
//!
//! `scripts/qemu.sh` decodes the output and compares it line by line with
//! `examples/firmware/qemu_defmt.out`. Broken variant that must fail that comparison:
//! `--cfg aemstep_broken="defmt-wrong"` (the last load sample 10.001 instead of 10: one
//! logged state differs).
//!
//! Run: `cargo run -p aemstep-firmware --features defmt --release --target
//! thumbv7em-none-eabihf --example qemu_defmt | defmt-print -e
//! target/thumbv7em-none-eabihf/release/examples/firmware/qemu_defmt` (or `bash scripts/qemu.sh`).
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;

use aemstep::models::Duffing;
use aemstep::{Linear, NewtonSettings, Nonlinear, State, Stepper};
use cortex_m_rt::entry;
use defmt_semihosting as _;
use nalgebra::vector;

const OMEGA: f64 = 2.0;
const XI: f64 = 0.07;
const H: f64 = 1.0 / 500.0;
const P: f32 = 10.0;
const STEPS: u32 = 500; // t = 1 s
/// `FIRMWARE_BOUND` of `tests/firmware_example2.rs` (as in `qemu_timer`).
const BOUND: f64 = 1.2e-4;

/// Example 2 (ii), operators computed by the compiler.
static SYS: Linear<f32, 1> =
    match Linear::<f32, 1>::from_rows_f32([[1.0]], [[2.0 * XI * OMEGA]], [[OMEGA * OMEGA]], H) {
        Ok(s) => s,
        Err(e) => panic!("{}", e.as_str()),
    };

/// Closed form of Example 2 (ii), u0 = 1, v0 = 20, p = 10.
fn exact(t: f64) -> f64 {
    let us = P as f64 / (OMEGA * OMEGA);
    let wd = OMEGA * libm::sqrt(1.0 - XI * XI);
    let w0 = 1.0 - us;
    let b = (20.0 + XI * OMEGA * w0) / wd;
    us + libm::exp(-XI * OMEGA * t) * (w0 * libm::cos(wd * t) + b * libm::sin(wd * t))
}

/// The load sample of step `n` (the broken variant changes the last one).
fn load_sample(n: u32) -> f32 {
    if cfg!(aemstep_broken = "defmt-wrong") && n == STEPS {
        return 10.001;
    }
    P
}

#[entry]
fn main() -> ! {
    let mut s: State<f32, 1> = match SYS.start(&vector![1.0], &vector![20.0], &vector![P]) {
        Ok(s) => s,
        Err(e) => fail!("start: {}", e.as_str()),
    };
    defmt::info!("Example 2 (ii), Linear<f32, 1>, h = 2 ms: {}", s);
    for n in 1..=STEPS {
        if let Err(e) = SYS.try_step(&mut s, &vector![load_sample(n)]) {
            fail!("step {} refused: {}", n, e.as_str());
        }
        if n % 250 == 0 {
            let err = libm::fabs(s.u()[0] as f64 - exact(n as f64 * H));
            if err > BOUND {
                fail!("step {}: |u - exact| = {:e} > bound {:e}", n, err, BOUND);
            }
            defmt::info!("step {=u32}: {}, |u - exact| <= {=f64}", n, s, BOUND);
        }
    }

    // A bad load sample: the step is refused with an `Error`, the state is kept.
    let kept = s;
    match SYS.try_step(&mut s, &vector![f32::NAN]) {
        Ok(()) => fail!("a NaN load was accepted"),
        Err(e) => defmt::warn!("NaN load refused: {}; state kept: {}", e, s),
    }
    if s != kept {
        fail!("a refused step changed the state");
    }

    // The nonlinear stepper's report.
    let duffing = match Nonlinear::<f32, 1>::new(0.01, NewtonSettings::exactly(2, 1.5e-5)) {
        Ok(d) => d,
        Err(e) => fail!("settings: {}", e.as_str()),
    };
    let mut d = match duffing.start(&Duffing, &vector![0.0], &vector![1.0], &vector![0.0]) {
        Ok(d) => d,
        Err(e) => fail!("start: {}", e.as_str()),
    };
    // p(t) of paper Example 5 at t = 0.01 s (exact solution e^{-0.1 t} sin t).
    let t = 0.01f64;
    let (e, sn) = (libm::exp(-0.1 * t), libm::sin(t));
    let p1 = (-0.01 * e * sn + e * e * e * sn * sn * sn) as f32;
    match duffing.try_step(&Duffing, &mut d, &vector![p1]) {
        Ok(report) => defmt::info!("Duffing, Nonlinear<f32, 1>, first step: {}; {}", report, d),
        Err(e) => fail!("Duffing step refused: {}", e.as_str()),
    }
    fw::exit_success()
}
