//! The banks of `examples/firmware/qemu_spectrum.rs`, shared with its host side
//! (`tests/firmware_spectrum.rs`): periods, damping, sample interval.
#![allow(dead_code)] // each includer uses a different subset

/// Damping ratio of every oscillator.
pub const ZETA: f64 = 0.05;
/// 100 periods (s), log-spaced from 0.01 s to 10 s (ratio 10^(3/99)).
pub const PERIODS_100: [f64; 100] = geometric(0.01, 1.072_267_222_010_323_3);
/// 10 periods (s), log-spaced from 0.05 s to 5 s (ratio 10^(2/9)).
pub const PERIODS_10: [f64; 10] = geometric(0.05, 1.668_100_537_200_058_8);

/// `first · ratio^i` by repeated multiplication (non-decreasing for `ratio ≥ 1`).
const fn geometric<const P: usize>(first: f64, ratio: f64) -> [f64; P] {
    let mut out = [0.0; P];
    let mut x = first;
    let mut i = 0;
    while i < P {
        out[i] = x;
        x *= ratio;
        i += 1;
    }
    out
}
