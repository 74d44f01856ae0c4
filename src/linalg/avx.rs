//! x86-64 only: the column-blocked product on 256-bit AVX registers when the CPU has them,
//! chosen at run time.
//!
//! The default x86-64 target may assume SSE2 only (2 `f64` lanes a packed operation). The
//! same column-blocked loop compiled with AVX enabled runs 4 lanes a packed operation
//! and reaches the operators' read floor at N = 100 (`docs/performance.md`: 4.1 → 2.7 µs a
//! step of `Linear<f64, 100>` on the benchmark machine). AVX adds no instruction that
//! changes a result: packed `vmulpd`/`vaddpd` round each lane as `mulpd`/`addpd` do, and
//! Rust never fuses a multiply and an add (no FMA contraction), so both paths compute every
//! row's chain in the same order and give the same bits (`cargo test --lib avx`).
//!
//! # Why `unsafe`, and why it is sound
//!
//! Calling a `#[target_feature(enable = "avx")]` function from code not compiled with AVX
//! is `unsafe`: on a CPU (or an OS) without AVX its instructions fault. The call is made
//! only when [`available`] is true, which requires CPUID to report AVX **and** OSXSAVE
//! and the OS to have enabled the SSE and AVX register state in `XCR0` — the conditions
//! under which the Intel and AMD manuals define AVX instructions to execute. `XGETBV`
//! itself is read only once CPUID reports OSXSAVE (its own precondition), and CPUID (an
//! `unsafe` intrinsic on the MSRV) exists on every x86-64 CPU. These blocks (the query and
//! the one guarded call in [`run`], through which the column-blocked product and the
//! spectrum bank's step go) are the crate's only `unsafe`. A build that already targets AVX
//! (`-C target-cpu=native`, `-C target-feature=+avx`) compiles the plain loop with AVX
//! and never takes this path.
//!
//! Cost: one relaxed atomic load and a branch a step (the CPUID query runs once per
//! process); the column-blocked product (`op_rows`) takes it only for operators of at
//! least [`MIN_BYTES`] bytes, below which the call does not pay for itself. [`run`] (the spectrum bank, about 100 ns a
//! sample at `P = 100`) halves `Bank<f64, 100>`'s step (`docs/spectrum.md`).

#![allow(unsafe_code)]

use core::sync::atomic::{AtomicU8, Ordering};

/// Operators of fewer bytes (`K·N²` values) stay on the inlined SSE2 loop: there a step is
/// a few tens of nanoseconds and the call's overhead is a fair share of it. Measured with
/// the threshold at 0 (`cargo bench -p xtask --bench steps -- 'step/f(32|64)/aem/'`, N = 1…12): AVX
/// is slower up to `Linear<f64, 7>` (1176 bytes) and `Linear<f32, 11>` (1452), faster from
/// `f64` N = 8 (1536) and `f32` N = 12 (1728).
pub(crate) const MIN_BYTES: usize = 1536;

/// Whether the build already targets AVX (then the plain loop is AVX code already), or is
/// the benchmark's SSE2-only control build (`--cfg aemstep_control="sse2-only"`): either
/// way the plain loop runs.
const PLAIN_ONLY: bool = cfg!(target_feature = "avx") || cfg!(aemstep_control = "sse2-only");

/// Cached answer of [`detect`]: 0 not yet asked, 1 no AVX, 2 AVX.
static AVX: AtomicU8 = AtomicU8::new(0);

/// Whether AVX instructions may run here (CPU and OS). Cost: a relaxed load after the
/// first call.
#[inline(always)]
pub(crate) fn available() -> bool {
    match AVX.load(Ordering::Relaxed) {
        2 => true,
        1 => false,
        _ => detect(),
    }
}

/// Query CPUID (and XCR0) once and cache the answer. Racing first calls compute the same
/// answer and store the same value.
#[cold]
#[inline(never)]
fn detect() -> bool {
    const OSXSAVE: u32 = 1 << 27;
    const AVX_BIT: u32 = 1 << 28;
    const XMM_YMM_STATE: u64 = 0b110;
    let yes = __cpuid(0).eax >= 1 && {
        let ecx = __cpuid(1).ecx;
        ecx & OSXSAVE != 0
            && ecx & AVX_BIT != 0
            // SAFETY: CPUID.1:ECX.OSXSAVE is set (checked just above): the OS has enabled
            // XGETBV, so it executes (the `xsave` precondition of `_xgetbv`).
            && unsafe { core::arch::x86_64::_xgetbv(0) } & XMM_YMM_STATE == XMM_YMM_STATE
    };
    AVX.store(if yes { 2 } else { 1 }, Ordering::Relaxed);
    yes
}

/// The CPUID leaf `leaf` (sub-leaf 0).
fn __cpuid(leaf: u32) -> core::arch::x86_64::CpuidResult {
    // The intrinsic became a safe function after Rust 1.89 (the MSRV), where it is still
    // `unsafe`: the block is needed there and unused on newer compilers.
    #[allow(unused_unsafe)]
    // SAFETY: every x86-64 CPU has the CPUID instruction; it has no other precondition.
    unsafe {
        core::arch::x86_64::__cpuid(leaf)
    }
}

/// Run `f` (a closure whose body is inlined loops over independent lanes, e.g. the
/// spectrum bank's per-sample step over its oscillators) compiled with AVX enabled when
/// [`available`], else as is. Same bits either way, for the reasons in the module docs:
/// AVX only widens the packed `mul`/`add`/`max`/compare operations, each lane rounded as
/// on SSE2, and nothing is fused. Cost: one relaxed load, a branch and a call.
#[inline(always)]
pub(crate) fn run<R>(f: impl FnOnce() -> R) -> R {
    if PLAIN_ONLY || !available() {
        f()
    } else {
        // SAFETY: `available()` is true: the CPU reports AVX and the OS saves its
        // registers (module docs), the precondition of `run_avx`.
        unsafe { run_avx(f) }
    }
}

/// `f` inlined into a function compiled with AVX enabled (a callee without target
/// features may be inlined into one with more).
#[target_feature(enable = "avx")]
#[inline(never)]
fn run_avx<R>(f: impl FnOnce() -> R) -> R {
    f()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CPUID/XCR0 query agrees with the standard library's detection.
    #[test]
    fn detection_agrees_with_std() {
        assert_eq!(available(), std::is_x86_feature_detected!("avx"));
    }
}
