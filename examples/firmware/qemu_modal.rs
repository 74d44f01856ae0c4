//! Firmware: a modal model stepped in real time from a timer interrupt on a Cortex-M4F
//! (QEMU `mps2-an386`): only what the scene needs.
//!
//! The benchmark 5-storey building under the El Centro 1940 NS record (embedded at build
//! time and parsed by the compiler, `scenes/modal/elcentro.rs`), 2 of its 5 modes,
//! roof drift as the one output: `Modal<f32, 5, 2>`, a `static` whose modes the compiler
//! solved (no eigen-solver in flash). SysTick fires every h = 0.02 s of the
//! core clock; its handler takes the next ground-acceleration sample, steps the modes and
//! reads the roof drift (`R·I + 7R` + `O·R` multiply-adds), and pushes it through a
//! `heapless::spsc::Queue` to the main loop. The main loop compares every 10th sample
//! with the full model's roof drift computed on the host (`Linear<f64, 5>`,
//! `scenes/modal/reference.rs`, generated and checked by `tests/firmware_modal.rs`)
//! and exits with failure if the difference exceeds the truncation bound measured there.
//!
//! Before the timer starts it counts the instructions of one step (SysTick under
//! `-icount shift=0`, as `examples/firmware/qemu_cost.rs`) for `Modal<f32, 5, R>`, R = 1…5 (step
//! and roof output), the full `LinearInput<f32, 5, 1>` and the full `Linear<f32, 5>` fed
//! `p = B a_g`, and prints one `COST` line each.
//!
//! Run: `cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_modal`
//! (or `bash scripts/qemu.sh`). Broken variant that must fail: feature
//! `--cfg aemstep_broken="modal-tight-bound"` (bound 100× tighter than the measured truncation).
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;
#[path = "../../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "fw/periodic.rs"]
mod periodic;
#[path = "../../scenes/modal/reference.rs"]
mod reference;

use core::cell::RefCell;
use core::hint::black_box;

use aemstep::models::base_excitation;
use aemstep::models::{self, Rows};
use aemstep::{Damping, Linear, LinearInput, Modal, ModalState, State, Stepper};
use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::SYST;
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::hprintln;
use heapless::spsc::{Producer, Queue};
use nalgebra::SVector;

const H: f64 = elcentro::DT;
/// Steps after step 0: the whole record.
const STEPS: u32 = (elcentro::SAMPLES - 1) as u32;

/// Max |roof drift − full-model roof drift| (m): measured and derived on the host.
#[cfg(not(aemstep_broken = "modal-tight-bound"))]
const BOUND: f64 = reference::BOUND;
/// Broken on purpose: 100× tighter than the truncation of 2 modes allows; must fail.
#[cfg(aemstep_broken = "modal-tight-bound")]
const BOUND: f64 = reference::BOUND / 100.0;

const BUILDING: (Rows<5>, Rows<5>, Rows<5>) = models::five_storey_building();
const ROOF: [[f64; 5]; 1] = [[0.0, 0.0, 0.0, 0.0, 1.0]];

/// The full models, operators computed by the compiler into flash.
static FULL: Linear<f32, 5> =
    match Linear::<f32, 5>::from_rows_f32(BUILDING.0, BUILDING.1, BUILDING.2, H) {
        Ok(s) => s,
        Err(e) => panic!("{}", e.as_str()),
    };
static FULL_INPUT: LinearInput<f32, 5, 1> = match LinearInput::from_rows_f32(
    BUILDING.0,
    BUILDING.1,
    BUILDING.2,
    base_excitation(&BUILDING.0),
    H,
) {
    Ok(s) => s,
    Err(e) => panic!("{}", e.as_str()),
};

