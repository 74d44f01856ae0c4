//! Firmware: a real-time hybrid test stepped from SysTick (issue 22) — the benchmark
//! 5-storey building under El Centro ×2 (`scenes/hybrid/scene.rs`), storey 1 a bilinear
//! "specimen" behind an emulated actuator (a pure delay of 5 ms, `FIRMWARE_DELAY`), storeys
//! 2–5 numerical. Each step (`scenes/hybrid/rig.rs`, shared with the host twin): the split
//! KR-α step's displacement command for storey 1, compensation (polynomial extrapolation of
//! order 2 over the known delay), the actuator, the specimen's force at the displacement
//! reached, the step completed with that force.
//!
//! Operators: `static`s computed by the compiler (`Split::from_rows_f32` / `_f64` and
//! `Polynomial::new_f32` / `_f64`) for h = 1/1024 s and 1/2048 s. The arithmetic type: `f32`
//! by default (the Cortex-M4F's single-precision FPU, QEMU `mps2-an386`); `f64` when built
//! with `--cfg aemstep_fpu="double"` together with `-C target-cpu=cortex-m7` (the M7's
//! double-precision FPU, QEMU `mps2-an500`; `scripts/qemu.sh` does both). An explicit cfg,
//! not a `target_feature` test: rustc exposes no ARM FPU feature to `cfg`.
//!
//! Per rate, two passes over the whole record. First, counted: SysTick as a free-running
//! counter under `-icount shift=0` gives the instructions of every step
//! (`COST hybrid <type> <rate> <mean> <max>`). Then real time: SysTick fires every step,
//! its handler takes the next ground-acceleration sample (the record interpolated to the
//! rate), steps the loop and sends the storey-1 drift through a `heapless::spsc::Queue`;
//! the main loop checks it every 1/16 s against the host's f64 run
//! (`scenes/hybrid/reference.rs`, generated and bounded by `tests/firmware_hybrid.rs`).
//! Fails (`FAIL: …`, exit 1) if a step is refused, if a drift leaves the bound, or if the
//! two passes do not end on the same bits.
//!
//! Run: `cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_hybrid`
//! (or `bash scripts/qemu.sh`, which also runs the M7 build). Broken variants that must
//! fail: `--cfg aemstep_broken="hybrid-tight-bound"` (a bound 100 times tighter than the
//! rounding estimate), `--cfg aemstep_broken="hybrid-nan"` (a NaN in the measured force,
//! which the step refuses).
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;
#[path = "../../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "fw/periodic.rs"]
mod periodic;
#[path = "../../scenes/hybrid/reference.rs"]
mod reference;
#[path = "../../scenes/hybrid/rig.rs"]
mod rig;
#[path = "../../scenes/hybrid/scene.rs"]
mod scene;

use core::cell::RefCell;

use aemstep::hybrid::{Actuator, Polynomial, Split};
use aemstep::hysteresis::Bilinear;
use aemstep::{Error, Real};
use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::SYST;
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::hprintln;
use heapless::spsc::{Producer, Queue};
use rig::{Loop, Rig};
use scene::{
    ALPHA, BLD, FIRMWARE_DELAY, FIRMWARE_ORDER, FIRMWARE_RATES, FIRMWARE_SAMPLE_HZ, FY, K_NUM, K1,
    N, RHO_INF,
};

/// The arithmetic type, its compile-time operators and its record, chosen by
/// `aemstep_fpu` (see the module documentation).
macro_rules! precision {
    ($t:ident, $split:ident, $poly:ident, $ag:ident, $bound:ident) => {
        type F = $t;
        /// The split KR-α step at each rate of `FIRMWARE_RATES`, computed by the compiler.
        static SYS: [Split<F, N>; 2] = [split(FIRMWARE_RATES[0]), split(FIRMWARE_RATES[1])];
        /// The compensator at each rate, computed by the compiler.
        static COMP: [Polynomial<F>; 2] = [poly(FIRMWARE_RATES[0]), poly(FIRMWARE_RATES[1])];
        const fn split(rate: u64) -> Split<F, N> {
            let h = 1.0 / rate as f64;
            match Split::$split(BLD.0, BLD.1, BLD.2, K_NUM, h, RHO_INF) {
                Ok(s) => s,
                Err(_) => panic!("the split step's operators"),
            }
        }
        const fn poly(rate: u64) -> Polynomial<F> {
            match Polynomial::$poly(FIRMWARE_ORDER, 1.0 / rate as f64, FIRMWARE_DELAY) {
                Ok(p) => p,
                Err(_) => panic!("the compensator's weights"),
            }
        }
        /// The record (m/s²), in `F`.
        static AG: &[F] = &elcentro::$ag;
        /// The bound of the host twin (`tests/firmware_hybrid.rs`) for this type.
        const HOST_BOUND: f64 = reference::$bound;
        /// `x` in `f64` (exact).
        #[allow(clippy::useless_conversion)] // the identity for `f64`
        fn wide(x: F) -> f64 {
            f64::from(x)
        }
    };
}
#[cfg(not(aemstep_fpu = "double"))]
precision!(f32, from_rows_f32, new_f32, AG_F32, BOUND_F32);
#[cfg(aemstep_fpu = "double")]
precision!(f64, from_rows_f64, new_f64, AG_F64, BOUND_F64);

