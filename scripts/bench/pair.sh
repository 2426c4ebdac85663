#!/usr/bin/env bash
# Two builds of a pt program side by side: which is faster, by how much.
#
#   scripts/bench/pair.sh [--serial] ROUNDS A B [-- ARGS...]
#
# Each round copies both binaries afresh (identical bytes in two files have run 3-5% apart:
# where their pages land), starts A and B at the same time, each on its own core with
# `--threads 1`, and swaps the cores every round, so that a machine whose speed drifts slows
# both alike. With --serial they run one after the other on the same core (the other idle), A
# first in odd rounds and B first in even ones: on a machine whose cores slow down unevenly
# (a shared host), short runs in many rounds then pair better than runs side by side (an A/A
# test of 60 rounds of the box at 128x128 and 64 spp: median 0.995, where side by side six
# rounds of 256x256 spread 0.87-1.39). ARGS are the program's (default: Mitsuba's Cornell box
# through the `render` example, 256x256 at 16 spp); `--threads 1 --out FILE` are added.
# Prints each round's Msamples/s and the ratio B/A, their geometric mean and median, and
# whether the two last images are the same bytes.
set -euo pipefail
source "$(dirname "$0")/common.sh"

serial=0
if [ "${1:-}" = --serial ]; then
    serial=1
    shift
fi
[ $# -ge 3 ] || { sed -n 2,17p "$0"; exit 2; }
rounds=$1 a=$2 b=$3
shift 3
[ "${1:-}" = "--" ] && shift
if [ $# -eq 0 ]; then
    # shellcheck disable=SC2046
    set -- $(box_args)
fi

sum=0
: >"$WORK/ratios"
# `run_side X CORE ARGS...`: side X (a or b) on CORE; a failure shows as a missing rate below.
run_side() {
    local x=$1 core=$2
    shift 2
    pin "$core" "$WORK/$x" "$@" --threads 1 --out "$WORK/$x.exr" >"$WORK/$x.log" 2>&1 || true
}
for i in $(seq 1 "$rounds"); do
    cp "$a" "$WORK/a" && cp "$b" "$WORK/b"
    if [ "$serial" -eq 1 ]; then
        if [ $((i % 2)) -eq 1 ]; then
            run_side a 0 "$@"
            run_side b 0 "$@"
        else
            run_side b 0 "$@"
            run_side a 0 "$@"
        fi
    else
        if [ $((i % 2)) -eq 1 ]; then ca=0 cb=1; else ca=1 cb=0; fi
        run_side a "$ca" "$@" &
        run_side b "$cb" "$@" &
        wait
    fi
    ra=$(rate "$WORK/a.log") rb=$(rate "$WORK/b.log")
    fail_unless "$ra" "$WORK/a.log" "rate (Msamples/s) from A"
    fail_unless "$rb" "$WORK/b.log" "rate (Msamples/s) from B"
    r=$(awk -v a="$ra" -v b="$rb" 'BEGIN {printf "%.4f", b / a}')
    echo "round $i: A $ra B $rb Msamples/s, B/A $r"
    sum=$(awk -v s="$sum" -v r="$r" 'BEGIN {print s + log(r)}')
    echo "$r" >>"$WORK/ratios"
done
echo "geometric mean B/A: $(awk -v s="$sum" -v n="$rounds" 'BEGIN {printf "%.4f", exp(s / n)}')"
echo "median B/A: $(median <"$WORK/ratios")"
if cmp -s "$WORK/a.exr" "$WORK/b.exr"; then
    echo "images: the same bytes"
else
    echo "images: different"
fi
