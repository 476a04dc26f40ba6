#!/bin/sh
# Issue 13's resting tanks: water at rest (H = 0.2 m in 2-D, 0.1 m in 3-D) in
# tanks of three aspect ratios (width / H = 0.5, 2, 5 in 2-D; a square base
# of side 0.5, 1, 2 H in 3-D), each at two spacings (2-D: l0 = 0.01 and
# 0.005 m, H/20 and H/40; 3-D: 0.01 and 0.005 m, H/10 and H/20), for 5 s, scored
# by the restingTank metric (driver/post/metric_resting_tank.c): largest
# fluid speed after 0.5 s against sqrt(g H) (pass: below 1%), bottom
# pressure against rho g (H - y) (pass: within 1%), snapshots with a
# particle past a wall face (pass: none).
#   bench/resting_tanks.sh [SCHEME] [2 | 3 | all] [ENDTIME]
# JOBS='2:2:0.01 3:1:0.005' runs only those tanks (DIM:ASPECT:L0).
# SCHEME: a `scheme` of MPSCoeffs, or `default` (the module's; the case sets
# nothing). EXTRA_COEFFS adds entries to MPSCoeffs, e.g.
#   EXTRA_COEFFS='relaxation 0.2; collision yes;' bench/resting_tanks.sh paper
# Two runs at a time, one thread each. Prints one row per tank and writes
# bench/results/resting_tanks_<SCHEME>.csv.
cd "$(dirname "$0")/.." || exit 1
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
scheme=${1:-default}; dims=${2:-all}; end=${3:-5}
export OMP_NUM_THREADS=1
out=bench/results; mkdir -p "$out"
tag=$scheme${TAG:+_$TAG}
csv=$out/resting_tanks_$tag.csv
work=$(mktemp -d)
[ -n "$KEEP" ] || trap 'rm -rf "$work"' EXIT

# make DIR DIM ASPECT L0: a copy of bench/cases/restingTank
make() {
    d=$1 dim=$2 ar=$3 l0=$4
    cp -r bench/cases/restingTank "$d"
    if [ "$dim" = 2 ]; then H=0.2; zmax=0.1; else H=0.1; fi
    w=$(awk "BEGIN { print $ar * $H }")
    [ "$dim" = 3 ] && zmax=$w
    top=$(awk "BEGIN { print 1.5 * $H }")
    sed -i "s/^dimension .*/dimension       $dim;/; s/^particleSpacing .*/particleSpacing $l0;/
            s/max         (0.4 0.2 0.1);/max         ($w $H $zmax);/
            s/max         (0.4 0.3 0.1);/max         ($w $top $zmax);/" "$d/constant/geometry"
    sed -i "s/^surface .*/surface         $H;/; s/^max .*/max             ($w 1e9 $zmax);/" \
        "$d/validation/metric"
    [ "$dim" = 2 ] && sed -i "s/^max .*/max             ($w 1e9 1e9);/" "$d/validation/metric"
    if [ "$scheme" != default ]; then
        sed -i "s/^{\$/{/; /^MPSCoeffs/,/^}/ s/^{\$/{\n    scheme $scheme;/" "$d/system/solverDict"
    fi
    [ -n "$EXTRA_COEFFS" ] && sed -i "/^MPSCoeffs/,/^}/ s/^}\$/    $EXTRA_COEFFS\n}/" "$d/system/solverDict"
    sed -i "s/^endTime .*/endTime         $end;/" "$d/system/controlDict"
}

# one DIM ASPECT L0: run and score one tank, print its row
one() {
    d=$work/tank_$1d_$2_$3
    make "$d" "$1" "$2" "$3"
    t0=$(date +%s)
    "$MPSFLOW" -case "$d" > "$d/log" 2>&1; rc=$?
    t1=$(date +%s)
    reached=$(awk '/^Time = / { t = $3 } END { print t + 0 }' "$d/log")
    [ $rc = 0 ] || reached="$reached (stopped: $(grep -m1 -i 'error\|unstable\|through' "$d/log" | cut -c1-60))"
    "$MPSFLOW" validate -case "$d" > "$d/validate" 2>&1
    awk -v dim="$1" -v ar="$2" -v l0="$3" -v reached="$reached" -v secs=$((t1 - t0)) '
        /^# largest speed/ { for (i = 1; i <= NF; i++) {
            if ($i == "speed") sp = $(i + 1)
            if ($i == "error" && $(i - 1) == "pressure") pe = $(i + 1)
            if ($i == "face:") past = $(i + 1) } }
        /^# error =/ { err = $4 }
        END { printf "%d-D  W/H %-4s l0 %-7s reached %-8s speed/sqrt(gH) %-9s bottom p error %-10s past-wall snapshots %-4s error %-8s %5d s\n", dim, ar, l0, reached, sp, pe, past, err, secs
              printf "%d,%s,%s,%s,%s,%s,%s,%s,%d\n", dim, ar, l0, reached, sp, pe, past, err, secs > "/dev/stderr" }' \
        "$d/validation/result.csv" 2>> "$csv"
}

echo "dim,aspect,l0,reached,speed_over_sqrt_gH,bottom_pressure_error,past_wall_snapshots,error,seconds" > "$csv"
echo "resting tanks, scheme $scheme ${EXTRA_COEFFS:+($EXTRA_COEFFS)}, endTime $end; $(getconf _NPROCESSORS_ONLN) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $(date -u '+%Y-%m-%d %H:%M UTC')"
jobs_list=$JOBS
if [ -z "$jobs_list" ]; then
    [ "$dims" = 3 ] || jobs_list="2:0.5:0.01 2:2:0.01 2:5:0.01 2:0.5:0.005 2:2:0.005 2:5:0.005"
    [ "$dims" = 2 ] || jobs_list="$jobs_list 3:0.5:0.01 3:1:0.01 3:2:0.01 3:0.5:0.005 3:1:0.005 3:2:0.005"
fi
n=0
for j in $jobs_list; do
    IFS=: read -r dim ar l0 <<JOB
$j
JOB
    one "$dim" "$ar" "$l0" &
    n=$((n + 1))
    [ $((n % 2)) = 0 ] && wait
done
wait
echo "table: $csv"
