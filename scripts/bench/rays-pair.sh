#!/usr/bin/env bash
# Two builds of pt-accel's `ray_queries` on the same rays, side by side.
#
#   scripts/bench/rays-pair.sh ROUNDS A B MESH DIR
#
# A and B are `ray_queries` binaries (`cargo build --release -p pt-accel --example
# ray_queries`); MESH is a path under PT_ASSETS_DIR (meshes/stanford-bunny.obj,
# meshes/dragon_vrip_res2.binary.ply); DIR holds the ray sets, written by A on the first call.
# Each round runs both at once, one per core, swapped every round, eight rays per call and
# one thread (`MESH DIR 5 eight-lanes 1t read`), and prints B/A for closest and any-hit
# queries of the camera rays ("primary") and the incoherent rays, then their geometric means
# and medians.
set -euo pipefail
source "$(dirname "$0")/common.sh"

[ $# -eq 5 ] || { sed -n 2,12p "$0"; exit 2; }
rounds=$1 a=$2 b=$3 mesh=$4 dir=$5
ray_sets "$a" "$mesh" "$dir"

: >"$WORK/ratios"
for i in $(seq 1 "$rounds"); do
    if [ $((i % 2)) -eq 1 ]; then ca=0 cb=1; else ca=1 cb=0; fi
    cp "$a" "$WORK/a" && cp "$b" "$WORK/b"
    pin "$ca" "$WORK/a" "$mesh" "$dir" 5 eight-lanes 1t read >"$WORK/a.log" 2>&1 &
    pin "$cb" "$WORK/b" "$mesh" "$dir" 5 eight-lanes 1t read >"$WORK/b.log" 2>&1 &
    wait
    ra=$(table_rates "$WORK/a.log" '[^|]+')
    rb=$(table_rates "$WORK/b.log" '[^|]+')
    paste -d' ' <(echo "$ra") <(echo "$rb") |
        awk '{printf "%s %.4f %.4f\n", $1, $5 / $2, $6 / $3}' >"$WORK/round"
    cat "$WORK/round" >>"$WORK/ratios"
    echo "round $i: $(awk '{printf "%s closest %s any hit %s; ", $1, $2, $3}' "$WORK/round")"
done
ratio_means B/A "$WORK/ratios"
