#!/usr/bin/env bash
# Fuzzing (issue 10): builds the fuzz targets of fuzz/ (libFuzzer through the crates.io
# crate libfuzzer-sys) and runs each for a bounded time, starting from its kept corpus
# fuzz/corpus/<target>/; fails on any crash (a panic, i.e. a broken property: the checks
# in fuzz/src/checks/ panic, and libfuzzer-sys aborts on a panic). Prints per-target
# executions, time, crashes and the checks' counters, and writes them to
# fuzz/target/fuzz-stats.txt.
#
# Two modes:
# - The default (what the test command runs) is reproducible: each target executes a
#   fixed number of inputs (RUNS below, about 30 s each here) from a fixed seed
#   (FUZZ_SEED, default 1), single process, no corpus reloading, from an empty scratch
#   directory, and without comparison-guided mutations (-use_cmp=0: the operands libFuzzer
#   records include addresses — a slice iterator compares pointers — which differ from
#   process to process, and two runs diverged after 4800 executions), with the corpus
#   given as a list in name order (see run). libFuzzer then
#   mutates the same inputs in the same order on every run of the same commit (same
#   toolchain and system; checked: three runs, with ASLR and different environments,
#   identical): a commit that passed here passes in CI,
#   and a crash CI reports is reproduced by running this script on that commit. A time
#   cap (FUZZ_CAP seconds, default 120) bounds a slow machine; what it cuts short is a
#   prefix of the same sequence. (Randomly seeded, the test command's 30 s found new cases
#   in two recent CI runs, one on a commit that changed only a docs page.)
# - --explore searches on: a random seed (printed), FUZZ_SECONDS per target, no run
#   limit. Run it to look for new failures; each one found is fixed, its input kept in
#   fuzz/regressions/<target>/, and --merge folds the new coverage into the corpus.
#
# How it is built, and why without cargo-fuzz: cargo-fuzz is only a driver — it runs
# `cargo build` with the sanitizer-coverage flags below and runs the binaries. Doing that
# here needs nothing but the stable toolchain and a C++ compiler (libfuzzer-sys compiles
# libFuzzer's sources), so there is no tool to install from source on every fresh machine
# (and no nightly: without AddressSanitizer, which this crate does not need —
# `#![forbid(unsafe_code)]` — no flag here is unstable). The flags are cargo-fuzz's: the
# SanitizerCoverage module pass with inline 8-bit counters, the PC table and comparison
# tracing, and `--cfg fuzzing`; the fuzz crate's release profile keeps debug assertions and
# overflow checks on. `--target` keeps the flags off build scripts and proc macros.
#
# Usage: bash scripts/fuzz.sh [options] [TARGET...]   (default: every target)
#   FUZZ_SEED=N      the seed of the reproducible run (default 1)
#   FUZZ_CAP=N       its time cap per target, seconds (default 120)
#   --explore        a randomly seeded run instead, FUZZ_SECONDS per target (default 30)
#   --merge          afterwards, minimize the kept corpus plus this run's new inputs into
#                    fuzz/corpus/<target>/ (libFuzzer -merge=1; capped at 200 files)
#   --record         copy the stats to fuzz/stats.txt (committed; docs/robustness.md
#                    tabulates it, crashes included: bash scripts/robustness.sh)
#   --self-test      show that a crash fails the run: with AEMSTEP_FUZZ_INJECT_PANIC=1 the
#                    fuzz binaries panic on inputs whose first byte is 0x2a; the fuzzer
#                    must find one within 30 s and the run must fail (exit 0 if it did)
set -euo pipefail
cd "$(dirname "$0")/.."

TARGETS_ALL=(linear_family modal nonlinear hysteresis observer spectrum estimation detection hybrid control)
# Executions per target of the reproducible run: about 30 s each on a 2-core host (the
# targets differ in cost per input by a factor of ten). spectrum, estimation and control
# ran 90000, 90000 and 400000 inputs and had grown to 66, 102 and 86 s; after the
# observers' build was made cheaper under the instrumentation (observer::flat::mul_into)
# they were cut to the counts below, read off their coverage along the old runs (seed 1,
# libFuzzer's cov/ft, the binaries of this commit): each keeps all but 0.04-0.8 % of the
# edges and 0.5-3.0 % of the features it had at the old count (spectrum cov 2133 of 2148,
# ft 6439 of 6637; estimation 9746 of 9826, 21973 of 22480; control 2609 of 2610, 7504
# of 7538), and every check counter still fires.
declare -A RUNS=([linear_family]=30000 [modal]=300000 [nonlinear]=300000
    [hysteresis]=200000 [observer]=150000 [spectrum]=45000
    [estimation]=45000 [detection]=220000 [hybrid]=120000 [control]=250000)
