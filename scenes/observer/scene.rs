//! The observer scene, shared by the host example (`xtask/src/bin/observer_building.rs`), the
//! firmware (`examples/qemu_observer.rs`) and the tests (`tests/observer.rs`): the 5-storey
//! building under El Centro; the "true" structure has a storey-1 stiffness 10 % below the
//! model's; the absolute accelerations of floors 2 and 5 are measured with noise; the
//! ground acceleration (the input) is measured exactly.
//!
//! Everything here is `const` or integer/`f64` arithmetic, so the host and the Cortex-M4F
//! (soft-float `f64`, IEEE like the host's) produce the same measurement samples bit for
//! bit.
#![allow(dead_code)] // each includer uses a different subset

use aemstep::models::{self, Rows, base_excitation};
use aemstep::observer::{Measurement, Outputs, StateSpace, SteadyState};

/// Time step (s): the record's sample interval.
pub const H: f64 = 0.02;
/// The model: the benchmark building.
pub const MODEL: (Rows<5>, Rows<5>, Rows<5>) = models::five_storey_building();
/// Storey-1 stiffness of the truth relative to the model's.
pub const TRUE_STOREY_1: f64 = 0.9;
/// The truth: the model's mass and damping matrices, storey 1 10 % softer.
pub const TRUTH: (Rows<5>, Rows<5>, Rows<5>) = {
    let (m, c, _) = MODEL;
    let mut ks = [models::FIVE_STOREY_STIFFNESS; 5];
    ks[0] *= TRUE_STOREY_1;
    let (_, k) = models::shear_building([models::FIVE_STOREY_MASS; 5], ks);
    (m, c, k)
};
/// The measured DOFs (floors 2 and 5).
pub const SENSORS: [usize; 2] = [1, 4];
/// What the accelerometers measure: absolute accelerations `a + a_g` of floors 2 and 5.
pub const ACCELEROMETERS: Outputs<5, 1, 2> =
    Outputs::absolute_accelerations(Outputs::<5, 1, 2>::select(SENSORS), 0);
/// What is estimated: every inter-storey drift (m).
pub const DRIFTS: Outputs<5, 1, 5> = Outputs::displacements(models::storey_drifts());
/// Peak |absolute acceleration| of the truth at floors 2 and 5 over the record (m/s²),
/// rounded to 4 digits; `tests/observer.rs` recomputes it.
pub const PEAK: [f64; 2] = [5.913, 8.553];
/// Accelerometer noise: 3 % of each sensor's peak (standard deviation, m/s²).
pub const NOISE_FRACTION: f64 = 0.03;
/// Standard deviation of the accelerometer noise (m/s²).
pub const SIGMA_Y: [f64; 2] = [NOISE_FRACTION * PEAK[0], NOISE_FRACTION * PEAK[1]];
/// The observer's process noise: white unmodelled forces on every floor (N), what the
/// model error looks like to the filter (a 10 % stiffness error on a 2 cm drift is
/// `2·10⁵` N; the filter only needs the order of magnitude).
pub const SIGMA_F: f64 = 5.0e4;
/// Seed of the noise generator.
pub const SEED: u64 = 20_260_519;

/// The model's state-space form (input: ground acceleration, m/s²).
pub const MODEL_SS: StateSpace<5, 10, 1> = ok(StateSpace::from_rows_aem(
    MODEL.0,
    MODEL.1,
    MODEL.2,
    base_excitation(&MODEL.0),
    H,
));
/// The model with unit forces on every floor as inputs (for the process noise).
const FORCES_SS: StateSpace<5, 10, 5> = ok(StateSpace::from_rows_aem(
    MODEL.0,
    MODEL.1,
    MODEL.2,
    diag([1.0; 5]),
    H,
));
/// The accelerometers on the model.
pub const MEAS: Measurement<10, 1, 2> = ok(MODEL_SS.outputs(&ACCELEROMETERS));
/// The drifts on the model.
pub const DRIFT_OUT: Measurement<10, 1, 5> = ok(MODEL_SS.outputs(&DRIFTS));
/// Process noise covariance `Q` (`S×S`).
pub const Q: [[f64; 10]; 10] = FORCES_SS.input_noise(&diag([SIGMA_F * SIGMA_F; 5]));
/// Measurement noise covariance `R`.
pub const R: [[f64; 2]; 2] = diag([SIGMA_Y[0] * SIGMA_Y[0], SIGMA_Y[1] * SIGMA_Y[1]]);
/// The steady-state Kalman gain, solved by the compiler.
pub const GAIN: SteadyState<10, 2> = ok(SteadyState::from_parts(&MODEL_SS, &MEAS, &Q, &R));

