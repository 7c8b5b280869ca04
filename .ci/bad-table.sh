#!/usr/bin/env bash
# Issue #16 (item 4, defect 9): a user probe table the build cannot bake into finite values
# fails the build with one clear line naming the file, the line and the problem, and no panic
# or backtrace note. Runs the custom-bake flow of tables/README.md (examples/custom-bake with
# SPHERE_QUADRATURE_PROBE_TABLE) with a bad table; `cargo check` only runs the build script.
# Too slow for `cargo test` (a separate build of the crate), so CI runs it as a step.
set -euo pipefail
cd "$(dirname "$0")/../examples/custom-bake"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
check() {
    local table=$1 want=$2
    printf '%b' "$table" > "$dir/probe.txt"
    if SPHERE_QUADRATURE_PROBE_TABLE="$dir/probe.txt" cargo check --quiet --target-dir "$dir/target" \
        > "$dir/out.txt" 2> "$dir/err.txt"; then
        echo "a bad table built: $table"; exit 1
    fi
    grep -q -- "$want" "$dir/err.txt" || { echo "missing '$want' in:"; cat "$dir/err.txt"; exit 1; }
    # One line names the table (no dump of the build script's output).
    local lines
    lines=$(grep -c -- "$dir/probe.txt" "$dir/err.txt")
    [ "$lines" -eq 1 ] || { echo "$lines lines name the table in:"; cat "$dir/err.txt"; exit 1; }
    if grep -q -e 'panicked at' -e 'RUST_BACKTRACE' -e 'stack backtrace' "$dir/err.txt"; then
        echo "a panic or backtrace note in:"; cat "$dir/err.txt"; exit 1
    fi
    echo "ok: $(grep -m1 -- "$want" "$dir/err.txt")"
}
# σ′ = 10²⁰ baked every output as NaN before the fix.
# Cargo prints the build script's `cargo::error` as `error: sphere-quadrature@VERSION: MESSAGE`.
check '# user table\nprobe = 48 1e20 2 8 32\n' "^error: .*: $dir/probe.txt:2: sigma = 1e20 must be in"
check 'probe = 48 0.05 2 8 32\nprobe = 24 0.05 2\n' "^error: .*: $dir/probe.txt:2: N = 24 must exceed"
check 'probe = 48 0.05 2 banana\n' "^error: .*: $dir/probe.txt:1: lambda \`banana\`"
