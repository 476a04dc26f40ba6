#!/bin/sh
# Every tutorial's Allrun on a copy (the ParaView picture left out), one
# thread; not a test (the `tutorials` test runs them, some coarser). Prints
# per tutorial: exit status, Allrun's wall seconds, the validate line, and
# the log's ExecutionTime (CPU of the time loop). For the tables of
# README.md and docs/validation-and-performance.md.
#   bench/run_tutorials.sh [WORKDIR]     (default ${TMPDIR:-/tmp}/mpsflow-tutorials)
cd "$(dirname "$0")/.." || exit 1
src=$PWD
work=${1:-${TMPDIR:-/tmp}/mpsflow-tutorials}
export OMP_NUM_THREADS=1 MPSFLOW=${MPSFLOW:-$src/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
mkdir -p "$work"
for dir in "$src"/tutorials/*/; do
    t=$(basename "$dir")
    [ -x "$dir/Allrun" ] || continue
    rm -rf "${work:?}/$t"; cp -r "$dir" "$work/$t"
    rm -rf "$work/$t/output" "$work/$t/postProcessing"
    sed -i 's/command -v pvbatch/false/' "$work/$t/Allrun"
    start=$(date +%s)
    (cd "$work/$t" && ./Allrun > log.allrun 2>&1); rc=$?
    end=$(date +%s)
    err=$(grep -h "^error" "$work/$t/log.validate" 2>/dev/null | tr '\n' ' ')
    cpu=$(grep -h "ExecutionTime" "$work/$t/log.mpsflow" 2>/dev/null | tail -n 1)
    echo "$t rc=$rc wall=$((end - start))s | $err | $cpu"
done
