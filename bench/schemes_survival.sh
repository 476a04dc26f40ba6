#!/bin/sh
# Issue 13's failing cases under each MPS scheme: does the run reach its
# endTime, and how (steps, retries, largest fluid speed, the watch's
# diagnosis when it stops)? Not a test: a table for docs/topics/schemes.md.
#   bench/schemes_survival.sh [VARIANT ...]
# VARIANT is one of
#   paper     `scheme paper;` as printed (relaxation 1, no collision)
#   stab      the paper scheme with today's stabilisation (relaxation 0.2, collision)
#   robust    `scheme robust;`
#   default   the module's defaults (the case sets no scheme key)
#   NAME=KEYS any other: MPSCoeffs entries, e.g. 'mixedOnly=source mixed; collision yes;'
# CASES (default: all below) picks cases by name; each case is run at its
# spacings, two runs at a time, one thread each:
#   damBreak3D       tutorials/damBreak3D to its endTime 0.35 s (issue: stops at 0.265 s)
#   damBreak3Dwall   the same to 0.5 s, the front hitting the far wall
#   obstacle         bench/cases/damBreakObstacle to 0.6 s (issue: stops at 0.33 s)
#   waterAir         tutorials/waterAirDamBreak (1000:1) at 0.02 and 0.01 m
#   fixedDt          damBreak2D at fixed dt 1e-4 and 5e-5, l0 0.01, to 0.6 s (issue: paper stops in 0.1 s)
#   tank3D           bench/cases/restingTank in 3-D at the damBreak3D settings, 1 s
#   damBreak2D       tutorials/damBreak2D at 0.02, 0.01 and 0.005 m, front error (validate)
#   extreme          bench/cases/extreme/* at 0.02, 0.01 (their own) and 0.005 m
#   waterAirCoarse   tutorials/waterAirDamBreak at 0.04 m (a third spacing)
# Writes bench/results/schemes_survival.csv (appends).
cd "$(dirname "$0")/.." || exit 1
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
export OMP_NUM_THREADS=1
out=bench/results; mkdir -p "$out"
csv=$out/schemes_survival.csv
[ -f "$csv" ] || echo "case,l0,variant,end,reached,steps,retries,ke_max_J,speed_max,seconds,validate,stop,watch_peak" > "$csv"
work=$(mktemp -d)
[ -n "$KEEP" ] || trap 'rm -rf "$work"' EXIT
[ $# -gt 0 ] || set -- paper stab robust
cases=${CASES:-damBreak3D damBreak3Dwall obstacle waterAir fixedDt tank3D damBreak2D}

# keys VARIANT: the MPSCoeffs entries of a variant
keys() {
    case $1 in
    paper) echo "scheme paper;" ;;
    stab) echo "scheme paper; relaxation 0.2; collision yes;" ;;
    robust) echo "scheme robust;" ;;
    default) echo "" ;;
    *=*) echo "${1#*=}" ;;
    *) echo "scheme $1;" ;;
    esac
}

