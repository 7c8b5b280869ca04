#!/usr/bin/env bash
# Flash cost of single calls on the Cortex-M4 (release, LTO): builds
# examples/cortex-m4/src/bin/flash.rs once per case and once per base case, and prints
# "# flash KEY N=n CODE DATA": the growth of `.text` (CODE) and of `.rodata` + `.data` (DATA)
# from the base case to the case, in bytes. `cargo writer doc_numbers` checks the docs against
# these lines. Usage: .ci/m4-flash.sh > target/ci/m4-flash.txt
set -euo pipefail
cd "$(dirname "$0")/../examples/cortex-m4"

# KEY BASE N: the case, the case it is measured from ("none": nothing), the size it uses
# (a number of points N, or K=k sensors).
cases="
sf_points none 64
qmc_irradiance none 64
qmc_estimate_from_samples none 64
nearest_index none 256
renderer_w_dot_y none 64
glossy_renderer_estimate none 64
probe_new none 64
probe_update probe_new 64
probe_update_one_member probe_new 64
probe_irradiance probe_new 64
cosine_weighted_average probe_new 64
probe_glossy probe_new 64
probe_glossy_variance probe_new 64
probe_phong probe_new 64
probe_phong_variance probe_new 64
probe_radiance_sh probe_new 64
probe_radiance_sh_variance probe_new 64
probe_sh_irradiance none 64
probe_masked_new none 64
probe_masked_update probe_masked_new 64
layout_new none K=6
layout_update layout_new K=6
layout_irradiance layout_new K=6
layout_irradiance_variance layout_new K=6
sg_clamped_cosine_fraction none 1
sg_hemispherical_fraction none 1
"

# Every case and base, once each, in order of first use.
keys=()
declare -A seen
while read -r key base _; do
    [ -n "$key" ] || continue
    for k in "$base" "$key"; do
        [ -n "${seen[$k]:-}" ] || { keys+=("$k"); seen[$k]=1; }
    done
done <<< "$cases"

# measure TARGET_DIR KEY...: builds each case in its own target directory and prints
# "KEY CODE DATA" for each, in bytes.
measure() {
    local dir=$1 key elf
    shift
    elf=$dir/thumbv7em-none-eabihf/release/flash
    for key in "$@"; do
        if [ "$key" = none ]; then
            env -u SQ_FLASH CARGO_TARGET_DIR="$dir" cargo build --release --quiet --bin flash
        else
            SQ_FLASH=$key CARGO_TARGET_DIR="$dir" cargo build --release --quiet --bin flash
        fi
        # `size -A`: "section size addr" rows.
        echo "$key $(size -A "$elf" | awk '$1 == ".text" { print $2 }') $(size -A "$elf" \
            | awk '$1 == ".rodata" || $1 == ".data" { s += $2 } END { print s }')"
    done
}

# The builds (one LTO link each, mostly on one core) alternate between two target
# directories, two at a time.
even=() odd=()
for i in "${!keys[@]}"; do
    if [ $((i % 2)) = 0 ]; then even+=("${keys[$i]}"); else odd+=("${keys[$i]}"); fi
done
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
measure target/flash-a "${even[@]}" > "$out/a" &
a=$!
measure target/flash-b "${odd[@]}" > "$out/b" &
b=$!
wait "$a"
wait "$b"

declare -A code data
while read -r key c d; do
    code[$key]=$c data[$key]=$d
done < <(cat "$out/a" "$out/b")

while read -r key base n; do
    [ -n "$key" ] || continue
    case $n in *=*) size=$n ;; *) size=N=$n ;; esac
    echo "# flash $key $size $((code[$key] - code[$base])) $((data[$key] - data[$base]))"
done <<< "$cases"
