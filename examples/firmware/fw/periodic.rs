//! Timer-driven stepping for the QEMU examples: SysTick fires once per step, its handler
//! steps the model and sends the result through a `heapless::spsc` queue, and the main
//! loop checks every result as it arrives. What the four timer examples (`qemu_timer`,
//! `qemu_modal`, `qemu_observer`, `qemu_hysteretic`) share, in one place.
//!
//! Include it beside `fw` (it reports failures through `fw::exit_failure`):
//!
//! ```ignore
//! #[macro_use]
//! #[path = "fw/mod.rs"]
//! mod fw;
//! #[path = "fw/periodic.rs"]
//! mod periodic;
//! ```
//!
//! The handler's context is moved in once with [`fw::handover`](crate::fw::handover).
#![allow(dead_code)] // each example uses a different subset

use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m::peripheral::SYST;
use cortex_m::peripheral::syst::SystClkSource;
use heapless::spsc::Consumer;

use crate::fw::{TICK_NS_X2, exit_failure};

/// Core clock of the board (Hz), which SysTick counts: 25 MHz on the mps2 boards.
pub const CORE_HZ: u32 = 2_000_000_000 / TICK_NS_X2;

/// Set by an interrupt handler that found its output queue full (the main loop fell
/// behind) or its input queue empty (the sensors did); [`serve`] fails the run on it.
pub static OVERRUN: AtomicBool = AtomicBool::new(false);

/// Record an overrun (from the handler).
pub fn overrun() {
    OVERRUN.store(true, Ordering::Relaxed);
}

/// Start SysTick interrupting every `h` seconds of the core clock: one step per tick.
/// Fails the run if `h` does not fit SysTick's 24-bit reload.
pub fn start(syst: &mut SYST, h: f64) {
    let ticks = CORE_HZ as f64 * h;
    if !(2.0..=16_777_216.0).contains(&ticks) {
        exit_failure(format_args!(
            "a step of {} s is {} SysTick ticks: outside 2 ..= 2^24",
            h, ticks
        ));
    }
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(ticks as u32 - 1);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

/// The main loop while SysTick steps: runs `feed` (e.g. push the next sensor samples),
/// hands every queued result to `check` in order, and sleeps until the next interrupt;
/// returns, with SysTick stopped, once `check` returns `true` (the last result). Fails the
/// run on an [`overrun`].
pub fn serve<T>(
    syst: &mut SYST,
    rx: &mut Consumer<'_, T>,
    mut feed: impl FnMut(),
    mut check: impl FnMut(T) -> bool,
) {
    loop {
        feed();
        while let Some(msg) = rx.dequeue() {
            if check(msg) {
                syst.disable_interrupt();
                syst.disable_counter();
                return;
            }
        }
        if OVERRUN.load(Ordering::Relaxed) {
            exit_failure(format_args!(
                "queue overrun: the SysTick handler found a queue full or empty"
            ));
        }
        cortex_m::asm::wfi();
    }
}
