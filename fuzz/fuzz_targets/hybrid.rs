//! Fuzz target `hybrid`: the checks of `aemstep_fuzz::hybrid` (fuzz/src/lib.rs) on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(init: aemstep_fuzz::init(), |data: &[u8]| {
    aemstep_fuzz::fuzz("hybrid", data)
});
