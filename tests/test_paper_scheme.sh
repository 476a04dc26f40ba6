#!/bin/sh
# The paper scheme (`scheme paper;`) gives today's results bit for bit: each
# case of tests/paper_scheme/ runs with `scheme paper;` added to its
# solver's Coeffs, and its last snapshot's particle groups are compared by
# h5diff (exact: no tolerance) with tests/paper_scheme/reference/<case>.h5,
# written from the same case files by main before the schemes merged, at
# 34602fe (speed's own PCG: rounding differs from 30c2725's hypre PCG):
#   MPS relaxation 0.2 + collision + collisionAfterCorrection (damBreak2D),
#   MPS plain (hydrostatic2D: relaxation 1, no collision),
#   MPS implicit viscosity on a periodic channel (poiseuille2D),
#   MPS 3-D (damBreak3D), MPS-MAFL (scalarAdvection), multiFluid water/air
#   with the two-step pressure (waterAirDamBreak).
# argv: mpsflow, tests/paper_scheme
mpsflow=$1; cases=$2
export OMP_NUM_THREADS=1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
passed=0; failed=0
for c in damBreak2D hydrostatic2D poiseuille2D damBreak3D scalarAdvection waterAirDamBreak; do
    rm -rf "$dir/$c"; cp -r "$cases/$c" "$dir/$c"
    # `scheme paper;` as the first entry of the Coeffs dictionary
    awk '{ print }
         /^(MPSCoeffs|MAFLCoeffs|multiFluidCoeffs)[ ]*$/ { want = 1; next }
         want && /^[{]/ { print "    scheme paper;"; want = 0 }' \
        "$cases/$c/system/solverDict" > "$dir/$c/system/solverDict"
    grep -q "scheme paper;" "$dir/$c/system/solverDict" ||
        { echo "FAIL $c: could not add scheme paper"; failed=$((failed + 1)); continue; }
    if ! "$mpsflow" -case "$dir/$c" > "$dir/$c.log" 2>&1; then
        echo "FAIL $c: the run failed"; tail -5 "$dir/$c.log"; failed=$((failed + 1)); continue
    fi
    grep -q "^MPS scheme paper: source density, gradient paper, laplacian paper, shifting none, surfaceDetection numberDensity" "$dir/$c.log" ||
        { echo "FAIL $c: the log does not say the paper scheme ran"; failed=$((failed + 1)); continue; }
    last=$(ls "$dir/$c/output"/snapshot_*.h5 | tail -1)
    ref="$cases/reference/$c.h5"
    ok=1
    for g in $(h5ls "$ref" | awk '/^PartType/ {print $1}'); do
        if ! h5diff -r "$ref" "$last" "/$g" "/$g" > "$dir/$c.diff" 2>&1; then
            echo "FAIL $c: /$g differs from main's"; head -5 "$dir/$c.diff"; ok=0
        fi
    done
    if [ $ok = 1 ]; then
        echo "ok   $c: $(h5ls "$ref" | awk '/^PartType/ {print $1}' | tr '\n' ' ')identical to main's"
        passed=$((passed + 1))
    else
        failed=$((failed + 1))
    fi
done
echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
