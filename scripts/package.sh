#!/usr/bin/env bash
# The crate as a user gets it: `cargo publish --dry-run` (packages, builds the package alone,
# stops before uploading) must be clean, and docs/package.md must state what it packaged.
#   bash scripts/package.sh           check (the test command runs this)
#   bash scripts/package.sh --write   regenerate docs/package.md
# Clean means no warning but cargo's notes that repository-only targets (tests, benches,
# examples) are left out of the package, which the `include` list in Cargo.toml does on purpose.
set -euo pipefail
cd "$(dirname "$0")/.."
fail() { printf '\nFAILED: %s\n' "$*" >&2; exit 1; }

log=$(mktemp)
trap 'rm -f "$log"' EXIT
# --allow-dirty: the check is about what the package holds and whether it builds alone, so it
# also runs in a tree with uncommitted work.
cargo publish -p aemstep --dry-run --allow-dirty >"$log" 2>&1 || { cat "$log"; fail "cargo publish --dry-run"; }
other=$(grep '^warning:' "$log" |
    grep -v -E '^warning: ignoring (test|benchmark|example|binary) `[^`]+` as `[^`]+` is not included in the published package$' |
    grep -v '^warning: aborting upload due to dry run$' || true)
[ -z "$other" ] || { cat "$log"; fail "cargo publish --dry-run warned: $other"; }
packaged=$(grep -o 'Packaged [0-9]* files, [^)]*)' "$log") || fail "no 'Packaged' line in cargo's output"
features=$(cargo metadata --no-deps --format-version 1 |
    python3 -c 'import json,sys; m=json.load(sys.stdin); p=[p for p in m["packages"] if p["name"]=="aemstep"][0]; print(", ".join("`%s`" % f for f in sorted(p["features"]) if f != "default"))')

page=$(cat <<PAGE
# The published package

Produced by \`bash scripts/package.sh --write\` (\`cargo publish -p aemstep --dry-run\`); the test
command re-runs it and fails when a figure here changes or cargo warns.

- ${packaged}: the library (\`src/\`), the pages of \`docs/\` with their figures, \`README.md\`,
  \`CHANGELOG.md\` and both licence files; tests, examples, scenes, data, firmware, generators,
  benchmarks and fuzzing stay in the repository (the \`include\` list in \`Cargo.toml\`).
- Public features: ${features} (none by default). \`std\` adds the host-only
  \`spectrum::batch\`; \`defmt\` adds \`defmt::Format\` to the public types. The firmware's crates
  (cortex-m, cortex-m-rt, semihosting) are dependencies of the \`examples/firmware/\` workspace member,
  never of the library.
- docs.rs builds every feature with \`--cfg docsrs\`, which labels each feature-gated item with
  the feature it needs.
PAGE
)
if [ "${1:-}" = "--write" ]; then
    # docs/package.md is itself in the package: write until the figures it states are those
    # of the package that holds it.
    if [ "${AEMSTEP_PACKAGE_PASS:-1}" -lt 4 ] && ! diff -q <(printf '%s\n' "$page") docs/package.md >/dev/null 2>&1; then
        printf '%s\n' "$page" >docs/package.md
        AEMSTEP_PACKAGE_PASS=$((${AEMSTEP_PACKAGE_PASS:-1} + 1)) exec bash "$0" --write
    fi
    diff -q <(printf '%s\n' "$page") docs/package.md >/dev/null || fail "docs/package.md did not settle"
    echo "docs/package.md states: $packaged"
else
    diff <(printf '%s\n' "$page") docs/package.md ||
        fail "docs/package.md is stale: bash scripts/package.sh --write"
    echo "package clean: $packaged; features: $features"
fi
