#!/bin/sh
# The work of each rank, in instructions (callgrind), of one case run
# serially and on 2 ranks: figures that do not depend on the machine's load
# (a rank that waits in a collective call polls, so its wall and CPU time
# say nothing about its work). Not a test.
#
#   bench/mpi_work.sh [WORKDIR]
#
# damBreak3D at l0 = L0 (default 0.02 m: 17,568 particles) to t = ENDTIME
# (default 0.004 s, 12 steps), serially and on 2 ranks with
# decomposeParDict's multiCriteria no and yes. Per run and rank it prints the
# instructions by where they run: mpsflow's own code, hypre, core/parallel,
# Zoltan, the MPI library (polling while waiting), the rest, and "work"
# (all but the MPI library). The work bound on the speed-up of 2 ranks is
# serial work / the largest rank's work. Start-up is included (every rank
# reads the case and builds the whole scene).
#
# Environment: MPSFLOW (default build/driver/mpsflow), L0, ENDTIME, MPIRUN;
# MULTI (default "no yes": the multiCriteria of the 2-rank runs); PRESSURE,
# keys added to solverDict's pressure dictionary (e.g. "ownCycle no;": hypre's
# PCG and V-cycle instead of ours); SERIAL (default yes; no: the 2-rank runs
# only).
cd "$(dirname "$0")/.." || exit 1
ROOT=$PWD
MPSFLOW=${MPSFLOW:-$ROOT/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
WORK=${1:-${TMPDIR:-/tmp}/mpsflow-mpi-work}
L0=${L0:-0.02}
ENDTIME=${ENDTIME:-0.004}
MPIRUN=${MPIRUN:-mpirun --oversubscribe --allow-run-as-root}
MULTI=${MULTI:-no yes}
PRESSURE=${PRESSURE:-}
SERIAL=${SERIAL:-yes}
export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive
mkdir -p "$WORK"

# prepare DIR MULTI: a copy of damBreak3D with multiCriteria MULTI.
prepare() {
    rm -rf "$1"
    mkdir -p "$1"
    cp -r tutorials/damBreak3D/system tutorials/damBreak3D/constant "$1/"
    printf 'multiCriteria %s;\n' "$2" > "$1/system/decomposeParDict"
    [ -z "$PRESSURE" ] ||
        sed -i "s|^\( *solver *PCG_BoomerAMG;\)|\1 $PRESSURE|" "$1/system/solverDict"
}

# split FILE: instructions by object, millions.
split() {
    callgrind_annotate --auto=no --inclusive=no --threshold=100 "$1" 2> /dev/null | awk -v root="$ROOT" '
        /^ *[0-9,]+ \(/ && !/PROGRAM TOTALS/ {
            n = $1; gsub(",", "", n)
            fn = $0; sub(/^[^)]*\) +/, "", fn)
            # The object is printed when it changes (inlined code: none).
            if ($0 ~ /\[/) { obj = $0; sub(/.*\[/, "", obj); sub(/\].*/, "", obj) }
            if (fn ~ /core\/parallel\//) c["parallel"] += n
            else if (index(fn, "build/../") || index(fn, root "/")) c["own"] += n
            else if (obj ~ /libmpi|libopen-pal|libopen-rte|mca_|libucp|libucs|libuct|libhwloc|libevent|libpmix/) c["mpi"] += n
            else if (obj ~ /HYPRE/) c["hypre"] += n
            else if (obj ~ /zoltan/) c["zoltan"] += n
            else if (obj ~ /mpsflow/) c["own"] += n
            else c["other"] += n
            total += n
        }
        END {
            printf "own %.0f  hypre %.0f  parallel %.0f  zoltan %.0f  mpi %.0f  other %.0f  work %.0f (millions)\n",
                c["own"] / 1e6, c["hypre"] / 1e6, c["parallel"] / 1e6, c["zoltan"] / 1e6,
                c["mpi"] / 1e6, c["other"] / 1e6, (total - c["mpi"]) / 1e6
        }'
}

if [ "$SERIAL" = yes ]; then
    d=$WORK/serial
    prepare "$d" yes
    valgrind --tool=callgrind --callgrind-out-file="$d/cg.out" "$MPSFLOW" -case "$d" -l0 "$L0" \
        -endTime "$ENDTIME" > "$d/log" 2>&1 || { echo "serial run failed: $d/log"; exit 1; }
    echo "serial: $(split "$d/cg.out")"
fi
for multi in $MULTI; do
    d=$WORK/np2.$multi
    prepare "$d" $multi
    $MPIRUN -np 2 valgrind --tool=callgrind --callgrind-out-file="$d/cg.%q{OMPI_COMM_WORLD_RANK}" \
        "$MPSFLOW" -parallel -case "$d" -l0 "$L0" -endTime "$ENDTIME" > "$d/log" 2>&1 ||
        { echo "np 2 run failed: $d/log"; exit 1; }
    grep -E "^Decomposed|^Parallel: 2 ranks, [0-9]" "$d/log" | sed "s/^/np 2 multiCriteria $multi: /"
    for r in 0 1; do
        echo "np 2 multiCriteria $multi rank $r: $(split "$d/cg.$r")"
    done
done
