//! Firmware: a response spectrum streamed on a Cortex-M4F (QEMU `mps2-an386`), one
//! ground-acceleration sample at a time, as a structural-monitoring node would compute it.
//!
//! The El Centro 1940 NS record (embedded and parsed by the compiler,
//! `scenes/modal/elcentro.rs`) feeds a `static` `Bank<f32, 100>` (5 % damping, 100
//! periods log-spaced 0.01–10 s, exact scheme, default sub-steps; operators computed by the
//! compiler into flash, `scenes/spectrum/config.rs`). SysTick fires every
//! dt = 0.02 s of the core clock; its handler takes the next sample and steps the bank.
//! After the last sample the main loop continues the bank in free vibration
//! (`free_vibration_samples()`), then checks every Sd, Sv, Sa against the host's `f64`
//! spectrum (`scenes/spectrum/reference.rs`, generated and checked by
//! `tests/firmware_spectrum.rs`) within the relative bound measured there, and the bits of
//! the whole spectrum against the host's `f32` run (hash). Exits with failure otherwise.
//!
//! Before the timer starts it counts the instructions per incoming sample (SysTick under
//! `-icount shift=0`, as `examples/firmware/qemu_cost.rs`), averaged over the whole record (the
//! sub-step walks happen where a peak can rise, so the cost varies from sample to sample),
//! of `Bank<f32, 10>` (periods 0.05–5 s) and `Bank<f32, 100>`, and prints
//! `COST spectrum_P10 <instructions> <multiply-adds>` and `COST spectrum_P100 …`
//! (multiply-adds of the whole-interval steps, 10 P; the walks come on top). That run's
//! spectra are checked as well.
//!
//! Run: `cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_spectrum`
//! (or `bash scripts/qemu.sh`). Broken variant that must fail (bound 1000× tighter than
//! measured): build with `RUSTFLAGS='--cfg aemstep_broken="spectrum-tight-bound" -C link-arg=-Tlink.x'`.
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;
#[path = "../../scenes/spectrum/config.rs"]
mod config;
#[path = "../../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "../../scenes/spectrum/reference.rs"]
mod reference;

use core::cell::RefCell;
use core::hint::black_box;
use core::sync::atomic::{AtomicBool, Ordering};

use aemstep::spectrum::{Bank, Response};
use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::SYST;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::hprintln;

const DT: f64 = elcentro::DT;
/// SysTick reload for one sample per dt on the 25 MHz core clock.
const TICKS_PER_SAMPLE: u32 = (25_000_000.0 * DT) as u32;

/// Relative bound on |Sd, Sv, Sa − host f64| (measured on the host).
#[cfg(not(aemstep_broken = "spectrum-tight-bound"))]
const BOUND: f64 = reference::BOUND;
/// Broken on purpose: 1000× tighter than the f32 rounding allows; must fail.
#[cfg(aemstep_broken = "spectrum-tight-bound")]
const BOUND: f64 = reference::BOUND / 1000.0;

static BANK100: Bank<f32, 100> = match Bank::new_f32(config::PERIODS_100, [config::ZETA; 100], DT) {
    Ok(b) => b,
    Err(e) => panic!("{}", e.as_str()),
};
static BANK10: Bank<f32, 10> = match Bank::new_f32(config::PERIODS_10, [config::ZETA; 10], DT) {
    Ok(b) => b,
    Err(e) => panic!("{}", e.as_str()),
};

/// One incoming sample through the 100-oscillator bank. Out of line so its code size
/// (symbol `qemu_spectrum_step`) and stack can be measured alone.
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_spectrum_step(b: &Bank<f32, 100>, r: &mut Response<f32, 100>, ag: f32) {
    b.step(r, ag);
}

/// One incoming sample through the 10-oscillator bank.
#[unsafe(no_mangle)]
#[inline(never)]
fn cost_step_spectrum_p10(b: &Bank<f32, 10>, r: &mut Response<f32, 10>, ag: f32) {
    b.step(r, ag);
}

/// A call that does nothing but cannot be removed: the loop overhead to subtract.
#[inline(never)]
fn empty(x: f32) -> f32 {
    black_box(x)
}

/// Instructions per sample (in tenths) of `f` fed the whole record, minus the same loop
/// around an empty call.
fn per_sample(syst: &mut SYST, mut f: impl FnMut(f32)) -> u32 {
    let ag = &elcentro::AG_F32;
    let full = fw::instructions(syst, || {
        for &a in ag.iter() {
            f(black_box(a));
        }
    });
    let mut acc = 0.0f32;
    let base = fw::instructions(syst, || {
        for &a in ag.iter() {
            acc += empty(black_box(a));
        }
    });
    black_box(acc);
    ((full.saturating_sub(base)) as u64 * 10 / ag.len() as u64) as u32
}

/// FNV-1a over the bits of Sd, Sv, Sa (as `tests/firmware_spectrum.rs`).
fn hash<const P: usize>(r: &Response<f32, P>) -> u32 {
    let mut h: u32 = 0x811c_9dc5;
    for x in r.sd().iter().chain(r.sv()).chain(r.sa()) {
        for byte in x.to_bits().to_le_bytes() {
            h = (h ^ byte as u32).wrapping_mul(0x0100_0193);
        }
    }
    h
}

