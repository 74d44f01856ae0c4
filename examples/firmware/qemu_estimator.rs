//! Firmware: the joint input–state estimator from a timer interrupt on a Cortex-M4F (QEMU
//! `mps2-an386`): the unknown force at the roof of the 5-storey building, and every storey
//! drift, estimated from 3 accelerometers and the roof displacement.
//!
//! The scene of `scenes/estimator/scene.rs`: the model, its standard form and the
//! steady-state gains of the Gillijns–De Moor filter are `static`s computed by the compiler
//! (`InputStateObserver<f32, 10, 1, 4>`: no factorization or Riccati code in flash). The
//! main loop plays the sensors: it steps the "true" building (soft-float `f64`,
//! bit-identical to the host's) under a low-pass filtered pseudo-random roof force, adds
//! sensor noise, and pushes the samples into a `heapless::spsc::Queue`. SysTick fires every
//! h = 0.02 s of the core clock; its handler takes the next sample, steps the `f32`
//! estimator, reads the force and the five drifts, and pushes them through a second queue
//! back to the main loop. There the same estimator in `f64` (soft float, bit-identical to
//! the host's `f64` run of `tests/firmware_estimator.rs`) is stepped on the same samples,
//! and at the end the largest force and drift differences must be within
//! `scene::bound(peak)` (`AMPLIFICATION · √(S+I+O) · ε₃₂ · max|·|`), and no sample may be
//! missing.
//!
//! Beside the estimator the handler steps a χ² detector (`Detector<f32, 4, 50>`) on the
//! estimator's own residual (`step_innovation`: what is left of the sensors once the force
//! is estimated, 3 degrees of freedom a sample, whitened by the gains' `R̃`); on the intact
//! building it must raise no alarm, and its last window sum is compared bit for bit with
//! the host's by `scripts/qemu.sh`.
//!
//! Before the timer starts it counts the instructions of one estimator step and of one
//! estimator step with the detector (SysTick under `-icount shift=0`) and prints `COST` lines; the estimator
//! must take at most 3 instructions per multiply-add.
//!
//! Run: `cargo run -p aemstep-firmware --release --target thumbv7em-none-eabihf --example qemu_estimator`
//! (or `bash scripts/qemu.sh`). Broken variant that must fail, through
//! `RUSTFLAGS='--cfg aemstep_broken="estimator-tight-bound"'` (not a feature): the bound
//! 100× tighter than derived.
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;
#[path = "fw/periodic.rs"]
mod periodic;
#[path = "../../scenes/estimator/scene.rs"]
mod scene;

use core::cell::RefCell;
use core::hint::black_box;

use aemstep::detection::{ChiSquareTest, Detector, Whitener, Window};
use aemstep::estimation::{InputStateObserver, JointEstimate};
use aemstep::observer::Readout;
use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::SYST;
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::hprintln;
use heapless::spsc::{Consumer, Producer, Queue};
use nalgebra::SVector;

/// Steps of the run (80 s).
const STEPS: u32 = scene::STEPS as u32;

/// The checked bound for an `f64` peak `peak`.
#[cfg(not(aemstep_broken = "estimator-tight-bound"))]
fn bound(peak: f64) -> f64 {
    scene::bound(peak)
}
/// Broken on purpose: 100× tighter than derived; must fail.
#[cfg(aemstep_broken = "estimator-tight-bound")]
fn bound(peak: f64) -> f64 {
    scene::bound(peak) / 100.0
}

/// Unwrap in `const` (a build error names the reason).
const fn ok<T: Copy>(r: Result<T, aemstep::Error>) -> T {
    match r {
        Ok(t) => t,
        Err(e) => panic!("{}", e.as_str()),
    }
}

/// The estimator: model and gains computed by the compiler into flash.
static ESTIMATOR: InputStateObserver<f32, 10, 1, 4> = ok(
    InputStateObserver::<f32, 10, 1, 4>::from_parts_f32(&scene::MODEL, &scene::GAINS),
);
/// The reference: the same estimator in `f64` (soft float).
static ESTIMATOR_F64: InputStateObserver<f64, 10, 1, 4> = ok(
    InputStateObserver::<f64, 10, 1, 4>::from_parts_f64(&scene::MODEL, &scene::GAINS),
);
/// Every drift from the physical state.
static DRIFTS: Readout<f32, 10, 1, 5> =
    ok(Readout::<f32, 10, 1, 5>::from_parts_f32(&scene::DRIFT_OUT));
