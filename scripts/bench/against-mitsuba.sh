#!/usr/bin/env bash
# pt against Mitsuba 3 on Mitsuba's Cornell box (the speed issue's goal 2), alternating.
#
#   scripts/bench/against-mitsuba.sh RUNS SPP [RENDER]
#
# RENDER defaults to target/release/examples/render (`cargo build --release --example
# render`). Each run renders the box at 256x256 and SPP samples per pixel with Mitsuba's
# `llvm_ad_rgb` variant and its best sampler on this scene (multijitter), then with pt, both on
# every core, one after the other; pt's depth 7 is Mitsuba's max_depth 8 (camera.txt). Prints
# each pair's Msamples/s and throughput ratio pt/Mitsuba, the relative MSE of its two images
# against the anchors' 8192-spp reference, and its efficiency ratio (efficiency = 1 / (relMSE x
# seconds), the seconds taken from the rates). Run i renders with seed i in both (pt's
# `--seed`, Mitsuba's MI_SEED), so that the error is sampled afresh each run; at the end, the
# mean relMSE of each and the efficiency ratio of the means.
set -euo pipefail
source "$(dirname "$0")/common.sh"

[ $# -ge 2 ] || { sed -n 2,14p "$0"; exit 2; }
runs=$1 spp=$2
render="${3:-$ROOT/target/release/examples/render}"
[ -x "$PY" ] || { echo "against-mitsuba.sh: no anchors' python at $PY (run setup.sh)" >&2; exit 2; }

: >"$WORK/pairs"
ref="$ANCHORS/mitsuba/cbox_ref_8192_256.exr"
relmse() {
    local e
    e=$("$PY" "$ANCHORS/imgcmp.py" relmse "$1" "$ref" | tail -1)
    awk -v e="$e" 'BEGIN {exit !(e + 0 > 0)}' ||
        { echo "against-mitsuba.sh: relMSE '$e' of $1 is not a positive number" >&2; exit 1; }
    echo "$e"
}
for i in $(seq 1 "$runs"); do
    MI_SEED=$i MI_SAMPLER=multijitter "$PY" "$ANCHORS/mitsuba/cbox.py" render "$spp" 256 \
        "$WORK/mi.exr" >"$WORK/mi.log" 2>&1
    # shellcheck disable=SC2046
    "$render" "$ANCHORS/mitsuba/cbox.obj" $(cat "$ANCHORS/mitsuba/camera.txt") \
        --size 256x256 --spp "$spp" --seed "$i" --out "$WORK/pt.exr" >"$WORK/pt.log" 2>&1
    m=$(rate "$WORK/mi.log") p=$(rate "$WORK/pt.log")
    fail_unless "$m" "$WORK/mi.log" "rate (Msamples/s) from Mitsuba"
    fail_unless "$p" "$WORK/pt.log" "rate (Msamples/s) from pt"
    em=$(relmse "$WORK/mi.exr")
    ep=$(relmse "$WORK/pt.exr")
    echo "$p $m $ep $em" >>"$WORK/pairs"
    awk -v p="$p" -v m="$m" -v ep="$ep" -v em="$em" -v i="$i" 'BEGIN {
        f = "run %d: pt %s Msamples/s, Mitsuba %s, pt/Mitsuba %.3f; "
        f = f "relMSE pt %s, Mitsuba %s; efficiency pt/Mitsuba %.3f\n"
        printf f, i, p, m, p / m, ep, em, (p / ep) / (m / em)
    }'
done
awk '{p += $1; m += $2; ep += $3; em += $4} END {
    n = NR
    f = "means: pt %.3f Msamples/s, Mitsuba %.3f, pt/Mitsuba %.3f; "
    f = f "relMSE pt %.4g, Mitsuba %.4g; efficiency pt/Mitsuba %.3f\n"
    printf f, p / n, m / n, p / m, ep / n, em / n, (p / ep) / (m / em)
}' "$WORK/pairs"
