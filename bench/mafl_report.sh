#!/bin/sh
# Error against run time of the MPS-MAFL convection schemes on
# tutorials/scalarAdvection (not a test). Writes
# bench/results/mafl_scalar_advection.csv and .png. Build first (./Allwmake).
#   bench/mafl_report.sh                 l0 = 0.02 0.01 0.005
#   bench/mafl_report.sh 0.02 0.01       other spacings
cd "$(dirname "$0")/.." || exit 1
BUILD=${BUILD:-build}
MPSFLOW=${MPSFLOW:-$PWD/$BUILD/driver/mpsflow}
REPORT=$PWD/$BUILD/bench/mafl_report
[ -x "$MPSFLOW" ] && [ -x "$REPORT" ] || { echo "build first: ./Allwmake"; exit 1; }
mkdir -p bench/results
echo "machine: $(nproc) cores, $(uname -sr); $(date -u +%Y-%m-%d)" >&2
exec "$REPORT" "$MPSFLOW" "$PWD/tutorials/scalarAdvection" "$PWD/bench/results" "$@"
