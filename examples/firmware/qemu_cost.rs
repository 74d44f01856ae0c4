//! Firmware: instructions per step on a Cortex-M4F (QEMU `mps2-an386`, `-icount shift=0`),
//! for the fast form (`Linear`, 3N² multiply-adds) and the paper's A-form (`AForm`, 12N²),
//! `f32` (hardware FPU) and `f64` (software floating point on this core), N = 1, 2, 3, 5
//! (the benchmark building), 6, 12; and the nonlinear stepper on the Duffing oscillator
//! `u'' + 0.2 u' + u + u³ = p` with exactly 2 Newton iterations a step (analytic tangent).
//!
//! Each step function is a separate `#[no_mangle]` symbol `cost_step_<form>_<T>_<N>`, so
//! `scripts/qemu.sh` can read its code size from the ELF. The firmware prints one `ROW`
//! line per case (parsed by the script into `docs/cortex-m4-cost.md`):
//!
//! ```text
//! ROW <form> <T> <N> <instructions per step> <multiply-adds> <step stack bytes> <symbol>
//! ```
//!
//! Method: SysTick counts the core clock, which QEMU's `-icount shift=0` ties to the
//! instruction count (40 instructions a tick; checked against 100 000 `nop`s first). A case
//! times `reps` steps and subtracts the same loop calling an empty out-of-line function,
//! so a figure is the step's own instructions, prologue and epilogue included. Counts are
//! exactly repeatable; `f64` ones depend slightly on the data (soft-float shortcuts).
//!
//! Run: `cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_cost`
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;

use aemstep::models::Duffing;
use aemstep::models::{Rows, rayleigh, shear_building};
use aemstep::{Linear, NewtonSettings, Nonlinear, Real, State, Stepper};
use core::hint::black_box;
use cortex_m::peripheral::SYST;
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use nalgebra::{SVector, vector};

/// Step (s) of every case; the cost does not depend on it.
const H: f64 = 0.01;

