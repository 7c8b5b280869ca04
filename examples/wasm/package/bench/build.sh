#!/usr/bin/env bash
# Builds the modules that bench/throughput.mjs times: the package's own (`build.sh 16 64 256
# layout`, into wasm/) and the same crate built three other ways, each into
# target/wasm-bench/<variant>/ at the repository root (not the package's wasm/, which ships the
# plain modules), each passed through wasm-opt at the same level as rustc (-Oz or -O3), as
# build.sh passes the package's:
#   simd128      the package's profile (opt-level "z", LTO) with -C target-feature=+simd128
#   o3           opt-level 3 (LLVM's loop and SLP vectorisers run only above "s"/"z")
#   o3-simd128   opt-level 3 with -C target-feature=+simd128
#
#   examples/wasm/package/bench/build.sh
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
package="$here/.."
crate="$package/../package-wasm"
root="$(cd "$package/../../.." && pwd)"
"$package/build.sh" 16 64 256 layout
cargo_home="${CARGO_HOME:-$HOME/.cargo}"
wasm_opt="$package/../node_modules/.bin/wasm-opt"
# As build.sh: home paths remapped in the panic locations.
remap="--remap-path-prefix=$root=sphere-quadrature --remap-path-prefix=$cargo_home=cargo"
for variant in simd128 o3 o3-simd128; do
    case "$variant" in
        simd128) flags="-C target-feature=+simd128" opt=z ;;
        o3) flags="" opt=3 ;;
        o3-simd128) flags="-C target-feature=+simd128" opt=3 ;;
    esac
    out="$root/target/wasm-bench/$variant"
    build_dir="$root/target/wasm-bench/build-$variant"
    mkdir -p "$out"
    for n in 16 64 256 layout; do
        case "$n" in
            layout) feature=layout module=layout.wasm ;;
            *) feature="n$n" module="probe-$n.wasm" ;;
        esac
        (cd "$crate" && RUSTFLAGS="${RUSTFLAGS:-} $flags $remap" CARGO_PROFILE_RELEASE_OPT_LEVEL="$opt" \
            cargo build --release --target wasm32-unknown-unknown --features "$feature" --target-dir "$build_dir")
        "$wasm_opt" "-O$opt" --enable-bulk-memory --enable-sign-ext --enable-mutable-globals \
            --enable-nontrapping-float-to-int --enable-simd \
            "$build_dir/wasm32-unknown-unknown/release/sphere_quadrature_js.wasm" -o "$out/$module"
        echo "target/wasm-bench/$variant/$module $(wc -c < "$out/$module") bytes"
    done
done