/// `Modal<f32, 5, R>` of the building, its modes solved by the compiler (`const fn`
/// `from_rows_f32`): the operators sit in flash and no eigen-solver code is linked
/// (`scripts/qemu.sh` checks the symbol list).
macro_rules! modal {
    ($r:literal) => {{
        static S: Modal<f32, 5, $r> = match Modal::from_rows_f32(
            BUILDING.0,
            BUILDING.2,
            Damping::Matrix(BUILDING.1),
            base_excitation(&BUILDING.0),
            ROOF,
            H,
        ) {
            Ok(s) => s,
            Err(e) => panic!("{}", e.as_str()),
        };
        &S
    }};
}

/// One real-time step: the modes, then the one output. Out of line so its code size
/// (symbol `qemu_modal_step`) and stack can be measured alone.
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_modal_step(sys: &Modal<f32, 5, 2>, s: &mut ModalState<f32, 2>, ag: f32) -> f32 {
    sys.step(s, &SVector::from([ag]));
    sys.output(s)[0]
}

/// A call that does nothing but cannot be removed: the loop overhead to subtract.
#[inline(never)]
fn empty(x: f32) -> f32 {
    black_box(x)
}

/// Instructions per call of `f` (in tenths) over `reps` calls fed the record, minus the
/// same loop around an empty call.
fn per_step(syst: &mut SYST, reps: u32, mut f: impl FnMut(f32) -> f32) -> u32 {
    let ag = &elcentro::AG_F32;
    let mut acc = 0.0f32;
    let full = fw::instructions(syst, || {
        for i in 0..reps as usize {
            acc += f(black_box(ag[i % ag.len()]));
        }
    });
    let base = fw::instructions(syst, || {
        for i in 0..reps as usize {
            acc += empty(black_box(ag[i % ag.len()]));
        }
    });
    black_box(acc);
    ((full - base) as u64 * 10 / reps as u64) as u32
}

/// One `COST <what> <instructions per step> <multiply-adds>` line.
fn cost(what: &str, tenths: u32, madds: usize) {
    hprintln!("COST {} {}.{} {}", what, tenths / 10, tenths % 10, madds);
}

macro_rules! modal_cost {
    ($syst:expr, $r:literal, $sym:ident) => {{
        #[unsafe(no_mangle)]
        #[inline(never)]
        fn $sym(sys: &Modal<f32, 5, $r>, s: &mut ModalState<f32, $r>, ag: f32) -> f32 {
            sys.step(s, &SVector::from([ag]));
            sys.output(s)[0]
        }
        let sys = modal!($r);
        let mut s = match sys.start_at_rest(&SVector::from([0.0])) {
            Ok(s) => s,
            Err(e) => fail!("start: {}", e.as_str()),
        };
        let c = per_step($syst, 1000, |a| $sym(black_box(sys), &mut s, a));
        cost(concat!("Modal<f32,5,", $r, ">"), c, 9 * $r);
    }};
}

#[unsafe(no_mangle)]
#[inline(never)]
fn cost_step_linear_input_5(sys: &LinearInput<f32, 5, 1>, s: &mut State<f32, 5>, ag: f32) -> f32 {
    sys.step(s, &SVector::from([ag]));
    s.u()[4]
}

#[unsafe(no_mangle)]
#[inline(never)]
fn cost_step_linear_5_b(
    sys: &Linear<f32, 5>,
    s: &mut State<f32, 5>,
    b: &SVector<f32, 5>,
    ag: f32,
) -> f32 {
    sys.step(s, &(b * ag));
    s.u()[4]
}

/// Handed from `main` to the SysTick handler once, before the timer starts.
type Ctx = (
    &'static Modal<f32, 5, 2>,
    Producer<'static, (u32, f32)>,
    ModalState<f32, 2>,
);
static CTX: Mutex<RefCell<Option<Ctx>>> = Mutex::new(RefCell::new(None));

#[exception]
fn SysTick() {
    static mut LOCAL: Option<Ctx> = None;
    let Some((sys, tx, state)) = fw::handover(&CTX, LOCAL) else {
        return;
    };
    let n = state.steps() as u32 + 1;
    if n > STEPS {
        return;
    }
    // The sensor in a real system; the embedded record here.
    let ag = elcentro::AG_F32
        .get(n as usize)
        .copied()
        .unwrap_or(f32::NAN);
    let y = qemu_modal_step(sys, state, ag);
    if tx.enqueue((n, y)).is_err() {
        periodic::overrun();
    }
}