/// An `N`-storey uniform shear building (the benchmark building's storeys,
/// `m = 1e5 kg`, `k = 1e8 N/m`) with Rayleigh damping `C = 0.5 M + 1e-3 K`: `(M, C, K)`.
const fn building<const N: usize>() -> (Rows<N>, Rows<N>, Rows<N>) {
    let (m, k) = shear_building([1.0e5; N], [1.0e8; N]);
    let c = rayleigh(&m, &k, 0.5, 1.0e-3);
    (m, c, k)
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

/// `static` operators for an `N`-storey building in type `$t`, computed by the compiler.
macro_rules! ops {
    ($t:ident, $n:literal) => {{
        const B: (Rows<$n>, Rows<$n>, Rows<$n>) = building::<$n>();
    static S: Linear<$t, $n> = match from_rows!($t, Linear<$t, $n>, B.0, B.1, B.2, H) {
            Ok(s) => s,
            Err(e) => panic!("{}", e.as_str()),
        };
        &S
    }};
}

/// The loop body the baseline times: a call that does nothing but cannot be removed.
#[inline(never)]
fn empty_step<S, T, const N: usize>(_: &S, _: &mut State<T, N>, _: &SVector<T, N>) {
    // SAFETY: an empty `asm!` block: no instructions, no memory access.
    unsafe { core::arch::asm!("", options(nostack, preserves_flags)) }
}

/// Instructions per step (in tenths) of `step` on `sys`, over `reps` steps from a
/// non-zero state, and the stack bytes one step uses.
fn measure<
    S: Stepper<T, N, Input = SVector<T, N>, State = State<T, N>>,
    T: Real,
    const N: usize,
>(
    syst: &mut SYST,
    sys: &S,
    step: fn(&S, &mut State<T, N>, &SVector<T, N>),
    reps: u32,
) -> (u32, usize) {
    let u0 = SVector::<T, N>::from_element(T::from_f64_rounded(0.01));
    let v0 = SVector::<T, N>::from_element(T::from_f64_rounded(0.1));
    let p = SVector::<T, N>::from_fn(|i, _| T::from_f64_rounded(1.0e5 * (i + 1) as f64));
    let mut s = match sys.start(&u0, &v0, &p) {
        Ok(s) => s,
        Err(e) => fail!("start: {}", e.as_str()),
    };
    let full = fw::instructions(syst, || {
        for _ in 0..reps {
            step(black_box(sys), black_box(&mut s), black_box(&p));
        }
    });
    let base = fw::instructions(syst, || {
        for _ in 0..reps {
            empty_step(black_box(sys), black_box(&mut s), black_box(&p));
        }
    });
    if !s.is_finite() {
        fail!("state not finite after {} steps", reps);
    }
    let stack = fw::stack_used_by(|| step(black_box(sys), black_box(&mut s), black_box(&p)));
    (((full - base) as u64 * 10 / reps as u64) as u32, stack)
}

/// Print one `ROW` line (see the module docs).
fn row(form: &str, ty: &str, n: usize, tenths: u32, madds: usize, stack: usize, sym: &str) {
    hprintln!(
        "ROW {} {} {} {}.{} {} {} {}",
        form,
        ty,
        n,
        tenths / 10,
        tenths % 10,
        madds,
        stack,
        sym
    );
}

/// Instructions per Duffing step (in tenths), 2 Newton iterations, over `reps` steps
/// under a constant load from u0 = 0, v0 = 1, and the stack bytes one step uses.
fn measure_duffing<T: Real>(
    syst: &mut SYST,
    step: fn(&Nonlinear<T, 1>, &mut State<T, 1>, &SVector<T, 1>),
    reps: u32,
) -> (u32, usize) {
    let r = T::from_f64_rounded;
    let Ok(stepper) = Nonlinear::<T, 1>::new(0.01, NewtonSettings::exactly(2, r(1e-5))) else {
        fail!("Newton settings");
    };
    let p = vector![r(0.5)];
    let mut s = match stepper.start(&Duffing, &vector![r(0.0)], &vector![r(1.0)], &p) {
        Ok(s) => s,
        Err(e) => fail!("start: {}", e.as_str()),
    };
    let full = fw::instructions(syst, || {
        for _ in 0..reps {
            step(black_box(&stepper), black_box(&mut s), black_box(&p));
        }
    });
    let base = fw::instructions(syst, || {
        for _ in 0..reps {
            empty_step(black_box(&stepper), black_box(&mut s), black_box(&p));
        }
    });
    if s.steps() != reps as u64 || !s.is_finite() {
        fail!("Duffing: {} of {} steps taken", s.steps(), reps);
    }
    let stack = fw::stack_used_by(|| step(black_box(&stepper), black_box(&mut s), black_box(&p)));
    (((full - base) as u64 * 10 / reps as u64) as u32, stack)
}

/// One case: an out-of-line `#[no_mangle]` step function named `$sym`, measured.
macro_rules! case {
    ($syst:expr, fast, $t:ident, $n:literal, $reps:expr, $sym:ident) => {{
        #[unsafe(no_mangle)]
        #[inline(never)]
        fn $sym(sys: &Linear<$t, $n>, s: &mut State<$t, $n>, p: &SVector<$t, $n>) {
            sys.step(s, p)
        }
        let (c, st) = measure($syst, ops!($t, $n), $sym, $reps);
        row(
            "fast",
            stringify!($t),
            $n,
            c,
            3 * $n * $n,
            st,
            stringify!($sym),
        );
    }};
    ($syst:expr, aform, $t:ident, $n:literal, $reps:expr, $sym:ident) => {{
        #[unsafe(no_mangle)]
        #[inline(never)]
        fn $sym(sys: &aemstep::AForm<$t, $n>, s: &mut State<$t, $n>, p: &SVector<$t, $n>) {
            sys.step(s, p)
        }
        let a = ops!($t, $n).a_form();
        let (c, st) = measure($syst, &a, $sym, $reps);
        row(
            "aform",
            stringify!($t),
            $n,
            c,
            12 * $n * $n,
            st,
            stringify!($sym),
        );
    }};
    ($syst:expr, compensated, $t:ident, $n:literal, $reps:expr, $sym:ident) => {{
        // `CompensatedLinear` (two-sum state update, its own state type): the same
        // measurement as `measure`, against the same empty call.
        #[unsafe(no_mangle)]
        #[inline(never)]
        fn $sym(
            sys: &aemstep::CompensatedLinear<$t, $n>,
            s: &mut aemstep::CompensatedState<$t, $n>,
            p: &SVector<$t, $n>,
        ) {
            sys.step(s, p)
        }
        const B: (Rows<$n>, Rows<$n>, Rows<$n>) = building::<$n>();
        static S: aemstep::CompensatedLinear<$t, $n> =
            match from_rows!($t, aemstep::CompensatedLinear<$t, $n>, B.0, B.1, B.2, H) {
                Ok(s) => s,
                Err(e) => panic!("{}", e.as_str()),
            };
        let p = SVector::<$t, $n>::from_fn(|i, _| 1.0e5 * (i + 1) as $t);
        let mut s = match S.start(
            &SVector::from_element(0.01),
            &SVector::from_element(0.1),
            &p,
        ) {
            Ok(s) => s,
            Err(e) => fail!("start: {}", e.as_str()),
        };
        let mut e = S.full_state(&s);
        let full = fw::instructions($syst, || {
            for _ in 0..$reps {
                $sym(black_box(&S), black_box(&mut s), black_box(&p));
            }
        });
        let base = fw::instructions($syst, || {
            for _ in 0..$reps {
                empty_step(black_box(&S), black_box(&mut e), black_box(&p));
            }
        });
        if !aemstep::StepState::is_finite(&s) {
            fail!("state not finite after {} steps", $reps);
        }
        let st = fw::stack_used_by(|| $sym(black_box(&S), black_box(&mut s), black_box(&p)));
        let c = ((full - base) as u64 * 10 / $reps as u64) as u32;
        row(
            "compensated",
            stringify!($t),
            $n,
            c,
            5 * $n * $n,
            st,
            stringify!($sym),
        );
    }};
    ($syst:expr, duffing, $t:ident, $reps:expr, $sym:ident) => {{
        /// A Duffing step; a failed step (none is expected) is caught by the step count.
        #[unsafe(no_mangle)]
        #[inline(never)]
        fn $sym(sys: &Nonlinear<$t, 1>, s: &mut State<$t, 1>, p: &SVector<$t, 1>) {
            let _ = sys.try_step(&Duffing, s, p);
        }
        let (c, st) = measure_duffing::<$t>($syst, $sym, $reps);
        row("duffing", stringify!($t), 1, c, 0, st, stringify!($sym));
    }};
}

#[entry]
fn main() -> ! {
    let mut cp = fw::init();
    let syst = &mut cp.SYST;

    case!(syst, fast, f32, 1, 1000, cost_step_fast_f32_1);
    case!(syst, fast, f32, 2, 1000, cost_step_fast_f32_2);
    case!(syst, fast, f32, 3, 1000, cost_step_fast_f32_3);
    case!(syst, fast, f32, 5, 1000, cost_step_fast_f32_5);
    case!(syst, fast, f32, 6, 1000, cost_step_fast_f32_6);
    case!(syst, fast, f32, 12, 1000, cost_step_fast_f32_12);
    case!(syst, aform, f32, 1, 1000, cost_step_aform_f32_1);
    case!(syst, aform, f32, 2, 1000, cost_step_aform_f32_2);
    case!(syst, aform, f32, 3, 1000, cost_step_aform_f32_3);
    case!(syst, aform, f32, 5, 1000, cost_step_aform_f32_5);
    case!(syst, aform, f32, 6, 1000, cost_step_aform_f32_6);
    case!(syst, aform, f32, 12, 1000, cost_step_aform_f32_12);
    case!(syst, fast, f64, 1, 200, cost_step_fast_f64_1);
    case!(syst, fast, f64, 2, 200, cost_step_fast_f64_2);
    case!(syst, fast, f64, 3, 200, cost_step_fast_f64_3);
    case!(syst, fast, f64, 5, 200, cost_step_fast_f64_5);
    case!(syst, fast, f64, 6, 200, cost_step_fast_f64_6);
    case!(syst, fast, f64, 12, 200, cost_step_fast_f64_12);
    case!(syst, aform, f64, 1, 200, cost_step_aform_f64_1);
    case!(syst, aform, f64, 2, 200, cost_step_aform_f64_2);
    case!(syst, aform, f64, 3, 200, cost_step_aform_f64_3);
    case!(syst, aform, f64, 5, 200, cost_step_aform_f64_5);
    case!(syst, aform, f64, 6, 200, cost_step_aform_f64_6);
    case!(syst, aform, f64, 12, 200, cost_step_aform_f64_12);

    case!(syst, compensated, f32, 1, 1000, cost_step_compensated_f32_1);
    case!(syst, compensated, f32, 5, 1000, cost_step_compensated_f32_5);

    case!(syst, duffing, f32, 1000, cost_step_duffing_f32_1);
    case!(syst, duffing, f64, 200, cost_step_duffing_f64_1);

    fw::report_stack("qemu_cost");
    fw::exit_success()
}
