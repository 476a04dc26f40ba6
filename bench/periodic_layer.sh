#!/bin/sh
# bench/periodic_layer.sh NAME END ['EXTRA COEFFS'] -> $OUT/NAME (OUT default /tmp/layer)
# The periodic resting layer of docs/notes/mps.md (resting3, hex): a copy of
# bench/cases/restingTank (2-D, 0.4 m x 0.2 m water, l0 0.01) with the side
# walls open (xmin, xmax) and `periodicLength 0.4;` in MPSCoeffs: a resting
# layer on a floor with no side walls, scored by the restingTank metric with
# its box opened in x. Prints the metric's summary lines; the per-snapshot
# largest speed is in $OUT/NAME/validation/result.csv. Env: L0 (spacing).
W=$(cd "$(dirname "$0")/.." && pwd); OUT=${OUT:-/tmp/layer}; mkdir -p "$OUT"
d=$OUT/$1; end=$2; extra=$3
rm -rf "$d"; cp -r "$W/bench/cases/restingTank" "$d"
sed -i "s/^endTime .*/endTime         $end;/" "$d/system/controlDict"
sed -i "/^MPSCoeffs/,/^}/ s/^}\$/    periodicLength 0.4; $extra\n}/" "$d/system/solverDict"
sed -i "s/open        (ymax);/open        (xmin xmax ymax);/" "$d/constant/geometry"
sed -i "s/^max .*/max             (1e9 1e9 1e9);/; s/^min .*/min             (-1e9 0 -1e9);/" \
    "$d/validation/metric"
[ -n "$L0" ] && sed -i "s/^particleSpacing .*/particleSpacing $L0;/" "$d/constant/geometry"
export OMP_NUM_THREADS=1 MPSFLOW_PLUGIN_PATH="$W/build/plugins"
"$W/build/driver/mpsflow" -case "$d" > "$d/log" 2>&1; echo "rc $?" >> "$d/log"
"$W/build/driver/mpsflow" validate -case "$d" > "$d/validate" 2>&1
grep '^# largest' "$d/validation/result.csv" | sed "s|^|$1: |"
