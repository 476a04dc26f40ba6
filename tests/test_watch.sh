#!/bin/sh
# Each criterion of the run's watch fires on a case built to trip it, the run
# stops with that criterion named in its message and in output/runSummary,
# and every snapshot it leaves is whole. argv: mpsflow, tutorials/damBreak2D,
# folder of libfaultInjection.so
mpsflow=$1; tutorial=$2; export MPSFLOW_PLUGIN_PATH=$3
export OMP_NUM_THREADS=1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
passed=0; failed=0
fail() { echo "FAIL $*"; failed=$((failed + 1)); }

# trip NAME CRITERION: run $dir/case (prepared by the caller) and check.
trip() {
    name=$1; criterion=$2; shift 2
    "$mpsflow" -case "$dir/case" -quiet "$@" > "$dir/log" 2>&1
    status=$?
    [ $status -eq 1 ] || { fail "$name: exit status $status, expected 1"; tail -5 "$dir/log"; return; }
    grep -q "unstable ($criterion)" "$dir/log" || { fail "$name: no 'unstable ($criterion)' in the log"; grep -E "FATAL|unstable" "$dir/log" | head -3; return; }
    grep -q "^criterion *$criterion;" "$dir/case/output/runSummary" || { fail "$name: runSummary does not name $criterion"; cat "$dir/case/output/runSummary"; return; }
    for f in "$dir"/case/output/snapshot_*.h5; do
        h5dump -H "$f" > /dev/null 2>&1 || { fail "$name: $f is not whole"; return; }
    done
    [ -z "$(ls "$dir"/case/output/*.tmp 2>/dev/null)" ] || { fail "$name: a temporary file was left"; return; }
    echo "ok   $name: $(grep -o "unstable ($criterion)[^;]*" "$dir/log" | tail -1 | cut -c1-150)"
    passed=$((passed + 1))
}

fresh() {
    rm -rf "$dir/case"; cp -r "$tutorial/." "$dir/case/"; rm -rf "$dir/case/output" "$dir/case/postProcessing"
    sed -i 's/^libs .*/libs ("libkineticEnergy.so" "libfaultInjection.so");/' "$dir/case/system/controlDict"
}
add_force() { # the fault force, with its settings
    python3 - "$dir/case/system/solverDict" "$1" <<'PY'
import sys
p, body = sys.argv[1], sys.argv[2]
s = open(p).read()
s = s.replace("forces\n{", "forces\n{\n    fault { type fault; %s }" % body, 1)
open(p, "w").write(s)
PY
}

fresh; add_force "nanAt 0.02;"
trip "NaN injected" nonFinite -endTime 0.1
grep -q "force 'fault' gave" "$dir/log" || fail "NaN injected: the force is not named"

# A linear solve that returns a NaN: mf_pressure_solve's check names it.
fresh; add_force "solveNanAt 0.02;"
trip "NaN from the pressure solve" nonFinite -endTime 0.1
grep -q "PCG_BoomerAMG returned a non-finite p" "$dir/log" || fail "NaN from the solve: the solve is not named"

fresh; add_force "pushAt 0.02; push (0 -1e7 0);"
printf 'watch { energyTolerance 1e6; }\n' >> "$dir/case/system/controlDict"
trip "pushed through the floor" throughWall -endTime 0.1

# The column without walls, pushed apart from its centroid: it thins until
# its mean number density is below half of what it started with.
fresh; add_force "scatterAt 0.01; scatter 2e4;"
python3 - "$dir/case/constant/geometry" <<'PY'
import re, sys
p = sys.argv[1]
s = open(p).read()
i = s.index("walls")
j = s.index("{", i); depth = 0
for k in range(j, len(s)):
    depth += {"{": 1, "}": -1}.get(s[k], 0)
    if depth == 0:
        break
open(p, "w").write(s[:i] + s[k + 1:])
PY
trip "fluid pushed apart" densityCollapse -endTime 0.2

# The paper's scheme without stabilisation blows up on this case (README):
# the energy criterion sees it first. When it blows up depends on the
# rounding of the pressure solves (t = 0.29 to 0.49 s with one solver or
# another, a tolerance of 1e-8 or 1e-9), and so does what a retry of the
# step meets: a particle may then pass the floor within the retried step
# (throughWall, checked before energy). No retry: the first failure ends
# the run. (The module's default scheme survives it: docs/topics/schemes.md.)
fresh; awk '{ print } /^MPSCoeffs[ ]*$/ { want = 1; next } want && /^[{]/ { print "    scheme          paper;"; want = 0 }' \
    "$dir/case/system/solverDict" > "$dir/solverDict" && mv "$dir/solverDict" "$dir/case/system/solverDict"
grep -q "scheme          paper;" "$dir/case/system/solverDict" || { echo "FAIL could not set scheme paper"; exit 1; }
sed -i 's/^maxRetries.*//' "$dir/case/system/controlDict"; printf 'maxRetries 0;\n' >> "$dir/case/system/controlDict"
trip "plain scheme blowing up" energy

