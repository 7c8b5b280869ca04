#!/usr/bin/env bash
# Flash cost of single calls on the Cortex-M4 (release, LTO): builds
# examples/cortex-m4/src/bin/flash.rs once per case and once per base case, and prints
# "# flash KEY N=n CODE DATA": the growth of `.text` (CODE) and of `.rodata` + `.data` (DATA)
# from the base case to the case, in bytes. `cargo eval doc_numbers` checks the docs against
# these lines. Usage: .ci/m4-flash.sh > target/ci/m4-flash.txt
set -euo pipefail
cd "$(dirname "$0")/../examples/cortex-m4"
elf=target/thumbv7em-none-eabihf/release/flash

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

declare -A code data
measure() {
    local key=$1
    [ -n "${code[$key]:-}" ] && return
    if [ "$key" = none ]; then
        env -u SQ_FLASH cargo build --release --quiet --bin flash
    else
        SQ_FLASH=$key cargo build --release --quiet --bin flash
    fi
    # `size -A`: "section size addr" rows.
    code[$key]=$(size -A "$elf" | awk '$1 == ".text" { print $2 }')
    data[$key]=$(size -A "$elf" | awk '$1 == ".rodata" || $1 == ".data" { s += $2 } END { print s }')
}

while read -r key base n; do
    [ -n "$key" ] || continue
    measure "$base"
    measure "$key"
    case $n in *=*) size=$n ;; *) size=N=$n ;; esac
    echo "# flash $key $size $((code[$key] - code[$base])) $((data[$key] - data[$base]))"
done <<< "$cases"
