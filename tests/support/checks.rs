//! Checks the tests make the same way in several files. Unlike `support/mod.rs`, this
//! drives or inspects the code under test.
#![allow(dead_code)]

use aemstep::{Real, State};

/// Bit patterns of a state and its step count, so "unchanged" means bit-identical
/// (NaN-safe).
pub fn bits<T: Real, const N: usize>(s: &State<T, N>) -> Vec<u64> {
    s.u()
        .iter()
        .chain(s.v().iter())
        .chain(s.a().iter())
        .map(|x| x.as_f64().to_bits())
        .chain([s.steps()])
        .collect()
}
