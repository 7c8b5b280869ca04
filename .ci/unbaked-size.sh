#!/usr/bin/env bash
# The compile error for a size the build did not bake lists the sizes (and pairs) this build
# baked, for the renderer (`bmc::BakedSize`), its fixed-point form
# (`fixed_point::FixedSize`) and the probe (`probe::ProbeSize`), also when user tables
# (SPHERE_QUADRATURE_BMC_TABLE, SPHERE_QUADRATURE_PROBE_TABLE) bake other sizes than the
# shipped ones. Compiles a scratch crate that asks for N = 64 against tables of N = 24 and 48.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/user/src"
cat > "$dir/user/Cargo.toml" <<TOML
[package]
name = "unbaked-size"
version = "0.0.0"
edition = "2021"
publish = false

[dependencies]
sphere-quadrature = { path = "$root", features = ["fixed"] }

[workspace]
TOML
cat > "$dir/user/src/main.rs" <<'RS'
use sphere_quadrature::bmc::footprint::{FootprintRenderer, Phong};
use sphere_quadrature::{bmc::GlossyRenderer, bmc::Renderer, fixed_point::BmcFixed, probe::Probe};

fn main() {
    let _ = Renderer::<64>::new();
    let _ = BmcFixed::<64>::weights_q31();
    let _ = Probe::<64>::new();
    let _ = GlossyRenderer::<64, 20>::new();
    let _ = FootprintRenderer::<48, Phong<20>>::new();
}
RS
printf 'set = 24 0.9051 0.1 cosine\nset = 48 0.9051 0.1 cosine\n' > "$dir/bmc.txt"
printf 'probe = 24 0.05 2\nprobe = 48 0.05 2\n' > "$dir/probe.txt"
if (cd "$dir/user" && SPHERE_QUADRATURE_BMC_TABLE="$dir/bmc.txt" \
    SPHERE_QUADRATURE_PROBE_TABLE="$dir/probe.txt" cargo check --quiet \
    --target-dir "$dir/target" > "$dir/out.txt" 2> "$dir/err.txt"); then
    echo "N = 64 compiled against tables of N = 24 and 48"; exit 1
fi
for want in "no Bayesian Monte Carlo weights are baked for \`Size<64>\`" \
    "no fixed-point Bayesian Monte Carlo weights are baked for \`Size<64>\`" \
    "no Bayesian Monte Carlo probe family is baked for \`Size<64>\`"; do
    grep -qF -- "$want" "$dir/err.txt" || { echo "missing '$want' in:"; cat "$dir/err.txt"; exit 1; }
done
notes=$(grep -c "the baked sizes are N = 24, 48 " "$dir/err.txt" || true)
[ "$notes" -ge 3 ] || { echo "$notes notes list N = 24, 48 in:"; cat "$dir/err.txt"; exit 1; }
# The probe's (N, footprint) pairs of this build, and the options of the glossy and footprint
# renderers (the shipped tables).
for want in "the baked (N, footprint) pairs are (24, Point), (48, Point) " \
    "the baked (N, e) pairs are (16, 10), (16, 50)" \
    "the baked sets are Diffuse at N = 16, 32, 64"; do
    grep -qF -- "$want" "$dir/err.txt" || { echo "missing '$want' in:"; cat "$dir/err.txt"; exit 1; }
done
if grep "baked sizes" "$dir/err.txt" | grep -q "16, 32"; then
    echo "a note lists the shipped sizes:"; cat "$dir/err.txt"; exit 1
fi
echo "ok: $notes compile-error notes list this build's sizes, N = 24, 48"
