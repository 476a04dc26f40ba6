#!/bin/sh
# Wall weight walls (MPSCoeffs `wall wallWeight;`) against wall particles on
# the channel tutorials at a coarse spacing, l0 = H/10: poiseuille2D and
# couette2D, each run with both walls; the wall weight run must have no
# wall particles, reach its endTime, and score a `validate` error below the
# particle wall's (the no-slip condition on the face, not l0/2 outside it)
# and below 2%. With `laplacian leastSquares;` as well (the walls' virtual
# points in each LSMPS fit, mps_wall.c), both channels at H/10 and H/20:
# the error below 2% at H/20 and the observed order between the two above
# 1.85 (measured 1.89 on poiseuille2D, 2.04 on couette2D). Also: MAFL
# refuses the key, and leastSquares with a cylinder obstacle is refused,
# each naming the file, line and key.
# argv: mpsflow, tutorials/
mpsflow=$1; tutorials=$2
export OMP_NUM_THREADS=1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
failed=0
fail() { echo "FAIL $*"; failed=$((failed + 1)); }
for c in poiseuille2D couette2D; do
    for w in particles wallWeight; do
        d=$dir/${c}_$w
        cp -r "$tutorials/$c" "$d"
        sed -i "/^MPSCoeffs/,/^}/ s/^}\$/    wall $w;\n}/" "$d/system/solverDict"
        grep -q "wall $w;" "$d/system/solverDict" || { fail "$c: could not set wall $w"; continue; }
        "$mpsflow" -case "$d" -l0 0.01 > "$d/log" 2>&1 || { fail "$c $w: the run failed"; tail -5 "$d/log"; continue; }
        "$mpsflow" validate -case "$d" > "$d/validate" 2>&1 || { fail "$c $w: validate failed"; tail -3 "$d/validate"; continue; }
        awk '/error/ { e = $NF } END { print e }' "$d/validate" > "$d/error"
    done
    ep=$(cat "$dir/${c}_particles/error" 2>/dev/null); ew=$(cat "$dir/${c}_wallWeight/error" 2>/dev/null)
    [ -n "$ep" ] && [ -n "$ew" ] || continue
    grep -q "^    wall " "$dir/${c}_wallWeight/log" && fail "$c: wallWeight run has wall particles"
    grep -q "^    wall " "$dir/${c}_particles/log" || fail "$c: particle run lists no wall particles"
    echo "$c at l0 = H/10: error with wall particles $ep, with wall weight $ew"
    awk -v p="$ep" -v w="$ew" 'BEGIN { exit !(w < p && w < 0.02) }' ||
        fail "$c: wall weight error $ew not below the particle wall's $ep and 2%"
done
# laplacian leastSquares with the wall weight walls: second order.
for c in poiseuille2D couette2D; do
    for l0 in 0.01 0.005; do
        d=$dir/${c}_ls_$l0
        cp -r "$tutorials/$c" "$d"
        sed -i "/^MPSCoeffs/,/^}/ s/^}\$/    wall wallWeight;\n    laplacian leastSquares;\n}/" "$d/system/solverDict"
        "$mpsflow" -case "$d" -l0 $l0 > "$d/log" 2>&1 || { fail "$c leastSquares l0 $l0: the run failed"; tail -5 "$d/log"; continue; }
        grep -q "laplacian leastSquares" "$d/log" || fail "$c: the run does not take laplacian leastSquares"
        "$mpsflow" validate -case "$d" 2>&1 | awk '/error/ { e = $NF } END { print e }' > "$d/error"
    done
    e1=$(cat "$dir/${c}_ls_0.01/error" 2>/dev/null); e2=$(cat "$dir/${c}_ls_0.005/error" 2>/dev/null)
    [ -n "$e1" ] && [ -n "$e2" ] || { fail "$c leastSquares: no validate error"; continue; }
    order=$(awk -v a="$e1" -v b="$e2" 'BEGIN { printf "%.3f", log(a / b) / log(2) }')
    echo "$c, wall weight + leastSquares: error $e1 at H/10, $e2 at H/20, order $order"
    awk -v e="$e2" -v o="$order" 'BEGIN { exit !(e < 0.02 && o > 1.85) }' ||
        fail "$c leastSquares: error $e2 at H/20 (< 0.02) or order $order (> 1.85)"
done
# leastSquares takes the virtual points behind plane faces: a cylinder is refused.
d=$dir/cylinder
cp -r "$tutorials/poiseuille2D" "$d"
sed -i "/^MPSCoeffs/,/^}/ s/^}\$/    wall wallWeight;\n    laplacian leastSquares;\n}/" "$d/system/solverDict"
printf 'obstacles\n{\n    post\n    {\n        type cylinder;\n        centre (0.04 0.3 0);\n        radius 0.01;\n    }\n}\n' >> "$d/constant/geometry"
if "$mpsflow" -case "$d" -l0 0.01 -endTime 0.01 > "$d/log" 2>&1; then
    fail "leastSquares with a cylinder and wall wallWeight ran"
else
    grep -q "solverDict:[0-9]*:[0-9]*: key 'laplacian'.*cylinder" "$d/log" ||
        { fail "the cylinder's refusal does not name the file, line and key"; tail -3 "$d/log"; }
fi
# A composing solver refuses it, naming where it was set.
d=$dir/mafl
cp -r "$tutorials/poiseuille2D" "$d"
sed -i 's/^solver .*/solver          MAFL;/; s/^MPSCoeffs/MAFLCoeffs/; /periodic/d' "$d/system/solverDict"
sed -i "/^MAFLCoeffs/,/^}/ s/^}\$/    wall wallWeight;\n}/" "$d/system/solverDict"
if "$mpsflow" -case "$d" -l0 0.01 -endTime 0.01 > "$d/log" 2>&1; then
    fail "MAFL with wall wallWeight ran"
else
    grep -q "solverDict:[0-9]*.*wall wallWeight: only solver MPS" "$d/log" ||
        { fail "MAFL's refusal does not name the file, line and key"; tail -3 "$d/log"; }
fi
[ $failed = 0 ] && echo "wall_weight_channel: all passed"
exit $failed