/// The modal observer's model: R = 2 modes, `x = [η; η']`.
pub const MODAL_SS: StateSpace<5, 4, 1> = ok(StateSpace::from_rows_modal::<2>(
    MODEL.0,
    MODEL.2,
    aemstep::Damping::Matrix(MODEL.1),
    base_excitation(&MODEL.0),
    [0, 1],
    H,
));
const MODAL_FORCES: StateSpace<5, 4, 5> = ok(StateSpace::from_rows_modal::<2>(
    MODEL.0,
    MODEL.2,
    aemstep::Damping::Matrix(MODEL.1),
    diag([1.0; 5]),
    [0, 1],
    H,
));
/// The accelerometers and the drifts on the modal model.
pub const MODAL_MEAS: Measurement<4, 1, 2> = ok(MODAL_SS.outputs(&ACCELEROMETERS));
/// The drifts read from the modal state.
pub const MODAL_DRIFT_OUT: Measurement<4, 1, 5> = ok(MODAL_SS.outputs(&DRIFTS));
/// The modal observer's process noise (the same forces, on 2 modes).
pub const MODAL_Q: [[f64; 4]; 4] = MODAL_FORCES.input_noise(&diag([SIGMA_F * SIGMA_F; 5]));
/// The modal observer's steady-state gain. The dropped modes' response is measurement
/// error to it; it is in the accelerometers' noise budget here.
pub const MODAL_GAIN: SteadyState<4, 2> = ok(SteadyState::from_parts(
    &MODAL_SS,
    &MODAL_MEAS,
    &MODAL_Q,
    &R,
));

/// `diag(d)`.
pub const fn diag<const N: usize>(d: [f64; N]) -> [[f64; N]; N] {
    let mut a = [[0.0; N]; N];
    let mut i = 0;
    while i < N {
        a[i][i] = d[i];
        i += 1;
    }
    a
}

/// Unwrap in `const` (a build error names the reason).
const fn ok<T: Copy>(r: Result<T, aemstep::Error>) -> T {
    match r {
        Ok(t) => t,
        Err(e) => panic!("{}", e.as_str()),
    }
}

/// Deterministic noise: xorshift64* and the Irwin–Hall sum of 12 uniforms (mean 0,
/// variance 1, within ±6), computed from integers and one `f64` division: the same
/// numbers on every machine.
pub struct Noise(u64);

impl Noise {
    /// The generator of [`SEED`].
    pub const fn new() -> Self {
        Noise(SEED.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next_u24(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40
    }
    /// A standard (approximately) normal sample.
    pub fn gauss(&mut self) -> f64 {
        let mut s = 0u64;
        for _ in 0..12 {
            s += self.next_u24();
        }
        s as f64 / (1u64 << 24) as f64 - 6.0
    }
}

/// The accelerometer reading of the truth's state: `a_i + a_g + noise_i` (m/s²).
pub fn measure(a: &[f64; 5], ag: f64, noise: &mut Noise) -> [f64; 2] {
    let n0 = noise.gauss();
    let n1 = noise.gauss();
    [
        a[SENSORS[0]] + ag + SIGMA_Y[0] * n0,
        a[SENSORS[1]] + ag + SIGMA_Y[1] * n1,
    ]
}
