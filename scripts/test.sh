#!/usr/bin/env bash
# Every test of aemstep, on a fresh machine: installs what it needs, fails loudly.
# This is the test command README.md names; .ci/run calls it.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n==> %s\n' "$*"; }
fail() { printf '\nFAILED: %s\n' "$*" >&2; exit 1; }
# Test runner output is also collected here, to print one total at the end.
log=$(mktemp)
trap 'rm -f "$log"' EXIT
tests() { "$@" 2>&1 | tee -a "$log"; }

step "toolchain: thumb targets (idempotent)"
rustup target add thumbv7em-none-eabihf thumbv6m-none-eabi thumbv7m-none-eabi thumbv8m.main-none-eabihf

step "format and lints"
cargo fmt --all -- --check || fail "cargo fmt: run 'cargo fmt --all'"
cargo clippy --all-targets -- -D warnings || fail "clippy"
cargo clippy --all-targets --features std -- -D warnings || fail "clippy (std)"
cargo clippy -p xtask --all-targets -- -D warnings || fail "clippy (xtask: page generators, benchmarks)"
cargo clippy -p aemstep-python --all-targets -- -D warnings || fail "clippy (python/: the Python bindings)"

step "host tests (debug: overflow checks on)"
tests cargo test --all-targets --features std || fail "host tests (with the host-only std feature)"
tests cargo test --doc --features std || fail "doctests"
# The page generators and benchmarks (workspace member xtask/): build, benchmarks run once each.
tests cargo test -p xtask --all-targets || fail "xtask tests (generators, benchmarks once)"

step "long host tests (release)"
tests cargo test --release --all-targets --features std -- --ignored || fail "long tests"

step "fuzzing: each fuzz target for a bounded time from its kept corpus (scripts/fuzz.sh)"
# Its self-test first: a panic injected into the fuzz binaries must fail a fuzz run.
bash scripts/fuzz.sh --self-test || fail "scripts/fuzz.sh --self-test"
# Every target (scripts/fuzz.sh's default): a fixed number of executions from a fixed seed
# each, about 30 s, reproducible (the same inputs on every run of a commit).
bash scripts/fuzz.sh ||
    fail "fuzzing found a crash (scripts/fuzz.sh; inputs in fuzz/target/fuzz-run/<target>/crash-*)"

step "energy behaviour of the nonlinear stepper (numbers quoted in README.md)"
cargo run --release -p xtask --bin energy || fail "energy example"

step "the examples a user runs first: they run and print their units"
out=$(mktemp)
cargo run -q --release --example yielding_building > "$out" || fail "yielding_building example"
grep -q 'peak drift (m)' "$out" && grep -q 'kN' "$out" && grep -q 'ductility' "$out" ||
    fail "yielding_building: drifts (m), base shear (kN), ductility expected"
cargo run -q --release --example spectrum_csv > "$out" || fail "spectrum_csv example"
[ "$(head -1 "$out")" = "period_s,sd_m,sv_m_per_s,sa_g" ] && [ "$(wc -l < "$out")" -eq 51 ] ||
    fail "spectrum_csv: a header and 50 rows expected"
cargo run -q --release --example observer > "$out" || fail "observer example"
grep -q 'RMS drift error (m)' "$out" || fail "observer: RMS drift errors (m) expected"
cargo run -q --release --example estimation_detection > "$out" || fail "estimation_detection example"
grep -q 'force RMS error (kN)' "$out" && grep -q 'drift RMS error (mm)' "$out" &&
    grep -q '^as designed.* no$' "$out" && grep -q '^storey 1 30 % softer.* yes, t = [0-9.]* s$' "$out" ||
    fail "estimation_detection: force (kN) and drift (mm) RMS errors; no alarm intact, an alarm (s) damaged"
