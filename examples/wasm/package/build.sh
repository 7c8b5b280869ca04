#!/usr/bin/env bash
# Builds the package's WebAssembly modules, one per baked probe size and the layout probes'
# one, into wasm/: wasm/probe-16.wasm … wasm/probe-256.wasm and wasm/layout.wasm (from the
# crate in ../package-wasm), each shrunk by binaryen's wasm-opt -Oz, and prints their sizes.
# Needs the Rust target wasm32-unknown-unknown and `npm ci` in examples/wasm (binaryen).
#
#   examples/wasm/package/build.sh [N | layout …]     # default: 16 32 64 128 256 layout
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
crate="$here/../package-wasm"
sizes=("$@")
[ "${#sizes[@]}" -gt 0 ] || sizes=(16 32 64 128 256 layout)
mkdir -p "$here/wasm"
wasm_opt="$here/../node_modules/.bin/wasm-opt"
[ -x "$wasm_opt" ] || { echo "no $wasm_opt: run npm ci in examples/wasm" >&2; exit 1; }
# Panic locations in the modules name source files; with the checkout's and Cargo's home paths
# remapped, the modules are the same bytes wherever the repository is cloned.
root="$(cd "$here/../../.." && pwd)"
cargo_home="${CARGO_HOME:-$HOME/.cargo}"
export RUSTFLAGS="${RUSTFLAGS:-} --remap-path-prefix=$root=sphere-quadrature --remap-path-prefix=$cargo_home=cargo"
for n in "${sizes[@]}"; do
    case "$n" in
        16 | 32 | 64 | 128 | 256) feature="n$n" module="probe-$n.wasm" ;;
        layout) feature=layout module=layout.wasm ;;
        *) echo "no baked probe of size $n" >&2; exit 1 ;;
    esac
    (cd "$crate" && cargo build --release --target wasm32-unknown-unknown --features "$feature")
    # The features rustc's wasm32-unknown-unknown target enables; -Oz keeps every f32 operation
    # (the package's test compares the answers with the host's bit for bit).
    "$wasm_opt" -Oz --enable-bulk-memory --enable-sign-ext --enable-mutable-globals \
        --enable-nontrapping-float-to-int \
        "$crate/target/wasm32-unknown-unknown/release/sphere_quadrature_js.wasm" -o "$here/wasm/$module"
    echo "wasm/$module $(wc -c < "$here/wasm/$module") bytes"
done
