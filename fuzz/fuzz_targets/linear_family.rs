//! Fuzz target `linear_family`: the checks of `aemstep_fuzz::linear_family` (fuzz/src/lib.rs) on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(init: aemstep_fuzz::init(), |data: &[u8]| {
    aemstep_fuzz::fuzz("linear_family", data)
});
