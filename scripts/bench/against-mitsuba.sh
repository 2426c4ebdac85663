#!/usr/bin/env bash
# pt against Mitsuba 3 on Mitsuba's Cornell box (the speed issue's goal 2), alternating.
#
#   scripts/bench/against-mitsuba.sh RUNS SPP [RENDER]
#
# RENDER defaults to target/release/examples/render (`cargo build --release --example
# render`). Each run renders the box at 256x256 and SPP samples per pixel with Mitsuba's
# `llvm_ad_rgb` variant and its best sampler on this scene (multijitter), then with pt, both on
# every core, one after the other; pt's depth 7 is Mitsuba's max_depth 8 (camera.txt). Prints
# each pair's Msamples/s and throughput ratio pt/Mitsuba; at the end the relative MSE of the
# last two images against the anchors' 8192-spp reference, and each pair's efficiency ratio
# (efficiency = 1 / (relMSE x seconds), the seconds taken from the rates).
set -euo pipefail
source "$(dirname "$0")/common.sh"

[ $# -ge 2 ] || { sed -n 2,12p "$0"; exit 2; }
runs=$1 spp=$2
render="${3:-$ROOT/target/release/examples/render}"
[ -x "$PY" ] || { echo "against-mitsuba.sh: no anchors' python at $PY (run setup.sh)" >&2; exit 2; }

: >"$WORK/pairs"
for i in $(seq 1 "$runs"); do
    MI_SAMPLER=multijitter "$PY" "$ANCHORS/mitsuba/cbox.py" render "$spp" 256 "$WORK/mi.exr" \
        >"$WORK/mi.log" 2>&1
    # shellcheck disable=SC2046
    "$render" "$ANCHORS/mitsuba/cbox.obj" $(cat "$ANCHORS/mitsuba/camera.txt") \
        --size 256x256 --spp "$spp" --out "$WORK/pt.exr" >"$WORK/pt.log" 2>&1
    m=$(rate "$WORK/mi.log") p=$(rate "$WORK/pt.log")
    fail_unless "$m" "$WORK/mi.log" "rate (Msamples/s) from Mitsuba"
    fail_unless "$p" "$WORK/pt.log" "rate (Msamples/s) from pt"
    echo "$p $m" >>"$WORK/pairs"
    echo "run $i: pt $p Msamples/s, Mitsuba $m, pt/Mitsuba $(awk -v p="$p" -v m="$m" \
        'BEGIN {printf "%.3f", p / m}')"
done
ref="$ANCHORS/mitsuba/cbox_ref_8192_256.exr"
ept=$("$PY" "$ANCHORS/imgcmp.py" relmse "$WORK/pt.exr" "$ref" | tail -1)
emi=$("$PY" "$ANCHORS/imgcmp.py" relmse "$WORK/mi.exr" "$ref" | tail -1)
for e in "$ept" "$emi"; do
    awk -v e="$e" 'BEGIN {exit !(e + 0 > 0)}' ||
        { echo "against-mitsuba.sh: relMSE '$e' is not a positive number" >&2; exit 1; }
done
echo "relMSE: pt $ept, Mitsuba $emi"
awk -v ep="$ept" -v em="$emi" '{printf "efficiency pt/Mitsuba, run %d: %.3f\n", NR,
    ($1 / ep) / ($2 / em)}' "$WORK/pairs"
