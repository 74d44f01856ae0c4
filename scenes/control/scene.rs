//! The semi-active control scene of issue 33: the 3-storey model building of the MR-damper
//! benchmark of Dyke, Spencer, Sain & Carlson (1996), *Modeling and control of
//! magnetorheological dampers for seismic response reduction*, Smart Mater. Struct. 5, with
//! one MR damper between the ground and floor 1, under El Centro 1940 NS played at five
//! times its recorded rate, closed by the clipped-optimal controller (LQG observer on the
//! three absolute floor accelerations and the measured damper force, the regulator's gain,
//! the switching law) at `RATE` = 1 kHz. Structure and damper values: as
//! `tests/support/dyke1996.rs` / `docs/control-benchmark-data.md` restate them, with the
//! damper's `MrParameters` of the firmware brief ([`DAMPER`]).
//!
//! Data and every gain as `const`s (the observer's Riccati gain and the regulator solved by
//! the compiler), shared by `tests/firmware_control.rs` (the host twin) and
//! `examples/firmware/qemu_control.rs` (`f32` on the M4F, `f64` on the M7).
#![allow(dead_code)] // each includer uses a different subset

use aemstep::control::{Controller, DesignModel, Lqr, MrParameters, Weights};
use aemstep::models::{Rows, base_excitation};
use aemstep::observer::{Measurement, Observer, Outputs, StateSpace, SteadyState};

/// Floors.
pub const N: usize = 3;
/// Observer states (`[x; ẋ]`), control inputs (the damper force), measurements (the three
/// absolute floor accelerations), states of the delayed design (`[x; ẋ; f_{k−1}]`).
pub const S: usize = 6;
/// See [`S`].
pub const I: usize = 1;
/// See [`S`].
pub const O: usize = 3;
/// See [`S`].
pub const Z: usize = 7;

/// Floor mass (kg).
pub const MASS: f64 = 98.3;
/// `M` (kg).
pub const M: Rows<N> = [[MASS, 0.0, 0.0], [0.0, MASS, 0.0], [0.0, 0.0, MASS]];
/// `K` (N/m).
pub const K: Rows<N> = [
    [12.0e5, -6.84e5, 0.0],
    [-6.84e5, 13.7e5, -6.84e5],
    [0.0, -6.84e5, 6.84e5],
];
/// `C` (N·s/m).
pub const C: Rows<N> = [
    [175.0, -50.0, 0.0],
    [-50.0, 100.0, -50.0],
    [0.0, -50.0, 50.0],
];
/// The MR damper (Bouc–Wen, `n = 1`), SI units: the crate's named set of the benchmark.
pub const DAMPER: MrParameters = MrParameters::DYKE_1996;

/// Steps per second (Hz): the controller's sample rate and the emulated plant's step.
pub const RATE: u64 = 1000;
/// `h = 1/RATE` (s).
pub const H: f64 = 1.0 / RATE as f64;
/// The record is played at five times its recorded rate: its 0.02 s samples are 4 ms
/// apart in model time, `STEPS_PER_SAMPLE` steps.
pub const STEPS_PER_SAMPLE: u64 = 4;

/// The ground acceleration (m/s²) at step `n`: the record (`elcentro::AG_F64` or `AG_F32`)
/// at model time `n h`, linearly interpolated between its samples (`n / 4` and the fraction
/// `(n mod 4)/4`, exact), zero after its end.
pub fn ground<T: aemstep::Real>(ag: &[T], n: u64) -> T {
    let (i, rem) = ((n / STEPS_PER_SAMPLE) as usize, n % STEPS_PER_SAMPLE);
    if i + 1 >= ag.len() {
        return T::zero();
    }
    let frac = T::from_f64_rounded(rem as f64 / STEPS_PER_SAMPLE as f64);
    ag[i] + frac * (ag[i + 1] - ag[i])
}

/// Steps after step 0 covering the record: `(samples − 1) · 4`.
pub const fn steps(samples: usize) -> u64 {
    (samples as u64 - 1) * STEPS_PER_SAMPLE
}

/// The step at which the floor-1 accelerometer's sample is missing (NaN): the controller
/// must report it and hold its last safe output (3.0 s, in the strong motion).
pub const MISSING_STEP: u64 = 3000;
/// The firmware checks the floor-1 displacement every `CHECK_EVERY` steps (50 ms).
pub const CHECK_EVERY: u64 = 50;

/// The design model: the structure with the damper force `f` (internal sign: resisting a
/// positive floor-1 displacement) as its input, `M ẍ + C ẋ + K x = −e₁ f`, discretized by
/// the crate's AEM step at `h`.
pub const SS: StateSpace<N, S, I> = ok(StateSpace::from_rows_aem(
    M,
    C,
    K,
    [[-1.0], [0.0], [0.0]],
    H,
));
/// The same structure with the ground acceleration as its input (for the process noise).
pub const SS_GROUND: StateSpace<N, S, I> =
    ok(StateSpace::from_rows_aem(M, C, K, base_excitation(&M), H));
