#!/bin/sh
# A/B of the neighbour service and the pair engine (issue 12): the MPS
# phases outside the pressure solve, two builds of mpsflow side by side.
#
#   bench/engine_ab.sh A B [RUNS]
#       A, B: mpsflow executables (e.g. a build of main and this tree's
#       build/driver/mpsflow). Runs the 2-D bench case (cases/damBreak2D_l0_0.005,
#       fixed dt 4e-4, STEPS2 steps, default 300) and the 3-D dam break at
#       l0 = 0.009 (99,009 particles, dt 6e-4, STEPS3 steps, default 10), A and
#       B alternately RUNS times (default 3), one thread (OMP_NUM_THREADS,
#       default 1), and prints the median time per step of each phase and the
#       peak memory.
#   CALLGRIND=1 bench/engine_ab.sh A B
#       instead: instruction counts (valgrind --tool=callgrind) of each phase
#       over 50 steps of the 2-D case, which do not depend on the machine's
#       load; about a minute each.
#
# Wall clock depends on what else the machine does: quote the load (uptime)
# with the figures, or use the instruction counts.
cd "$(dirname "$0")/.." || exit 1
A=${1:?usage: bench/engine_ab.sh A B [RUNS]}
B=${2:?usage: bench/engine_ab.sh A B [RUNS]}
RUNS=${3:-3}
STEPS2=${STEPS2:-300}
STEPS3=${STEPS3:-10}
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-1}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

# prepare NAME CASE DT: a copy of bench/cases/CASE with a fixed step DT.
prepare() {
    mkdir -p "$WORK/$1"
    cp -r "bench/cases/$2/." "$WORK/$1/"
    sed -i "s/^deltaT .*/deltaT          $3;/; s/^adjustTimeStep .*/adjustTimeStep  no;/" \
        "$WORK/$1/system/controlDict"
}
prepare 2d damBreak2D_l0_0.005 0.0004
prepare 3d damBreak3D 0.0006

# phases LOG: "neighbours explicit assembly solve correction total peakMB"
phases() {
    awk '/^MPS time per step/ {
            for (i = 1; i <= NF; i++) {
                if ($i == "search") nb = $(i + 1) + 0
                if ($i == "explicit") ex = $(i + 1) + 0
                if ($i == "assembly") as = $(i + 1) + 0
                if ($i == "solve") so = $(i + 1) + 0
                if ($i == "correction") co = $(i + 1) + 0
                if ($i == "total") tot = $(i + 1) + 0
            }
        }
        /peak memory/ { for (i = 1; i <= NF; i++) if ($i == "memory") mb = $(i + 1) + 0 }
        END { printf "%.3f %.3f %.3f %.3f %.3f %.3f %.1f\n", nb, ex, as, so, co, tot, mb }' "$1"
}

# run BIN CASE L0 STEPS DT OUT
run() {
    end=$(awk "BEGIN { printf \"%.10g\", $5 * $4 }")
    "$1" -case "$WORK/$2" -l0 "$3" -endTime "$end" -quiet -overwrite > "$WORK/log" 2>&1 ||
        { echo "run failed: $1 $2"; tail -5 "$WORK/log"; exit 1; }
    phases "$WORK/log" >> "$6"
}

# median FILE COLUMN
median() {
    sort -g -k "$2" "$1" | awk -v c="$2" '{ v[NR] = $c } END { print v[int((NR + 1) / 2)] }'
}

if [ "${CALLGRIND:-0}" = 1 ]; then
    command -v valgrind > /dev/null || { echo "valgrind is missing (apt-get install valgrind)"; exit 1; }
    # mpsflow re-executes itself to set OpenMP's wait policy when none is
    # set, and valgrind does not follow the exec: set it here.
    export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
    for bin in "$A" "$B"; do
        valgrind --tool=callgrind --callgrind-out-file="$WORK/cg" "$bin" -case "$WORK/2d" \
            -l0 0.005 -endTime 0.02 -quiet -overwrite > /dev/null 2>&1
        echo "$bin: instructions over 50 steps of the 2-D case (millions)"
        callgrind_annotate --inclusive=yes "$WORK/cg" 2>/dev/null | awk '
            /PROGRAM TOTALS/ { gsub(",", "", $1); printf "  %-22s %8.0f\n", "total", $1 / 1e6 }
            /^ *[0-9,]+ +[(] *[0-9.]+%[)] +[^ ]*(mps_step|mps_ppe)[.]c:mps_(build_neighbours|explicit_phase|surface_phase|assemble_ppe|solve_ppe|correction_phase) / {
                n = $1; gsub(",", "", n); match($0, /mps_[a-z_]+ /)
                printf "  %-22s %8.0f\n", substr($0, RSTART, RLENGTH - 1), n / 1e6 }'
    done
    exit 0
fi

echo "machine: $(nproc) cores, $(uname -sr); OMP_NUM_THREADS=$OMP_NUM_THREADS; $(date -u +%Y-%m-%d); load $(cut -d' ' -f1-3 /proc/loadavg)"
for c in "2d 0.005 $STEPS2 0.0004" "3d 0.009 $STEPS3 0.0006"; do
    set -- $c
    : > "$WORK/a" && : > "$WORK/b"
    for r in $(seq "$RUNS"); do
        run "$A" "$1" "$2" "$3" "$4" "$WORK/a"
        run "$B" "$1" "$2" "$3" "$4" "$WORK/b"
    done
    echo "$1 case, $3 steps, median of $RUNS (ms a step; peak MB):"
    printf "  %-10s %10s %10s %10s %10s %10s %10s %8s\n" "" neighbours explicit assembly solve correction total peak
    for ab in a b; do
        name=$A; [ $ab = b ] && name=$B
        printf "  %-10s" "$ab"
        for col in 1 2 3 4 5 6 7; do printf " %10s" "$(median "$WORK/$ab" $col)"; done
        echo "   $name"
    done
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
