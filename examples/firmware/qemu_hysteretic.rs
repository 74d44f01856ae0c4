//! Firmware: a yielding structure on a Cortex-M4F (QEMU `mps2-an386`) — the 3-storey
//! shear building with bilinear (kinematic hardening) storeys of
//! `scenes/hysteretic/building.rs` under the whole El Centro record, h = 0.02 s (one
//! step per record sample), `f32`, exactly `ITERATIONS` Newton iterations a step
//! (constant work, as a hard real-time loop needs), the storey histories committed only
//! with a converged step.
//!
//! Two passes over the record. First, counted: SysTick as a free-running counter under
//! `-icount shift=0` gives the instructions of every step (`COST hysteretic_3 <mean>
//! <max>`). Then real time: SysTick fires every h = 0.02 s of the core clock, its handler
//! takes the next ground-acceleration sample, steps the building from the committed
//! state and histories, and sends `(n, roof, report)` through a `heapless::spsc::Queue`;
//! the main loop checks every 10th roof displacement against the host's f64 run
//! (`scenes/hysteretic/reference.rs`, generated and bounded by
//! `tests/firmware_hysteretic.rs`). Fails if a step is refused or not converged, if the
//! roof leaves the bound, or if the two passes do not end on the same bits.
//!
//! Run: `cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_hysteretic`
//! (or `bash scripts/qemu.sh`). Broken variant that must fail:
//! `RUSTFLAGS='--cfg aemstep_broken="hysteretic-tight-bound" -C link-arg=-Tlink.x'` (a bound 100 times tighter
//! than the measured f32 rounding).
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;
#[path = "../../scenes/hysteretic/building.rs"]
mod building;
#[path = "../../scenes/modal/elcentro.rs"]
mod elcentro;
#[path = "fw/periodic.rs"]
mod periodic;
#[path = "../../scenes/hysteretic/reference.rs"]
mod reference;

use core::cell::RefCell;

use aemstep::hysteresis::{Bilinear, BilinearHistory, HistoryModel, ShearBuilding};
use aemstep::{Error, NewtonReport, NewtonSettings, Nonlinear, State};
use cortex_m::interrupt::Mutex;
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::hprintln;
use heapless::spsc::{Producer, Queue};
use nalgebra::SVector;

type Building = ShearBuilding<f32, Bilinear<f32>, 3>;
type History = [BilinearHistory<f32>; 3];

/// `NewtonSettings::default_tolerance()` for f32 (1.5e-5), as in the host twin.
const TOL: f32 = 1.5e-5;
/// Steps after step 0: the whole record.
const STEPS: u32 = (elcentro::SAMPLES - 1) as u32;
/// The bound of the host twin (`tests/firmware_hysteretic.rs`); 100 times tighter in the
/// broken variant.
const BOUND: f64 = if cfg!(aemstep_broken = "hysteretic-tight-bound") {
    reference::BOUND / 100.0
} else {
    reference::BOUND
};

/// One real-time step. Out of line so its code size (symbol `qemu_hysteretic_step`, read
/// by `scripts/qemu.sh`) and stack can be measured alone.
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_hysteretic_step(
    stepper: &Nonlinear<f32, 3>,
    building: &Building,
    s: &mut State<f32, 3>,
    history: &mut History,
    ag: f32,
) -> Result<NewtonReport<f32>, Error> {
    stepper.try_step_with_history(building, s, history, &building.ground_load(ag))
}

/// The next ground-acceleration sample (the sensor in a real system; the embedded record
/// here): NaN past the end, which the step refuses.
fn sample(n: u32) -> f32 {
    elcentro::AG_F32
        .get(n as usize)
        .copied()
        .unwrap_or(f32::NAN)
}

/// Fail the run unless the step was taken with exactly the fixed iteration count.
fn accepted(n: u32, result: Result<NewtonReport<f32>, Error>) -> NewtonReport<f32> {
    match result {
        Ok(r) if r.converged && r.iterations == reference::ITERATIONS => r,
        Ok(r) => fail!(
            "step {}: converged = {}, iterations = {}",
            n,
            r.converged,
            r.iterations
        ),
        Err(e) => fail!("step {} refused: {}", n, e.as_str()),
    }
}

/// What the handler sends for step `n`: the roof displacement (m), the step's report, and
/// whether any storey has yielded so far.
type Msg = (u32, Result<(f32, NewtonReport<f32>, bool), Error>);

/// Handed from `main` to the SysTick handler once, before the timer starts.
type Ctx = (
    Nonlinear<f32, 3>,
    Building,
    Producer<'static, Msg>,
    State<f32, 3>,
    History,
);
static CTX: Mutex<RefCell<Option<Ctx>>> = Mutex::new(RefCell::new(None));

