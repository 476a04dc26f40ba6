#!/bin/sh
# bench_threads.sh: one thread, two threads and the run's own choice
# (OMP_NUM_THREADS not set: core/run/mf_thread_tuner.h) on the 2-D bench
# case, with the second core idle and with a busy loop holding it (issue
# 12: "two threads never slower than one on a loaded machine"). Not a test;
# whole processes timed by hyperfine, medians.
#
#   bench/bench_threads.sh [STEPS] [RUNS]    (defaults 400 steps, 5 runs)
#
# Environment: MPSFLOW (default build/driver/mpsflow).
cd "$(dirname "$0")/.." || exit 1
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
command -v hyperfine > /dev/null || { echo "needs hyperfine (apt-get install hyperfine)"; exit 1; }
steps=${1:-400}; runs=${2:-5}
work=${TMPDIR:-/tmp}/mpsflow-bench-threads
rm -rf "$work"; mkdir -p "$work"
cp -r bench/cases/damBreak2D_l0_0.005 "$work/case"
end=$(awk "BEGIN { printf \"%.10g\", 0.0004 * $steps }")
run="rm -rf $work/case/output; $MPSFLOW -case $work/case -l0 0.005 -endTime $end -quiet"
busy=""
cleanup() { [ -n "$busy" ] && kill "$busy" 2> /dev/null; }
trap cleanup EXIT
for load in idle busy; do
    if [ $load = busy ]; then
        sh -c 'while :; do :; done' &
        busy=$!
    fi
    echo "== second core $load (load $(cut -d' ' -f1-3 /proc/loadavg))"
    hyperfine --runs "$runs" --export-json "$work/$load.json" \
        -n "1 thread" "env OMP_NUM_THREADS=1 sh -c '$run'" \
        -n "2 threads" "env OMP_NUM_THREADS=2 sh -c '$run'" \
        -n "the run's choice" "env -u OMP_NUM_THREADS sh -c '$run'" > /dev/null
    python3 -c 'import json, statistics, sys
for r in json.load(open(sys.argv[1]))["results"]:
    print("| %s | %.3f s median of %d | %.3f ms a step |" % (r["command"], statistics.median(r["times"]),
          len(r["times"]), 1000 * statistics.median(r["times"]) / int(sys.argv[2])))' "$work/$load.json" "$steps"
    cleanup; busy=""
done