/// The bound checked: the host twin's; 100 times tighter in the broken variant.
const BOUND: f64 = if cfg!(aemstep_broken = "hybrid-tight-bound") {
    HOST_BOUND / 100.0
} else {
    HOST_BOUND
};
/// Added to the measured force: zero; NaN in the broken variant.
const FORCE_ERROR: f64 = if cfg!(aemstep_broken = "hybrid-nan") {
    f64::NAN
} else {
    0.0
};

/// The host's f64 storey-1 drift at each rate, every `rate / FIRMWARE_SAMPLE_HZ` steps.
static REFERENCE: [&[f64]; 2] = [&reference::DRIFT_1024, &reference::DRIFT_2048];

/// One real-time step. Out of line so its code size (symbol `qemu_hybrid_step`, read by
/// `scripts/qemu.sh`) and stack can be measured alone.
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_hybrid_step(sys: &Split<F, N>, rig: &Rig<F>, s: &mut Loop<F>, ag: F) -> Result<F, Error> {
    rig.step(sys, s, ag, F::from_f64_rounded(FORCE_ERROR))
}

/// Steps after step 0 at `rate` Hz: the whole record.
fn steps(rate: u64) -> u64 {
    scene::steps(elcentro::SAMPLES, rate)
}

/// What the handler sends for step `n`: the storey-1 drift (m), or why the step failed.
type Msg = (u64, Result<F, Error>);

