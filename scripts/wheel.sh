#!/usr/bin/env bash
# The Python package as a user installs it: a portable abi3 manylinux wheel and an sdist.
#   bash scripts/wheel.sh [DIR]        build DIR/aemstep-*.whl and DIR/aemstep-*.tar.gz
#                                      (DIR defaults to target/wheels, or $CARGO_TARGET_DIR/wheels)
#   bash scripts/wheel.sh --page DIR   build into the default DIR, then write DIR/wheel.md
#                                      (docs/wheel.md: scripts/check_docs.py regenerates it)
# maturin builds the extension in release for CPython's stable ABI (abi3, CPython 3.9 and
# later) against glibc 2.17 (manylinux2014) with zig from PyPI as the linker, so the wheel
# installs on x86-64 Linux without Rust. auditwheel (PyPI) then checks the wheel is what its
# tag says: the script fails unless `auditwheel show` finds it consistent with
# manylinux_2_17_x86_64 (its abi3 tag is proven by --page, which imports it on every CPython
# 3.9+ the machine has). The build tools (pinned below) live in
# a virtual environment under the cargo target directory, made on the first run and reused;
# the build reuses the target directory, so a second run with no change takes seconds (the
# first: 6-8 minutes on 2 cores). Prints the wheel's path and size; the test command
# (scripts/test.sh) calls it.
# --page also installs the wheel, with numpy already present and no cargo or rustc on PATH,
# into a fresh virtual environment of this machine's python3 and of every other CPython 3.9+
# that pyenv holds (~/.pyenv/versions), imports it and runs one call in each, and times each
# install (about 15 s per version, most of it installing numpy into the fresh environment).
set -euo pipefail
cd "$(dirname "$0")/.."
fail() { printf '\nFAILED: %s\n' "$*" >&2; exit 1; }

MATURIN=1.16.0
ZIGLANG=0.14.1
AUDITWHEEL=6.8.2

target=${CARGO_TARGET_DIR:-$PWD/target}
page=
if [ "${1:-}" = "--page" ]; then
    page=${2:?usage: bash scripts/wheel.sh --page DIR}
    out=$target/wheels
else
    out=${1:-$target/wheels}
fi
tools=$target/wheel-tools-$MATURIN-$ZIGLANG-$AUDITWHEEL
if [ ! -x "$tools/bin/maturin" ]; then
    rm -rf "$tools"
    python3 -m venv "$tools" || fail "python3 -m venv (Debian: apt-get install python3-venv)"
    "$tools/bin/pip" install -q "maturin==$MATURIN" "ziglang==$ZIGLANG" "auditwheel==$AUDITWHEEL" ||
        { rm -rf "$tools"; fail "pip install maturin ziglang auditwheel"; }
fi
mkdir -p "$out"
rm -f "$out"/aemstep-*.whl "$out"/aemstep-*.tar.gz
# maturin finds zig through the `ziglang` module of the Python that runs it: the tools venv's.
PATH="$tools/bin:$PATH" CARGO_TARGET_DIR="$target" maturin build -q --release \
    -m python/Cargo.toml --compatibility manylinux2014 --zig --out "$out" ||
    fail "maturin build (manylinux2014, zig)"
PATH="$tools/bin:$PATH" CARGO_TARGET_DIR="$target" maturin sdist -m python/Cargo.toml --out "$out" ||
    fail "maturin sdist"
wheel=$(ls "$out"/aemstep-*.whl)
sdist=$(ls "$out"/aemstep-*.tar.gz) || fail "no sdist in $out"
[ "$(printf '%s\n' "$wheel" | wc -l)" = 1 ] || fail "expected one wheel in $out, got: $wheel"
case "$wheel" in
    *-cp39-abi3-manylinux2014_x86_64.manylinux_2_17_x86_64.whl) ;;
    *) fail "the wheel is not tagged cp39-abi3 manylinux2014: $wheel" ;;
esac
report=$("$tools/bin/auditwheel" show "$wheel" 2>&1) || { echo "$report"; fail "auditwheel show"; }
echo "$report"
flat=$(tr -s ' \n' '  ' <<<"$report")
verdict=$(grep -o 'is consistent with the following platform tag: "[^"]*"' <<<"$flat") ||
    fail "auditwheel: no platform tag"
[ "$verdict" = 'is consistent with the following platform tag: "manylinux_2_17_x86_64"' ] ||
    fail "auditwheel: the wheel is not consistent with manylinux_2_17_x86_64 ($verdict)"
