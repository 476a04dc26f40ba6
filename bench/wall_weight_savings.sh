#!/bin/sh
# What `wall wallWeight;` saves against wall particles on the dam breaks:
# particle counts (mpsflow -dryRun), peak resident memory and time per step
# of a short run (the run summary's lines), and callgrind instruction counts
# of a shorter one (load-independent A/B), for tutorials/damBreak2D (l0 0.01)
# and bench/cases/damBreak3D (l0 0.009, 99,009 particles with walls).
#   bench/wall_weight_savings.sh              # both cases
#   CASES=damBreak2D NOCALLGRIND=1 bench/wall_weight_savings.sh
# One run at a time, one thread.
cd "$(dirname "$0")/.." || exit 1
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
export OMP_NUM_THREADS=1
# mpsflow re-executes itself to set OpenMP's wait policy when none is set,
# and valgrind does not follow the exec: set it here.
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
work=$(mktemp -d)
[ -n "$KEEP" ] || trap 'rm -rf "$work"' EXIT
echo "wall particles vs wallWeight: savings; $(getconf _NPROCESSORS_ONLN) cores, load $(cut -d' ' -f1-3 /proc/loadavg), $(date -u '+%Y-%m-%d %H:%M UTC')"
for c in ${CASES:-damBreak2D damBreak3D}; do
    case $c in
        damBreak2D) src=tutorials/damBreak2D; run_end=0.1; cg_end=0.02 ;;
        damBreak3D) src=bench/cases/damBreak3D; run_end=0.005; cg_end=${CG3D:-} ;;  # callgrind of 99,009 particles: CG3D=0.0005
    esac
    for w in particles wallWeight; do
        d=$work/${c}_$w
        cp -r "$src" "$d"
        sed -i "/^MPSCoeffs/,/^}/ s/^}\$/    wall $w;\n}/" "$d/system/solverDict"
        "$MPSFLOW" -case "$d" -dryRun > "$d/dry" 2>&1
        counts=$(awk '/^Particles:/ { printf "%s in all", $2 } /^    (fluid|wall|dummy) / { printf ", %s %s", $1, $2 }' "$d/dry")
        "$MPSFLOW" -case "$d" -endTime $run_end > "$d/log" 2>&1 || echo "$c $w: run failed"
        steps=$(awk '/^Steps / { print $2 }' "$d/log")
        peak=$(awk '/peak memory/ { for (i = 1; i <= NF; i++) if ($i == "memory") print $(i + 1), $(i + 2) }' "$d/log" | tail -1)
        per=$(awk '/^MPS time per step/ { print $NF }' "$d/log")
        ir="-"
        if [ -z "$NOCALLGRIND" ] && [ -n "$cg_end" ] && command -v valgrind > /dev/null; then
            rm -rf "$d/output" "$d/postProcessing"
            valgrind --tool=callgrind --callgrind-out-file="$d/cg.out" "$MPSFLOW" -case "$d" \
                -endTime $cg_end > "$d/cg.log" 2>&1
            ir=$(sed -n "s/^summary: //p" "$d/cg.out")
            cgsteps=$(awk '/^Steps / { print $2 }' "$d/cg.log")
            ir="$ir instructions in $cgsteps steps"
        fi
        echo "$c $w: particles $counts; to t = $run_end: $steps steps, $per ms a step, peak $peak; callgrind to t = $cg_end: $ir"
    done
done
