#!/usr/bin/env bash
# What a dependant pays to build this crate: a scratch no_std library crate that calls
# `Probe<64, f32>::update` and `irradiance`, built as a user's own project (its own workspace
# and profiles, so this workspace's `[profile.*.build-override]` does not apply), each build
# from a cold target directory with the registry warm (fetched first). Prints the wall-clock
# seconds of its `cargo check`, its clean debug `cargo build` and its release build for
# thumbv7em-none-eabihf, each after the load average (`uptime`). With KEEP=1 the scratch
# directory stays, and `--timings` reports per unit (build script run, each crate) are in
# its target directories. It fails only when a build fails: no timing
# assertions (docs/measurements.md, "Build time of a dependant", reports measured figures).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dir=$(mktemp -d)
if [ "${KEEP:-0}" = 1 ]; then
    echo "keeping $dir"
else
    trap 'rm -rf "$dir"' EXIT
fi
mkdir -p "$dir/user/src"
cat > "$dir/user/Cargo.toml" <<TOML
[package]
name = "dependant-build"
version = "0.0.0"
edition = "2021"
publish = false

[dependencies]
sphere-quadrature = { path = "$root" }

[workspace]
TOML
cat > "$dir/user/src/lib.rs" <<'RS'
#![no_std]
use sphere_quadrature::probe::Probe;
use sphere_quadrature::Vec3;

/// One update from the samples, then the irradiance about `normal` (0 on an error).
pub fn irradiance(samples: &[f32; 64], normal: Vec3) -> f32 {
    let mut probe = Probe::<64, f32>::new();
    if probe.update(samples).is_err() {
        return 0.0;
    }
    probe.irradiance(normal).map_or(0.0, |e| e.value)
}
RS
cd "$dir/user"
# A path dependency would be compiled incrementally in debug builds; one from crates.io is not.
export CARGO_INCREMENTAL=0
rustup target add thumbv7em-none-eabihf >/dev/null 2>&1 || true
# Warm registry: resolve and download first, so the timings are of building only.
cargo fetch --quiet
timed() {
    local what=$1
    shift
    rm -rf "$dir/target"
    echo "-- $what: $* (load: $(uptime | sed 's/.*load average: //'))"
    local start end
    start=$(date +%s.%N)
    local timings=()
    [ "${KEEP:-0}" = 1 ] && timings=(--timings)
    CARGO_TARGET_DIR="$dir/target" "$@" --quiet "${timings[@]}"
    end=$(date +%s.%N)
    [ "${KEEP:-0}" = 1 ] && mv "$dir/target" "$dir/target-${what// /-}"
    awk -v w="$what" -v a="$start" -v b="$end" 'BEGIN { printf "%s: %.1f s\n", w, b - a }'
}
timed "cargo check" cargo check
timed "clean debug build" cargo build
timed "release build, thumbv7em-none-eabihf" cargo build --release --target thumbv7em-none-eabihf
