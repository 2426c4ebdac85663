#!/usr/bin/env bash
# pt-accel against Embree 4 on the same rays (the speed issue's goal 1), side by side.
#
#   scripts/bench/against-embree.sh ROUNDS MESH DIR [RAY_QUERIES]
#
# RAY_QUERIES defaults to target/release/examples/ray_queries (`cargo build --release -p
# pt-accel --example ray_queries`); MESH and DIR as for rays-pair.sh. Embree is the anchors'
# `embree-direct` (../shared/anchors/README.md says how to build it; PT_EMBREE_DIRECT names
# another path). Each round runs pt (eight rays per call, one thread) and Embree (one
# `rtcIntersect1`/`rtcOccluded1` per ray, MEDIUM quality, not robust) at once, one per core,
# swapped every round; prints pt/Embree for closest and any-hit queries of the camera rays
# ("primary") and the incoherent rays, then their geometric means. Embree also times other
# configurations after its MEDIUM row, while pt's run may already be over: each round's
# MEDIUM rows overlap pt's run, the rest do not matter.
set -euo pipefail
source "$(dirname "$0")/common.sh"

[ $# -ge 3 ] || { sed -n 2,14p "$0"; exit 2; }
rounds=$1 mesh=$2 dir=$3
pt="${4:-$ROOT/target/release/examples/ray_queries}"
[ -x "$EMBREE" ] || { echo "against-embree.sh: no embree-direct at $EMBREE" >&2; exit 2; }
ray_sets "$pt" "$mesh" "$dir"

: >"$WORK/ratios"
for i in $(seq 1 "$rounds"); do
    if [ $((i % 2)) -eq 1 ]; then ca=0 cb=1; else ca=1 cb=0; fi
    pin "$ca" "$pt" "$mesh" "$dir" 5 eight-lanes 1t read >"$WORK/pt.log" 2>&1 &
    pin "$cb" "$EMBREE" "$dir" 5 >"$WORK/embree.log" 2>&1 &
    wait
    rp=$(table_rates "$WORK/pt.log" '[A-Za-z]+')
    re=$(table_rates "$WORK/embree.log" MEDIUM)
    paste -d' ' <(echo "$rp") <(echo "$re") |
        awk '{printf "%s %.4f %.4f %s %s %s %s\n", $1, $2 / $5, $3 / $6, $2, $5, $3, $6}' \
            >"$WORK/round"
    cat "$WORK/round" >>"$WORK/ratios"
    echo "round $i: $(awk '{printf "%s closest %s (%s/%s) any hit %s (%s/%s); ",
        $1, $2, $4, $5, $3, $6, $7}' "$WORK/round")"
done
ratio_means pt/Embree "$WORK/ratios"
