#!/usr/bin/env bash
# The reports in docs/ are what their benchmarks write now: reruns each benchmark in full
# (the maps of examples/envmaps/, as `--out docs` would) into target/docs-current/ and
# compares the Markdown with docs/, ignoring only what a rerun cannot reproduce: wall and CPU
# times ("12 s", "3.1 s wall"), the --out folder and --csv file of the quoted command, and
# the `## Cost` sections of host timings. A stale report fails with the command that regenerates it.
# Each run also writes its CSV rows (`--csv target/docs-current/NAME/rows.csv`), and its plot
# beside the report: .ci/run checks those too.
# Usage: .ci/docs-current.sh [BENCHMARK...] (default: all of them; about 22 min on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."
out=target/docs-current
mkdir -p "$out"

normalise() {
    sed -E -e 's/--out [^ `)]+/--out DIR/g' -e 's/ --csv [^ `)]+//g' \
        -e 's/[0-9]+(\.[0-9]+)? s\b/T s/g' "$1" \
        | awk '/^## Cost/ { skip = 1; next } /^## / { skip = 0 } !skip'
}

# check NAME FILE ARGS...: `cargo eval NAME -- ARGS --out DIR --csv DIR/rows.csv` must write docs/FILE.
check() {
    local name=$1 file=$2
    shift 2
    local dir="$out/${file%.md}"
    local start=$SECONDS
    cargo eval "$name" -- "$@" --out "$dir" --csv "$dir/rows.csv" > "$dir.log" 2>&1 \
        || { echo "cargo eval $name -- $* failed:"; tail -20 "$dir.log"; exit 1; }
    if ! diff <(normalise "docs/$file") <(normalise "$dir/$file") > "$dir.diff"; then
        echo "docs/$file is not what \`cargo eval $name -- ${*:+$* }--out docs\` writes now:"
        head -40 "$dir.diff"
        exit 1
    fi
    echo "ok: docs/$file is current (cargo eval $name${*:+ -- $*}: $((SECONDS - start)) s)"
}

all="precision lookup_precision temporal room sensors missing probe_trust accuracy glossy footprint footprint_raw renderer"
# shellcheck disable=SC2048,SC2086 # the names split on spaces
for b in ${*:-$all}; do
    case $b in
        footprint) check footprint footprint.md ;;
        footprint_raw) check footprint footprint_raw.md --tier raw ;;
        *) check "$b" "$b.md" ;;
    esac
done
