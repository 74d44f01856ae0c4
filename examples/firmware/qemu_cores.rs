//! Firmware: instructions per step on every Cortex-M core QEMU has a board for
//! (`scripts/cores.sh` builds it once per core and runs it under `-icount shift=0`):
//! `Linear<T, N>` for N = 1…12, the benchmark building's `Modal<T, 5, 2>` (2 of 5 modes,
//! step and roof-drift output) and the Duffing oscillator of paper Example 5 (`Nonlinear`,
//! exactly 2 Newton iterations), each in `f32` and `f64`.
//!
//! Portable across ARMv6-M (no FPU), ARMv7-M, ARMv7E-M and ARMv8-M Mainline: no FPU-only
//! code, no A-form (its `f64` N = 12 operators would not fit the 16 KiB of RAM of the
//! Cortex-M0 board), nothing kept on the stack beyond one state. Operators are `static`s
//! computed by the compiler (`from_rows_f32`/`_f64`). Prints one line per case:
//!
//! ```text
//! CORE <form> <T> <N> <instructions per step> <multiply-adds> <symbol>
//! ```
//!
//! Method as `examples/firmware/qemu_cost.rs`: SysTick counts the core clock, which `-icount
//! shift=0` ties to the instruction count (`fw::TICK_NS_X2`, set per board by
//! `--cfg aemstep_board="…"`, checked against 100 000 `nop`s first); a case times `reps`
//! steps and subtracts the same loop around an empty out-of-line call.
//!
//! Run on the M4F: `cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf
//! --example qemu_cores`; on the other cores: `bash scripts/cores.sh`.
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;

use aemstep::models::Duffing;
use aemstep::models::base_excitation;
use aemstep::models::{self, Rows, rayleigh, shear_building};
use aemstep::{
    Damping, Linear, Modal, ModalState, NewtonSettings, Nonlinear, Real, State, Stepper,
};
use core::hint::black_box;
use cortex_m::peripheral::SYST;
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use nalgebra::{SVector, vector};

/// Step (s) of the `Linear` cases; the cost does not depend on it.
const H: f64 = 0.01;

/// An `N`-storey uniform shear building with Rayleigh damping, as `examples/firmware/qemu_cost.rs`.
const fn building<const N: usize>() -> (Rows<N>, Rows<N>, Rows<N>) {
    let (m, k) = shear_building([1.0e5; N], [1.0e8; N]);
    let c = rayleigh(&m, &k, 0.5, 1.0e-3);
    (m, c, k)
}

/// The call the baseline times: does nothing, cannot be removed.
#[inline(never)]
fn empty<A, B, C>(_: &A, _: &mut B, _: &C) {
    // SAFETY: an empty `asm!` block: no instructions, no memory access.
    unsafe { core::arch::asm!("", options(nostack, preserves_flags)) }
}

/// Instructions per call (in tenths) of `step(sys, s, x)`, `reps` calls, minus the same
/// loop around [`empty`].
fn per_call<A, B, C>(
    syst: &mut SYST,
    sys: &A,
    s: &mut B,
    x: &C,
    step: fn(&A, &mut B, &C),
    reps: u32,
) -> u32 {
    let full = fw::instructions(syst, || {
        for _ in 0..reps {
            step(black_box(sys), black_box(&mut *s), black_box(x));
        }
    });
    let base = fw::instructions(syst, || {
        for _ in 0..reps {
            empty(black_box(sys), black_box(&mut *s), black_box(x));
        }
    });
    ((full - base) as u64 * 10 / reps as u64) as u32
}

fn row(form: &str, ty: &str, n: usize, tenths: u32, madds: usize, sym: &str) {
    hprintln!(
        "CORE {} {} {} {}.{} {} {}",
        form,
        ty,
        n,
        tenths / 10,
        tenths % 10,
        madds,
        sym
    );
}

/// `<$ty>::from_rows_f32(…)` or `<$ty>::from_rows_f64(…)` as the scalar `$t` says (the
/// `const fn` constructors name their scalar).
macro_rules! from_rows {
    (f32, $ty:ty, $($a:expr),* $(,)?) => {
        <$ty>::from_rows_f32($($a),*)
    };
    (f64, $ty:ty, $($a:expr),* $(,)?) => {
        <$ty>::from_rows_f64($($a),*)
    };
}

/// `Linear<$t, $n>` of the `$n`-storey building: a `static`, `reps` steps.
macro_rules! linear {
    ($syst:expr, $t:ident, $n:literal, $reps:expr, $sym:ident) => {{
        const B: (Rows<$n>, Rows<$n>, Rows<$n>) = building::<$n>();
    static S: Linear<$t, $n> = match from_rows!($t, Linear<$t, $n>, B.0, B.1, B.2, H) {
            Ok(s) => s,
            Err(e) => panic!("{}", e.as_str()),
        };
        #[unsafe(no_mangle)]
        #[inline(never)]
        fn $sym(sys: &Linear<$t, $n>, s: &mut State<$t, $n>, p: &SVector<$t, $n>) {
            sys.step(s, p)
        }
        let r = <$t as Real>::from_f64_rounded;
        let p = SVector::<$t, $n>::from_fn(|i, _| r(1.0e5 * (i + 1) as f64));
        let mut s = match S.start(
            &SVector::from_element(r(0.01)),
            &SVector::from_element(r(0.1)),
            &p,
        ) {
            Ok(s) => s,
            Err(e) => fail!("start: {}", e.as_str()),
        };
        let c = per_call($syst, &S, &mut s, &p, $sym, $reps);
        if !s.is_finite() {
            fail!("{}: state not finite", stringify!($sym));
        }
        row(
            "linear",
            stringify!($t),
            $n,
            c,
            3 * $n * $n,
            stringify!($sym),
        );
    }};
}

