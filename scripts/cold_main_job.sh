#!/usr/bin/env bash
# Cold time of the README's main job, as on a fresh machine: a fresh clone of the current
# commit, an empty CARGO_HOME (every crate is downloaded from the registry) and an empty
# target dir, all under a temporary directory outside the repository, removed afterwards.
#
# Usage: bash scripts/cold_main_job.sh [COMMIT]    (default: HEAD)
# Prints the wall-clock seconds (a host timing: it depends on the machine, its load and the
# network), the CPU seconds of the build (user + system, all processes: what an idle machine
# with C cores needs at least CPU/C of), the load average before, and the command. Needs
# network access to the crate registry. With --timings, also keeps cargo's timing report
# (which crate took how long) as /tmp/aemstep-cold-timings.html.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
timings=()
if [ "${1:-}" = --timings ]; then timings=(--timings); shift; fi
commit="$(git -C "$repo" rev-parse "${1:-HEAD}")"
tmp="$(mktemp -d /tmp/aemstep-cold.XXXXXX)"
trap 'rm -rf "$tmp"' EXIT
git clone -q --no-checkout "$repo" "$tmp/src"
git -C "$tmp/src" checkout -q "$commit"
cmd="cargo run --release --example paper_example4"
# The toolchain stays where rustup put it; only the registry, git and build caches are fresh.
export RUSTUP_HOME="${RUSTUP_HOME:-$HOME/.rustup}"
toolchain_bin="$(dirname "$(rustup which cargo 2>/dev/null || command -v cargo)")"
export PATH="$toolchain_bin:$PATH"
export CARGO_HOME="$tmp/cargo-home"
export CARGO_TARGET_DIR="$tmp/target"
mkdir -p "$CARGO_HOME"
cd "$tmp/src"
load="$(cut -d' ' -f1-3 /proc/loadavg)"
TIMEFORMAT='%R %U %S'
{ time $cmd "${timings[@]}" > "$tmp/out.txt" 2> "$tmp/err.txt"; } 2> "$tmp/time.txt" ||
    { cat "$tmp/err.txt" >&2; exit 1; }
read -r wall user sys < "$tmp/time.txt"
grep -q 'second order' "$tmp/out.txt" || { cat "$tmp/out.txt" >&2; echo "main job output?" >&2; exit 1; }
if [ ${#timings[@]} -gt 0 ]; then cp "$tmp/target/cargo-timings/cargo-timing.html" /tmp/aemstep-cold-timings.html; fi
printf 'commit %s on %s cores, load average before %s (host timing)\n' "${commit:0:12}" "$(nproc)" "$load"
printf '%.1f s cold (wall), %.1f s CPU (user + system): %s\n' "$wall" "$(echo "$user + $sys" | bc)" "$cmd"