/// The accelerometers: `ẍ` of the model without the ground input, `M⁻¹(−e₁ f − C ẋ − K x)`,
/// is the absolute floor acceleration `ẍ + ẍ_g` of the plant.
pub const SENSORS: Measurement<S, I, O> = ok(SS.outputs(&Outputs::accelerations(
    Outputs::<N, I, O>::select([0, 1, 2]),
)));
/// The weighted outputs: the floor displacements (m).
pub const DISPLACEMENTS: Measurement<S, I, N> =
    ok(
        SS.outputs(&Outputs::displacements(Outputs::<N, I, N>::select([
            0, 1, 2,
        ]))),
    );
/// Process noise: the ground acceleration, white, `σ_g = 1 m/s²`, through the model.
pub const GROUND_SIGMA: f64 = 1.0;
/// Accelerometer noise (m/s², standard deviation).
pub const SENSOR_SIGMA: f64 = 0.1;
/// The observer's steady-state Kalman gain, solved by the compiler.
pub const KALMAN: SteadyState<S, O> = ok(SteadyState::from_parts(
    &SS,
    &SENSORS,
    &SS_GROUND.input_noise(&[[GROUND_SIGMA * GROUND_SIGMA]]),
    &diag([SENSOR_SIGMA * SENSOR_SIGMA; O]),
));
/// Weight on each floor displacement (1/m², per N² of force weight `R = 1`): the ratio of
/// the continuous design of `tests/control_benchmark_reference.rs` (`Q = 10¹⁰`, `R = 1`).
pub const Q_DISPLACEMENT: f64 = 1.0e10;
/// The weight on the delayed force state `f_{k−1}` (1/N²): small, so the delay is modelled,
/// not penalised.
pub const R_DELAYED: f64 = 1.0e-3;
/// The regulator's weights on the delayed model.
pub const WEIGHTS: Weights<Z, I> =
    ok(
        Weights::outputs(&DISPLACEMENTS, &diag([Q_DISPLACEMENT; N]), &[[1.0]])
            .delayed(&[[R_DELAYED]]),
    );
/// The regulator on the delayed model (`f_k` acts over the step after it is measured),
/// solved and certified by the compiler.
pub const LQR: Lqr<Z, I> = ok(Lqr::from_parts(
    &ok(DesignModel::from_state_space(&SS).delayed::<Z>()),
    &WEIGHTS,
));
/// The controller's bound on the desired force (N): beyond what the damper can deliver
/// (`α(V_max) z_u + c₀(V_max) ẋ`, about 2.5 kN at 0.3 m/s), so it never clips the law's
/// input in this scene.
pub const LIMIT: f64 = 1.0e4;

/// The controller in `f32`, every operator rounded by the compiler.
pub const CONTROLLER_F32: Controller<f32, S, I, O> = ok(Controller::from_parts_f32(
    ok(Observer::<f32, S, I, O>::from_parts_f32(
        &SS,
        &SENSORS,
        &KALMAN.gain,
    )),
    &LQR.gain,
    &[LIMIT],
));
/// The controller in `f64`.
pub const CONTROLLER_F64: Controller<f64, S, I, O> = ok(Controller::from_parts_f64(
    ok(Observer::<f64, S, I, O>::from_parts_f64(
        &SS,
        &SENSORS,
        &KALMAN.gain,
    )),
    &LQR.gain,
    &[LIMIT],
));

/// Multiply-adds of one controller step: the observer's `S² + 2S·I + 2S·O + O·I` and the
/// command's `S·I + I²` ([`Controller`]'s cost), `36 + 12 + 36 + 3 + 6 + 1 = 94`.
pub const CONTROLLER_MADDS: usize = S * S + 2 * S * I + 2 * S * O + O * I + S * I + I * I;

/// Multiply-adds of the controller's observer update alone (`Observer::step`):
/// `S² + 2S·I + 2S·O + O·I = 36 + 12 + 36 + 3 = 87`.
pub const OBSERVER_MADDS: usize = S * S + 2 * S * I + 2 * S * O + O * I;

/// `diag(d)`.
pub const fn diag<const D: usize>(d: [f64; D]) -> [[f64; D]; D] {
    let mut a = [[0.0; D]; D];
    let mut i = 0;
    while i < D {
        a[i][i] = d[i];
        i += 1;
    }
    a
}

/// Unwrap in `const` (a build error names the reason).
pub const fn ok<T: Copy>(r: Result<T, aemstep::Error>) -> T {
    match r {
        Ok(t) => t,
        Err(e) => panic!("{}", e.as_str()),
    }
}
