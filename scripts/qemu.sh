#!/usr/bin/env bash
# Firmware checks: builds and runs every bare-metal example on QEMU's Cortex-M4F board
# (mps2-an386), fails if any exits non-zero or times out, runs the deliberately broken
# variants and requires them to FAIL, checks that no inversion code is linked into the
# compile-time-operator firmware, and writes the cost and memory tables to
# docs/cortex-m4-cost.md (quoted by README.md). Last, scripts/cores.sh: the cost table
# across Cortex-M cores (docs/cortex-m-cores.md), which fails if the M4F's f32 step
# exceeds 3 instructions per multiply-add at N >= 6.
#
# `qemu_hybrid` and `qemu_control` run twice: as every example on the M4F (f32), and built
# with `-C target-cpu=cortex-m7 --cfg aemstep_fpu="double"` on the Cortex-M7 board
# (`mps2-an500`, the runner of scripts/cores.sh) in f64; both runs' costs go into their
# sections. `qemu_control` also fails if its controller's whole checked step exceeds 3
# instructions per multiply-add on the M4F (checked here too, with a control).
#
# The examples are package `aemstep-firmware` (examples/firmware/, a workspace member; the
# root crate has no firmware feature or dependency). One more, `qemu_defmt`, logs through
# defmt: its output is decoded by `defmt-print` and compared line by line with
# examples/firmware/qemu_defmt.out, and a broken variant must fail that comparison.
#
# Installs what it needs (thumb target, llvm-tools, qemu-system-arm, defmt-print). Called by
# scripts/test.sh; runs alone too: `bash scripts/qemu.sh`.
set -euo pipefail
cd "$(dirname "$0")/.."

TARGET=thumbv7em-none-eabihf
# Examples that must exit 0. Each prints `MEM <name> stack_high_water_bytes <n>` and may
# print `MEM <name> step_stack_bytes <n>` and define a `#[no_mangle]` `<name>_step`.
EXAMPLES=(qemu_timer qemu_cost qemu_nonlinear qemu_modal qemu_schemes qemu_spectrum qemu_hysteretic qemu_observer qemu_estimator qemu_hybrid qemu_control)
# Broken on purpose: "example variant" pairs that must exit with failure (status 1); the
# variant is `--cfg aemstep_broken="<variant>"` (not a public feature, see Cargo.toml).
BROKEN=("qemu_timer inject-nan" "qemu_timer tight-bound" "qemu_nonlinear inject-nan"
    "qemu_modal modal-tight-bound" "qemu_schemes inject-nan" "qemu_spectrum spectrum-tight-bound"
    "qemu_hysteretic hysteretic-tight-bound"
    "qemu_observer observer-nan" "qemu_observer observer-tight-bound"
    "qemu_estimator estimator-tight-bound"
    "qemu_hybrid hybrid-tight-bound" "qemu_hybrid hybrid-nan"
    "qemu_control control-tight-bound" "qemu_control control-nan")
RUN_TIMEOUT=300 # seconds per QEMU run (each takes a few seconds)
PKG=(-p aemstep-firmware)
DEFMT_PRINT_VERSION=1.2.0 # the host decoder; its format must match the target's defmt 1.x
DEFMT_EXPECTED=examples/firmware/qemu_defmt.out
TARGET_DIR=${CARGO_TARGET_DIR:-target}
OUT=$TARGET_DIR/qemu
COST_DOC=docs/cortex-m4-cost.md

step() { printf '\n==> %s\n' "$*"; }
fail() { printf '\nFAILED: %s\n' "$*" >&2; exit 1; }

step "qemu: tools (thumb target, llvm-tools, qemu-system-arm, defmt-print)"
rustup target add "$TARGET"
rustup component add llvm-tools
LLVM_BIN="$(rustc --print sysroot)/lib/rustlib/$(rustc -vV | sed -n 's/^host: //p')/bin"
NM="$LLVM_BIN/llvm-nm"
SIZE="$LLVM_BIN/llvm-size"
OBJDUMP="$LLVM_BIN/llvm-objdump"
[[ -x $NM && -x $SIZE && -x $OBJDUMP ]] || fail "llvm-nm/llvm-size/llvm-objdump not found in $LLVM_BIN"
if ! command -v qemu-system-arm >/dev/null; then
    SUDO=""
    [[ $(id -u) -eq 0 ]] || SUDO=sudo
    $SUDO apt-get update -q
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q qemu-system-arm
fi
qemu-system-arm --version | sed -n 1p
DEFMT_PRINT=$(command -v defmt-print || echo "${CARGO_HOME:-$HOME/.cargo}/bin/defmt-print")
if [[ ! -x $DEFMT_PRINT ]]; then
    cargo install defmt-print --locked --version "$DEFMT_PRINT_VERSION"
fi
"$DEFMT_PRINT" --version

