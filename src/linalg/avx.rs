//! x86-64 only: the column-blocked product on 256-bit AVX registers when the CPU has them,
//! and the lane-batched steppers on 512-bit AVX-512 registers, chosen at run time.
//!
//! The default x86-64 target may assume SSE2 only (2 `f64` lanes a packed operation). The
//! same column-blocked loop compiled with AVX enabled runs 4 lanes a packed operation
//! and reaches the operators' read floor at N = 100 (`docs/performance.md`: 4.1 → 2.7 µs a
//! step of `Linear<f64, 100>` on the benchmark machine). AVX adds no instruction that
//! changes a result: packed `vmulpd`/`vaddpd` round each lane as `mulpd`/`addpd` do, and
//! Rust never fuses a multiply and an add (no FMA contraction), so both paths compute every
//! row's chain in the same order and give the same bits (`cargo test --lib avx`).
//!
//! [`run_lanes`] takes one step further for loops whose lane arrays fill a 512-bit
//! register (`f64 × 8`, `f32 × 16`: [`LaneStepper`](crate::lanes::LaneStepper) at
//! `L = 8` in `f64`): compiled with AVX-512 (F, DQ, BW, VL) when the CPU has it, one
//! instruction does what took two on AVX; `docs/performance.md` (lanes) measures it against
//! the benchmark's AVX-only control build (`--cfg aemstep_control="avx-only"`). Narrower
//! loops stay on AVX, where AVX-512's mask registers cost more than they save (the `L = 4`
//! step ran slower with it). The same argument for the bits holds: the 512-bit
//! `add`/`sub`/`mul`/`div`/`max`/compare round each lane as the scalar instructions do,
//! and nothing is fused (AVX-512 implies FMA, which Rust never emits for `a * b + c`); the
//! lanes' unit test runs every level the CPU has against single analyses, bit for bit.
//!
//! # Why `unsafe`, and why it is sound
//!
//! Calling a `#[target_feature(enable = "avx")]` function from code not compiled with AVX
//! is `unsafe`: on a CPU (or an OS) without AVX its instructions fault. The call is made
//! only when [`available`] is true, which requires CPUID to report AVX **and** OSXSAVE
//! and the OS to have enabled the SSE and AVX register state in `XCR0` — the conditions
//! under which the Intel and AMD manuals define AVX instructions to execute. AVX-512 is
//! called only when, in addition, CPUID leaf 7 reports AVX512F, DQ, BW and VL and `XCR0`
//! has the opmask and both upper-ZMM states enabled (the manuals' conditions for AVX-512).
//! `XGETBV` itself is read only once CPUID reports OSXSAVE (its own precondition), and
//! CPUID (an `unsafe` intrinsic on the MSRV) exists on every x86-64 CPU. These blocks (the
//! query and the guarded calls in [`run`] and [`run_lanes`], through which the
//! column-blocked product, the spectrum bank's step and the lane steppers go) are the
//! crate's only `unsafe`. A build that already targets AVX (`-C target-cpu=native`,
//! `-C target-feature=+avx`) compiles the plain loop with what it targets and never takes
//! this path.
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

/// The benchmark's AVX-only control build (`--cfg aemstep_control="avx-only"`): the lanes
/// never take AVX-512, to measure what it adds.
const NO_AVX512: bool = cfg!(aemstep_control = "avx-only");

/// Cached answer of [`detect`]: 0 not yet asked, else [`NONE`], [`AVX`] or [`AVX512`].
static LEVEL: AtomicU8 = AtomicU8::new(0);

/// No AVX: the plain (SSE2) loops.
const NONE: u8 = 1;
/// AVX, not the AVX-512 subset [`run_lanes`] uses.
const AVX: u8 = 2;
/// AVX and AVX-512 F, DQ, BW, VL.
const AVX512: u8 = 3;

/// The instruction sets the dispatch may use here (CPU and OS): [`NONE`], [`AVX`] or
/// [`AVX512`]. Cost: a relaxed load after the first call.
#[inline(always)]
fn level() -> u8 {
    let level = match LEVEL.load(Ordering::Relaxed) {
        0 => detect(),
        x => x,
    };
    #[cfg(test)]
    let level = level.min(tests::CAP.load(Ordering::Relaxed));
    level
}

/// Whether AVX instructions may run here (CPU and OS). Cost: a relaxed load after the
/// first call.
#[inline(always)]
pub(crate) fn available() -> bool {
    level() >= AVX
}

