#!/bin/sh
# damBreak2D's front error (the tutorial's surgeFront metric against Martin &
# Moyce) with wall particles and with `wall wallWeight;`, at l0 = 0.02, 0.01
# and 0.005 m (the robust default scheme). Two runs at a time, one thread.
#   bench/wall_weight_dambreak.sh          L0S='0.02 0.01' to pick spacings
cd "$(dirname "$0")/.." || exit 1
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
export OMP_NUM_THREADS=1
work=$(mktemp -d)
[ -n "$KEEP" ] || trap 'rm -rf "$work"' EXIT
one() { # WALL L0
    d=$work/$1_$2
    cp -r tutorials/damBreak2D "$d"
    sed -i "/^MPSCoeffs/,/^}/ s/^}\$/    wall $1;\n}/" "$d/system/solverDict"
    t0=$(date +%s)
    "$MPSFLOW" -case "$d" -l0 "$2" > "$d/log" 2>&1 || echo "(stopped: $(grep -m1 'FATAL' "$d/log" | cut -c1-80))" > "$d/err"
    t1=$(date +%s)
    e=$("$MPSFLOW" validate -case "$d" 2>&1 | awk '/error/ { print $NF }' | tail -1)
    printf "damBreak2D %-11s l0 %-6s particles %-6s steps %-6s surgeFront error %-10s %4d s %s\n" "$1" "$2" \
        "$(awk '/^Particles:/ { print $2 }' "$d/log")" "$(awk '/^Steps / { print $2 }' "$d/log")" "$e" \
        $((t1 - t0)) "$(cat "$d/err" 2>/dev/null)" > "$d/row"
}
echo "damBreak2D front, wall particles vs wallWeight; $(getconf _NPROCESSORS_ONLN) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $(date -u '+%Y-%m-%d %H:%M UTC')"
for l0 in ${L0S:-0.02 0.01 0.005}; do
    one particles "$l0" & one wallWeight "$l0" & wait
done
for w in particles wallWeight; do for l0 in ${L0S:-0.02 0.01 0.005}; do cat "$work/${w}_$l0/row"; done; done
