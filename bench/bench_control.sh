#!/bin/sh
# issue 18: what the control forces cost. The directedSplash tutorial (2-D,
# l0 = 0.01 m unless given: bench/bench_control.sh 0.005) with its attraction
# force and without it (the uncontrolled run), and with the three control
# forces acting nowhere (their regions above the tank): instructions of the
# whole run (valgrind --tool=callgrind's total, which does not depend on the
# load) for a short run, and each force's own seconds from the run's log
# (`Force NAME: calls, seconds`) for the full run. One thread.
# Writes bench/results/bench_control.md.
cd "${0%/*}/.." || exit 1
l0=${1:-0.01}
exe=$PWD/build/driver/mpsflow
[ -x "$exe" ] || { echo "build first: ./Allwmake"; exit 1; }
export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=PASSIVE # no re-exec under valgrind
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mk() { # NAME: a copy of the tutorial with its forces block as $2
    mkdir -p "$tmp/$1" && cp -r tutorials/directedSplash/system tutorials/directedSplash/constant "$tmp/$1/"
    [ -n "$2" ] && { sed -i '/control begin/,/control end/d' "$tmp/$1/system/solverDict"
                     sed -i "/^forces\$/{n;a\\$2
}" "$tmp/$1/system/solverDict"; }
}
mk controlled ""
mk uncontrolled " "
mk away "    steer { type attraction; shape box; min (0.7 1.5 0); max (1.0 1.7 0); attraction 150; influenceRadius 10; } push { type velocityRegion; shape sphere; centre (0.5 2 0); radius 0.2; velocity (1 0 0); } drag { type pathFollow; shape box; min (0 1.2 0); max (0.3 1.4 0); path { table ((0 (0.15 1.3 0)) (1 (0.8 1.3 0))); } }"
out=bench/results/bench_control.md
mkdir -p bench/results
{
    echo "# bench_control.sh, l0 = $l0 m, $(date -u '+%Y-%m-%d %H:%M UTC'), $(uname -n), load $(cut -d' ' -f1-3 /proc/loadavg)"
    echo
    echo "| run | steps | wall s | force seconds (calls) |"
    echo "|---|---|---|---|"
    for c in uncontrolled controlled away; do
        "$exe" -case "$tmp/$c" -l0 "$l0" > "$tmp/$c.log" 2>&1 || { tail -n 5 "$tmp/$c.log"; exit 1; }
        steps=$(sed -n 's/^Steps \([0-9]*\).*/\1/p' "$tmp/$c.log")
        wall=$(sed -n 's/.*wall time \([0-9.]*\) s.*/\1/p' "$tmp/$c.log")
        forces=$(grep '^Force ' "$tmp/$c.log" | sed 's/^Force \([^:]*\): \([0-9]*\) calls, \([0-9.]*\) s/\1 \3 (\2)/' | paste -sd ';' -)
        echo "| $c | $steps | $wall | $forces |"
    done
    if command -v valgrind > /dev/null; then
        echo
        echo "Instructions of a 0.05 s run (callgrind, whole process):"
        echo
        echo "| run | instructions |"
        echo "|---|---|"
        for c in uncontrolled controlled away; do
            rm -rf "$tmp/$c/output"
            valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$c" "$exe" -case "$tmp/$c" \
                -l0 "$l0" -endTime 0.05 > "$tmp/$c.cg.log" 2>&1
            ir=$(sed -n 's/^summary: //p' "$tmp/cg.$c")
            echo "| $c | $ir |"
        done
    fi
} | tee "$out"
