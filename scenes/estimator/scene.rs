//! The estimator scene, shared by the firmware (`examples/firmware/qemu_estimator.rs`) and
//! its host twin (`tests/firmware_estimator.rs`): the 5-storey benchmark building (fixed
//! base) loaded at the roof by an unknown force, measured by 3 accelerometers (floors 1,
//! 3, 5) and the roof displacement; the joint input–state estimator's model, noises and
//! steady-state gains are `const`s computed by the compiler.
//!
//! The force, the truth and the sensor noise are integer and `f64` arithmetic only (no
//! `libm`), so the host and the Cortex-M4F (soft-float `f64`, IEEE like the host's)
//! produce the same samples bit for bit.
#![allow(dead_code)] // each includer uses a different subset

use aemstep::estimation::{InputModel, InputStateGains};
use aemstep::models::{self, Rows};
use aemstep::observer::{Measurement, Outputs, StateSpace};

/// Time step (s).
pub const H: f64 = 0.02;
/// Steps after step 0 (80 s).
pub const STEPS: usize = 4000;
/// The building.
pub const BLD: (Rows<5>, Rows<5>, Rows<5>) = models::five_storey_building();
/// The unknown force acts at the roof (N).
pub const ROOF: [[f64; 1]; 5] = [[0.0], [0.0], [0.0], [0.0], [1.0]];
/// The model with the roof force as its input.
pub const SS: StateSpace<5, 10, 1> = ok(StateSpace::from_rows_aem(BLD.0, BLD.1, BLD.2, ROOF, H));
/// The sensors: accelerations of floors 1, 3, 5 (fixed base: absolute = relative, m/s²)
/// and the roof displacement (m).
pub const SENSORS: Outputs<5, 1, 4> = {
    let mut o = Outputs::<5, 1, 4>::zero();
    o.a = [
        [1.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 0.0, 1.0],
        [0.0; 5],
    ];
    o.u[3] = [0.0, 0.0, 0.0, 0.0, 1.0];
    o
};
/// The sensors on the model.
pub const MEAS: Measurement<10, 1, 4> = ok(SS.outputs(&SENSORS));
/// Every inter-storey drift (m), read from the physical state.
pub const DRIFT_OUT: Measurement<10, 1, 5> =
    ok(SS.outputs(&Outputs::displacements(models::storey_drifts())));
/// The model in the estimator's standard form.
pub const MODEL: InputModel<10, 1, 4> = ok(InputModel::from_parts(&SS, &MEAS));
/// Standard deviations of the sensor noise: 0.03 m/s² on the accelerometers, 10 µm on the
/// displacement.
pub const SIGMA_Y: [f64; 4] = [0.03, 0.03, 0.03, 1e-5];
/// Measurement noise covariance `R`.
pub const R: [[f64; 4]; 4] = diag([
    SIGMA_Y[0] * SIGMA_Y[0],
    SIGMA_Y[1] * SIGMA_Y[1],
    SIGMA_Y[2] * SIGMA_Y[2],
    SIGMA_Y[3] * SIGMA_Y[3],
]);
/// Process noise on `ξ`: unmodelled forces of 100 N on every floor.
pub const Q: [[f64; 10]; 10] = ok(StateSpace::<5, 10, 5>::from_rows_aem(
    BLD.0,
    BLD.1,
    BLD.2,
    diag([1.0; 5]),
    H,
))
.input_noise(&diag([1e4; 5]));
/// The steady-state gains of the joint input–state filter, solved by the compiler.
pub const GAINS: InputStateGains<10, 1, 4> = ok(InputStateGains::solve(&MODEL, &Q, &R));

/// Degrees of freedom a sample of the detector's statistic: the joint estimator's
/// residual has `O − I = 3` (one of the 4 sensor directions is spent on the force).
pub const DOF: usize = 3;
/// The detector's window: 1 s (50 samples, 150 degrees of freedom).
pub const WINDOW: usize = 50;
/// The detector's false-alarm probability per evaluation.
pub const ALPHA: f64 = 1e-3;

/// Pole of the force's first-order filter (per step).
pub const FORCE_POLE: f64 = 0.98;
/// Amplitude of the force's uniform increments (N): increments uniform in ±`FORCE_STEP`/2.
pub const FORCE_STEP: f64 = 1.0e4;
/// Seed of the generators.
pub const SEED: u64 = 20_261_126;

