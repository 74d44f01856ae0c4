//! Fuzz target `hysteresis`: the checks of `aemstep_fuzz::hysteresis` (fuzz/src/lib.rs) on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(init: aemstep_fuzz::init(), |data: &[u8]| {
    aemstep_fuzz::fuzz("hysteresis", data)
});