mkdir -p "$OUT" docs
# The QEMU command of .cargo/config.toml for $TARGET (one place for it).
read -r -a RUNNER < <(sed -n "/^\[target.$TARGET\]/,/^\[/ s/^runner = \"\(.*\)\"/\1/p" .cargo/config.toml)
[[ ${#RUNNER[@]} -gt 0 ]] || fail "no runner for $TARGET in .cargo/config.toml"
# A variant is `qemu` (the example as shipped) or `<kind>:<value>`, built with
# `--cfg aemstep_<kind>="<value>"` (kind: broken, control). The cfg goes to the example
# crate only (`cargo rustc`), so the library and dependencies are not rebuilt.
build() { # <example> <variant> [cargo args]: builds and keeps a copy of the ELF as $OUT/<example>-<variant>
    local args=(-q "${PKG[@]}" --release --target "$TARGET" --example "$1" "${@:3}")
    if [[ $2 == qemu ]]; then
        cargo build "${args[@]}" || fail "build $1"
    else
        cargo rustc "${args[@]}" -- --cfg "aemstep_${2%%:*}=\"${2#*:}\"" || fail "build $1 ($2)"
    fi
    cp "$TARGET_DIR/$TARGET/release/examples/$1" "$OUT/$1-$2"
}
run() { # <example> <variant>: runs the ELF `build` kept under QEMU; sets RC
    local log="$OUT/$1-$2.log"
    set +e
    timeout "$RUN_TIMEOUT" "${RUNNER[@]}" "$OUT/$1-$2" >"$log" 2>&1
    RC=$?
    set -e
    cat "$log"
    [[ $RC -ne 124 ]] || fail "$1 ($2) timed out after ${RUN_TIMEOUT}s"
}

step "qemu: clippy of the firmware examples ($TARGET)"
cargo clippy "${PKG[@]}" --release --target "$TARGET" --features defmt --examples -- -D warnings ||
    fail "clippy (firmware examples)"
for ex in qemu_hybrid qemu_control; do
    cargo clippy "${PKG[@]}" --release --target "$TARGET" --example "$ex" \
        -- -D warnings --cfg 'aemstep_fpu="double"' || fail "clippy ($ex, f64)"
done
for variant in footprint-modal footprint-all; do
    cargo clippy "${PKG[@]}" --release --target "$TARGET" --example qemu_footprint \
        -- -D warnings --cfg "aemstep_control=\"$variant\"" || fail "clippy (qemu_footprint, $variant)"
done

step "qemu: run every example (must exit 0)"
for ex in "${EXAMPLES[@]}"; do
    build "$ex" qemu
    run "$ex" qemu
    [[ $RC -eq 0 ]] || fail "$ex exited with $RC"
    echo "ok: $ex exited 0"
done

step "qemu: deliberately broken variants (must exit 1)"
for pair in "${BROKEN[@]}"; do
    read -r ex variant <<<"$pair"
    build "$ex" "broken:$variant"
    run "$ex" "broken:$variant"
    [[ $RC -eq 1 ]] || fail "$ex with --cfg aemstep_broken=\"$variant\" exited $RC, expected the failure status 1"
    grep -q '^FAIL: ' "$OUT/$ex-broken:$variant.log" || fail "$ex ($variant) failed without saying why"
    echo "ok: $ex with --cfg aemstep_broken=\"$variant\" failed as it must (exit 1)"
done

step "qemu: qemu_hybrid and qemu_control in f64 on the Cortex-M7 (mps2-an500, double-precision FPU)"
# The runner and target directory of scripts/cores.sh's M7 (its dependencies stay cached);
# `cargo rustc` passes the cfg to the example crate only.
M7_RUNNER=(qemu-system-arm -machine mps2-an500 -cpu cortex-m7 -nographic -semihosting-config
    enable=on,target=native -icount shift=0,sleep=off -kernel)
M7_DIR=$TARGET_DIR/core-M7
m7_run() { # <example> <name> <extra cfg or ->: builds <example> in f64 for the M7 as $OUT/<example>-<name>, runs it; sets RC
    local ex=$1 name=$2 extra=()
    [[ $3 == - ]] || extra=(--cfg "$3")
    env CARGO_TARGET_DIR="$M7_DIR" CARGO_TARGET_THUMBV7EM_NONE_EABIHF_RUSTFLAGS="-C target-cpu=cortex-m7" \
        cargo rustc -q "${PKG[@]}" --release --target "$TARGET" --example "$ex" -- \
        --cfg 'aemstep_fpu="double"' "${extra[@]}" || fail "build $ex ($name)"
    cp "$M7_DIR/$TARGET/release/examples/$ex" "$OUT/$ex-$name"
    set +e
    timeout "$RUN_TIMEOUT" "${M7_RUNNER[@]}" "$OUT/$ex-$name" >"$OUT/$ex-$name.log" 2>&1
    RC=$?
    set -e
    cat "$OUT/$ex-$name.log"
    [[ $RC -ne 124 ]] || fail "$ex ($name) timed out after ${RUN_TIMEOUT}s"
}
# The broken variant on the M7 is the NaN force: the f64 run is bit-identical to the host's
# (error 0), so no tightened bound can fail it.
for pair in "qemu_hybrid hybrid" "qemu_control control"; do
    read -r ex cost <<<"$pair"
    m7_run "$ex" m7 -
    [[ $RC -eq 0 ]] || fail "$ex on the Cortex-M7 (f64) exited with $RC"
    grep "^COST $cost f64 " "$OUT/$ex-m7.log" >/dev/null || fail "$ex on the M7 did not step in f64"
    echo "ok: $ex in f64 on the Cortex-M7 exited 0"
    m7_run "$ex" m7-broken "aemstep_broken=\"$cost-nan\""
    [[ $RC -eq 1 ]] || fail "$ex on the M7 with --cfg aemstep_broken=\"$cost-nan\" exited $RC, expected 1"
    grep '^FAIL: ' "$OUT/$ex-m7-broken.log" >/dev/null || fail "$ex on the M7 (broken) failed without saying why"
    echo "ok: $ex on the M7 with --cfg aemstep_broken=\"$cost-nan\" failed as it must (exit 1)"
done

step "qemu: defmt: the decoded log of qemu_defmt, line by line against $DEFMT_EXPECTED"
# The firmware writes defmt frames to semihosting stdout; defmt-print formats them on the
# host. `--log-format '{L} {s}'`: level and message only (no timestamp is defined; source
# locations would pin line numbers), so the comparison is exact and repeatable.
defmt_check() { # <variant>: runs qemu_defmt; sets RC (QEMU) and DIFF (decoded vs expected)
    local elf="$OUT/qemu_defmt-$1" decoded="$OUT/qemu_defmt-$1.decoded"
    set +e
    timeout "$RUN_TIMEOUT" "${RUNNER[@]}" "$elf" >"$OUT/qemu_defmt-$1.raw" 2>"$OUT/qemu_defmt-$1.err"
    RC=$?
    set -e
    [[ $RC -ne 124 ]] || fail "qemu_defmt ($1) timed out after ${RUN_TIMEOUT}s"
    "$DEFMT_PRINT" -e "$elf" --log-format '{L} {s}' <"$OUT/qemu_defmt-$1.raw" >"$decoded" ||
        fail "defmt-print could not decode the output of qemu_defmt ($1)"
    cat "$decoded"
    DIFF=$(diff <(grep -v '^#' "$DEFMT_EXPECTED") "$decoded" || true)
}
build qemu_defmt qemu --features defmt
defmt_check qemu
[[ $RC -eq 0 ]] || fail "qemu_defmt exited with $RC: $(grep -a '^FAIL' "$OUT/qemu_defmt-qemu.raw" || true)"
[[ -z $DIFF ]] || fail "the decoded defmt log differs from $DEFMT_EXPECTED (< expected, > decoded):
$DIFF"
echo "ok: qemu_defmt exited 0; its $(wc -l <"$OUT/qemu_defmt-qemu.decoded") decoded lines match $DEFMT_EXPECTED"
build qemu_defmt broken:defmt-wrong --features defmt
defmt_check broken:defmt-wrong
[[ $RC -eq 0 && -n $DIFF ]] ||
    fail "qemu_defmt with --cfg aemstep_broken=\"defmt-wrong\" (exit $RC) was not caught by the comparison"
echo "ok: with --cfg aemstep_broken=\"defmt-wrong\" the comparison fails as it must:"
echo "$DIFF"

step "qemu: no operator inversion code in the compile-time-operator firmware"
# The build with run-time operators (Linear::new) is the control: the same check must find
# the inversion code there, or the check proves nothing.
INVERSION='aemstep::linalg::|inverse|cholesky|::lu::'
build qemu_timer control:runtime-ops
"$NM" -C "$OUT/qemu_timer-control:runtime-ops" | grep -E "$INVERSION" >/dev/null ||
    fail "control: the symbol check did not see the inversion code of the run-time build"
if "$NM" -C "$OUT/qemu_timer-qemu" | grep -E "$INVERSION"; then
    fail "qemu_timer links operator inversion code (symbols above)"
fi
echo "ok: qemu_timer has no symbol matching /$INVERSION/ (the run-time build has: $("$NM" -C \
    "$OUT/qemu_timer-control:runtime-ops" | grep -E "$INVERSION" | awk '{print $3}' | tr '\n' ' '))"

# The observer firmware: model, Riccati gain and operators all computed by the compiler.
if "$NM" -C "$OUT/qemu_observer-qemu" | grep -E "$INVERSION|riccati|SteadyState"; then
    fail "qemu_observer links factorization or Riccati code (symbols above)"
fi
echo "ok: qemu_observer has no symbol matching /$INVERSION|riccati|SteadyState/"
if "$NM" -C "$OUT/qemu_estimator-qemu" | grep -E "$INVERSION|riccati|InputStateGains"; then
    fail "qemu_estimator links factorization or Riccati code (symbols above)"
fi
echo "ok: qemu_estimator has no symbol matching /$INVERSION|riccati|InputStateGains/"

step "qemu: no panic reachable from any step function (call graph of the ELFs)"
# Roots: every `#[no_mangle]` step symbol (`<example>_step`, `cost_step_*`). Edges: direct
# calls and tail branches between functions in the disassembly. A panic path in a step
# (an index or unwrap the compiler could not prove) would reach `core::panicking::*`.
step_roots() { # <elf>: the step symbols (`<example>_step`, `cost_step_*`)
    "$NM" "$1" | awk '$3 ~ /^cost_step_|_step$/ { print $3 }'
}
reachable() { # <elf> <root>...: every function reachable from the roots, one per line
    local elf=$1
    shift
    "$OBJDUMP" -d --no-show-raw-insn "$elf" | awk -v roots="$*" '
        /^[0-9a-f]+ <[^>]+>:$/ { fn = $2; gsub(/[<>:]/, "", fn); next }
        /\t(bl|blx|b|b\.w)\t+0x[0-9a-f]+ </ {
            if (match($0, /<[^>+]+/)) { t = substr($0, RSTART + 1, RLENGTH - 1); if (t != fn) edge[fn] = edge[fn] " " t }
        }
        END {
            n = split(roots, queue, " "); for (i = 1; i <= n; i++) seen[queue[i]] = 1
            for (i = 1; i <= n; i++) {
                m = split(edge[queue[i]], next_, " ")
                for (j = 1; j <= m; j++) if (!(next_[j] in seen)) { seen[next_[j]] = 1; queue[++n] = next_[j] }
            }
            for (f in seen) print f
        }'
}
# The walk follows direct branches only, so it also proves there is nothing else to follow:
# no reachable function may branch through a register (`blx rN`, `bx rN` other than
# `bx lr`, a load into pc) — a call through a function pointer or vtable that could hide a
# panic. `indirect <elf> <fn>...` prints each such instruction with its function.
indirect() {
    local elf=$1
    shift
    "$OBJDUMP" -d --no-show-raw-insn "$elf" | awk -v fns="$*" '
        BEGIN { n = split(fns, f, " "); for (i = 1; i <= n; i++) want[f[i]] = 1 }
        /^[0-9a-f]+ <[^>]+>:$/ { fn = $2; gsub(/[<>:]/, "", fn); next }
        (fn in want) && (/\tblx\tr[0-9]/ || /\tbx\tr[0-9]/ || /\tmov\tpc, r/ || /\tldr(\.w)?\tpc, \[r[0-9]/) {
            print fn ": " $0
        }'
}
# Controls: the same walk must find the panic machinery behind the firmware's own formatted
# failure path (core::fmt indexes slices), and the indirect-branch scan must find core::fmt's
# calls through its `dyn Write` vtable there, or the checks prove nothing.
# (No `| grep -q` anywhere here: with pipefail, its early exit fails the writer.)
control=$(reachable "$OUT/qemu_timer-qemu" "$("$NM" "$OUT/qemu_timer-qemu" | awk '$3 ~ /exit_failure/ { print $3 }')")
grep -i panic <<<"$control" >/dev/null || fail "control: the call-graph walk found no panic behind exit_failure"
mapfile -t control_fns <<<"$control"
[[ -n $(indirect "$OUT/qemu_timer-qemu" "${control_fns[@]}") ]] ||
    fail "control: the indirect-branch scan found nothing behind exit_failure (core::fmt calls through vtables)"
for ex in "${EXAMPLES[@]}"; do
    mapfile -t roots < <(step_roots "$OUT/$ex-qemu")
    [[ ${#roots[@]} -gt 0 ]] || fail "$ex: no step symbol found"
    fns=$(reachable "$OUT/$ex-qemu" "${roots[@]}")
    if grep -i 'panic' <<<"$fns"; then
        fail "$ex: a panic is reachable from a step function (above)"
    fi
    mapfile -t fn_list <<<"$fns"
    ind=$(indirect "$OUT/$ex-qemu" "${fn_list[@]}")
    [[ -z $ind ]] || fail "$ex: a step function branches through a register; the walk cannot follow it:
$ind"
    echo "ok: $ex: ${#roots[@]} step function(s), $(wc -l <<<"$fns") functions reachable, none panics, no indirect branch"
done

step "qemu: the f32 detector's step links no soft-double routine (qemu_estimator)"
# `qemu_estimator_step` steps the f32 joint estimator and its χ² detector and reads the
# window's sum as a handler logs it (`Window::sum`, f32): nothing reachable from it may be a
# double-precision routine (`__aeabi_d*`, a conversion to double `__aeabi_*2d`,
# compiler-builtins' `__*df3`/`__extendsfdf2`). Control: the same walk from `main`, which
# steps the f64 reference estimator in soft float, must find them.
SOFT_DOUBLE='__aeabi_d|__aeabi_[a-z0-9]+2d$|df[0-9]$|sfdf'
control=$(reachable "$OUT/qemu_estimator-qemu" main)
grep -E "$SOFT_DOUBLE" <<<"$control" >/dev/null ||
    fail "control: the call-graph walk from qemu_estimator's main found no soft-double routine"
fns=$(reachable "$OUT/qemu_estimator-qemu" qemu_estimator_step cost_step_detector)
if grep -E "$SOFT_DOUBLE" <<<"$fns"; then
    fail "qemu_estimator: the f32 detector's step reaches a soft-double routine (above)"
fi
echo "ok: qemu_estimator: $(wc -l <<<"$fns") functions reachable from the f32 detector's step, no soft-double routine (main reaches $(grep -cE "$SOFT_DOUBLE" <<<"$control"))"

step "qemu: host and Cortex-M4F f32 runs are bit-identical (Example 2, u at 25 s)"
host_bits=$(cargo test -q --release --test firmware_example2 -- --nocapture --exact \
    f32_error_within_the_firmware_bound 2>&1 | sed -n 's/^host u(25 s) f32 bits = //p')
target_bits=$(sed -n 's/^target u(25 s) f32 bits = //p' "$OUT/qemu_timer-qemu.log")
[[ -n $host_bits && $host_bits == "$target_bits" ]] ||
    fail "u(25 s): host '$host_bits', target '$target_bits'"
echo "ok: both $host_bits"

step "qemu: host and Cortex-M4F f32 runs are bit-identical (modal building, roof drift at 80 s)"
host_bits=$(cargo test -q --release --test firmware_modal -- --nocapture --exact \
    reference_is_current_and_host_f32_run_is_within_bound 2>&1 |
    sed -n 's/^host roof drift f32 bits = //p')
target_bits=$(sed -n 's/^target roof drift f32 bits = //p' "$OUT/qemu_modal-qemu.log")
[[ -n $host_bits && $host_bits == "$target_bits" ]] ||
    fail "roof drift: host '$host_bits', target '$target_bits'"
echo "ok: both $host_bits"

step "qemu: host and Cortex-M4F f32 runs are bit-identical (yielding building, roof at 79.9 s)"
host_bits=$(cargo test -q --release --test firmware_hysteretic -- --nocapture 2>&1 |
    sed -n 's/^host roof displacement f32 bits = //p')
target_bits=$(sed -n 's/^target roof displacement f32 bits = //p' "$OUT/qemu_hysteretic-qemu.log")
[[ -n $host_bits && $host_bits == "$target_bits" ]] ||
    fail "hysteretic roof: host '$host_bits', target '$target_bits'"
echo "ok: both $host_bits"

step "qemu: host and Cortex-M4F f32 runs are bit-identical (observer, storey-1 drift at 80 s)"
host_bits=$(cargo test -q --release --test observer -- --nocapture --exact \
    scene_constants_and_firmware_reference_are_current 2>&1 |
    sed -n 's/^host f32 storey-1 drift at the last step, f32 bits = //p')
target_bits=$(sed -n 's/^target storey-1 drift f32 bits = //p' "$OUT/qemu_observer-qemu.log")
[[ -n $host_bits && $host_bits == "$target_bits" ]] ||
    fail "observer storey-1 drift: host '$host_bits', target '$target_bits'"
echo "ok: both $host_bits"

step "qemu: host and target runs are bit-identical (hybrid loop: storey-1 drift at 79.9 s; M4F f32, M7 f64)"
host_log=$(cargo test -q --release --features std --test firmware_hybrid -- --nocapture 2>&1)
for rate in 1024 2048; do
    for pair in "f32 qemu_hybrid-qemu" "f64 qemu_hybrid-m7"; do
        read -r ty log <<<"$pair"
        host_bits=$(sed -n "s/^host last storey-1 drift $rate $ty bits = //p" <<<"$host_log")
        target_bits=$(sed -n "s/^target last storey-1 drift $rate $ty bits = //p" "$OUT/$log.log")
        [[ -n $host_bits && $host_bits == "$target_bits" ]] ||
            fail "hybrid storey-1 drift at $rate Hz ($ty): host '$host_bits', target '$target_bits'"
        echo "ok: $rate Hz $ty: both $host_bits"
    done
done

step "qemu: host and target runs are bit-identical (control loop: floor-1 displacement at 16.0 s; M4F f32, M7 f64)"
host_log=$(cargo test -q --release --features std --test firmware_control -- --nocapture 2>&1)
for pair in "f32 qemu_control-qemu" "f64 qemu_control-m7"; do
    read -r ty log <<<"$pair"
    host_bits=$(sed -n "s/^host last floor-1 displacement $ty bits = //p" <<<"$host_log")
    target_bits=$(sed -n "s/^target last floor-1 displacement $ty bits = //p" "$OUT/$log.log")
    [[ -n $host_bits && $host_bits == "$target_bits" ]] ||
        fail "control floor-1 displacement ($ty): host '$host_bits', target '$target_bits'"
    echo "ok: $ty both $host_bits"
done

step "qemu: the controller's whole step within 3 instructions per multiply-add on the Cortex-M4F"
# The firmware fails on its own count too; this reads the logged row and proves, on a
# made-up row just above the limit, that the check can fail.
MAX_CONTROL_PER_MADD=3
control_over() { # <log>: the M4F f32 control-step row if above the limit
    awk -v max="$MAX_CONTROL_PER_MADD" '$1 == "COST" && $2 == "control-step" && $3 == "f32" &&
        $5 > 0 && $4 / $5 > max { printf "%s instructions for %d multiply-adds (%.2f each)\n", $4, $5, $4 / $5 }' "$1"
}
[[ -n $(control_over <(echo "COST control-step f32 282.1 94")) ]] ||
    fail "control: the limit check passed a row of 3.001 instructions per multiply-add"
grep '^COST control-step f32 ' "$OUT/qemu_control-qemu.log" >/dev/null || fail "qemu_control printed no control-step row"
bad=$(control_over "$OUT/qemu_control-qemu.log")
[[ -z $bad ]] || fail "the controller's step above $MAX_CONTROL_PER_MADD instructions per multiply-add: $bad"
echo "ok: $(awk '$2 == "control-step" { printf "%.2f", $4 / $5 }' "$OUT/qemu_control-qemu.log") instructions per multiply-add"

step "qemu: host and Cortex-M4F runs are bit-identical (joint estimator: roof force and detector window at 80 s)"
host_log=$(cargo test -q --release --test firmware_estimator -- --nocapture --exact \
    f32_run_within_the_firmware_bound 2>&1)
for ty in f32 f64; do
    host_bits=$(sed -n "s/^host roof force $ty bits = //p" <<<"$host_log")
    target_bits=$(sed -n "s/^target roof force $ty bits = //p" "$OUT/qemu_estimator-qemu.log")
    [[ -n $host_bits && $host_bits == "$target_bits" ]] ||
        fail "estimator roof force ($ty): host '$host_bits', target '$target_bits'"
    echo "ok: $ty both $host_bits"
done
host_sum=$(cargo test -q --release --test firmware_estimator -- --nocapture --exact \
    detector_is_quiet_on_the_intact_building_and_sees_a_faulty_sensor 2>&1 |
    sed -n 's/^host detector window sum fixed = //p')
target_sum=$(sed -n 's/^target detector window sum fixed = //p' "$OUT/qemu_estimator-qemu.log")
[[ -n $host_sum && $host_sum == "$target_sum" ]] ||
    fail "estimator's detector window sum: host '$host_sum', target '$target_sum'"
echo "ok: detector window sum (fixed point) both $host_sum"

step "qemu: footprint: a firmware pays only for the capabilities it uses"
# qemu_footprint uses only Linear<f32, 5>; with control "footprint-modal" also a compile-time
# Modal<f32, 5, 2>; with "footprint-all" also the nonlinear stepper and a Modal built at
# run time. The last is the control: the symbol checks must find the code there.
UNUSED='modal|nonlinear|varying|jacobi|LinearInput|input[:.]|cholesky|Cholesky'
EIGEN='jacobi|cholesky|modes_of|modal_operators'
for variant in qemu control:footprint-modal control:footprint-all; do
    build qemu_footprint "$variant"
    run qemu_footprint "$variant"
    [[ $RC -eq 0 ]] || fail "qemu_footprint ($variant) exited with $RC"
done
"$NM" -C "$OUT/qemu_footprint-control:footprint-all" | grep -E "$UNUSED" >/dev/null ||
    fail "control: no nonlinear/modal symbol found in the build that uses them"
"$NM" -C "$OUT/qemu_footprint-control:footprint-all" | grep -E "$EIGEN" >/dev/null ||
    fail "control: no eigen-solver symbol found in the build that runs Modal::new"
if "$NM" -C "$OUT/qemu_footprint-qemu" | grep -E "$UNUSED"; then
    fail "the Linear-only firmware links code of capabilities it does not use (symbols above)"
fi
for elf in "$OUT/qemu_footprint-control:footprint-modal" "$OUT/qemu_modal-qemu"; do
    if "$NM" -C "$elf" | grep -E "$EIGEN"; then
        fail "$elf links eigen-solver code although its modes were solved at compile time"
    fi
done
flash_of() { "$SIZE" -B "$1" | awk 'NR == 2 { print $1 + $2 }'; }
FP_LEAN=$(flash_of "$OUT/qemu_footprint-qemu")
FP_MODAL=$(flash_of "$OUT/qemu_footprint-control:footprint-modal")
FP_ALL=$(flash_of "$OUT/qemu_footprint-control:footprint-all")
echo "ok: flash: Linear only $FP_LEAN bytes; + static Modal $FP_MODAL; + Nonlinear + run-time" \
    "Modal $FP_ALL. No /$UNUSED/ symbol in the Linear-only build, no /$EIGEN/ symbol in the" \
    "static-Modal builds"

step "qemu: cost and memory tables -> $COST_DOC"
sym_size() { # <elf> <symbol>: code bytes of the symbol and of every function it calls, or "-"
    local syms
    syms=$("$NM" -S "$1")
    grep " $2\$" <<<"$syms" >/dev/null || { echo -; return; }
    reachable "$1" "$2" | sort -u >"$OUT/fns"
    awk 'NR == FNR { want[$1] = 1; next } NF == 4 && ($4 in want) && !done[$4]++ { s += strtonum_hex($2) }
        function strtonum_hex(h,   i, v, c) { v = 0; h = tolower(h); for (i = 1; i <= length(h); i++) { c = index("0123456789abcdef", substr(h, i, 1)) - 1; v = v * 16 + c } return v }
        END { print s + 0 }' "$OUT/fns" - <<<"$syms"
}
hyb_err() { # <run: qemu or m7> <rate>: the max |drift − host| the run printed
    sed -n "s/^qemu_hybrid: .* at $2 Hz .* = \\([^ ]*\\) m <= bound .*/\\1/p" "$OUT/qemu_hybrid-$1.log"
}
hyb_bound() { # <run>: the bound the run checked
    sed -n 's/^qemu_hybrid: .* <= bound \([^ ]*\) m$/\1/p' "$OUT/qemu_hybrid-$1.log" | sed -n 1p
}
ctl_err() { # <run: qemu or m7>: the max |x1 − host| the control run printed
    sed -n 's/^qemu_control: .* = \([^ ]*\) m <= bound .*/\1/p' "$OUT/qemu_control-$1.log"
}
ctl_bound() { # <run>: the bound the control run checked
    sed -n 's/^qemu_control: .* <= bound \([^ ]*\) m$/\1/p' "$OUT/qemu_control-$1.log"
}
mem_of() { # <example> <key>: a MEM figure from the example's log, or "-"
    awk -v e="$1" -v k="$2" '$1 == "MEM" && $2 == e && $3 == k { v = $4 } END { printf "%s", v == "" ? "-" : v }' \
        "$OUT/$1-qemu.log"
}
{
    echo "# aemstep on a Cortex-M4F: instructions per step and memory"
    echo
    echo "Generated by \`bash scripts/qemu.sh\` — do not edit by hand. QEMU $(qemu-system-arm --version |
        awk 'NR == 1 {print $4}') \`mps2-an386\` (Cortex-M4F) with \`-icount shift=0\`; $(rustc --version |
        awk '{print $1, $2}'), \`--release\`, target \`$TARGET\`. Instruction counts do not depend on the host"
    echo "($(lscpu | sed -n 's/^Model name: *//p' | sed -n 1p)); they are instructions, not cycles."
    echo
    echo "## Instructions per step (\`examples/firmware/qemu_cost.rs\`)"
    echo
    echo "Fast form: \`Linear<T, N>\` (3N² multiply-adds). A-form: \`AForm<T, N>\` (12N²). Building: N-storey"
    echo "uniform shear building (N = 5 is the benchmark building's size), dense operators. \`f64\` is software"
    echo "floating point on this core (its FPU is single precision)."
    echo
    echo "Step code: the step's own symbol and every function it calls, in bytes; step stack: what one call"
    echo "uses, measured on target by painting (see below)."
    echo
    echo "| form | type | N | instructions / step | multiply-adds | instructions / multiply-add | step code (bytes) | step stack (bytes) |"
    echo "|---|---|---:|---:|---:|---:|---:|---:|"
    grep '^ROW ' "$OUT/qemu_cost-qemu.log" | while read -r _ form ty n instr madds stack sym; do
        case $form in
        fast) name="fast (\`Linear\`)" ;;
        aform) name="A-form (\`AForm\`)" ;;
        compensated) name="compensated (\`CompensatedLinear\`)" ;;
        duffing) name="Duffing (\`Nonlinear\`, exactly 2 Newton iterations)" ;;
        *) fail "unknown cost row '$form'" ;;
        esac
        if [[ $madds -gt 0 ]]; then
            ratio=$(awk -v a="$instr" -v b="$madds" 'BEGIN { printf "%.2f", a / b }')
        else
            ratio="—" madds="—"
        fi
        echo "| $name | $ty | $n | $instr | $madds | $ratio | $(sym_size "$OUT/qemu_cost-qemu" "$sym") | $stack |"
    done
    echo
    echo "## Only what the scene needs (\`examples/firmware/qemu_modal.rs\`)"
    echo
    echo "The benchmark 5-storey building under El Centro, one step plus reading the roof drift, \`f32\`:"
    echo "\`Modal<f32, 5, R>\` (R of 5 modes), the full model with the input through \`B = −Mι\`"
    echo "(\`LinearInput<f32, 5, 1>\`), and the full \`Linear<f32, 5>\` fed \`p = B a_g\`."
    echo
    echo "| stepper | instructions / step | multiply-adds |"
    echo "|---|---:|---:|"
    grep '^COST ' "$OUT/qemu_modal-qemu.log" | while read -r _ what instr madds; do
        echo "| \`$what\` | $instr | $madds |"
    done
    echo
    echo "## Response spectrum (\`examples/firmware/qemu_spectrum.rs\`)"
    echo
    echo "\`Bank<f32, P>\` (5 %, exact scheme, default sub-steps) fed El Centro: instructions per incoming sample,"
    echo "averaged over the record (sub-step walks included); multiply-adds of the whole-interval steps (10P)."
    echo
    echo "| bank | instructions / sample | multiply-adds |"
    echo "|---|---:|---:|"
    grep '^COST spectrum' "$OUT/qemu_spectrum-qemu.log" | while read -r _ what instr madds; do echo "| \`$what\` | $instr | $madds |"; done
    echo
    echo "## A yielding building (\`examples/firmware/qemu_hysteretic.rs\`)"
    echo
    echo "The 3-storey building with bilinear storeys under El Centro, \`Nonlinear<f32, 3>\` with exactly 3"
    echo "Newton iterations a step, storey histories committed with each step; over the 3994 steps of the record."
    echo
    echo "| model | instructions / step (mean) | instructions / step (max) |"
    echo "|---|---:|---:|"
    grep '^COST ' "$OUT/qemu_hysteretic-qemu.log" | while read -r _ what mean max; do
        echo "| \`$what\` | $mean | $max |"
    done
    echo
    echo "## Observer loops (\`examples/firmware/qemu_observer.rs\`)"
    echo
    echo "One step of the fixed-gain observer (predict, correct with 2 accelerometers), \`f32\`: the full building"
    echo "(\`Observer<f32, 10, 1, 2>\`, 10 states) and 2 of its 5 modes (\`Observer<f32, 4, 1, 2>\`)."
    echo
    echo "| observer | instructions / step | multiply-adds | instructions / multiply-add |"
    echo "|---|---:|---:|---:|"
    grep '^COST ' "$OUT/qemu_observer-qemu.log" | while read -r _ what instr madds; do
        echo "| \`$what\` | $instr | $madds | $(awk -v a="$instr" -v b="$madds" 'BEGIN { printf "%.2f", a / b }') |"
    done
    echo
    echo "## Joint input–state estimator (\`examples/firmware/qemu_estimator.rs\`)"
    echo
    echo "One step of the fixed-gain joint input–state estimator (Gillijns–De Moor: predict, estimate the"
    echo "unknown roof force, correct with 3 accelerometers and the roof displacement), \`f32\`:"
    echo "\`InputStateObserver<f32, 10, 1, 4>\` (10 states, 1 unknown input, 4 sensors). Second row: the same step"
    echo "returning its residual (\`step_innovation\`), whitened and pushed into the 50-sample \`Window\` of the χ²"
    echo "detector (\`Detector<f32, 4, 50>\`, 3 degrees of freedom a sample; its fixed-point terms rounded in \`f32\`)."
    echo
    echo "| estimator | instructions / step | multiply-adds | instructions / multiply-add |"
    echo "|---|---:|---:|---:|"
    grep '^COST estimator' "$OUT/qemu_estimator-qemu.log" | while read -r _ what instr madds; do
        echo "| \`$what\` | $instr | $madds | $(awk -v a="$instr" -v b="$madds" 'BEGIN { printf "%.2f", a / b }') |"
    done
    echo
    echo "## Hybrid loop (\`examples/firmware/qemu_hybrid.rs\`)"
    echo
    echo "One step of the real-time hybrid loop of issue 22 (\`scenes/hybrid/rig.rs\`): the 5-storey building's split"
    echo "KR-α step (\`Split<T, 5>\`: displacement command, then completion with the measured force), order-2"
    echo "polynomial compensation of a 5 ms actuator delay, the emulated actuator, the bilinear storey-1 specimen;"
    echo "mean and worst case over every step of El Centro ×2 (79.9 s), stepped from SysTick. \`f32\` on the"
    echo "Cortex-M4F (\`mps2-an386\`); \`f64\` on the Cortex-M7 (\`mps2-an500\`, \`-C target-cpu=cortex-m7\`, its"
    echo "double-precision FPU). Against the host's f64 run, at 1024 Hz: max |storey-1 drift − host| ="
    echo "$(hyb_err qemu 1024) m in \`f32\` (bound $(hyb_bound qemu) m), $(hyb_err m7 1024) m in \`f64\` (bound $(hyb_bound m7) m)."
    echo
    echo "Share of the budget: instructions per step over the core clock's cycles in one sample period"
    echo "(clock / rate), assuming 1 instruction per cycle. These are instructions, not cycles: flash wait states,"
    echo "FPU latencies (an \`f64\` divide takes many cycles) and the M7's dual issue move the true share either way,"
    echo "and the interrupt's entry and exit are not counted; read DWT CYCCNT on the part for time. Each step is"
    echo "counted in whole SysTick ticks of 40 instructions (± 40 on one count; the mean averages them)."
    echo
    echo "| core | type | rate (Hz) | instructions / step (mean) | instructions / step (max) | clock (MHz) | budget (cycles / step) | share of the budget (mean) | share of the budget (max) |"
    echo "|---|---|---:|---:|---:|---:|---:|---:|---:|"
    for pair in "qemu Cortex-M4F 168" "m7 Cortex-M7 480"; do
        read -r run core mhz <<<"$pair"
        grep '^COST hybrid ' "$OUT/qemu_hybrid-$run.log" | while read -r _ _ ty rate mean max; do
            awk -v c="$core" -v t="$ty" -v r="$rate" -v a="$mean" -v b="$max" -v m="$mhz" 'BEGIN {
                budget = m * 1e6 / r
                printf "| %s | `%s` | %d | %d | %d | %d | %d | %.2f %% | %.2f %% |\n", c, t, r, a, b, m, budget, 100 * a / budget, 100 * b / budget }'
        done
    done
    echo
    echo "## Semi-active control loop (\`examples/firmware/qemu_control.rs\`)"
    echo
    echo "The clipped-optimal MR-damper controller of issue 33 on the 3-storey model building of the Dyke et al. (1996)"
    echo "benchmark (\`scenes/control/\`), stepped from SysTick at 1 kHz with the structure and the damper emulated beside it."
    echo "Controller step: \`Controller::try_step\` (\`Controller<T, 6, 1, 3>\`: observer, gain on the delayed model,"
    echo "saturation, checks and status), \`S² + 2S·I + 2S·O + O·I + S·I + I²\` = 94 multiply-adds (S = 6 states, I = 1"
    echo "input, O = 3 accelerometers), must stay within 3 instructions per multiply-add on the Cortex-M4F, its checks"
    echo "included (\`scripts/qemu.sh\` fails otherwise); beside it its observer update alone (\`Observer::step\`),"
    echo "\`S² + 2S·I + 2S·O + O·I\` = 87. Averages of 1000 calls, loop overhead subtracted. \`f32\` on the Cortex-M4F,"
    echo "\`f64\` on the Cortex-M7."
    echo
    echo "| core | type | step | instructions / step | multiply-adds | instructions / multiply-add |"
    echo "|---|---|---|---:|---:|---:|"
    for pair in "qemu Cortex-M4F" "m7 Cortex-M7"; do
        read -r run core <<<"$pair"
        grep -E '^COST control-(step|observer) ' "$OUT/qemu_control-$run.log" | while read -r _ what ty instr madds; do
            case $what in
            control-step) name="\`Controller::try_step\`" ;;
            control-observer) name="its \`Observer::step\`" ;;
            esac
            echo "| $core | \`$ty\` | $name | $instr | $madds | $(awk -v a="$instr" -v b="$madds" 'BEGIN { printf "%.2f", a / b }') |"
        done
    done
    echo
    echo "The whole loop step (sense, controller, switching law, the emulated structure and damper: \`Coupled\` and"
    echo "\`Nonlinear<T, 3>\` with up to 20 Newton iterations), mean and worst case over the 15976 steps of the record."
    echo "Against the host's f64 run: max |floor-1 displacement − host| = $(ctl_err qemu) m in \`f32\` (bound"
    echo "$(ctl_bound qemu) m), $(ctl_err m7) m in \`f64\` (bound $(ctl_bound m7) m). Share of the budget as for the hybrid loop."
    echo
    echo "| core | type | rate (Hz) | instructions / step (mean) | instructions / step (max) | clock (MHz) | budget (cycles / step) | share of the budget (mean) | share of the budget (max) |"
    echo "|---|---|---:|---:|---:|---:|---:|---:|---:|"
    for pair in "qemu Cortex-M4F 168" "m7 Cortex-M7 480"; do
        read -r run core mhz <<<"$pair"
        grep '^COST control ' "$OUT/qemu_control-$run.log" | while read -r _ _ ty mean max; do
            awk -v c="$core" -v t="$ty" -v r=1000 -v a="$mean" -v b="$max" -v m="$mhz" 'BEGIN {
                budget = m * 1e6 / r
                printf "| %s | `%s` | %d | %d | %d | %d | %d | %.2f %% | %.2f %% |\n", c, t, r, a, b, m, budget, 100 * a / budget, 100 * b / budget }'
        done
    done
    echo
    echo "## Footprint (\`examples/firmware/qemu_footprint.rs\`)"
    echo
    echo "Flash (\`.text\` + \`.rodata\` + vector table + \`.data\`) of the same firmware using only"
    echo "\`Linear<f32, 5>\`; also a \`Modal<f32, 5, 2>\` solved by the compiler ("
    echo "\`--cfg aemstep_control=\"footprint-modal\"\`); also \`Nonlinear<f32, 5>\` and a \`Modal<f32, 5, 2>\` built at run time"
    echo "(\`--cfg aemstep_control=\"footprint-all\"\`). Checked: the Linear-only build links no symbol of the others,"
    echo "the compile-time-modal builds no eigen-solver."
    echo
    echo "| firmware | flash (bytes) |"
    echo "|---|---:|"
    echo "| \`Linear<f32, 5>\` only | $FP_LEAN |"
    echo "| + \`Modal<f32, 5, 2>\` (\`static\`, \`from_rows_f32\`) | $FP_MODAL |"
    echo "| + \`Nonlinear<f32, 5>\` + \`Modal<f32, 5, 2>\` (\`Modal::new\` on target) | $FP_ALL |"
    echo
    echo "## Memory of each example"
    echo
    echo "Flash = \`.text\` + \`.rodata\` + vector table + \`.data\` initialisers; static RAM = \`.data\` + \`.bss\`"
    echo "(\`llvm-size\`); stack high-water = deepest stack use since reset, measured on target by scanning"
    echo "the paint (\`0xCCCCCCCC\`) cortex-m-rt lays at reset. Step function: its own symbol's code bytes and the"
    echo "stack one call uses (painted and scanned around the call). Step code counts the step's symbol and every"
    echo "function it calls (for \`f64\`, the soft-float routines: shared by all \`f64\` code)."
    echo
    echo "| example | flash (bytes) | static RAM (bytes) | stack high-water (bytes) | step function code (bytes) | step function stack (bytes) |"
    echo "|---|---:|---:|---:|---:|---:|"
    for ex in "${EXAMPLES[@]}"; do
        read -r text data bss < <("$SIZE" -B "$OUT/$ex-qemu" | awk 'NR == 2 { print $1, $2, $3 }')
        echo "| \`$ex\` | $((text + data)) | $((data + bss)) | $(mem_of "$ex" stack_high_water_bytes) |" \
            "$(sym_size "$OUT/$ex-qemu" "${ex}_step") | $(mem_of "$ex" step_stack_bytes) |"
    done
} >"$COST_DOC"
cat "$COST_DOC"
# README.md and docs/ quote these tables verbatim (scripts/check_docs.py checks every quoted
# number): fail when a quote has gone stale.
python3 scripts/check_docs.py --quotes ||
    fail "README.md or docs/ quote numbers that $COST_DOC no longer has (copy the new lines over)"

step "qemu: cost table across Cortex-M cores (scripts/cores.sh)"
bash scripts/cores.sh || fail "scripts/cores.sh"

printf '\nqemu: all firmware checks passed\n'
