#!/usr/bin/env bash
# Two builds of a pt program side by side: which is faster, by how much.
#
#   scripts/bench/pair.sh ROUNDS A B [-- ARGS...]
#
# Each round copies both binaries afresh (identical bytes in two files have run 3-5% apart:
# where their pages land), starts A and B at the same time, each on its own core with
# `--threads 1`, and swaps the cores every round, so that a machine whose speed drifts slows
# both alike. ARGS are the program's (default: Mitsuba's Cornell box through the `render`
# example, 256x256 at 16 spp); `--threads 1 --out FILE` are added. Prints each round's
# Msamples/s and the ratio B/A, their geometric mean and median, and whether the two last
# images are the same bytes.
set -euo pipefail
source "$(dirname "$0")/common.sh"

[ $# -ge 3 ] || { sed -n 2,12p "$0"; exit 2; }
rounds=$1 a=$2 b=$3
shift 3
[ "${1:-}" = "--" ] && shift
if [ $# -eq 0 ]; then
    # shellcheck disable=SC2046
    set -- $(box_args)
fi

sum=0
: >"$WORK/ratios"
for i in $(seq 1 "$rounds"); do
    if [ $((i % 2)) -eq 1 ]; then ca=0 cb=1; else ca=1 cb=0; fi
    cp "$a" "$WORK/a" && cp "$b" "$WORK/b"
    pin "$ca" "$WORK/a" "$@" --threads 1 --out "$WORK/a.exr" >"$WORK/a.log" 2>&1 &
    pin "$cb" "$WORK/b" "$@" --threads 1 --out "$WORK/b.exr" >"$WORK/b.log" 2>&1 &
    wait
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
