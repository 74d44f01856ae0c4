//! Fuzz target `estimation`: the checks of `aemstep_fuzz::estimation` (fuzz/src/lib.rs) on each input.
#![no_main]

libfuzzer_sys::fuzz_target!(init: aemstep_fuzz::init(), |data: &[u8]| {
    aemstep_fuzz::fuzz("estimation", data)
});
