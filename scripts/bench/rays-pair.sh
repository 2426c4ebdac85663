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
# queries of the camera rays ("primary") and the incoherent rays, then their geometric means.
set -euo pipefail
source "$(dirname "$0")/common.sh"

[ $# -eq 5 ] || { sed -n 2,11p "$0"; exit 2; }
rounds=$1 a=$2 b=$3 mesh=$4 dir=$5
if [ ! -e "$dir/tris.npy" ]; then
    mkdir -p "$dir"
    "$a" "$mesh" "$dir" 1 eight-lanes 1t >/dev/null
fi

# `rates LOG`: "set closest any-hit" per ray set, from a markdown table's 1T columns.
rates() {
    grep -E '^\| [^|]+\| [^|]+\| (primary|incoherent) ' "$1" | awk -F'|' '{print $4, $5, $7}' |
        awk '{print $1, $2, $3}' | head -2
}

: >"$WORK/ratios"
for i in $(seq 1 "$rounds"); do
    if [ $((i % 2)) -eq 1 ]; then ca=0 cb=1; else ca=1 cb=0; fi
    cp "$a" "$WORK/a" && cp "$b" "$WORK/b"
    pin "$ca" "$WORK/a" "$mesh" "$dir" 5 eight-lanes 1t read >"$WORK/a.log" 2>&1 &
    pin "$cb" "$WORK/b" "$mesh" "$dir" 5 eight-lanes 1t read >"$WORK/b.log" 2>&1 &
    wait
    paste -d' ' <(rates "$WORK/a.log") <(rates "$WORK/b.log") |
        awk '{printf "%s %.4f %.4f\n", $1, $5 / $2, $6 / $3}' >"$WORK/round"
    cat "$WORK/round" >>"$WORK/ratios"
    echo "round $i: $(awk '{printf "%s closest %s any hit %s; ", $1, $2, $3}' "$WORK/round")"
done
awk '{c[$1] += log($2); o[$1] += log($3); n[$1]++}
    END {for (s in n) printf "geometric mean B/A, %s: closest %.4f, any hit %.4f\n",
        s, exp(c[s] / n[s]), exp(o[s] / n[s])}' "$WORK/ratios"