/// Every drift, `f64`.
static DRIFTS_F64: Readout<f64, 10, 1, 5> =
    ok(Readout::<f64, 10, 1, 5>::from_parts_f64(&scene::DRIFT_OUT));

/// The χ² detector on the estimator's residual: `R̃` factored by the compiler, the
/// threshold's degrees of freedom (`O − I = 3` a sample) taken from the estimator's type.
static DETECTOR: Detector<f32, 4, { scene::WINDOW }> = Detector::from_parts(
    ok(Whitener::<f32, 4>::from_rows_f32(
        &scene::GAINS.innovation_covariance,
    )),
    ok(ChiSquareTest::new_f32(&ESTIMATOR, scene::ALPHA)),
);

/// One sample from the sensors: step index, the four readings.
type Sample = (u32, [f32; 4]);
/// One estimate: step index, the force (N), the five drifts (m), missing samples so far,
/// detector alarms so far, the detector's window sum (fixed point), the window sum as the
/// statistic is logged (`f32`: no double-precision routine in the handler).
type Est = (u32, f32, [f32; 5], u32, u32, u64, f32);

/// One real-time step: the estimator's step and its residual, the χ² test on the window,
/// then the force and the drifts; the `bool` is an alarm, the last `f32` the window's sum
/// (the statistic a handler logs, `Window::sum`, in `f32`). Out of line so its code size
/// (symbol `qemu_estimator_step`) and stack can be measured alone, and its call graph
/// checked for soft-double routines (`scripts/qemu.sh`).
#[unsafe(no_mangle)]
#[inline(never)]
fn qemu_estimator_step(
    est: &InputStateObserver<f32, 10, 1, 4>,
    det: &Detector<f32, 4, { scene::WINDOW }>,
    drifts: &Readout<f32, 10, 1, 5>,
    e: &mut JointEstimate<f32, 10, 1>,
    win: &mut Window<f32, { scene::WINDOW }>,
    y: [f32; 4],
) -> (f32, [f32; 5], bool, f32) {
    let nu = est.step_innovation(e, &SVector::from(y));
    let alarm = det.update(win, &nu);
    let w = *e.input();
    (
        w[0],
        drifts.read(&est.state(e), &w).into(),
        alarm,
        win.sum(),
    )
}

/// The estimator's step with the detector (the second `COST` line).
#[unsafe(no_mangle)]
#[inline(never)]
fn cost_step_detector(
    est: &InputStateObserver<f32, 10, 1, 4>,
    det: &Detector<f32, 4, { scene::WINDOW }>,
    e: &mut JointEstimate<f32, 10, 1>,
    win: &mut Window<f32, { scene::WINDOW }>,
    y: [f32; 4],
) -> bool {
    let nu = est.step_innovation(e, &SVector::from(y));
    det.update(win, &nu)
}

/// The estimator's step alone (the `COST` line).
#[unsafe(no_mangle)]
#[inline(never)]
fn cost_step_estimator(
    est: &InputStateObserver<f32, 10, 1, 4>,
    e: &mut JointEstimate<f32, 10, 1>,
    y: [f32; 4],
) {
    est.step(e, &SVector::from(y));
}

/// A call that does nothing but cannot be removed: the loop overhead to subtract.
#[inline(never)]
fn empty(y: [f32; 4]) -> f32 {
    black_box(y[0] + y[3])
}

/// Instructions per call of `f` (in tenths) over `reps` calls fed pseudo-random
/// samples, minus the same loop around an empty call.
fn per_step(syst: &mut SYST, reps: u32, mut f: impl FnMut([f32; 4])) -> u32 {
    let sample = |i: u32| {
        let a = black_box(((i % 97) as f32 - 48.0) * 0.01);
        [a, 0.5 * a, 0.25 * a, 1e-3 * a]
    };
    let full = fw::instructions(syst, || {
        for i in 0..reps {
            f(sample(i));
        }
    });
    let mut acc = 0.0f32;
    let base = fw::instructions(syst, || {
        for i in 0..reps {
            acc += empty(sample(i));
        }
    });
    black_box(acc);
    ((full.saturating_sub(base)) as u64 * 10 / reps as u64) as u32
}

