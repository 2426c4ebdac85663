#!/usr/bin/env bash
# Several builds of a pt program, every pair side by side in turn: a ranking that a drifting
# machine disturbs little.
#
#   scripts/bench/round-robin.sh ROUNDS BIN... [-- ARGS...]
#
# Each round runs every pair of the binaries at once, one per core (`--threads 1`), cores
# swapped between rounds; each binary's Msamples/s are collected over all its runs. Prints per
# binary the best, the upper quartile and the median (the best is least disturbed by a busy
# neighbour; compare medians from one call only). ARGS as for pair.sh.
set -euo pipefail
source "$(dirname "$0")/common.sh"

[ $# -ge 3 ] || { sed -n 2,10p "$0"; exit 2; }
rounds=$1
shift
bins=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    bins+=("$1")
    shift
done
[ "${1:-}" = "--" ] && shift
if [ $# -eq 0 ]; then
    # shellcheck disable=SC2046
    set -- $(box_args)
fi
n=${#bins[@]}
[ "$n" -ge 2 ] || { echo "round-robin.sh: give at least two binaries" >&2; exit 2; }

for k in $(seq 0 $((n - 1))); do
    : >"$WORK/rates$k"
    cp "${bins[$k]}" "$WORK/bin$k"
done
for r in $(seq 1 "$rounds"); do
    for i in $(seq 0 $((n - 1))); do
        for j in $(seq $((i + 1)) $((n - 1))); do
            if [ $(((r + i + j) % 2)) -eq 1 ]; then ci=0 cj=1; else ci=1 cj=0; fi
            pin "$ci" "$WORK/bin$i" "$@" --threads 1 --out "$WORK/i.exr" >"$WORK/i.log" 2>&1 &
            pin "$cj" "$WORK/bin$j" "$@" --threads 1 --out "$WORK/j.exr" >"$WORK/j.log" 2>&1 &
            wait
            rate "$WORK/i.log" >>"$WORK/rates$i"
            rate "$WORK/j.log" >>"$WORK/rates$j"
        done
    done
done
for k in $(seq 0 $((n - 1))); do
    sort -n "$WORK/rates$k" | awk -v name="${bins[$k]}" '
        NF { v[++m] = $1 }
        END {
            if (m == 0) { printf "%s: no rate printed\n", name; exit }
            median = m % 2 ? v[(m + 1) / 2] : (v[m / 2] + v[m / 2 + 1]) / 2
            printf "%s: best %.3f, upper quartile %.3f, median %.3f Msamples/s (%d runs)\n",
                name, v[m], v[int(m * 0.75 + 0.5)], median, m
        }'
done
for k in $(seq 0 $((n - 1))); do
    grep -q . "$WORK/rates$k" || exit 1
done
