//! Shared bare-metal glue for the QEMU examples (`mps2-an386`, Cortex-M4F): exit status
//! through semihosting, panic and HardFault handlers that exit with failure, SysTick
//! instruction counting under `-icount shift=0`, and stack measurement by painting.
//!
//! Include it from an example with
//!
//! ```ignore
//! #[path = "fw/mod.rs"]
//! mod fw;
//! ```
//!
//! Runner: `.cargo/config.toml` (`[target.thumbv7em-none-eabihf]`); memory layout and linker
//! scripts: `examples/firmware/build.rs`. The stack is
//! painted with `0xCCCC_CCCC` at reset by cortex-m-rt's `paint-stack` feature.
#![allow(dead_code)] // each example uses a different subset

use core::cell::RefCell;
use core::panic::PanicInfo;

// Links cortex-m's single-core critical section, which cortex-m-semihosting 0.6 needs.
use cortex_m as _;
use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::SYST;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{ExceptionFrame, exception};
use cortex_m_semihosting::{debug, hprintln};

/// The hand-over of an interrupt handler's context: `main` leaves it in `ctx` (a `static`
/// behind a critical section); on the handler's first run it is moved into the handler's
/// own `local` (a `static mut` of the handler), so later runs take no critical section.
/// `None` until `main` has handed it over.
pub fn handover<'a, C>(
    ctx: &Mutex<RefCell<Option<C>>>,
    local: &'a mut Option<C>,
) -> Option<&'a mut C> {
    if local.is_none() {
        *local = cortex_m::interrupt::free(|cs| ctx.borrow(cs).borrow_mut().take());
    }
    local.as_mut()
}

/// End the QEMU run with exit status 0.
pub fn exit_success() -> ! {
    debug::exit(debug::EXIT_SUCCESS);
    #[allow(clippy::empty_loop)]
    loop {}
}

/// Print `FAIL: why` and end the QEMU run with exit status 1.
pub fn exit_failure(why: core::fmt::Arguments) -> ! {
    hprintln!("FAIL: {}", why);
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}

/// `fail!("fmt", args…)`: [`exit_failure`] with a formatted reason (include the module
/// with `#[macro_use]`).
macro_rules! fail {
    ($($t:tt)*) => { $crate::fw::exit_failure(format_args!($($t)*)) };
}

#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    exit_failure(format_args!("panic: {}", info))
}

#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    exit_failure(format_args!("HardFault at pc {:#010x}", frame.pc()))
}

// ---------------------------------------------------------------------------------------
// Instruction counting

/// Nanoseconds per SysTick tick, doubled (so that 62.5 is an integer): QEMU's `-icount
/// shift=0` makes one guest instruction 1 ns, and SysTick on the core clock counts at the
/// board's clock: 25 MHz on the mps2 boards (`mps2-an385`, `-an386`, `-an500`: 40 ns),
/// 20 MHz on `mps2-an505` (50 ns), 16 MHz on `microbit` (62.5 ns). The board is chosen by
/// `--cfg aemstep_board="…"` (`scripts/cores.sh`; unset: mps2). [`calibrate`] checks it
/// at run time.
#[cfg(not(any(aemstep_board = "microbit", aemstep_board = "an505")))]
pub const TICK_NS_X2: u32 = 80;
#[cfg(aemstep_board = "an505")]
pub const TICK_NS_X2: u32 = 100;
#[cfg(aemstep_board = "microbit")]
pub const TICK_NS_X2: u32 = 125;

/// SysTick as a free-running 24-bit down-counter on the core clock, interrupt off.
pub fn start_counter(syst: &mut SYST) {
    syst.disable_interrupt();
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
}

