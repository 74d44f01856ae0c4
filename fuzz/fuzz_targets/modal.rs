//! Fuzz target `modal`: the checks of `aemstep_fuzz::modal` (fuzz/src/lib.rs) on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(init: aemstep_fuzz::init(), |data: &[u8]| {
    aemstep_fuzz::fuzz("modal", data)
});
