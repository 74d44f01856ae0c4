//! The fuzz checks of aemstep (issue 10): a decoder from raw bytes to inputs biased to the
//! extremes, and one check function per fuzz target that calls every constructor of its
//! group with the decoded data, steps every stepper it built with checked steps, and
//! panics when a property breaks.
//!
//! One module, used twice: the fuzz targets of `fuzz/` (libFuzzer, `scripts/fuzz.sh`) call
//! it through the `aemstep_fuzz` library (`fuzz/src/lib.rs`), and the stable-toolchain
//! test `tests/fuzz_corpus.rs` includes it (`#[path]`) to replay every kept input of
//! `fuzz/corpus/` and `fuzz/regressions/` through the same checks.
//!
//! Where to look: this file has the entry points (`run`, `TARGETS`) and the `check!` macro;
//! `common.rs` the decoder (`Bytes`), the counters, the independent references and the
//! checks several targets share; each fuzz target `fuzz_targets/<t>.rs` has its checks in
//! `<t>.rs` here (`linear_family`, `modal`, `nonlinear`, `hysteresis`, `observer`,
//! `spectrum`, `estimation`, `detection`, `hybrid`, `control`), each starting with a line saying what it checks.
//!
//! Properties (as `tests/properties.rs`, over much more varied data):
//! - never a panic (a panic aborts the fuzzer: a crash);
//! - `Ok` from a constructor ⇒ finite operators (accessors finite; a start and checked
//!   steps give a finite state or a typed error) — never "garbage accepted"; the
//!   energy-conserving schemes (AEM `Linear` and `AForm`, `CompensatedLinear`, Newmark
//!   average acceleration, `Modal`) do not grow the undamped energy `½ vᵀMv + ½ uᵀKu`
//!   beyond rounding over a few steps (generalized-α is stable but not conserving: it
//!   overshoots in its first steps at large `ωh`, so it has no such check);
//! - `Err` from a checked step ⇒ the state (and history) bit-identical to before; `Ok` ⇒
//!   the state the unchecked step gives, finite;
//! - the same bad input gives the same error variant from every stepper: a non-finite
//!   load, initial value or matrix entry is `NonFiniteInput`, a bad `h` is
//!   `InvalidTimeStep`, an effective matrix singular for one AEM-family constructor is
//!   singular for all, `f32` and `f64` agree except where `f32` overflows;
//! - the split step of real-time hybrid simulation (`hybrid`) is the KR-α step it splits:
//!   `Split` with `K_num = K` has `KrAlpha`'s operators bit for bit, its start is
//!   `KrAlpha`'s with the load `p0 − r0`, `command` is the `u` a successful `complete`
//!   commits, `complete` is the scheme's step with the load `p − r` bit for bit, and a
//!   failed `complete` (`NonFiniteForce`, `NonFiniteInput`, `NonFiniteState`) changes
//!   nothing;
//! - the control family (`control`): a failed controller step, command or coupled
//!   structure–damper step changes nothing; an `Lqr` that is `Ok` is finite with its
//!   closed loop's spectral radius within the certified bound; the clipped-optimal law
//!   is its sign rule.
//!
//! Every property break panics with a message starting `property broken:`.
#![allow(
    dead_code,
    // NaN-aware on purpose: `!(x < tol)` is true for NaN.
    clippy::neg_cmp_op_on_partial_ord,
    clippy::too_many_arguments,
    clippy::type_complexity,
    clippy::needless_range_loop
)]

macro_rules! check {
    ($cond:expr, $($arg:tt)+) => {
        if !$cond {
            panic!("property broken: {}\n  data: {}", format!($($arg)+), context());
        }
    };
}

mod common;
mod control;
mod detection;
mod estimation;
mod hybrid;
mod hysteresis;
mod linear_family;
mod modal;
mod nonlinear;
mod observer;
mod spectrum;

// The library API of `aemstep_fuzz` (as before the split into modules: `fuzz/src/lib.rs`
// re-exports all of it); the replay test uses only `run` and `TARGETS`.
#[allow(unused_imports)]
pub use common::{Bytes, SpdInfo, System, context, count, count_lines, counts, spd_info};
pub use control::control;
pub use detection::detection;
pub use estimation::estimation;
pub use hybrid::hybrid;
pub use hysteresis::hysteresis;
pub use linear_family::linear_family;
pub use modal::modal;
pub use nonlinear::nonlinear;
pub use observer::observer;
pub use spectrum::spectrum;

/// The fuzz targets, in the order of the docs table.
pub const TARGETS: [&str; 10] = [
    "linear_family",
    "modal",
    "nonlinear",
    "hysteresis",
    "observer",
    "spectrum",
    "estimation",
    "detection",
    "hybrid",
    "control",
];

/// Run the checks of `target` on one input. Panics when a property breaks.
pub fn run(target: &str, data: &[u8]) {
    match target {
        "linear_family" => linear_family(data),
        "modal" => modal(data),
        "nonlinear" => nonlinear(data),
        "hysteresis" => hysteresis(data),
        "observer" => observer(data),
        "spectrum" => spectrum(data),
        "estimation" => estimation(data),
        "detection" => detection(data),
        "hybrid" => hybrid(data),
        "control" => control(data),
        _ => panic!("unknown fuzz target {target}"),
    }
}
