#!/usr/bin/env bash
# pt-accel against Embree 4 on the same rays (the speed issue's goal 1), side by side or in turn.
#
#   scripts/bench/against-embree.sh [--alternate] ROUNDS MESH DIR [RAY_QUERIES]
#
# RAY_QUERIES defaults to target/release/examples/ray_queries (`cargo build --release -p
# pt-accel --example ray_queries`); MESH and DIR as for rays-pair.sh. Embree is the anchors'
# `embree-direct` (../shared/anchors/README.md says how to build it; PT_EMBREE_DIRECT names
# another path). Each round runs pt (eight rays per call, one thread) and Embree (one
# `rtcIntersect1`/`rtcOccluded1` per ray, MEDIUM quality, not robust) at once, one per core,
# swapped every round; prints pt/Embree for closest and any-hit queries of the camera rays
# ("primary") and the incoherent rays, then their geometric means and medians. Embree also times
# other configurations after its MEDIUM row, while pt's run may already be over: each round's
# MEDIUM rows overlap pt's run, the rest do not matter. With --alternate the two run one after
# the other on the same core (the other core idle), pt first in odd rounds and Embree first in
# even ones: neither then shares the last-level cache with the other, whose phases (pt's run is
# a few seconds, Embree's several configurations fifteen) overlap differently every round; on
# the dragon that moved the any-hit ratio from 0.85x side by side to 0.98-1.00x in turn.
set -euo pipefail
source "$(dirname "$0")/common.sh"

alternate=0
if [ "${1:-}" = --alternate ]; then
    alternate=1
    shift
fi
[ $# -ge 3 ] || { sed -n 2,18p "$0"; exit 2; }
rounds=$1 mesh=$2 dir=$3
pt="${4:-$ROOT/target/release/examples/ray_queries}"
[ -x "$EMBREE" ] || { echo "against-embree.sh: no embree-direct at $EMBREE" >&2; exit 2; }
ray_sets "$pt" "$mesh" "$dir"

# A failing run is reported below by table_rates, with its output's last lines.
run_pt() { pin "$1" "$pt" "$mesh" "$dir" 5 eight-lanes 1t read >"$WORK/pt.log" 2>&1 || true; }
run_embree() { pin "$1" "$EMBREE" "$dir" 5 >"$WORK/embree.log" 2>&1 || true; }
: >"$WORK/ratios"
for i in $(seq 1 "$rounds"); do
    if [ "$alternate" -eq 1 ]; then
        if [ $((i % 2)) -eq 1 ]; then run_pt 0; run_embree 0; else run_embree 0; run_pt 0; fi
    else
        if [ $((i % 2)) -eq 1 ]; then ca=0 cb=1; else ca=1 cb=0; fi
        run_pt "$ca" &
        run_embree "$cb" &
        wait
    fi
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