# Kinetic energy from nothing: from t = 0.02 every step ends with 3 m/s
# added to the fluid (the fault's kick, no force: no work), far above all
# the column can have (its start, its available potential energy). The
# energy criterion is held off to see the availableEnergy one catch it.
fresh; add_force "kickAt 0.02; kick (3 0 0);"
printf 'watch { energyTolerance 1e6; }\n' >> "$dir/case/system/controlDict"
trip "energy from no source" availableEnergy -endTime 0.1
# The budget by hand: the 125 kg column (25 x 50 particles at 0.01 m) drops
# its centroid from 0.25 m to the middle of a 0.0625 m layer on the 2 m
# floor: 125 x 9.81 x (0.25 - 0.03125) = 268.242 J; the layer's own energy
# 125 x 9.81 x 0.03125 = 38.3203 J.
grep -q "available to it 268.242 J .* the level fluid's own 38.3203 J" "$dir/log" &&
    { echo "ok   energy from no source: the available 268.242 J and the layer's 38.3203 J as by hand"; passed=$((passed + 1)); } ||
    fail "energy from no source: not the hand's 268.242 J available and 38.3203 J of the layer"
grep -q "back at the last good state, written as a snapshot" "$dir/log" &&
    ls "$dir"/case/output/snapshot_*.h5 > /dev/null 2>&1 ||
    fail "energy from no source: the last good state was not kept as a snapshot"
# ... and with the criterion off the same two kicked steps go on.
fresh; add_force "kickAt 0.02; kick (3 0 0);"
printf 'watch { energyTolerance 1e6; availableEnergy no; }\n' >> "$dir/case/system/controlDict"
"$mpsflow" -case "$dir/case" -quiet -endTime 0.0215 > "$dir/log" 2>&1 &&
    ! grep -q "availableEnergy" "$dir/log" &&
    { echo "ok   availableEnergy no: the kicked run goes on"; passed=$((passed + 1)); } ||
    { fail "availableEnergy no: the kicked run stopped"; grep -E "FATAL|unstable" "$dir/log" | head -2; }

# A pressure solve held to one PCG iteration at a tolerance it cannot reach.
fresh; sed -i 's/^\( *\)tolerance .*/\1tolerance 1e-14; maxIter 1;/' "$dir/case/system/solverDict"
sed -i 's/^maxRetries.*//' "$dir/case/system/controlDict"; printf 'maxRetries 1;\n' >> "$dir/case/system/controlDict"
trip "pressure solve not converging" pressureSolve -endTime 0.1

# And the stabilised case runs to the end with the watch on.
fresh
"$mpsflow" -case "$dir/case" -quiet -endTime 0.3 > "$dir/log" 2>&1 && grep -q "^status *completed;" "$dir/case/output/runSummary" &&
    { echo "ok   stable run: completed with the watch on"; passed=$((passed + 1)); } || fail "stable run did not complete"
# The watch makes no force pass of its own: one call of each force per attempt.
steps=$(sed -n 's/^Steps \([0-9]*\) (retried \([0-9]*\)).*/\1 \2/p' "$dir/log")
calls=$(sed -n 's/^Force gravity: \([0-9]*\) calls.*/\1/p' "$dir/log")
set -- $steps
[ -n "$calls" ] && [ "$calls" -eq $(($1 + $2)) ] &&
    { echo "ok   one force pass a step: gravity ran $calls times in $1 steps ($2 retried)"; passed=$((passed + 1)); } ||
    fail "force passes: gravity ran '$calls' times in '$steps' steps (retried)"

# The log says how close the stable run came to the energy criterion.
grep -q "^Watch: kinetic energy above its start and the forces' work by at most .* (t = .*; energyTolerance 0.02)" "$dir/log" &&
    { echo "ok   $(grep '^Watch:' "$dir/log" | head -1 | cut -c1-120)"; passed=$((passed + 1)); } || fail "no Watch: line in the stable run's log"
# ... and how close to the availableEnergy criterion, which applies here
# (one tank, its floor and sides closed) and stays below its tolerance.
peak=$(sed -n 's/^Watch: availableEnergy: .* by at most \([^ ]*\) of them.*(t = .*; availableEnergyTolerance 0.05)$/\1/p' "$dir/log")
[ -n "$peak" ] && python3 -c "import sys; sys.exit(not float('$peak') < 0.05)" &&
    { echo "ok   availableEnergy peak $peak on the stable run"; passed=$((passed + 1)); } ||
    fail "stable run: no Watch: availableEnergy line below 0.05 ('$peak')"

# A lid drives the fluid: the lid's work is no force module's, and the
# criterion counts 1/2 M u_w^2 in full (with it only in the scale, the
# excess reached 0.18 of it, above the default 0.02, and a plain Couette
# start-up would stop as "unstable").
rm -rf "$dir/couette"; cp -r "$tutorial/../couette2D" "$dir/couette"; rm -rf "$dir/couette/output"
"$mpsflow" -case "$dir/couette" > "$dir/log" 2>&1 && grep -q "^status *completed;" "$dir/couette/output/runSummary" &&
    { echo "ok   moving lid: completed with the default energyTolerance"; passed=$((passed + 1)); } ||
    { fail "moving lid: stopped"; grep FATAL "$dir/log" | head -2; }
# Without gravity there is no potential energy to bound the kinetic energy
# by: the availableEnergy criterion says once that it does not apply.
[ "$(grep -c '^Watch: no availableEnergy check: no gravity$' "$dir/log")" -eq 1 ] &&
    ! grep -q "^Watch: availableEnergy:" "$dir/log" &&
    { echo "ok   no gravity: the log says once that availableEnergy does not apply"; passed=$((passed + 1)); } ||
    fail "no gravity: no single 'Watch: no availableEnergy check: no gravity' line"

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