cargo run -q --release --example hybrid_loop > "$out" || fail "hybrid_loop example"
grep -q 'peak drift (m)' "$out" && grep -q 'tracking error (m)' "$out" &&
    grep -q 'specimen force (kN)' "$out" && grep -q 'actuator delay 10 ms' "$out" ||
    fail "hybrid_loop: peak drift (m), tracking error (m), specimen force (kN) expected"
cargo run -q --release --example mr_damper > "$out" || fail "mr_damper example"
grep -q 'peak drift (cm)' "$out" && grep -q 'peak damper force (N)' "$out" ||
    fail "mr_damper: peak drifts (cm) and damper force (N) expected"
cargo run -q --release --features std --example ida > "$out" || fail "ida example"
grep -q 'PGA (g)' "$out" && grep -q 'drift ratio (%)' "$out" && grep -q 'collapse between PGA' "$out" ||
    fail "ida: intensity (g) against peak drift ratio (%), a collapse bracket (g) expected"
rm -f "$out"

step "the Python package: the manylinux wheel (scripts/wheel.sh) installed in a fresh virtual environment with no Rust on PATH, pytest python/tests"
# The wheel a user installs, not a source build: scripts/wheel.sh builds it (abi3,
# manylinux2014, checked by auditwheel) into the cargo target directory, so a later run reuses
# the build. A clean environment every run (only the pip cache is shared).
venv=$(mktemp -d)
dist=$(mktemp -d)
trap 'rm -f "$log"; rm -rf "$venv" "$dist"' EXIT
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}" bash scripts/wheel.sh "$dist" ||
    fail "scripts/wheel.sh (the manylinux wheel and sdist of python/)"
python3 -m venv "$venv" || fail "python3 -m venv (Debian: apt-get install python3-venv)"
"$venv/bin/pip" install -q --upgrade "pip>=23" || fail "pip upgrade in the fresh venv"
# dask[distributed] and tqdm: the cluster and progress-bar tests (optional at run time);
# pandas, xarray, matplotlib: the table and plot tests (optional at run time); mypy: the
# type check below. Pinned: a new release must not change the verdict unseen.
"$venv/bin/pip" install -q "numpy>=1.21" "pytest>=7" "dask[distributed]>=2023.1" "tqdm>=4.60" \
    "pandas==3.1.1" "xarray==2026.9.0" "matplotlib==3.11.2" "mypy==2.4.1" ||
    fail "pip install numpy pytest dask[distributed] tqdm pandas xarray matplotlib mypy"
# The package's exports and the native module's stub, type-checked as a user's strict
# project sees them (python/pyproject.toml [tool.mypy]: strict; untyped optional imports).
# Its cache beside the wheel's build (about 18 s cold, mostly numpy's stubs; 2 s warm).
"$venv/bin/python" -m mypy --strict --config-file python/pyproject.toml \
    --cache-dir "${CARGO_TARGET_DIR:-$PWD/target}/mypy-cache" python/aemstep ||
    fail "mypy --strict python/aemstep (the package's types)"
# PATH without any directory holding cargo or rustc: the install and the tests see no Rust.
norust="$venv/bin"
IFS=: read -r -a dirs <<<"$PATH"
for d in "${dirs[@]}"; do
    [ -e "$d/cargo" ] || [ -e "$d/rustc" ] || norust="$norust:$d"
done
for tool in cargo rustc rustup; do
    ! PATH="$norust" command -v "$tool" >/dev/null ||
        fail "$tool is on the PATH of the wheel's environment: $(PATH="$norust" command -v "$tool")"
done
echo "no cargo, rustc or rustup on the environment's PATH"
# From the wheel alone (--no-index: nothing downloaded, numpy already present), timed.
t0=$(date +%s.%N)
PATH="$norust" "$venv/bin/pip" install -q --no-index --find-links "$dist" aemstep ||
    fail "pip install of the wheel with no Rust on PATH"
t1=$(date +%s.%N)
awk -v a="$t0" -v b="$t1" -v w="$(basename "$dist"/aemstep-*.whl)" -v n="$(stat -c %s "$dist"/aemstep-*.whl)" \
    'BEGIN { printf "install time from the wheel: %.1f s (%s, %d bytes)\n", b - a, w, n }'