const BUILDING5: (Rows<5>, Rows<5>, Rows<5>) = models::five_storey_building();
const ROOF: [[f64; 5]; 1] = [[0.0, 0.0, 0.0, 0.0, 1.0]];

/// `Modal<$t, 5, 2>` of the benchmark building (modes solved by the compiler), one step
/// and the roof drift: `R·I + 7R + O·R = 18` multiply-adds (as `examples/firmware/qemu_modal.rs`).
macro_rules! modal {
    ($syst:expr, $t:ident, $reps:expr, $sym:ident) => {{
        static S: Modal<$t, 5, 2> = match from_rows!(
            $t,
            Modal<$t, 5, 2>,
            BUILDING5.0,
            BUILDING5.2,
            Damping::Matrix(BUILDING5.1),
            base_excitation(&BUILDING5.0),
            ROOF,
            0.02,
        ) {
            Ok(s) => s,
            Err(e) => panic!("{}", e.as_str()),
        };
        #[unsafe(no_mangle)]
        #[inline(never)]
        fn $sym(sys: &Modal<$t, 5, 2>, s: &mut ModalState<$t, 2>, ag: &$t) {
            sys.step(s, &SVector::from([*ag]));
            black_box(sys.output(s)[0]);
        }
        let mut s = match S.start_at_rest(&SVector::from([0.0])) {
            Ok(s) => s,
            Err(e) => fail!("start: {}", e.as_str()),
        };
        let c = per_call($syst, &S, &mut s, &1.0, $sym, $reps);
        row("modal", stringify!($t), 5, c, 18, stringify!($sym));
    }};
}

/// The Duffing step with exactly 2 Newton iterations; every step must be taken.
macro_rules! duffing {
    ($syst:expr, $t:ident, $reps:expr, $sym:ident) => {{
        #[unsafe(no_mangle)]
        #[inline(never)]
        fn $sym(sys: &Nonlinear<$t, 1>, s: &mut State<$t, 1>, p: &SVector<$t, 1>) {
            let _ = sys.try_step(&Duffing, s, p);
        }
        let r = <$t as Real>::from_f64_rounded;
        let Ok(sys) = Nonlinear::<$t, 1>::new(0.01, NewtonSettings::exactly(2, r(1e-5))) else {
            fail!("Newton settings");
        };
        let p = vector![r(0.5)];
        let mut s = match sys.start(&Duffing, &vector![r(0.0)], &vector![r(1.0)], &p) {
            Ok(s) => s,
            Err(e) => fail!("start: {}", e.as_str()),
        };
        let c = per_call($syst, &sys, &mut s, &p, $sym, $reps);
        if s.steps() != $reps as u64 || !s.is_finite() {
            fail!("Duffing: {} of {} steps taken", s.steps(), $reps);
        }
        row("duffing", stringify!($t), 1, c, 0, stringify!($sym));
    }};
}

#[entry]
fn main() -> ! {
    let mut cp = fw::init();
    let syst = &mut cp.SYST;

    linear!(syst, f32, 1, 200, core_linear_f32_1);
    linear!(syst, f32, 2, 200, core_linear_f32_2);
    linear!(syst, f32, 3, 200, core_linear_f32_3);
    linear!(syst, f32, 4, 200, core_linear_f32_4);
    linear!(syst, f32, 5, 200, core_linear_f32_5);
    linear!(syst, f32, 6, 200, core_linear_f32_6);
    linear!(syst, f32, 7, 200, core_linear_f32_7);
    linear!(syst, f32, 8, 200, core_linear_f32_8);
    linear!(syst, f32, 9, 200, core_linear_f32_9);
    linear!(syst, f32, 10, 200, core_linear_f32_10);
    linear!(syst, f32, 11, 200, core_linear_f32_11);
    linear!(syst, f32, 12, 200, core_linear_f32_12);
    linear!(syst, f64, 1, 50, core_linear_f64_1);
    linear!(syst, f64, 2, 50, core_linear_f64_2);
    linear!(syst, f64, 3, 50, core_linear_f64_3);
    linear!(syst, f64, 4, 50, core_linear_f64_4);
    linear!(syst, f64, 5, 50, core_linear_f64_5);
    linear!(syst, f64, 6, 50, core_linear_f64_6);
    linear!(syst, f64, 7, 50, core_linear_f64_7);
    linear!(syst, f64, 8, 50, core_linear_f64_8);
    linear!(syst, f64, 9, 50, core_linear_f64_9);
    linear!(syst, f64, 10, 50, core_linear_f64_10);
    linear!(syst, f64, 11, 50, core_linear_f64_11);
    linear!(syst, f64, 12, 50, core_linear_f64_12);
    modal!(syst, f32, 200, core_modal_f32_5_2);
    modal!(syst, f64, 50, core_modal_f64_5_2);
    duffing!(syst, f32, 200, core_duffing_f32);
    duffing!(syst, f64, 50, core_duffing_f64);

    fw::exit_success()
}
