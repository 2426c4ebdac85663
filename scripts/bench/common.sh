# Shared by the scripts in this folder (sourced, not run).
#
# Where the anchors live and how to run them (../shared/anchors/README.md): override with
# PT_ANCHORS, PT_ANCHORS_PY and PT_EMBREE_DIRECT.
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
ANCHORS="${PT_ANCHORS:-$ROOT/../shared/anchors}"
PY="${PT_ANCHORS_PY:-$HOME/.cache/pt-anchors/venv/bin/python}"
EMBREE="${PT_EMBREE_DIRECT:-$HOME/.cache/pt-anchors/embree-direct/release/embree-direct}"
if [ -z "${PT_ASSETS_DIR:-}" ] && [ -d "$ROOT/../shared/assets" ]; then
    PT_ASSETS_DIR="$(cd "$ROOT/../shared/assets" && pwd)"
    export PT_ASSETS_DIR
fi

# A scratch folder of our own, removed on exit.
WORK="$(mktemp -d "${TMPDIR:-/tmp}/pt-bench.XXXXXX")"
trap 'rm -rf "$WORK"' EXIT

# `pin CORE CMD...`: run CMD on one core where `taskset` exists (the two sides of a pair then
# run on different cores, swapped every round), unpinned elsewhere.
pin() {
    local core=$1
    shift
    if command -v taskset >/dev/null 2>&1 && [ "$(nproc)" -ge 2 ]; then
        taskset -c "$core" "$@"
    else
        "$@"
    fi
}

# `rate FILE`: the last "N Msamples/s" a render printed to FILE.
rate() {
    { grep -o '[0-9.]* Msamples/s' "$1" || true; } | tail -1 | awk '{print $1}'
}

# `fail_unless VALUE LOG WHAT`: stop with a message naming WHAT and LOG's last lines when
# VALUE is empty (a program that failed or printed no rate).
fail_unless() {
    if [ -z "$1" ]; then
        echo "$(basename "$0"): no $3 in the output of a run; its last lines:" >&2
        tail -5 "$2" >&2
        exit 1
    fi
}

# The default scene: Mitsuba's Cornell box at 256x256 (the speed issue's yardstick).
box_args() {
    echo "$ANCHORS/mitsuba/cbox.obj $(cat "$ANCHORS/mitsuba/camera.txt") --size 256x256 --spp 16"
}

# `ray_sets RAY_QUERIES MESH DIR`: write the ray sets into DIR with pt-accel's `ray_queries`
# unless DIR holds them already.
ray_sets() {
    if [ ! -e "$3/tris.npy" ]; then
        mkdir -p "$3"
        "$1" "$2" "$3" 1 eight-lanes 1t >/dev/null
    fi
}

# `table_rates LOG ROW`: "set closest any-hit" per ray set (primary, incoherent) from the
# markdown table rows of LOG whose first column matches the pattern ROW, one-thread columns.
table_rates() {
    local rows
    rows=$({ grep -E "^\| $2 \| [^|]+\| (primary|incoherent) " "$1" || true; } |
        awk -F'|' '{print $4, $5, $7}' | awk '$2 > 0 && $3 > 0 {print $1, $2, $3}' | head -2)
    [ "$(echo "$rows" | grep -c .)" -eq 2 ] || rows=""
    fail_unless "$rows" "$1" "table of rates for both ray sets"
    echo "$rows"
}

# `ratio_means WHAT FILE`: per ray set, the geometric means of FILE's lines "set closest
# any-hit" (ratios), labelled WHAT, then their medians (the middle round, or the mean of the
# middle two), which one round of a noisy hour moves less.
ratio_means() {
    awk -v what="$1" '{c[$1] += log($2); o[$1] += log($3); n[$1]++}
        END {for (s in n) printf "geometric mean %s, %s: closest %.4f, any hit %.4f\n",
            what, s, exp(c[s] / n[s]), exp(o[s] / n[s])}' "$2"
    local set
    for set in $(awk '{print $1}' "$2" | sort -u); do
        printf 'median %s, %s: closest %s, any hit %s\n' "$1" "$set" \
            "$(awk -v s="$set" '$1 == s {print $2}' "$2" | median)" \
            "$(awk -v s="$set" '$1 == s {print $3}' "$2" | median)"
    done
}

# `median`: the median of the numbers on stdin, one per line, to four decimals.
median() {
    sort -g | awk '{v[NR] = $1} END {m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2;
        printf "%.4f", m}'
}