/// Instructions executed by `f` (SysTick ticks × the tick's ns, so ± one tick). Fails the run if the
/// 24-bit counter wrapped (more than 2^24 ticks: 671 million instructions on mps2). Needs
/// [`start_counter`].
#[inline(always)]
pub fn instructions<F: FnOnce()>(syst: &mut SYST, f: F) -> u32 {
    let _ = syst.has_wrapped(); // clears COUNTFLAG
    let t0 = SYST::get_current();
    f();
    let t1 = SYST::get_current();
    if syst.has_wrapped() && t1 >= t0 {
        exit_failure(format_args!("SysTick wrapped during a measurement"));
    }
    (t0.wrapping_sub(t1) & 0x00FF_FFFF) * TICK_NS_X2 / 2
}

/// The core peripherals, with SysTick started as the instruction counter
/// ([`start_counter`]) and checked ([`calibrate`], result printed): every example's first
/// line. Fails the run if the peripherals were already taken.
pub fn init() -> cortex_m::Peripherals {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        exit_failure(format_args!("peripherals taken twice"));
    };
    start_counter(&mut cp.SYST);
    let cal = calibrate(&mut cp.SYST);
    hprintln!("calibration: 100 x 1000 nops = {} instructions", cal);
    cp
}

/// Exactly 1000 instructions (and a call and return).
#[inline(never)]
fn nops_1000() {
    // SAFETY: `nop`s touch no memory, stack or flags.
    unsafe {
        core::arch::asm!(
            ".rept 1000",
            "nop",
            ".endr",
            options(nomem, nostack, preserves_flags)
        );
    }
}

/// Check [`TICK_NS_X2`]: 100 × 1000 `nop`s must measure as 100 000
/// instructions plus the loop and call overhead (≤ 10 a round). Fails the run otherwise
/// (e.g. QEMU started without `-icount shift=0`). Returns the measured count.
pub fn calibrate(syst: &mut SYST) -> u32 {
    let n = instructions(syst, || {
        for _ in 0..100 {
            nops_1000();
        }
    });
    if !(100_000..=101_040).contains(&n) {
        exit_failure(format_args!(
            "calibration: 100 000 nops measured as {} instructions (run QEMU with -icount shift=0)",
            n
        ));
    }
    n
}

// ---------------------------------------------------------------------------------------
// Stack

/// The value cortex-m-rt (`paint-stack`) fills the stack with at reset.
pub const PAINT: u32 = 0xCCCC_CCCC;

unsafe extern "C" {
    static _stack_start: u32;
    static _stack_end: u32;
}

/// Bytes of stack used since reset (highest point the stack has reached), by scanning the
/// paint from the bottom of the stack region (`_stack_end`) up.
pub fn stack_high_water() -> usize {
    let lo = &raw const _stack_end as usize;
    let hi = &raw const _stack_start as usize;
    let mut p = lo;
    // SAFETY: [lo, hi) is the stack region from the linker script: mapped, aligned RAM.
    while p < hi && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
        p += 4;
    }
    hi - p
}

/// Stack bytes used by `f` alone (its frame and everything it calls): paints 16 KiB below
/// the current stack pointer, calls `f`, and finds the lowest word no longer painted.
/// Runs with interrupts off, since an exception frame would scrub the paint.
pub fn stack_used_by<F: FnOnce()>(f: F) -> usize {
    const DEPTH: usize = 16 * 1024;
    cortex_m::interrupt::free(|_| {
        let sp = cortex_m::register::msp::read() as usize & !3;
        let lo = sp - DEPTH;
        let mut p = lo;
        while p < sp {
            // SAFETY: below the stack pointer, above the 4 MiB stack region's floor, with
            // interrupts off: memory nothing else uses right now.
            unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
            p += 4;
        }
        f();
        let mut p = lo;
        // SAFETY: as above.
        while p < sp && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
            p += 4;
        }
        sp - p
    })
}

/// Print the static-RAM and stack figures every example reports (parsed by
/// `scripts/qemu.sh`).
pub fn report_stack(example: &str) {
    hprintln!(
        "MEM {} stack_high_water_bytes {}",
        example,
        stack_high_water()
    );
}
