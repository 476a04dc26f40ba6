#!/bin/sh
# damBreak2D's surge front against refinement: the tutorial's surgeFront
# metric (Martin & Moyce 1952, a = 1.125 in) at several spacings, the front
# Z(T) of each run beside the experiment, and the time shift that fits each
# run best, the RMS difference between successive spacings and the RMS against
# Martin & Moyce's larger column (a = 2.25 in). Not a test: the tables of
# docs/notes/front.md (2026-12-03).
#   bench/dambreak_front_refinement.sh [N ...]      spacings l0 = a/N (default 12.5 25 50)
# Environment:
#   SCALE=tutorial    the tutorial as it is, a = 0.25 m (default)
#   SCALE=experiment  the same case shrunk to the experiment's a = 2.86 cm (1.125 in):
#                     column and tank times 0.1144, output interval and step limits times
#                     sqrt(0.1144) (times scale as sqrt(a/g)),
#                     water's viscosity kept (Re = sqrt(g a) a / nu falls from 3.9e5 to 1.5e4)
#   COEFFS='...'      MPSCoeffs entries added, e.g. 'wall wallWeight;' or 'scheme stabilised;'
#   CONTROL='...'     controlDict entries replaced, e.g. 'maxCo 0.1;'
#   TENSION=yes       water's sigma 0.0728 N/m and the surfaceTension force (its defaults)
#   ENDTIME=T         end time (default: the last reference point, T = 5.316, and a little more;
#                     the tutorial's own 0.6 s stops at T = 5.315, just before it)
#   KEEP=1            keep the runs (their folder is printed)
# Two runs at a time, one thread each.
cd "$(dirname "$0")/.." || exit 1
src=$PWD/tutorials/damBreak2D
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: meson setup build && ninja -C build"; exit 1; }
export OMP_NUM_THREADS=1
export MPSFLOW_PLUGIN_PATH=${MPSFLOW_PLUGIN_PATH:-$PWD/build/plugins}
work=$(mktemp -d)
if [ -n "$KEEP" ]; then echo "runs in $work"; else trap 'rm -rf "$work"' EXIT; fi
[ $# -gt 0 ] || set -- 12.5 25 50
case ${SCALE:=tutorial} in
tutorial) s=1 ;;
experiment) s=0.1144 ;;  # 0.0286 / 0.25
*) echo "SCALE: tutorial or experiment"; exit 1 ;;
esac
a=$(awk -v s=$s 'BEGIN { print 0.25 * s }')
# t of the last reference point, T = 5.316 = t sqrt(2 g / a), plus 1.5%
end=${ENDTIME:-$(awk -v a=$a 'BEGIN { printf "%.4g", 1.015 * 5.316 / sqrt(2 * 9.81 / a) }')}

# prepare DIR: the tutorial, scaled and set up as asked
prepare() {
    d=$1
    cp -r "$src" "$d"; rm -rf "$d/output" "$d/postProcessing" "$d"/log.*
    awk -v s=$s '
        /^ *max +\(0\.25 0\.5 0\);/ { printf "        max         (%.6g %.6g 0);\n", 0.25 * s, 0.5 * s; next }
        /^ *max +\(2\.0 0\.6 0\);/ { printf "        max         (%.6g %.6g 0);\n", 2.0 * s, 0.6 * s; next }
        { print }' "$src/constant/geometry" > "$d/constant/geometry"
    # times scale as sqrt(a / g)
    awk -v s=$s -v end=$end '
        $1 == "endTime" { printf "endTime         %s;\n", end; next }
        $1 == "deltaT" || $1 == "maxDeltaT" || $1 == "writeInterval" {
            v = $2; sub(";", "", v); printf "%-16s%.4g;\n", $1, v * sqrt(s); next }
        { print }' "$src/system/controlDict" > "$d/system/controlDict"
    for kv in $(echo "$CONTROL" | tr ' ;' '=\n'); do
        k=${kv%%=*}; v=${kv#*=}
        [ -n "$k" ] && sed -i "s/^$k .*/$k $v;/" "$d/system/controlDict"
    done
    sed -i "s/^columnWidth .*/columnWidth     $a;/" "$d/validation/metric"
    [ -n "$COEFFS" ] && sed -i "/^MPSCoeffs/,/^}/ s/^}\$/    $COEFFS\n}/" "$d/system/solverDict"
    if [ "$TENSION" = yes ]; then
        sed -i 's/^\( *nu .*\)$/\1\n    sigma       0.0728;     \/\/ N\/m, water against air/' "$d/constant/fluids"
        sed -i '/^forces/,/^{/ s/^{$/{\n    tension { type surfaceTension; }/' "$d/system/solverDict"
    fi
}

# Z at dense T through the case's own metric: a probe reference (Z = 0) in a scratch copy
ztable() {
    d=$1 p=$1/probe
    mkdir -p "$p"; cp -r "$d/system" "$d/constant" "$d/validation" "$p/"; ln -s "$d/output" "$p/output"
    { echo "T,Z"; awk 'BEGIN { for (i = 0; i <= 270; i++) printf "%.2f,0\n", 0.02 * i }'; } > "$p/validation/probe.csv"
    sed -i 's/"martin_moyce_1952.csv"/"probe.csv"/' "$p/validation/metric"
    "$MPSFLOW" validate -case "$p" > /dev/null 2>&1
    grep -v '^#' "$p/validation/result.csv" | tail -n +2 | cut -d, -f1,3 > "$d/ztable.csv"
}

one() { # N
    l0=$(awk -v a=$a -v n=$1 'BEGIN { printf "%.6g", a / n }')
    d=$work/a_$1
    prepare "$d"
    "$MPSFLOW" -case "$d" -l0 "$l0" > "$d/log" 2>&1
    e=$("$MPSFLOW" validate -case "$d" 2>&1 | awk '/error surgeFront/ { print $4 }')
    ztable "$d"
    printf "a/%-5s l0 %-9s fluid %-6s steps %-6s retried %s surgeFront %s (%s)\n" "$1" "$l0" \
        "$(awk '$1 == "fluid" { print $2; exit }' "$d/log")" "$(awk '/^Steps / { print $2 }' "$d/log")" \
        "$(awk '/^Steps / { print $4 }' "$d/log" | tr -d ')')" "$e" \
        "$(grep -m1 -o 'the run stops at time [0-9.e-]*' "$d/log" || echo "reached $end s")" > "$d/row"
}

echo "damBreak2D front, SCALE=$SCALE (a = $a m), endTime $end s, COEFFS='$COEFFS' CONTROL='$CONTROL'" \
    "TENSION=${TENSION:-no}; $(getconf _NPROCESSORS_ONLN) cores, load $(cut -d' ' -f1-3 /proc/loadavg)," \
    "$(date -u '+%Y-%m-%d %H:%M UTC')"
set -- "$@" ""
while [ -n "$1" ]; do
    one "$1" & [ -n "$2" ] && one "$2" & wait
    shift; [ -n "$1" ] && shift
done
labels=""
for d in $(ls -d "$work"/a_* | sort -t_ -k2 -g); do
    cat "$d/row"
    labels="$labels ${d##*/}=$d"
done
python3 bench/front_table.py --also bench/martin_moyce_1952_a2.25in.csv "$src/validation/martin_moyce_1952.csv" $labels