/// Deterministic generator: xorshift64*, uniforms from its top 24 bits, and the
/// Irwin–Hall sum of 12 of them (mean 0, variance 1, within ±6).
pub struct Lcg(u64);

impl Lcg {
    /// The generator of `seed`.
    pub const fn new(seed: u64) -> Self {
        Lcg(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    fn next_u24(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40
    }
    /// Uniform in `[−0.5, 0.5)`.
    pub fn uniform(&mut self) -> f64 {
        self.next_u24() as f64 / (1u64 << 24) as f64 - 0.5
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

/// The truth: the roof force (low-pass filtered uniform noise), the building's state in the
/// estimator's coordinates `ξ` stepped exactly by the model's `ξ_n = A ξ_{n−1} + B w_{n−1}`,
/// and the noisy sensors `y_n = C ξ_n + D̃ w_n + noise`.
pub struct Truth {
    force_rng: Lcg,
    noise_rng: Lcg,
    xi: [f64; 10],
    /// The force of the last step `w_n` (N).
    pub w: f64,
    /// Steps taken.
    pub n: usize,
}

impl Truth {
    /// At rest, no force.
    pub const fn new() -> Self {
        Truth {
            force_rng: Lcg::new(SEED),
            noise_rng: Lcg::new(SEED ^ 0x5555),
            xi: [0.0; 10],
            w: 0.0,
            n: 0,
        }
    }

    /// The next step: returns the sensor readings `y_n`.
    pub fn next(&mut self) -> [f64; 4] {
        let mut xi = [0.0; 10];
        for (i, x) in xi.iter_mut().enumerate() {
            let mut s = MODEL.b[i][0] * self.w;
            for j in 0..10 {
                s += MODEL.a[i][j] * self.xi[j];
            }
            *x = s;
        }
        self.xi = xi;
        self.w = FORCE_POLE * self.w + FORCE_STEP * self.force_rng.uniform();
        self.n += 1;
        let mut y = [0.0; 4];
        for (o, yo) in y.iter_mut().enumerate() {
            let mut s = MODEL.d[o][0] * self.w;
            for j in 0..10 {
                s += MODEL.c[o][j] * self.xi[j];
            }
            *yo = s + SIGMA_Y[o] * self.noise_rng.gauss();
        }
        y
    }

    /// The physical state `x_n = ξ_n + Γ₁ w_n` (`[u; v]`).
    pub fn x(&self) -> [f64; 10] {
        core::array::from_fn(|i| self.xi[i] + MODEL.gamma1[i][0] * self.w)
    }
}

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

/// Terms of the longest dot product a step rounds into one estimate entry: `S + I + O`
/// (prediction `S + I`, then the correction's `O`).
pub const ROUNDING_TERMS: usize = 15;
/// `√ROUNDING_TERMS`: independent roundings of `ε₃₂/2` relative accumulate as a random
/// walk (`tests/firmware_estimator.rs` checks the literal).
pub const SQRT_TERMS: f64 = 3.872_983_346_207_417;
/// The fixed-gain loop's amplification of one step's rounding into the steady error of
/// the estimate (dimensionless). A margin over what `tests/firmware_estimator.rs`
/// measures (3.5 for the force, 4.1 for the drifts, in units of `√n ε₃₂ max|·|`): a
/// regression pin of the loop's gain, not derived.
pub const AMPLIFICATION: f64 = 8.0;

/// The bound on `max_n |f32 estimate − f64 estimate|` for a quantity whose `f64` estimates
/// peak at `peak` over the run: `AMPLIFICATION · √(S+I+O) · ε₃₂ · peak` (units of `peak`).
pub fn bound(peak: f64) -> f64 {
    AMPLIFICATION * SQRT_TERMS * f32::EPSILON as f64 * peak
}

/// Multiply-adds of one step of `InputStateObserver<_, 10, 1, 4>`: prediction `S(S+I)`,
/// innovation `O·S`, input `I·O`, state `S·O`.
pub const STEP_MADDS: usize = 10 * 11 + 4 * 10 + 4 + 10 * 4;

/// Multiply-adds of one estimator step with the detector: the step, the residual `O·I`,
/// then the whitening `O(O+1)/2`.
pub const DETECTOR_MADDS: usize = STEP_MADDS + 4 + 10;
