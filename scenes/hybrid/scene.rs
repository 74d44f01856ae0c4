//! The hybrid-simulation scene of issue 22: the benchmark 5-storey building under El Centro
//! 1940 NS ×2, storey 1 the "physical" specimen (bilinear), storeys 2–5 numerical, stepped
//! at `RATE` Hz by the split KR-α step. Data as `const`s and the record's resampling, shared
//! by `xtask/src/bin/hybrid_building.rs` (the page, `f64`), `tests/firmware_hybrid.rs` (the
//! host twin) and `examples/firmware/qemu_hybrid.rs` (`f32` on the M4F, `f64` on the M7).
#![allow(dead_code)] // each includer uses a different subset

use aemstep::models::{self, Rows};

/// Storeys.
pub const N: usize = 5;
/// The building `(M, C, K)`: `models::five_storey_building` (kg, N·s/m, N/m).
pub const BLD: (Rows<N>, Rows<N>, Rows<N>) = models::five_storey_building();
/// Storey stiffness (N/m): the specimen's initial stiffness, in the operators' `K`.
pub const K1: f64 = models::FIVE_STOREY_STIFFNESS;
/// The numerical part's stiffness: the building without storey 1 (N/m).
pub const K_NUM: Rows<N> =
    models::shear_building([models::FIVE_STOREY_MASS; N], [0.0, K1, K1, K1, K1]).1;
/// Record scale factor.
pub const SCALE: f64 = 2.0;
/// The specimen's yield force (N) and post-yield stiffness ratio.
pub const FY: f64 = 3.0e6;
/// See [`FY`].
pub const ALPHA: f64 = 0.05;
/// KR-α's high-frequency spectral radius.
pub const RHO_INF: f64 = 0.9;

/// The ground acceleration (m/s², record ×`SCALE`) at step `n` of a run at `rate` Hz
/// (`rate` a multiple of 50, or a power of two: the record's sample position `50 n / rate`
/// is formed exactly in integers), linearly interpolated between the record's samples;
/// zero after its end. `ag`: the record in m/s² (`elcentro::AG_F64` or `AG_F32`).
pub fn ground<T: aemstep::Real>(ag: &[T], n: u64, rate: u64) -> T {
    let pos = n * 50;
    let (i, rem) = ((pos / rate) as usize, pos % rate);
    if i + 1 >= ag.len() {
        return T::zero();
    }
    let frac = T::from_f64_rounded(rem as f64 / rate as f64);
    let scale = T::from_f64_rounded(SCALE);
    scale * (ag[i] + frac * (ag[i + 1] - ag[i]))
}

/// Steps in a run at `rate` Hz covering the record (`(samples − 1) · 0.02 s`).
pub const fn steps(samples: usize, rate: u64) -> u64 {
    (samples as u64 - 1) * rate / 50
}

/// Steps per second of the scene (Hz): `h = 1/RATE`.
pub const RATE: u64 = 1024;
/// The longest delay the adaptive compensator may estimate (s).
pub const MAX_DELAY: f64 = 0.05;

/// The floor masses (kg), ground storey first.
pub const fn masses() -> [f64; N] {
    models::floor_masses(&BLD.0)
}
/// The adaptive compensator's extrapolation order.
pub const ADAPTIVE_ORDER: usize = 2;

/// The firmware's rig (`examples/firmware/qemu_hybrid.rs`, `scenes/hybrid/rig.rs`): the
/// emulated actuator's pure delay (s), no lag.
pub const FIRMWARE_DELAY: f64 = 0.005;
/// The firmware's compensator: polynomial extrapolation of this order over
/// [`FIRMWARE_DELAY`] (the delay known, as a calibrated rig's would be).
pub const FIRMWARE_ORDER: usize = 2;
/// The firmware's step rates (Hz): `h = 1/1024` and `1/2048` s.
pub const FIRMWARE_RATES: [u64; 2] = [1024, 2048];
/// The firmware checks the storey-1 drift every `1/FIRMWARE_SAMPLE_HZ` s (every
/// `rate / FIRMWARE_SAMPLE_HZ` steps).
pub const FIRMWARE_SAMPLE_HZ: u64 = 16;
