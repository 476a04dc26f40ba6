#!/bin/sh
# One case on 2 MPI ranks against 1 (issue 14), timed with hyperfine; not a
# test. Per step, from the difference of two run lengths (so that start-up:
# reading the case, building the scene on every rank, the first partition,
# drops out):
#   per step = (T(long) - T(short)) / (steps(long) - steps(short)),
# T the median wall time of RUNS runs, the step counts from runSummary.
# np = 1 runs with OMP_NUM_THREADS=2 (the serial run's best on 2 cores),
# np = 2 with 1 thread a rank: the same two cores either way.
#
#   bench/bench_mpi.sh dambreak [WORKDIR]   damBreak3D at ~1,000,000 particles
#   bench/bench_mpi.sh dambreak100k [WORKDIR]  damBreak3D at l0 0.009 m (97,542
#                                           particles), 5 and 25 steps: the
#                                           quiet-machine figure of
#                                           docs/topics/parallel.md (83 s)
#   bench/bench_mpi.sh scenes [WORKDIR]     the paper's scenes at its counts
#   bench/bench_mpi.sh all [WORKDIR]        both (default)
#   bench/bench_mpi.sh quick [WORKDIR]      small versions: checks the script
#
# Scenes: the states bench/bench_scenes.sh prepares (corridorFlood at
# ~100,000 fluid particles, boxFilling at ~155,000; an hour or more each on
# 2 cores, cached in WORKDIR, shared with that script), restarted on 1 and 2
# ranks for SHORT and LONG frames of 1/30 s.
#
# Writes bench/results/mpi.csv and, per case and rank count, the log of one
# run (the time split: neighbours with halos, explicit, assembly, solve;
# per rank the halo's share of particles, its bytes and time a step,
# migration and rebalancing) to WORKDIR/<case>.np<N>.log.
#
# Environment: MPSFLOW (default build/driver/mpsflow), RUNS (default 3),
# DAMBREAK_L0 (default 0.0029 m: 1,000,000 fluid particles), DAMBREAK_STEPS
# ("2 4"), SCENE_FRAMES ("1 2"), MPIRUN (default "mpirun --oversubscribe
# --allow-run-as-root"; a cluster's launcher otherwise).
cd "$(dirname "$0")/.." || exit 1
ROOT=$PWD
MPSFLOW=${MPSFLOW:-$ROOT/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
command -v hyperfine > /dev/null || { echo "needs hyperfine (apt-get install hyperfine)"; exit 1; }
WHAT=${1:-all}
[ $# -gt 0 ] && shift
WORK=${1:-${TMPDIR:-/tmp}/mpsflow-bench-scenes}
RUNS=${RUNS:-3}
MPIRUN=${MPIRUN:-mpirun --oversubscribe --allow-run-as-root}
DAMBREAK_L0=${DAMBREAK_L0:-0.0029}
DAMBREAK_STEPS=${DAMBREAK_STEPS:-"2 4"}
SCENE_FRAMES=${SCENE_FRAMES:-"1 2"}
if [ "$WHAT" = quick ]; then
    DAMBREAK_L0=0.01; DAMBREAK_STEPS="5 10"; RUNS=2
fi
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
mkdir -p "$WORK" bench/results
csv=$ROOT/bench/results/mpi.csv
[ -f "$csv" ] || echo "case,particles,np,steps_short,steps_long,s_short,s_long,ms_per_step,speedup,load_before,load_after,date" > "$csv"

# The command of a run on NP ranks (NP 1: no mpirun).
cmd() {
    np=$1; shift
    if [ "$np" = 1 ]; then
        echo "env OMP_NUM_THREADS=2 $MPSFLOW $*"
    else
        echo "env OMP_NUM_THREADS=1 $MPIRUN -np $np $MPSFLOW -parallel $*"
    fi
}

# steps_of DIR: the steps of its last run (runSummary).
steps_of() {
    awk '/^steps/ { gsub(";", "", $2); print $2 }' "$1/output/runSummary"
}

# measure NAME PARTICLES SHORT_DIR LONG_DIR ARGS...: hyperfine over np 1 and
# 2, short and long; prepare_run (a function of the caller) resets a folder
# before each run.
measure() {
    name=$1 particles=$2 short=$3 long=$4; shift 4
    load0=$(cut -d' ' -f1 /proc/loadavg)
    json=$WORK/$name.hyperfine.json
    hyperfine --runs "$RUNS" --export-json "$json" --style basic \
        --prepare "sh -c '$PREPARE'" \
        -n "np1 short" "$(cmd 1 -case "$short" "$@") > /dev/null" \
        -n "np1 long" "$(cmd 1 -case "$long" "$@") > /dev/null" \
        -n "np2 short" "$(cmd 2 -case "$short" "$@") > /dev/null" \
        -n "np2 long" "$(cmd 2 -case "$long" "$@") > /dev/null" >&2 || return 1
    load1=$(cut -d' ' -f1 /proc/loadavg)
    # The step counts and the logs of one more run each (the time split).
    for np in 1 2; do
        sh -c "$PREPARE"
        $(cmd $np -case "$short" "$@") > "$WORK/$name.np$np.short.log" 2>&1
        ns=$(steps_of "$short")
        sh -c "$PREPARE"
        $(cmd $np -case "$long" "$@") > "$WORK/$name.np$np.log" 2>&1
        nl=$(steps_of "$long")
        python3 - "$json" "$np" "$ns" "$nl" "$name" "$particles" "$load0" "$load1" "$csv" << 'PY'
import json, sys, statistics, datetime
path, np, ns, nl, name, particles, l0, l1, csv = sys.argv[1:]
res = {r["command"]: statistics.median(r["times"]) for r in json.load(open(path))["results"]}
ts, tl = res["np%s short" % np], res["np%s long" % np]
ms = 1e3 * (tl - ts) / max(int(nl) - int(ns), 1)
base = 1e3 * (res["np1 long"] - res["np1 short"]) / max(int(nl) - int(ns), 1)
speedup = base / ms if ms > 0 else float("nan")
print(f"{name} np={np}: {ms:.0f} ms/step ({int(nl) - int(ns)} steps between the runs), "
      f"{speedup:.2f} times np=1; load {l0} -> {l1}", file=sys.stderr)
with open(csv, "a") as f:
    f.write(f"{name},{particles},{np},{ns},{nl},{ts:.3f},{tl:.3f},{ms:.1f},{speedup:.3f},"
            f"{l0},{l1},{datetime.date.today()}\n")
PY
        grep -E "^MPS time per step|^    rank|^ +[0-9]+ +[0-9]" "$WORK/$name.np$np.log" >&2
    done
}

echo "machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GB", $2/1048576}' /proc/meminfo), $(uname -sr), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); $(date -u +%Y-%m-%d)" >&2

# ---- damBreak3D at ~1,000,000 particles, a fixed step --------------------------
dambreak() {
    set -- $DAMBREAK_STEPS
    ss=$1 sl=$2
    for len in short long; do
        d=$WORK/dambreak.$len
        rm -rf "$d"
        mkdir -p "$d"
        cp -r tutorials/damBreak3D/system tutorials/damBreak3D/constant "$d/"
        steps=$ss; [ $len = long ] && steps=$sl
        # deltaT: Courant 0.2 at 2 m/s; one snapshot at the end (and the first).
        dt=$(awk "BEGIN { printf \"%.17g\", 0.2 * $DAMBREAK_L0 / 2 }")
        printf 'endTime %s;\nadjustTimeStep no;\ndeltaT %s;\nwriteControl timeStep;\nwriteInterval %s;\n' \
            "$(awk "BEGIN { printf \"%.17g\", $steps * $dt }")" "$dt" "$steps" > "$d/system/controlDict"
    done
    PREPARE="rm -rf $WORK/dambreak.short/output $WORK/dambreak.long/output"
    n=$("$MPSFLOW" -case "$WORK/dambreak.short" -l0 "$DAMBREAK_L0" -dryRun | awk '/^Particles:/ { print $2 }')
    echo "damBreak3D at l0 = $DAMBREAK_L0 m: $n particles" >&2
    measure damBreak3D "$n" "$WORK/dambreak.short" "$WORK/dambreak.long" -l0 "$DAMBREAK_L0"
}

# ---- the paper's scenes from bench_scenes.sh's states --------------------------
scene() {
    name=$1 l0=$2
    src=$WORK/$name
    if ! ls "$src"/output/snapshot_*.h5 > /dev/null 2>&1; then
        echo "preparing $name with bench/bench_scenes.sh (once)" >&2
        FRAMES=1 bench/bench_scenes.sh "$WORK" > /dev/null || return 1
    fi
    snap=$(ls "$src"/output/snapshot_*.h5 | tail -n 1)
    t0=$(h5dump -a /Header/Time "$snap" | awk '/\(0\)/ { print $2 }')
    set -- $SCENE_FRAMES
    for len in short long; do
        d=$WORK/$name.mpi.$len
        rm -rf "$d"
        mkdir -p "$d/output"
        cp -r "$src/system" "$src/constant" "$d/"
        frames=$1; [ $len = long ] && frames=$2
        end=$(awk "BEGIN { printf \"%.17g\", $t0 + $frames / 30 }")
        sed -i "s|^endTime .*|endTime $end;|; s|^writeInterval .*|writeInterval $(awk 'BEGIN { printf "%.17g", 1 / 30 }');|" "$d/system/controlDict"
    done
    PREPARE="for d in $WORK/$name.mpi.short $WORK/$name.mpi.long; do rm -rf \$d/output; mkdir -p \$d/output; cp $snap \$d/output/; done"
    n=$(h5dump -a /Header/NumPart_Total "$snap" | awk -F'[:,]' '/\(0\)/ { s = 0; for (i = 2; i <= NF; i++) s += $i; print s }')
    measure "$name" "$n" "$WORK/$name.mpi.short" "$WORK/$name.mpi.long" -l0 "$l0" -latestTime
}

case $WHAT in
quick) dambreak ;;
dambreak) dambreak ;;
dambreak100k) DAMBREAK_L0=0.009; DAMBREAK_STEPS="5 25"; dambreak ;;
scenes) scene corridorFlood 0.0215 && scene boxFilling 0.0117 ;;
all) dambreak && scene corridorFlood 0.0215 && scene boxFilling 0.0117 ;;
*) echo "usage: bench/bench_mpi.sh [dambreak|dambreak100k|scenes|all|quick] [WORKDIR]"; exit 2 ;;
esac
echo "table: $csv" >&2
