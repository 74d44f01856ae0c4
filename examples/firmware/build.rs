//! Link setup of the bare-metal examples: the board's memory layout and the linker scripts.
//!
//! The layout is `memory.x` beside this script for the default board (QEMU `mps2-an386`,
//! Cortex-M4F; the same map serves `mps2-an385` and `mps2-an500`), `memory/<board>/memory.x`
//! for the others. The board is the `--cfg aemstep_board="…"` that `.cargo/config.toml` sets
//! per target (unset: the default board). The chosen file is copied into `OUT_DIR` as
//! `memory.x`, which this script puts on the linker search path, where cortex-m-rt's `link.x`
//! (`INCLUDE memory.x`) finds it.
//!
//! Not at the repository root: the linker runs in the workspace root and looks for an
//! included script in its working directory before the search path, so a `memory.x` there
//! would be linked for every board (measured: the Cortex-M0 build got the mps2 map, stack
//! top `0x2040_0000` on a 16 KiB part).
use std::{env, fs, path::PathBuf};

fn main() {
    let here = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").unwrap());
    let board = env::var("CARGO_CFG_AEMSTEP_BOARD").unwrap_or_default();
    let memory = match board.as_str() {
        "" | "mps2" => here.join("memory.x"),
        "microbit" | "an505" => here.join("memory").join(&board).join("memory.x"),
        other => panic!("unknown aemstep_board {other:?}"),
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    fs::copy(&memory, out.join("memory.x"))
        .unwrap_or_else(|e| panic!("copying {}: {e}", memory.display()));
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={}", memory.display());
    println!("cargo:rerun-if-changed=build.rs");

    // Only when building for a bare-metal target: cortex-m-rt's `link.x`, and defmt's
    // `defmt.x` (its interned strings) for the defmt example.
    if env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("none") {
        println!("cargo:rustc-link-arg-examples=-Tlink.x");
        if env::var_os("CARGO_FEATURE_DEFMT").is_some() {
            println!("cargo:rustc-link-arg-examples=-Tdefmt.x");
        }
    }
}