/// Handed from `main` to the SysTick handler, once per rate: the rate's index, the rig,
/// the loop's state, the queue and the last step taken.
type Ctx = (usize, Rig<F>, Loop<F>, Producer<'static, Msg>, u64);
static CTX: Mutex<RefCell<Option<Ctx>>> = Mutex::new(RefCell::new(None));

#[exception]
fn SysTick() {
    static mut LOCAL: Option<Ctx> = None;
    let Some((k, rig, s, tx, n)) = fw::handover(&CTX, LOCAL) else {
        return;
    };
    let Some((&sys, &rate)) = SYS.get(*k).zip(FIRMWARE_RATES.get(*k)) else {
        return;
    };
    *n += 1;
    let result = qemu_hybrid_step(&sys, rig, s, scene::ground(AG, *n, rate));
    let last = *n >= steps(rate) || result.is_err();
    if tx.enqueue((*n, result)).is_err() {
        periodic::overrun();
    }
    if last {
        // This rate is done: the next `main` hands over a new context.
        *LOCAL = None;
    }
}

/// The rig at rate `FIRMWARE_RATES[k]`, at rest.
fn rig(k: usize, specimen: Bilinear<F>) -> (Rig<F>, Loop<F>) {
    let rate = FIRMWARE_RATES[k];
    let actuator = match Actuator::new(1.0 / rate as f64, FIRMWARE_DELAY, 0.0) {
        Ok(a) => a,
        Err(e) => fail!("actuator: {}", e.as_str()),
    };
    let rig = Rig {
        actuator,
        compensator: COMP[k],
        specimen,
        iota: rig::IOTA.map(|r| F::from_f64_rounded(r[0])),
    };
    match rig.rest(&SYS[k], scene::ground(AG, 0, rate)) {
        Ok(s) => (rig, s),
        Err(e) => fail!("start at {} Hz: {}", rate, e.as_str()),
    }
}

/// Both passes at `FIRMWARE_RATES[k]`; prints the result and the `COST` line.
fn run(k: usize, syst: &mut SYST, queue: &'static mut Queue<Msg, 16>, specimen: Bilinear<F>) {
    let (rate, sys, reference) = (FIRMWARE_RATES[k], &SYS[k], REFERENCE[k]);
    let (rig, s0) = rig(k, specimen);
    let every = rate / FIRMWARE_SAMPLE_HZ;

    // Pass 1, counted: the instructions of every step.
    fw::start_counter(syst);
    let mut s = s0;
    let (mut total, mut worst) = (0u64, 0u32);
    let mut drift: F = 0.0;
    for n in 1..=steps(rate) {
        let ag = scene::ground(AG, n, rate);
        let mut result = Err(Error::NonFiniteInput);
        let c = fw::instructions(syst, || result = qemu_hybrid_step(sys, &rig, &mut s, ag));
        drift = match result {
            Ok(d) => d,
            Err(e) => fail!("{} Hz, counted step {} refused: {}", rate, n, e.as_str()),
        };
        total += c as u64;
        worst = worst.max(c);
    }
    let counted = drift;

    // Pass 2, real time: the same record from the same start, one step per SysTick.
    let (tx, mut rx) = queue.split();
    cortex_m::interrupt::free(|cs| CTX.borrow(cs).replace(Some((k, rig, s0, tx, 0))));
    periodic::start(syst, 1.0 / rate as f64);
    let (mut expected, mut max_err, mut last): (u64, f64, F) = (1, 0.0, 0.0);
    periodic::serve(
        syst,
        &mut rx,
        || {},
        |(n, result)| {
            if n != expected {
                fail!("{} Hz: step {} arrived, expected {}", rate, n, expected);
            }
            let d = match result {
                Ok(d) => d,
                Err(e) => fail!("{} Hz: step {} refused: {}", rate, n, e.as_str()),
            };
            if n.is_multiple_of(every) {
                let r = reference.get((n / every) as usize).copied();
                let err = libm::fabs(wide(d) - r.unwrap_or(f64::NAN));
                if err.is_nan() || err > BOUND {
                    fail!(
                        "{} Hz, step {}: |storey-1 drift - host f64| = {:e} m > bound {:e} m",
                        rate,
                        n,
                        err,
                        BOUND
                    );
                }
                max_err = max_err.max(err);
            }
            last = d;
            expected += 1;
            n == steps(rate)
        },
    );
    if last.to_bits() != counted.to_bits() {
        fail!(
            "{} Hz: the timer run ended at drift {:e} m, the counted run at {:e} m",
            rate,
            last,
            counted
        );
    }
    let ty = core::any::type_name::<F>();
    hprintln!(
        "qemu_hybrid: {} SysTick steps at {} Hz of the hybrid 5-storey building under El Centro x2 (bilinear storey 1 behind a 5 ms actuator, order-2 compensation, {}), max |storey-1 drift - host f64| = {:e} m <= bound {:e} m",
        steps(rate),
        rate,
        ty,
        max_err,
        BOUND
    );
    hprintln!(
        "target last storey-1 drift {} {} bits = {:#x}",
        rate,
        ty,
        last.to_bits()
    );
    hprintln!(
        "COST hybrid {} {} {} {}",
        ty,
        rate,
        total / steps(rate),
        worst
    );
}

#[entry]
fn main() -> ! {
    let mut cp = fw::init();
    let syst = &mut cp.SYST;
    let specimen = match Bilinear::<F>::new(K1, FY, ALPHA) {
        Ok(b) => b,
        Err(e) => fail!("specimen: {}", e.as_str()),
    };
    let Some(q0) = cortex_m::singleton!(: Queue<Msg, 16> = Queue::new()) else {
        fail!("queue taken twice");
    };
    let Some(q1) = cortex_m::singleton!(: Queue<Msg, 16> = Queue::new()) else {
        fail!("queue taken twice");
    };

    let (probe_rig, mut probe) = rig(0, specimen);
    let step_stack = fw::stack_used_by(|| {
        let _ = core::hint::black_box(qemu_hybrid_step(
            &SYS[0],
            &probe_rig,
            &mut probe,
            scene::ground(AG, 1, FIRMWARE_RATES[0]),
        ));
    });

    run(0, syst, q0, specimen);
    run(1, syst, q1, specimen);
    hprintln!("MEM qemu_hybrid step_stack_bytes {}", step_stack);
    fw::report_stack("qemu_hybrid");
    fw::exit_success()
}
