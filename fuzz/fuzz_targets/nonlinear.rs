//! Fuzz target `nonlinear`: the checks of `aemstep_fuzz::nonlinear` (fuzz/src/lib.rs) on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(init: aemstep_fuzz::init(), |data: &[u8]| {
    aemstep_fuzz::fuzz("nonlinear", data)
});