pyout=$(mktemp)
PATH="$norust" "$venv/bin/python" -m pytest python/tests -q -p no:cacheprovider 2>&1 | tee "$pyout" ||
    { rm -f "$pyout"; fail "pytest python/tests"; }
# Its count in the total below, in the form the sum reads.
awk '/ passed/ { p = 0; f = 0; for (i = 2; i <= NF; i++) { if ($i ~ /^passed/) p = $(i - 1);
    if ($i ~ /^failed/) f = $(i - 1) } } END { printf "test result: pytest. %d passed; %d failed;\n", p, f }' \
    "$pyout" >> "$log"
rm -f "$pyout"

step "no_std builds for thumb targets"
for t in thumbv7em-none-eabihf thumbv6m-none-eabi thumbv7m-none-eabi thumbv8m.main-none-eabihf; do
    cargo build --lib --release --target "$t" || fail "no_std build for $t"
done
cargo check --lib --target thumbv7em-none-eabihf --features defmt || fail "defmt feature"

msrv=$(sed -n 's/^rust-version = "\(.*\)"/\1/p' Cargo.toml)
step "MSRV: Rust ${msrv} (Cargo.toml rust-version) checks every target and builds the firmware library"
rustup toolchain install "$msrv" --profile minimal --target thumbv7em-none-eabihf ||
    fail "installing Rust ${msrv}"
cargo +"$msrv" check --all-targets --features std || fail "Rust ${msrv} (MSRV): host targets"
cargo +"$msrv" build --lib --release --target thumbv7em-none-eabihf ||
    fail "Rust ${msrv} (MSRV): thumbv7em library"

step "firmware on QEMU (Cortex-M4F; cost table across M0, M3, M4F, M7, M33): run every example, broken variants must fail, cost tables"
bash scripts/qemu.sh || fail "firmware (scripts/qemu.sh)"

step "docs: every quoted number from its generator (scripts/check_docs.py)"
# Its self-test first: a perturbed number in a copy of the docs must fail the check.
python3 scripts/check_docs.py --self-test || fail "scripts/check_docs.py --self-test"
python3 scripts/check_docs.py ||
    fail "docs: a quoted number drifted (python3 scripts/check_docs.py --write regenerates the pages)"

step "docs build without warnings"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps || fail "rustdoc"
# The way docs.rs builds them (Cargo.toml [package.metadata.docs.rs]): nightly, every feature,
# `--cfg docsrs`, so each feature-gated item is labelled with its feature.
rustup toolchain install nightly --profile minimal || fail "installing the nightly toolchain"
RUSTDOCFLAGS="--cfg docsrs -D warnings" cargo +nightly doc --no-deps --all-features ||
    fail "rustdoc as docs.rs builds it (nightly, --all-features, --cfg docsrs)"

step "every code block of README, docs and rustdoc builds and runs in a crate that depends on aemstep alone (scripts/downstream.py)"
# Its self-test first: a README block that names `nalgebra` and a rustdoc block that fails
# when run, in a copy of the repository, must both fail the check.
python3 scripts/downstream.py --self-test || fail "scripts/downstream.py --self-test"
python3 scripts/downstream.py || fail "a code block fails downstream (python3 scripts/downstream.py lists them)"

step "the published package: cargo publish --dry-run clean, its size as docs/package.md states"
bash scripts/package.sh || fail "package (bash scripts/package.sh; --write regenerates docs/package.md)"

read -r passed failed < <(awk '/^test result:/ { for (i = 1; i < NF; i++) {
    if ($(i + 1) ~ /^passed;/) p += $i; if ($(i + 1) ~ /^failed;/) f += $i } }
    END { print p + 0, f + 0 }' "$log")
printf '\nall test stages passed\n'
echo "total: ${passed} passed, ${failed} failed"