/// Check a finished spectrum against the host: every value within `BOUND` relative of
/// the f64 reference, and the bits equal to the host's f32 run. Returns the worst error.
fn check<const P: usize>(
    what: &str,
    r: &Response<f32, P>,
    reference: [&[f64; P]; 3],
    host_hash: u32,
) -> f64 {
    let mut worst = 0.0f64;
    for (k, (got, want)) in [r.sd(), r.sv(), r.sa()].iter().zip(reference).enumerate() {
        for p in 0..P {
            let e = libm::fabs(got[p] as f64 - want[p]) / want[p];
            if e.is_nan() || e > BOUND {
                fail!(
                    "{} {} at period {}: relative error {:e} > bound {:e}",
                    what,
                    ["Sd", "Sv", "Sa"][k],
                    p,
                    e,
                    BOUND
                );
            }
            worst = worst.max(e);
        }
    }
    let h = hash(r);
    if h != host_hash {
        fail!(
            "{}: f32 bits hash {:#010x} != host {:#010x}",
            what,
            h,
            host_hash
        );
    }
    worst
}

/// Handed from `main` to the SysTick handler once, before the timer starts.
type Ctx = Response<f32, 100>;
static CTX: Mutex<RefCell<Option<Ctx>>> = Mutex::new(RefCell::new(None));
/// The finished response, handed back by the handler after the last sample.
static DONE: Mutex<RefCell<Option<Ctx>>> = Mutex::new(RefCell::new(None));
static FINISHED: AtomicBool = AtomicBool::new(false);

#[exception]
fn SysTick() {
    static mut LOCAL: Option<Ctx> = None;
    let Some(r) = fw::handover(&CTX, LOCAL) else {
        return;
    };
    let n = r.samples() as usize;
    if n >= elcentro::SAMPLES {
        if !FINISHED.load(Ordering::Relaxed) {
            let done = *r;
            cortex_m::interrupt::free(|cs| DONE.borrow(cs).replace(Some(done)));
            FINISHED.store(true, Ordering::Release);
        }
        return;
    }
    // The sensor in a real system; the embedded record here.
    let ag = elcentro::AG_F32.get(n).copied().unwrap_or(f32::NAN);
    qemu_spectrum_step(&BANK100, r, ag);
}

#[entry]
fn main() -> ! {
    let mut cp = fw::init();
    let syst = &mut cp.SYST;

    // Instructions per incoming sample, averaged over the record; the spectra checked.
    let mut r10 = BANK10.at_rest();
    let c10 = per_sample(syst, |a| {
        cost_step_spectrum_p10(black_box(&BANK10), &mut r10, a)
    });
    let mut r100 = BANK100.at_rest();
    let c100 = per_sample(syst, |a| {
        qemu_spectrum_step(black_box(&BANK100), &mut r100, a)
    });
    hprintln!("COST spectrum_P10 {}.{} {}", c10 / 10, c10 % 10, 10 * 10);
    hprintln!(
        "COST spectrum_P100 {}.{} {}",
        c100 / 10,
        c100 % 10,
        10 * 100
    );
    BANK10.free_vibration(&mut r10, BANK10.free_vibration_samples());
    let w10 = check(
        "P = 10",
        &r10,
        [&reference::SD_10, &reference::SV_10, &reference::SA_10],
        reference::HOST_F32_HASH_10,
    );

    // The real-time run: P = 100, one sample per SysTick.
    let mut probe = BANK100.at_rest();
    qemu_spectrum_step(&BANK100, &mut probe, 0.0);
    let step_stack = fw::stack_used_by(|| qemu_spectrum_step(&BANK100, &mut probe, 1.0));
    cortex_m::interrupt::free(|cs| CTX.borrow(cs).replace(Some(BANK100.at_rest())));
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(TICKS_PER_SAMPLE - 1);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
    while !FINISHED.load(Ordering::Acquire) {
        cortex_m::asm::wfi();
    }
    syst.disable_interrupt();
    syst.disable_counter();
    let Some(mut r) = cortex_m::interrupt::free(|cs| DONE.borrow(cs).borrow_mut().take()) else {
        fail!("the handler finished without handing the response back");
    };
    if r != r100 {
        fail!("the SysTick run differs from the cost run");
    }
    BANK100.free_vibration(&mut r, BANK100.free_vibration_samples());
    let w100 = check(
        "P = 100",
        &r,
        [&reference::SD_100, &reference::SV_100, &reference::SA_100],
        reference::HOST_F32_HASH_100,
    );
    hprintln!(
        "qemu_spectrum: {} SysTick samples of El Centro through Bank<f32, 100> (+ free vibration), max relative |Sd, Sv, Sa - host f64| = {:e} (P = 100), {:e} (P = 10) <= bound {:e}; bits equal to the host f32 run",
        r.samples(),
        w100,
        w10,
        BOUND
    );
    hprintln!("MEM qemu_spectrum step_stack_bytes {}", step_stack);
    fw::report_stack("qemu_spectrum");
    fw::exit_success()
}