#[entry]
fn main() -> ! {
    let mut cp = fw::init();
    let syst = &mut cp.SYST;

    // Instructions per step, one output (roof drift) read each step.
    modal_cost!(syst, 1, cost_step_modal_r1);
    modal_cost!(syst, 2, cost_step_modal_r2);
    modal_cost!(syst, 3, cost_step_modal_r3);
    modal_cost!(syst, 4, cost_step_modal_r4);
    modal_cost!(syst, 5, cost_step_modal_r5);
    let z = SVector::<f32, 5>::zeros();
    let mut s = match FULL_INPUT.start(&z, &z, &SVector::from([0.0])) {
        Ok(s) => s,
        Err(e) => fail!("start: {}", e.as_str()),
    };
    let c = per_step(syst, 1000, |a| {
        cost_step_linear_input_5(black_box(&FULL_INPUT), &mut s, a)
    });
    cost("LinearInput<f32,5,1>", c, 2 * 25 + 5 + 5 * 5);
    let b = SVector::<f32, 5>::from_fn(|i, _| base_excitation(&BUILDING.0)[i][0] as f32);
    let mut s = match FULL.start(&z, &z, &z) {
        Ok(s) => s,
        Err(e) => fail!("start: {}", e.as_str()),
    };
    let c = per_step(syst, 1000, |a| {
        cost_step_linear_5_b(black_box(&FULL), &mut s, black_box(&b), a)
    });
    cost("Linear<f32,5>", c, 3 * 25 + 5 * 5 + 5);

    // The real-time run: R = 2, roof drift.
    let sys: &'static Modal<f32, 5, 2> = modal!(2);
    let Some(queue) = cortex_m::singleton!(: Queue<(u32, f32), 16> = Queue::new()) else {
        fail!("queue taken twice");
    };
    let (tx, mut rx) = queue.split();
    let s0 = match sys.start_at_rest(&SVector::from([elcentro::AG_F32[0]])) {
        Ok(s) => s,
        Err(e) => fail!("start: {}", e.as_str()),
    };
    let mut probe = s0;
    let step_stack = fw::stack_used_by(|| {
        black_box(qemu_modal_step(sys, &mut probe, 1.0));
    });
    let mut max_err = libm::fabs(sys.output(&s0)[0] as f64 - reference::ROOF[0] as f64);
    cortex_m::interrupt::free(|cs| CTX.borrow(cs).replace(Some((sys, tx, s0))));

    periodic::start(syst, H);
    let mut expected = 1;
    let mut last = 0.0f32;
    periodic::serve(
        syst,
        &mut rx,
        || {},
        |(n, y)| {
            if n != expected {
                fail!("sample {} arrived, expected {}", n, expected);
            }
            if (n as usize).is_multiple_of(reference::EVERY) {
                let r = reference::ROOF.get(n as usize / reference::EVERY).copied();
                let err = libm::fabs(y as f64 - r.unwrap_or(f32::NAN) as f64);
                if err.is_nan() || err > BOUND {
                    fail!(
                        "step {}: |roof drift - full model| = {:e} m > bound {:e} m",
                        n,
                        err,
                        BOUND
                    );
                }
                max_err = max_err.max(err);
            }
            last = y;
            expected += 1;
            n == STEPS
        },
    );

    hprintln!(
        "qemu_modal: {} SysTick steps of the 5-storey building under El Centro (R = 2, f32), max |roof drift - full model| = {:e} m <= bound {:e} m",
        STEPS,
        max_err,
        BOUND
    );
    hprintln!("target roof drift f32 bits = {:#010x}", last.to_bits());
    hprintln!("MEM qemu_modal step_stack_bytes {}", step_stack);
    fw::report_stack("qemu_modal");
    fw::exit_success()
}
