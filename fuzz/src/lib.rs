//! The fuzz targets' library: the checks (`checks/`, one module per target, shared with
//! the replay test `tests/fuzz_corpus.rs` of the main crate) and the harness glue of the
//! fuzz binaries.

mod checks;

pub use checks::*;

/// Register, at the start of a fuzz run, the writing of the counters at its end: libFuzzer
/// ends a run with `exit()`, so an `atexit` handler writes them to the file named by
/// `AEMSTEP_FUZZ_COUNTS` (`scripts/fuzz.sh` tabulates them; unset: nothing is written).
pub fn init() {
    unsafe extern "C" {
        fn atexit(f: extern "C" fn()) -> core::ffi::c_int;
    }
    extern "C" fn dump() {
        if let Ok(path) = std::env::var("AEMSTEP_FUZZ_COUNTS") {
            let _ = std::fs::write(path, count_lines());
        }
    }
    // SAFETY: the C library's `atexit`, given a function that takes nothing and does not
    // unwind (it ignores every error; the counters' lock recovers from poisoning).
    unsafe {
        atexit(dump);
    }
}

/// One fuzz input: the checks of `target` on `data`. With `AEMSTEP_FUZZ_INJECT_PANIC=1`
/// in the environment (`bash scripts/fuzz.sh --self-test`) it panics on every input whose
/// first byte is `0x2a`, to show that a panic fails the fuzz run (the variable is read
/// once).
pub fn fuzz(target: &str, data: &[u8]) {
    static INJECT: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let inject = *INJECT
        .get_or_init(|| std::env::var_os("AEMSTEP_FUZZ_INJECT_PANIC").is_some_and(|v| v == "1"));
    if inject && data.first() == Some(&0x2a) {
        panic!("injected panic (scripts/fuzz.sh --self-test)");
    }
    run(target, data);
}
