#!/bin/sh
# tutorials/damBreakObstacle at l0 = 0.00487 (its 0.024 x 0.048 m block is
# 4 x 9 particles, 0.01948 x 0.04383 m) to t = 0.46 s, with the module's
# default scheme: before the obstacle's record was the box its particles
# stand for (core/scene/scene_solids.c), the watch saw the asked box and
# stopped the run at t = 0.445 s (throughWall: fluid particle 283 at
# (0.31356 0.0196), 0.93 l0 beside the block's last wall column, "inside
# obstacle 'block'"). Passes when the run reaches 0.46 s without a retry and
# the containment metric counts no fluid inside the block. About 1600 steps.
# argv: mpsflow, tutorials/damBreakObstacle
mpsflow=$1; tutorial=$2
export OMP_NUM_THREADS=1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cp -r "$tutorial/." "$dir/case/"; rm -rf "$dir/case/output" "$dir/case/postProcessing"
if ! "$mpsflow" -case "$dir/case" -l0 0.00487 -endTime 0.46 > "$dir/log" 2>&1; then
    echo "FAIL the run stopped:"; grep -E "FATAL|unstable" "$dir/log" | tail -3; exit 1
fi
steps=$(grep "^Steps" "$dir/log")
echo "$steps"
case "$steps" in
*"(retried 0)"*) ;;
*) echo "FAIL retries:"; grep "retrying" "$dir/log" | head -3 | cut -c1-300; exit 1 ;;
esac
"$mpsflow" validate -case "$dir/case" > "$dir/validate" 2>&1 || { tail -3 "$dir/validate"; exit 1; }
inside=$(awk -F, 'NR > 3 { s += $4 } END { print s + 0 }' "$dir/case/validation/result.csv")
[ "$inside" -eq 0 ] || { echo "FAIL $inside fluid particles inside the block over the snapshots"; exit 1; }
echo "ok   damBreakObstacle at l0 0.00487 to 0.46 s: no retry, none inside the block ($(tail -1 "$dir/validate"))"