#[exception]
fn SysTick() {
    static mut LOCAL: Option<Ctx> = None;
    let Some((stepper, building, tx, s, history)) = fw::handover(&CTX, LOCAL) else {
        return;
    };
    let n = s.steps() as u32 + 1;
    if n > STEPS {
        return;
    }
    let result = qemu_hysteretic_step(stepper, building, s, history, sample(n));
    let yielded = history.iter().any(|h| h.plastic != 0.0);
    let msg = (n, result.map(|r| (s.u()[2], r, yielded)));
    if tx.enqueue(msg).is_err() {
        periodic::overrun();
    }
}

#[entry]
fn main() -> ! {
    let mut cp = fw::init();
    let syst = &mut cp.SYST;

    let building = match building::bilinear::<f32>() {
        Ok(b) => b,
        Err(e) => fail!("building: {}", e.as_str()),
    };
    let settings = NewtonSettings::exactly(reference::ITERATIONS, TOL);
    let stepper = match Nonlinear::<f32, 3>::new(elcentro::DT, settings) {
        Ok(s) => s,
        Err(e) => fail!("stepper: {}", e.as_str()),
    };
    let z = SVector::zeros();
    let p0 = building.ground_load(sample(0));
    let (s0, h0) =
        match stepper.start_with_history(&building, &z, &z, &p0, &building.initial_history()) {
            Ok(x) => x,
            Err(e) => fail!("start: {}", e.as_str()),
        };
    let (mut probe, mut probe_h) = (s0, h0);
    let step_stack = fw::stack_used_by(|| {
        let _ = core::hint::black_box(qemu_hysteretic_step(
            &stepper,
            &building,
            &mut probe,
            &mut probe_h,
            sample(1),
        ));
    });

    // Pass 1, counted: the instructions of every step.
    let (mut s, mut history) = (s0, h0);
    let (mut total, mut worst_cost) = (0u64, 0u32);
    for n in 1..=STEPS {
        let (ag, mut result) = (sample(n), Err(Error::NonFiniteInput));
        let c = fw::instructions(syst, || {
            result = qemu_hysteretic_step(&stepper, &building, &mut s, &mut history, ag);
        });
        accepted(n, result);
        total += c as u64;
        worst_cost = worst_cost.max(c);
    }
    let counted_roof = s.u()[2];

    // Pass 2, real time: the same record from the same start, one step per SysTick.
    let Some(queue) = cortex_m::singleton!(: Queue<Msg, 16> = Queue::new()) else {
        fail!("queue taken twice");
    };
    let (tx, mut rx) = queue.split();
    cortex_m::interrupt::free(|cs| {
        CTX.borrow(cs)
            .replace(Some((stepper, building, tx, s0, h0)))
    });
    periodic::start(syst, elcentro::DT);
    let (mut expected, mut max_err, mut yielded, mut branch_changes) = (1, 0.0f64, false, 0u32);
    let mut last = 0.0f32;
    periodic::serve(
        syst,
        &mut rx,
        || {},
        |(n, result)| {
            if n != expected {
                fail!("step {} arrived, expected {}", n, expected);
            }
            let (roof, report, y) = match result {
                Ok(x) => x,
                Err(e) => fail!("step {} refused: {}", n, e.as_str()),
            };
            branch_changes += accepted(n, Ok(report)).branch_changes;
            yielded |= y;
            if (n as usize).is_multiple_of(reference::EVERY) {
                let r = reference::ROOF.get(n as usize / reference::EVERY).copied();
                let err = libm::fabs(roof as f64 - r.unwrap_or(f32::NAN) as f64);
                if err.is_nan() || err > BOUND {
                    fail!(
                        "step {}: |roof - host f64| = {:e} m > bound {:e} m",
                        n,
                        err,
                        BOUND
                    );
                }
                max_err = max_err.max(err);
            }
            last = roof;
            expected += 1;
            n == STEPS
        },
    );
    if !yielded {
        fail!("no storey yielded: the check would not exercise the history");
    }
    if last.to_bits() != counted_roof.to_bits() {
        fail!(
            "the timer run ended at roof {:e} m, the counted run at {:e} m",
            last,
            counted_roof
        );
    }
    hprintln!(
        "qemu_hysteretic: {} SysTick steps of the yielding 3-storey building under El Centro (bilinear storeys, f32, {} Newton iterations each, all converged, {} branch changes), max |roof - host f64| = {:e} m <= bound {:e} m",
        STEPS,
        reference::ITERATIONS,
        branch_changes,
        max_err,
        BOUND
    );
    hprintln!(
        "target roof displacement f32 bits = {:#010x}",
        last.to_bits()
    );
    hprintln!("COST hysteretic_3 {} {}", total / STEPS as u64, worst_cost);
    hprintln!("MEM qemu_hysteretic step_stack_bytes {}", step_stack);
    fw::report_stack("qemu_hysteretic");
    fw::exit_success()
}