/// Handed from `main` to the SysTick handler once, before the timer starts.
type Ctx = (
    Consumer<'static, Sample>,
    Producer<'static, Est>,
    JointEstimate<f32, 10, 1>,
    (Window<f32, { scene::WINDOW }>, u32),
);
static CTX: Mutex<RefCell<Option<Ctx>>> = Mutex::new(RefCell::new(None));

#[exception]
fn SysTick() {
    static mut LOCAL: Option<Ctx> = None;
    let Some((rx, tx, e, (win, alarms))) = fw::handover(&CTX, LOCAL) else {
        return;
    };
    if e.steps() >= STEPS as u64 {
        return;
    }
    let Some((n, y)) = rx.dequeue() else {
        periodic::overrun();
        return;
    };
    // `black_box`: the statics' addresses as arguments, so the compiler keeps the one
    // step symbol the memory table measures instead of a copy specialized to them.
    let (w, d, alarm, sum) = qemu_estimator_step(
        black_box(&ESTIMATOR),
        black_box(&DETECTOR),
        black_box(&DRIFTS),
        e,
        win,
        y,
    );
    if alarm {
        *alarms += 1;
    }
    if tx
        .enqueue((n, w, d, e.missing() as u32, *alarms, win.sum_fixed(), sum))
        .is_err()
    {
        periodic::overrun();
    }
}

/// Largest |·| of a slice.
fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(libm::fabs(*x)))
}