SECS=${FUZZ_SECONDS:-30}
SEED=${FUZZ_SEED:-1}
CAP=${FUZZ_CAP:-120}
explore=0
merge=0
record=0
selftest=0
targets=()
for a in "$@"; do
    case "$a" in
    --merge) merge=1 ;;
    --explore) explore=1 ;;
    --record) record=1 ;;
    --self-test) selftest=1 ;;
    -*) echo "unknown option $a" >&2; exit 2 ;;
    *) targets+=("$a") ;;
    esac
done
[ ${#targets[@]} -gt 0 ] || targets=("${TARGETS_ALL[@]}")

fail() { printf '\nFAILED: %s\n' "$*" >&2; exit 1; }

# What the build needs: a C++ compiler for libFuzzer (installed if missing; fails loudly).
if ! command -v c++ >/dev/null 2>&1; then
    echo "==> installing a C++ compiler (libFuzzer is C++)"
    { apt-get update -qq && apt-get install -y -qq g++; } || fail "no C++ compiler and could not install g++"
fi
host=$(rustc -vV | sed -n 's/^host: //p')
[ -n "$host" ] || fail "rustc -vV gave no host triple"

# Built from a copy of the sources at a fixed path, into a fixed target directory: the
# path of the build enters the binaries (debug info of libFuzzer's C++, layout), and two
# checkouts of one commit built binaries that differ, and fuzz differently from one seed.
# From one path, every checkout builds the same binary and runs the same inputs.
# FUZZ_BUILD_DIR moves it (one path for every run that is to be compared).
fixed=${FUZZ_BUILD_DIR:-/tmp/aemstep-fuzz-build}
export CARGO_TARGET_DIR="$fixed/target"
work="$PWD/fuzz/target"
mkdir -p "$work"
flags="-Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4"
flags+=" -Cllvm-args=-sanitizer-coverage-inline-8bit-counters"
flags+=" -Cllvm-args=-sanitizer-coverage-pc-table"
flags+=" -Cllvm-args=-sanitizer-coverage-trace-compares --cfg fuzzing"
# (cargo's registry may sit elsewhere on another machine)
flags+=" --remap-path-prefix=${CARGO_HOME:-$HOME/.cargo}=/cargo"

build() { # the instrumented binaries, from the copy at $fixed/tree
    rm -rf "$fixed/tree" && mkdir -p "$fixed/tree"
    tar -c --exclude=./target --exclude=./fuzz/target --exclude=./.git \
        --exclude=./fuzz/corpus --exclude=./fuzz/regressions . | tar -x -C "$fixed/tree" ||
        fail "copying the sources to $fixed/tree"
    (cd "$fixed/tree" && RUSTFLAGS="$flags" cargo build --release --manifest-path fuzz/Cargo.toml \
        --target "$host" --bins) || fail "building the fuzz targets"
}

bin="$CARGO_TARGET_DIR/$host/release"
out="$work/fuzz-run"

# run TARGET SECONDS [RUNS SEED]: one bounded run from the kept corpus; new inputs go to
# an emptied scratch directory (the committed corpus is only read). With RUNS and SEED:
# that many executions from that seed (SECONDS caps them), reproducibly; without, a random
# seed for SECONDS. Returns libFuzzer's exit status.
run() {
    local t=$1 secs=$2 runs=${3:-} seed=${4:-0}
    rm -rf "$out/$t/new"
    mkdir -p "$out/$t/new" "fuzz/corpus/$t"
    rm -f "$out/$t/counts" "$out/$t/crash-"*
    local limit=() seeds=("fuzz/corpus/$t")
    if [ -n "$runs" ]; then
        # The kept corpus as a list in name order: libFuzzer sorts its seed inputs by size
        # alone, with an unstable sort, so inputs of equal size kept the order the directory
        # listed them in — which differs between checkouts (the counts of two clones of one
        # commit differed). A list in a fixed order is sorted the same way everywhere.
        find "fuzz/corpus/$t" -type f | LC_ALL=C sort | paste -sd, - >"$out/$t/seeds"
        seeds=(-seed_inputs="@$out/$t/seeds")
        limit=(-runs="$runs" -use_cmp=0)
    fi
    AEMSTEP_FUZZ_COUNTS="$out/$t/counts" "$bin/$t" "$out/$t/new" "${seeds[@]}" \
        "${limit[@]}" -seed="$seed" -reload=0 \
        -max_total_time="$secs" -max_len=1024 -timeout=20 -rss_limit_mb=2048 \
        -artifact_prefix="$out/$t/" -print_final_stats=1 >"$out/$t/log" 2>&1
}

if [ "$selftest" = 1 ]; then
    # The fuzz binaries panic on every input whose first byte is 0x2a when
    # AEMSTEP_FUZZ_INJECT_PANIC=1: the fuzzer must find one, report the crash, write the
    # input, and this script's run must fail. (The same binaries as the real runs.)
    echo "==> self-test: an injected panic must fail the fuzz run"
    build
    t=linear_family
    if AEMSTEP_FUZZ_INJECT_PANIC=1 run "$t" 30 "" "$SEED"; then
        fail "self-test: the run with an injected panic passed"
    fi
    grep -q "injected panic" "$out/$t/log" || fail "self-test: no injected panic in the log"
    [ -n "$(find "$out/$t" -maxdepth 1 -name 'crash-*')" ] || fail "self-test: no crash artifact written"
    echo "self-test: the injected panic failed the run (crash artifact written)"
    exit 0
fi

echo "==> building the fuzz targets ($host, libFuzzer via libfuzzer-sys, stable toolchain)"
start=$(date +%s)
build
echo "built in $(( $(date +%s) - start )) s"

stats="$work/fuzz-stats.txt"
if [ "$explore" = 1 ]; then
    mode="exploring: a random seed, $SECS s per target"
else
    mode="reproducible: seed $SEED, a fixed number of executions per target"
fi
echo "# scripts/fuzz.sh: $mode; $(rustc --version)" >"$stats"
crashed=()
for t in "${targets[@]}"; do
    [ -x "$bin/$t" ] || fail "no fuzz target $t"
    n=$(find "fuzz/corpus/$t" -type f 2>/dev/null | wc -l)
    status=0
    t0=$(date +%s)
    if [ "$explore" = 1 ]; then
        echo "==> fuzzing $t for $SECS s, randomly seeded (from fuzz/corpus/$t: $n inputs)"
        run "$t" "$SECS" || status=$?
        sed -n 's/^INFO: Seed: /seed: /p' "$out/$t/log" | head -1
    else
        echo "==> fuzzing $t: ${RUNS[$t]} executions from seed $SEED (from fuzz/corpus/$t: $n inputs; cap $CAP s)"
        run "$t" "$CAP" "${RUNS[$t]}" "$SEED" || status=$?
    fi
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$out/$t/log" | tail -1)
    time_s=$(( $(date +%s) - t0 ))
    crashes=$(find "$out/$t" -maxdepth 1 -name 'crash-*' | wc -l)
    if [ "$explore" = 0 ] && [ "$status" = 0 ] && [ "${execs:-0}" -lt "${RUNS[$t]}" ]; then
        echo "note: $t stopped at its cap of $CAP s after ${execs:-0} of ${RUNS[$t]} executions (a prefix of the same sequence)"
    fi
    if [ "$status" != 0 ] || [ "$crashes" != 0 ]; then
        crashed+=("$t")
        grep -E "property broken|panicked|ERROR: libFuzzer|data:" "$out/$t/log" | head -20 >&2 || true
        find "$out/$t" -maxdepth 1 -name 'crash-*' >&2
        [ "$crashes" != 0 ] || crashes=1
    fi
    {
        echo "TARGET $t executions ${execs:-0} seconds $time_s crashes $crashes"
        [ -f "$out/$t/counts" ] && cat "$out/$t/counts"
    } >>"$stats"
    echo "$t: ${execs:-0} executions in $time_s s, $crashes crash(es)"
    if [ "$merge" = 1 ] && [ "$crashes" = 0 ]; then
        # Minimize the kept corpus and this run's new inputs into a fresh set covering all
        # of their coverage; keep it if it is small enough to commit.
        m="$out/$t/merged"
        rm -rf "$m" && mkdir -p "$m"
        "$bin/$t" -merge=1 -max_len=1024 "$m" "fuzz/corpus/$t" "$out/$t/new" >"$out/$t/merge.log" 2>&1 ||
            fail "merging the corpus of $t"
                n=$(find "$m" -type f | wc -l)
        if [ "$n" -gt 200 ]; then
            # Over the cap: 200 of them, by name (libFuzzer names an input by its hash, so
            # this is an unbiased, reproducible sample); the rest of the coverage is the
            # fuzzer's to find again in each run.
            find "$m" -type f | sort | tail -n +201 | xargs rm -f
            echo "$t: merged corpus had $n inputs; kept 200 (fuzz/corpus/$t)"
        else
            echo "$t: corpus minimized to $n inputs (fuzz/corpus/$t)"
        fi
        rm -rf "fuzz/corpus/$t" && mv "$m" "fuzz/corpus/$t"
    fi
done

echo
echo "per-target results (also in $stats):"
grep '^TARGET' "$stats" | awk '{ printf "  %-14s %10s executions %5s s %s crash(es)\n", $2, $4, $6, $8 }'
if [ "$record" = 1 ]; then
    [ ${#targets[@]} = ${#TARGETS_ALL[@]} ] || fail "--record needs a run of every target"
    cp "$stats" fuzz/stats.txt
    echo "recorded in fuzz/stats.txt (bash scripts/robustness.sh tabulates it)"
fi
if [ ${#crashed[@]} -gt 0 ]; then
    fail "fuzzing found a crash in: ${crashed[*]} (inputs in $out/<target>/crash-*; replay one with AEMSTEP_FUZZ_REPLAY=<dir>/<target>/<file> cargo test --test fuzz_corpus -- --nocapture, the file in a directory named after its target)"
fi
echo "fuzzing: no crash"