printf 'wheel: %s (%s bytes)\nsdist: %s (%s bytes)\n' "$wheel" "$(stat -c %s "$wheel")" \
    "$sdist" "$(stat -c %s "$sdist")"
[ -n "$page" ] || exit 0

# The page: each CPython in a fresh venv with numpy, the wheel installed with no Rust on PATH.
norust=
IFS=: read -r -a dirs <<<"$PATH"
for d in "${dirs[@]}"; do
    [ -e "$d/cargo" ] || [ -e "$d/rustc" ] || norust="$norust:$d"
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pythons=("$(command -v python3)")
for d in $(ls -d "$HOME"/.pyenv/versions/3.* 2>/dev/null | sort -V); do
    p=$d/bin/python3
    [ -x "$p" ] || continue
    "$p" -c 'import sys; sys.exit(sys.version_info < (3, 9))' 2>/dev/null || continue
    [ "$("$p" -c 'import sys; print(sys.version)')" = "$(python3 -c 'import sys; print(sys.version)')" ] ||
        pythons+=("$p")
done
rows=
for p in "${pythons[@]}"; do
    v=$("$p" -c 'import platform; print(platform.python_version())')
    env=$work/$v
    "$p" -m venv "$env" || fail "venv of CPython $v"
    "$env/bin/pip" install -q --disable-pip-version-check "numpy>=1.21" || fail "numpy on CPython $v"
    ! PATH="$env/bin$norust" command -v cargo >/dev/null || fail "cargo on the PATH of CPython $v's venv"
    ! PATH="$env/bin$norust" command -v rustc >/dev/null || fail "rustc on the PATH of CPython $v's venv"
    t0=$(date +%s.%N)
    PATH="$env/bin$norust" "$env/bin/pip" install -q --disable-pip-version-check --no-index \
        --find-links "$out" aemstep || fail "install of the wheel on CPython $v"
    t1=$(date +%s.%N)
    # Import and one call: an undamped oscillator (m = k = 1) released from u = 1 follows cos t.
    PATH="$env/bin$norust" "$env/bin/python" -c '
import numpy as np, aemstep
one = np.ones((1, 1))
u, v, a = aemstep.linear_response(one, 0 * one, one, 0.01, p=np.zeros((101, 1)), u0=[1.0])
assert abs(u[-1, 0] - np.cos(1.0)) < 1e-4, u[-1, 0]
' || fail "import and one call on CPython $v"
    rows+=$(awk -v v="$v" -v a="$t0" -v b="$t1" 'BEGIN { printf "| `%s` | %.1f |\n", v, b - a }')$'\n'
done
mb() { awk -v n="$(stat -c %s "$1")" 'BEGIN { printf "%.1f MB", n / 1e6 }'; }
mkdir -p "$page"
cat >"$page/wheel.md" <<PAGE
# The Python wheel

Produced by \`bash scripts/wheel.sh --page docs\` (maturin $MATURIN with \`--compatibility
manylinux2014 --zig\`, zig from the \`ziglang\` package $ZIGLANG, auditwheel $AUDITWHEEL, all from
PyPI and pinned in the script). Generated page: \`python3 scripts/check_docs.py --write\` writes
it; the test command regenerates it and compares the sizes to one unit in their last digit; the
install times are host timings (this machine), not compared.

- The wheel: \`$(basename "$wheel")\`,
  $(mb "$wheel"); one file for every CPython from 3.9 on (the stable ABI) on any x86-64 Linux with glibc 2.17 or later.
- The sdist: \`$(basename "$sdist")\`, $(mb "$sdist") (building it needs Rust).
- \`auditwheel show\`: the wheel
  $verdict.
- Installed from the wheel alone (\`pip install --no-index --find-links DIR aemstep\`) into a
  fresh virtual environment of each CPython this machine has, numpy already present and no
  cargo or rustc on PATH; then imported, and one call run (a free vibration checked against
  \`cos t\`):

| CPython | install from the wheel (s, host) |
|---|---|
${rows}
Before the package is on an index: \`bash scripts/wheel.sh\` builds the wheel into
\`target/wheels/\` (\`\$CARGO_TARGET_DIR/wheels/\` if set; once, with Rust), and
\`pip install target/wheels/aemstep-*.whl\` installs it on any machine, no Rust needed; the
test command does this in its Python stage.
PAGE
echo "wrote $page/wheel.md"