# one CASE_DIR NAME L0 VARIANT [CONTROL_SED]: copy, set the variant, run, print a row
one() {
    src=$1 name=$2 l0=$3 var=$4 ctl=$5
    vname=${var%%=*}
    d=$work/${name}_${l0}_$vname
    rm -rf "$d"; cp -r "$src" "$d"; rm -rf "$d/output" "$d/postProcessing" "$d"/log.*
    # the case's own relaxation and collision go; the variant's keys come first
    sed -i -E '/^(MPSCoeffs|multiFluidCoeffs|MAFLCoeffs)[ ]*$/,/^}/ { /^ *(relaxation|collision|collisionAfterCorrection) /d }' "$d/system/solverDict"
    k=$(keys "$var")
    awk -v k="$k" '{ print } /^(MPSCoeffs|multiFluidCoeffs|MAFLCoeffs)[ ]*$/ { want = 1; next }
        want && /^[{]/ { if (k != "") print "    " k; want = 0 }' "$d/system/solverDict" > "$d/sd" &&
        mv "$d/sd" "$d/system/solverDict"
    [ -n "$ctl" ] && sed -i -E "$ctl" "$d/system/controlDict"
    end=$(awk '/^endTime/ { print $2 + 0 }' "$d/system/controlDict")
    t0=$(date +%s)
    "$MPSFLOW" -case "$d" -l0 "$l0" > "$d/log" 2>&1; rc=$?
    secs=$(($(date +%s) - t0))
    reached=$(awk '/^Time = / { t = $3 } END { print t + 0 }' "$d/log")
    steps=$(grep -c '^Time = ' "$d/log")
    retries=$(grep -c 'retrying with' "$d/log")
    stop=""
    [ $rc = 0 ] || stop=$(grep -m1 -E 'unstable|through|error|Error|failed' "$d/log" | tr ',' ';' | cut -c1-140)
    ke=$(awk '!/^#/ { if ($2 > m) m = $2; if ($3 > u) u = $3 } END { printf "%.4g,%.3g", m, u }' \
        "$d/postProcessing/energy/kineticEnergy.dat" 2>/dev/null)
    # how close the run came to the energy criterion (the log's Watch: line)
    peak=$(sed -n 's/^Watch: kinetic energy above.* by at most \([^ ]*\) of the energy scale.*/\1/p' "$d/log")
    val=""
    if [ $rc = 0 ] && [ -d "$d/validation" ]; then
        val=$("$MPSFLOW" validate -case "$d" 2>&1 | awk '/^[Ee]rror / { print $NF }' | head -1)
    fi
    printf "%-15s l0 %-8s %-12s end %-5s reached %-8s steps %6s retries %3s KE max, speed max %-14s %6s s  validate %-9s watch %-9s %s\n" \
        "$name" "$l0" "$vname" "$end" "$reached" "$steps" "$retries" "$ke" "$secs" "$val" "$peak" "$stop"
    echo "$name,$l0,$vname,$end,$reached,$steps,$retries,$ke,$secs,$val,$stop,$peak" >> "$csv"
}

# The 3-D resting tank at the damBreak3D settings (l0 0.025 m, radii 3.1,
# beta 0.97): water 0.5 m x 0.25 m x 0.2 m in a tank 0.5 m wide.
tank3d() {
    t=$work/tank3D_src
    [ -d "$t" ] && return
    cp -r bench/cases/restingTank "$t"
    sed -i "s/^dimension .*/dimension       3;/; s/^particleSpacing .*/particleSpacing 0.025;/
            s/max         (0.4 0.2 0.1);/max         (0.5 0.25 0.2);/
            s/max         (0.4 0.3 0.1);/max         (0.5 0.4 0.2);/" "$t/constant/geometry"
    sed -i "s/^surface .*/surface         0.25;/; s/^max .*/max             (0.5 1e9 0.2);/" "$t/validation/metric"
    sed -i "s/^endTime .*/endTime         1.0;/" "$t/system/controlDict"
}

echo "schemes survival: $(getconf _NPROCESSORS_ONLN) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $(date -u '+%Y-%m-%d %H:%M UTC')"
list=""
for c in $cases; do
    for v in "$@"; do
        case $c in
        damBreak3D) list="$list
tutorials/damBreak3D|damBreak3D|0.025|$v|" ;;
        damBreak3Dwall) list="$list
tutorials/damBreak3D|damBreak3Dwall|0.025|$v|s/^endTime .*/endTime 0.5;/" ;;
        obstacle) for l in 0.0073 0.00487 0.00365; do list="$list
bench/cases/damBreakObstacle|obstacle|$l|$v|"; done ;;
        waterAir) for l in 0.02 0.01; do list="$list
tutorials/waterAirDamBreak|waterAir|$l|$v|"; done ;;
        fixedDt) for dt in 1e-4 5e-5; do list="$list
tutorials/damBreak2D|fixedDt$dt|0.01|$v|s/^deltaT .*/deltaT $dt;/;s/^adjustTimeStep .*/adjustTimeStep no;/"; done ;;
        tank3D) tank3d; list="$list
$work/tank3D_src|tank3D|0.025|$v|" ;;
        damBreak2D) for l in 0.02 0.01 0.005; do list="$list
tutorials/damBreak2D|damBreak2D|$l|$v|"; done ;;
        extreme) for e in ${EXTREME:-columnImpact cornerJet freeFall overlapped singleParticle thinSheet}; do
            for l in 0.02 0.01 0.005; do list="$list
bench/cases/extreme/$e|$e|$l|$v|"; done; done ;;
        waterAirCoarse) list="$list
tutorials/waterAirDamBreak|waterAir|0.04|$v|" ;;
        esac
    done
done
n=0
printf '%s\n' "$list" | while IFS='|' read -r src name l0 var ctl; do
    [ -n "$src" ] || continue
    one "$src" "$name" "$l0" "$var" "$ctl" &
    n=$((n + 1))
    [ $((n % ${PAR:-2})) = 0 ] && wait
done
wait
