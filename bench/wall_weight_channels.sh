#!/bin/sh
# Wall particles against wall weight functions (MPSCoeffs `wall wallWeight;`,
# solvers/solver/mps/mps_wall.c) on the channel tutorials: poiseuille2D and
# couette2D at l0 = H/10, H/20, H/40 (0.01, 0.005, 0.0025 m), scored by
# their `validate` metric (relative RMS error of u against the series
# solution at t = 1 s), with the observed order between spacings. Variants:
# particles, wallWeight (eq. 7's wall term), wallWeightLS (wall wallWeight
# with laplacian leastSquares: the walls' virtual points in each LSMPS fit).
#   bench/wall_weight_channels.sh            # both cases, three spacings
#   CASES=couette2D L0S=0.00125 WALLS=wallWeightLS CSV=couette_h80.csv bench/wall_weight_channels.sh
#   CASES=couette2D L0S='0.01 0.005' bench/wall_weight_channels.sh
#   WALLS=wallWeight MAXDI=0.025 bench/wall_weight_channels.sh   # a quarter of the step
# Two runs at a time, one thread each; writes bench/results/wall_weight_channels.csv.
cd "$(dirname "$0")/.." || exit 1
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
export OMP_NUM_THREADS=1
cases=${CASES:-poiseuille2D couette2D}
l0s=${L0S:-0.01 0.005 0.0025}
walls=${WALLS:-particles wallWeight wallWeightLS}
out=bench/results; mkdir -p "$out"
csv=$out/${CSV:-wall_weight_channels.csv}
work=$(mktemp -d)
[ -n "$KEEP" ] || trap 'rm -rf "$work"' EXIT

one() { # CASE WALL L0
    d=$work/$1_$2_$3
    cp -r "tutorials/$1" "$d"
    case $2 in
    wallWeightLS) keys='    wall wallWeight;\n    laplacian leastSquares;' ;;
    *) keys="    wall $2;" ;;
    esac
    sed -i "/^MPSCoeffs/,/^}/ s/^}\$/$keys\n}/" "$d/system/solverDict"
    # the explicit viscous limit nu dt / l0^2 (the tutorials' 0.1; it sets dt ~ l0^2)
    [ -z "$MAXDI" ] || sed -i "s/^maxDi .*/maxDi $MAXDI;/" "$d/system/controlDict"
    t0=$(date +%s.%N)
    "$MPSFLOW" -case "$d" -l0 "$3" > "$d/log" 2>&1 || echo "$1 $2 $3: stopped" > "$d/err"
    t1=$(date +%s.%N)
    e=$("$MPSFLOW" validate -case "$d" 2>&1 | awk '/error/ { print $NF }' | tail -1)
    np=$(awk '/^Particles:/ { print $2 }' "$d/log")
    echo "$1,$2,$3,$np,$e,$(awk "BEGIN { printf \"%.1f\", $t1 - $t0 }")" > "$d/row"
}

echo "walls ($walls), channels, maxDi ${MAXDI:-0.1}; $(getconf _NPROCESSORS_ONLN) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $(date -u '+%Y-%m-%d %H:%M UTC')"
n=0
for c in $cases; do
    for l0 in $l0s; do
        for w in $walls; do
            one "$c" "$w" "$l0" &
            n=$((n + 1))
            [ $((n % 2)) = 0 ] && wait
        done
    done
done
wait
echo "case,wall,l0,particles,error,seconds" > "$csv"
for c in $cases; do for w in $walls; do for l0 in $l0s; do
    cat "$work/${c}_${w}_${l0}/row"; done; done; done >> "$csv"
# the observed order between successive spacings: log(e1/e2)/log(l1/l2)
awk -F, 'NR > 1 { key = $1 " " $2
        if (key == last && $5 > 0 && pe > 0) order = sprintf("%.2f", log(pe / $5) / log(pl / $3)); else order = "-"
        printf "%-13s %-11s l0 %-7s particles %-6s error %-10s order %-5s %6s s\n", $1, $2, $3, $4, $5, order, $6
        last = key; pe = $5; pl = $3 }' "$csv"
cat "$work"/*/err 2>/dev/null
echo "table: $csv"
