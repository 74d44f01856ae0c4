//! The yielding shear building of the nonlinear peer benchmark (`scripts/bench_nonlinear.py`,
//! `xtask/src/bin/nonlinear_bench.rs`): the benchmark 5-storey building
//! (`models::five_storey_building`) with bilinear storeys, under El Centro 1940 NS ×2
//! linearly interpolated to `h = 0.005 s`. Data as `const`s and the record's resampling;
//! the OpenSees twin in the script builds the same model from the same numbers.
#![allow(dead_code)] // each includer uses a different subset

use aemstep::models::{self, Rows};

/// Storeys of the reference case.
pub const N: usize = 5;
/// The building `(M, C, K)`: `models::five_storey_building` (kg, N·s/m, N/m).
pub const BLD: (Rows<N>, Rows<N>, Rows<N>) = models::five_storey_building();
/// Floor mass (kg), every floor.
pub const MASS: f64 = models::FIVE_STOREY_MASS;
/// Initial storey stiffness (N/m), every storey.
pub const STIFFNESS: f64 = models::FIVE_STOREY_STIFFNESS;
/// Storey yield force (N), every storey.
pub const FY: f64 = 3.0e6;
/// Post-yield stiffness ratio (Steel01's `b`).
pub const ALPHA: f64 = 0.05;
/// Rayleigh damping ratio in elastic modes 1 and 2.
pub const XI: f64 = models::FIVE_STOREY_DAMPING;
/// Record scale factor.
pub const SCALE: f64 = 2.0;
/// Steps per second: `h = 1/RATE = 0.005 s`.
pub const RATE: u64 = 200;
/// Steps of a run (the count: the record's 3995 samples at 0.02 s, minus the last
/// interpolation interval's final point).
pub const STEPS: u64 = 15_975;
/// Newton tolerance (relative residual).
pub const TOL: f64 = 1e-12;
/// Newton iteration budget.
pub const BUDGET: u32 = 50;

/// The ground acceleration (m/s², record ×`scale`) at step `n` of a run at `rate` Hz
/// (`rate` a multiple of 50: the sample position `50 n / rate` is formed exactly in
/// integers), linearly interpolated between the record's samples; zero after its end.
/// `ag`: the record in m/s² (`elcentro::AG_F64`). The same rule as `scenes/hybrid/scene.rs`.
pub fn ground(ag: &[f64], n: u64, rate: u64, scale: f64) -> f64 {
    let pos = n * 50;
    let (i, rem) = ((pos / rate) as usize, pos % rate);
    if i + 1 >= ag.len() {
        return 0.0;
    }
    let frac = rem as f64 / rate as f64;
    scale * (ag[i] + frac * (ag[i + 1] - ag[i]))
}