/// Query CPUID (and XCR0) once and cache the answer. Racing first calls compute the same
/// answer and store the same value.
#[cold]
#[inline(never)]
fn detect() -> u8 {
    const OSXSAVE: u32 = 1 << 27;
    const AVX_BIT: u32 = 1 << 28;
    const XMM_YMM_STATE: u64 = 0b110;
    // Opmask, ZMM0–15 upper halves, ZMM16–31 (XCR0 bits 5, 6, 7).
    const ZMM_STATE: u64 = 0b1110_0000;
    // CPUID.(7, 0):EBX: AVX512F (16), AVX512DQ (17), AVX512BW (30), AVX512VL (31).
    const AVX512_BITS: u32 = (1 << 16) | (1 << 17) | (1 << 30) | (1 << 31);
    let max_leaf = __cpuid(0).eax;
    let ecx = if max_leaf >= 1 { __cpuid(1).ecx } else { 0 };
    let xcr0 = if ecx & OSXSAVE != 0 {
        // SAFETY: CPUID.1:ECX.OSXSAVE is set (checked just above): the OS has enabled
        // XGETBV, so it executes (the `xsave` precondition of `_xgetbv`).
        unsafe { core::arch::x86_64::_xgetbv(0) }
    } else {
        0
    };
    let avx = ecx & AVX_BIT != 0 && xcr0 & XMM_YMM_STATE == XMM_YMM_STATE;
    let avx512 = avx
        && max_leaf >= 7
        && __cpuid(7).ebx & AVX512_BITS == AVX512_BITS
        && xcr0 & ZMM_STATE == ZMM_STATE;
    let level = match (avx, avx512) {
        (_, true) => AVX512,
        (true, false) => AVX,
        (false, false) => NONE,
    };
    LEVEL.store(level, Ordering::Relaxed);
    level
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

/// Run `f` (inlined loops over `bytes`-byte lane arrays: [`LaneStepper`]'s step, `bytes`
/// = `L` times the size of `T`) compiled with AVX-512 when the arrays fill a 512-bit
/// register and the CPU has AVX-512 (see the module docs), else as [`run`]. Same bits
/// either way. Cost: one relaxed load, a branch and a call.
///
/// [`LaneStepper`]: crate::lanes::LaneStepper
#[inline(always)]
pub(crate) fn run_lanes<R>(bytes: usize, f: impl FnOnce() -> R) -> R {
    if !PLAIN_ONLY && !NO_AVX512 && bytes >= 64 && level() == AVX512 {
        // SAFETY: `level()` is AVX512: the CPU reports AVX-512 F, DQ, BW and VL and the
        // OS saves their registers (module docs), the precondition of `run_avx512`.
        unsafe { run_avx512(f) }
    } else {
        run(f)
    }
}

/// `f` inlined into a function compiled with AVX-512 F, DQ, BW and VL enabled.
#[target_feature(enable = "avx512f,avx512dq,avx512bw,avx512vl")]
#[inline(never)]
fn run_avx512<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// `f` inlined into a function compiled with AVX enabled (a callee without target
/// features may be inlined into one with more).
#[target_feature(enable = "avx")]
#[inline(never)]
fn run_avx<R>(f: impl FnOnce() -> R) -> R {
    f()
}

#[cfg(test)]
pub(crate) mod tests {
    extern crate std;
    use std::vec::Vec;

    use super::*;

    /// The highest level the unit tests let the dispatch use (they lower it to run the
    /// lower paths on a CPU that has the higher ones).
    pub(crate) static CAP: AtomicU8 = AtomicU8::new(AVX512);

    /// Run `f` at each level this CPU has, from plain SSE2 up, and return its results
    /// (the cap is put back afterwards; other tests running meanwhile may run at a lower
    /// level, which gives the same bits).
    pub(crate) fn at_each_level<R>(mut f: impl FnMut() -> R) -> Vec<(u8, R)> {
        let top = match LEVEL.load(Ordering::Relaxed) {
            0 => detect(),
            x => x,
        };
        let out = (NONE..=top)
            .map(|cap| {
                CAP.store(cap, Ordering::Relaxed);
                (cap, f())
            })
            .collect();
        CAP.store(AVX512, Ordering::Relaxed);
        out
    }

    /// The CPUID/XCR0 query agrees with the standard library's detection (the query
    /// itself: `level()` may be capped meanwhile by a test running at each level).
    #[test]
    fn detection_agrees_with_std() {
        let detected = detect();
        assert_eq!(detected >= AVX, std::is_x86_feature_detected!("avx"));
        let all = std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512dq")
            && std::is_x86_feature_detected!("avx512bw")
            && std::is_x86_feature_detected!("avx512vl");
        assert_eq!(detected == AVX512, all, "AVX-512 F, DQ, BW, VL");
    }
}