#[entry]
fn main() -> ! {
    let mut cp = fw::init();
    let syst = &mut cp.SYST;

    // Instructions per estimator step.
    let mut e = ESTIMATOR.start_at_rest();
    let c = per_step(syst, 1000, |y| {
        cost_step_estimator(black_box(&ESTIMATOR), black_box(&mut e), y)
    });
    hprintln!(
        "COST estimator_joint {}.{} {}",
        c / 10,
        c % 10,
        scene::STEP_MADDS
    );
    // The goal every stepper meets: at most 3 instructions per multiply-add.
    if c > 30 * scene::STEP_MADDS as u32 {
        fail!(
            "estimator_joint: {}.{} instructions a step > 3 per multiply-add",
            c / 10,
            c % 10
        );
    }

    let mut e = ESTIMATOR.start_at_rest();
    let mut win = Window::at_rest();
    let c = per_step(syst, 1000, |y| {
        black_box(cost_step_detector(
            black_box(&ESTIMATOR),
            black_box(&DETECTOR),
            &mut e,
            &mut win,
            y,
        ));
    });
    hprintln!(
        "COST estimator_detector {}.{} {}",
        c / 10,
        c % 10,
        scene::DETECTOR_MADDS
    );

    // The real-time run.
    let Some(q_in) = cortex_m::singleton!(: Queue<Sample, 8> = Queue::new()) else {
        fail!("queue taken twice");
    };
    let Some(q_out) = cortex_m::singleton!(: Queue<Est, 8> = Queue::new()) else {
        fail!("queue taken twice");
    };
    let (mut sensor_tx, sensor_rx) = q_in.split();
    let (est_tx, mut est_rx) = q_out.split();
    let mut probe = ESTIMATOR.start_at_rest();
    let mut probe_win = Window::at_rest();
    let step_stack = fw::stack_used_by(|| {
        black_box(qemu_estimator_step(
            black_box(&ESTIMATOR),
            black_box(&DETECTOR),
            black_box(&DRIFTS),
            &mut probe,
            &mut probe_win,
            [0.1, 0.2, 0.3, 1e-3],
        ));
    });
    let mut sensors = scene::Truth::new();
    let mut sent = 0u32;
    let mut next_sample = |sensors: &mut scene::Truth| {
        sent += 1;
        let y = sensors.next();
        (sent, y.map(|v| v as f32))
    };
    // Two samples ready before the first tick.
    for _ in 0..2 {
        if sensor_tx.enqueue(next_sample(&mut sensors)).is_err() {
            fail!("sample queue full at start");
        }
    }
    cortex_m::interrupt::free(|cs| {
        CTX.borrow(cs).replace(Some((
            sensor_rx,
            est_tx,
            JointEstimate::at_rest_f32(),
            (Window::at_rest(), 0),
        )))
    });

    // The reference: the same samples again (the generator is deterministic), the f64
    // estimator stepped on them.
    let mut ref_sensors = scene::Truth::new();
    let mut e64 = ESTIMATOR_F64.start_at_rest();
    let mut expected = 1;
    // Largest differences and f64 peaks: force (N), drifts (m).
    let (mut err_w, mut err_d, mut peak_w, mut peak_d) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut last = (0u32, 0.0f32, [0.0f32; 5], 0u32, 0u32, 0u64, 0.0f32);
    let mut last_w64 = 0.0f64;

    periodic::start(syst, scene::H);
    let feed = || {
        while sensors.n < scene::STEPS && sensor_tx.ready() {
            let s = next_sample(&mut sensors);
            if sensor_tx.enqueue(s).is_err() {
                fail!("sample queue full");
            }
        }
    };
    periodic::serve(
        syst,
        &mut est_rx,
        feed,
        |(n, w, d, missing, alarms, sum, sum32)| {
            if n != expected {
                fail!("estimate {} arrived, expected {}", n, expected);
            }
            let y = ref_sensors.next();
            ESTIMATOR_F64.step(&mut e64, &SVector::from(y));
            let w64 = e64.input()[0];
            let d64: [f64; 5] = DRIFTS_F64
                .read(&ESTIMATOR_F64.state(&e64), e64.input())
                .into();
            let ew = libm::fabs(w as f64 - w64);
            let ed = max_abs(&core::array::from_fn::<f64, 5, _>(|i| d[i] as f64 - d64[i]));
            if ew.is_nan() || ed.is_nan() {
                fail!("step {}: a NaN estimate ({} samples missing)", n, missing);
            }
            err_w = err_w.max(ew);
            err_d = err_d.max(ed);
            peak_w = peak_w.max(libm::fabs(w64));
            peak_d = peak_d.max(max_abs(&d64));
            last = (n, w, d, missing, alarms, sum, sum32);
            last_w64 = w64;
            expected += 1;
            n == STEPS
        },
    );
    if last.3 != 0 {
        fail!("{} sensor samples were missing (NaN)", last.3);
    }
    // The model matches the truth (whose sensor noise is the detector's R and which has no
    // process noise): the χ² test must stay quiet. `tests/firmware_estimator.rs` shows the
    // same test alarming on a miscalibrated accelerometer.
    if last.4 != 0 {
        fail!(
            "the χ² detector raised {} alarms on the intact building",
            last.4
        );
    }
    let (bound_w, bound_d) = (bound(peak_w), bound(peak_d));
    if err_w > bound_w {
        fail!(
            "force estimate off the f64 estimate by {:e} N > bound {:e} N (peak {:e} N)",
            err_w,
            bound_w,
            peak_w
        );
    }
    if err_d > bound_d {
        fail!(
            "drift estimate off the f64 estimate by {:e} m > bound {:e} m (peak {:e} m)",
            err_d,
            bound_d,
            peak_d
        );
    }
    hprintln!(
        "qemu_estimator: {} SysTick steps of the joint input-state estimator (f32, 10 states, 1 unknown force, 4 sensors); force within {:e} N of the f64 estimate (max {:e} N, peak {:e} N), drifts within {:e} m (max {:e} m, peak {:e} m)",
        STEPS,
        bound_w,
        err_w,
        peak_w,
        bound_d,
        err_d,
        peak_d
    );
    hprintln!("target roof force f32 bits = {:#010x}", last.1.to_bits());
    hprintln!("target roof force f64 bits = {:#018x}", last_w64.to_bits());
    hprintln!("target detector window sum fixed = {}", last.5);
    // The logged statistic is the fixed-point sum rounded once to f32 (scaling by 2⁻²⁴ is
    // exact).
    if last.6 != last.5 as f32 * (1.0 / (1u32 << 24) as f32) {
        fail!(
            "the f32 window sum {} is not the fixed-point sum {} in f32",
            last.6,
            last.5
        );
    }
    hprintln!("MEM qemu_estimator step_stack_bytes {}", step_stack);
    fw::report_stack("qemu_estimator");
    fw::exit_success()
}
