//! Firmware: a yielding structure on a Cortex-M4F (QEMU `mps2-an386`) — the 3-storey
//! shear building with bilinear (kinematic hardening) storeys of
//! `examples/hysteretic_fw/building.rs` under the whole El Centro record, h = 0.02 s (one
//! step per record sample), `f32`, exactly `ITERATIONS` Newton iterations a step
//! (constant work, as a hard real-time loop needs), the storey histories committed only
//! with a converged step.
//!
//! Checked every 10th step against the host's f64 run (`examples/hysteretic_fw/reference.rs`,
//! generated and bounded by `tests/firmware_hysteretic.rs`); fails if a step is refused or
//! not converged, or if the roof displacement leaves the bound. Prints the instructions
//! per step (`COST hysteretic_3 <mean> <max>`, SysTick under `-icount shift=0`).
//!
//! Run: `cargo run --release --target thumbv7em-none-eabihf --features qemu --example qemu_hysteretic`
//! (or `bash scripts/qemu.sh`). Broken variant that must fail:
//! `RUSTFLAGS='--cfg aemstep_broken="hysteretic-tight-bound" -C link-arg=-Tlink.x'` (a bound 100 times tighter
//! than the measured f32 rounding).
#![no_std]
#![no_main]

#[macro_use]
#[path = "fw/mod.rs"]
mod fw;
#[path = "hysteretic_fw/building.rs"]
mod building;
#[path = "modal_fw/elcentro.rs"]
mod elcentro;
#[path = "hysteretic_fw/reference.rs"]
mod reference;

use aemstep::hysteresis::{Bilinear, BilinearHistory, HistoryModel, ShearBuilding};
use aemstep::{Error, NewtonReport, NewtonSettings, Nonlinear, State};
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use nalgebra::SVector;

type Building = ShearBuilding<f32, Bilinear<f32>, 3>;

/// `NewtonSettings::default_tolerance()` for f32 (1.5e-5), as in the host twin.
const TOL: f32 = 1.5e-5;
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
    history: &mut [BilinearHistory<f32>; 3],
    ag: f32,
) -> Result<NewtonReport<f32>, Error> {
    stepper.try_step_with_history(building, s, history, &building.ground_load(ag))
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        fail!("peripherals taken twice");
    };
    let syst = &mut cp.SYST;
    fw::start_counter(syst);
    let cal = fw::calibrate(syst);
    hprintln!("calibration: 100 x 1000 nops = {} instructions", cal);

    let building = match building::bilinear::<f32>() {
        Ok(b) => b,
        Err(e) => fail!("building: {}", e.as_str()),
    };
    let settings = NewtonSettings::exactly(reference::ITERATIONS, TOL);
    let stepper = match Nonlinear::<f32, 3>::new(elcentro::DT, settings) {
        Ok(s) => s,
        Err(e) => fail!("stepper: {}", e.as_str()),
    };
    let ag = &elcentro::AG_F32;
    let z = SVector::zeros();
    let p0 = building.ground_load(ag[0]);
    let (mut s, mut history) =
        match stepper.start_with_history(&building, &z, &z, &p0, &building.initial_history()) {
            Ok(x) => x,
            Err(e) => fail!("start: {}", e.as_str()),
        };
    let (mut probe, mut probe_h) = (s, history);
    let step_stack = fw::stack_used_by(|| {
        let _ = core::hint::black_box(qemu_hysteretic_step(
            &stepper,
            &building,
            &mut probe,
            &mut probe_h,
            ag[1],
        ));
    });

    let (mut total, mut worst_cost) = (0u64, 0u32);
    let (mut max_err, mut yielded, mut branch_changes) = (0.0f64, false, 0u32);
    let mut last = 0.0f32;
    for (n, &a) in ag.iter().enumerate().skip(1) {
        let mut result = Err(Error::NonFiniteInput);
        let c = fw::instructions(syst, || {
            result = qemu_hysteretic_step(&stepper, &building, &mut s, &mut history, a);
        });
        let report = match result {
            Ok(r) => r,
            Err(e) => fail!("step {} refused: {}", n, e.as_str()),
        };
        if !report.converged || report.iterations != reference::ITERATIONS {
            fail!(
                "step {}: converged = {}, iterations = {}",
                n,
                report.converged,
                report.iterations
            );
        }
        branch_changes += report.branch_changes;
        total += c as u64;
        worst_cost = worst_cost.max(c);
        yielded |= history.iter().any(|h| h.plastic != 0.0);
        last = s.u()[2];
        if n % reference::EVERY == 0 {
            let r = reference::ROOF.get(n / reference::EVERY).copied();
            let err = libm::fabs(last as f64 - r.unwrap_or(f32::NAN) as f64);
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
    }
    if !yielded {
        fail!("no storey yielded: the check would not exercise the history");
    }
    let steps = (elcentro::SAMPLES - 1) as u64;
    hprintln!(
        "qemu_hysteretic: {} steps of the yielding 3-storey building under El Centro (bilinear storeys, f32, {} Newton iterations each, all converged, {} branch changes), max |roof - host f64| = {:e} m <= bound {:e} m",
        steps,
        reference::ITERATIONS,
        branch_changes,
        max_err,
        BOUND
    );
    hprintln!(
        "target roof displacement f32 bits = {:#010x}",
        last.to_bits()
    );
    hprintln!("COST hysteretic_3 {} {}", total / steps, worst_cost);
    hprintln!("MEM qemu_hysteretic step_stack_bytes {}", step_stack);
    fw::report_stack("qemu_hysteretic");
    fw::exit_success()
}
