#!/bin/sh
# Bad input to the driver: each broken case must exit non-zero (not crash:
# exit status 1 or 2, no signal) with a message that names what is wrong and
# where. argv: mpsflow, tutorials/damBreak2D
mpsflow=$1; tutorial=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
failed=0; passed=0

# expect NAME PATTERN [mpsflow args...]: run, then check status and message.
expect() {
    name=$1; pattern=$2; shift 2
    "$mpsflow" "$@" > "$dir/out" 2>&1
    status=$?
    if [ $status -ne 1 ] && [ $status -ne 2 ]; then
        echo "FAIL $name: exit status $status (a crash or a success)"; cat "$dir/out"; failed=$((failed + 1)); return
    fi
    if ! grep -qE -- "$pattern" "$dir/out"; then
        echo "FAIL $name: message does not match /$pattern/:"; cat "$dir/out"; failed=$((failed + 1)); return
    fi
    echo "ok   $name: $(grep -E -- "$pattern" "$dir/out" | head -1 | cut -c1-160)"
    passed=$((passed + 1))
}

# fresh CASE: a copy of the tutorial in $dir/case
fresh() { rm -rf "$dir/case"; cp -r "$tutorial/." "$dir/case/"; rm -rf "$dir/case/output"; }

fresh
expect "no such case" "cannot open.*is '$dir/nothing' a case directory" -case "$dir/nothing" -dryRun
expect "unknown option" "unknown option '-dryrun'.*did you mean '-dryRun'" -case "$dir/case" -dryrun
expect "bad -l0" "-l0 takes a positive number, not 'abc'" -case "$dir/case" -l0 abc -dryRun
expect "unknown command" "unknown command 'modulse'.*did you mean 'modules'" modulse

fresh; sed -i 's/^endTime /endTme  /' "$dir/case/system/controlDict"
expect "misspelt key" "controlDict:[0-9]+:[0-9]+: unknown key 'endTme'.*did you mean 'endTime'" -case "$dir/case" -dryRun

fresh; sed -i 's/^endTime .*/endTime abc;/' "$dir/case/system/controlDict"
expect "wrong type" "controlDict:[0-9]+:[0-9]+: key 'endTime': expected a number" -case "$dir/case" -dryRun

fresh; sed -i 's/^    beta .*/    beta 2;/' "$dir/case/system/solverDict"
expect "out of range" "solverDict:[0-9]+:[0-9]+: key 'beta': 2 is out of range" -case "$dir/case" -dryRun

fresh; sed -i 's/^solver .*/solver MSP;/' "$dir/case/system/solverDict"
expect "unknown solver" "unknown solver module 'MSP'.*valid solver modules: MPS" -case "$dir/case" -dryRun

fresh; sed -i 's/solver          PCG_BoomerAMG;/solver PCG_AMG;/' "$dir/case/system/solverDict"
expect "unknown pressure solver" "unknown pressure module 'PCG_AMG'.*PCG_BoomerAMG" -case "$dir/case" -dryRun

fresh; sed -i 's/fluid       water;/fluid       watr;/' "$dir/case/constant/geometry"
expect "unknown fluid" "geometry:[0-9]+:[0-9]+: fluid block 'column': unknown fluid 'watr'.*did you mean 'water'" -case "$dir/case" -dryRun

fresh; sed -i 's/^    rho .*/    rho;/' "$dir/case/constant/fluids"
expect "key without value" "fluids:[0-9]+:[0-9]+:" -case "$dir/case" -dryRun

fresh; sed -i 's/^{$/{{/' "$dir/case/system/controlDict"
expect "unbalanced brace" "controlDict:[0-9]+:[0-9]+:" -case "$dir/case" -dryRun

fresh; printf '\000\001\002binary' > "$dir/case/constant/fluids"
expect "binary file" "fluids:1:[0-9]+: binary data" -case "$dir/case" -dryRun

fresh; : > "$dir/case/constant/geometry"
expect "empty file" "geometry.*empty" -case "$dir/case" -dryRun

fresh; sed -i 's/("libkineticEnergy.so")/("libnoSuchThing.so")/' "$dir/case/system/controlDict"
expect "missing plugin" "cannot load plugin 'libnoSuchThing.so'.*MPSFLOW_PLUGIN_PATH" -case "$dir/case" -dryRun

fresh
python3 - "$dir/case/constant/geometry" <<'PY'
import sys
p = sys.argv[1]; s = open(p).read()
s = s.replace("min         (0 0 0);\n        max         (0.25", "min         (-0.02 0 0);\n        max         (0.25", 1)
open(p, "w").write(s)
PY
expect "block inside a wall" "closer than l0/2.*reach into a wall" -case "$dir/case" -dryRun

fresh
expect "validate without output" "no output folder: run the case first" validate -case "$dir/case"
fresh; rm "$dir/case/validation/metric"
expect "validate without metric" "cannot open dictionary file '.*validation/metric'" validate -case "$dir/case"
fresh
expect "restart without snapshots" "no snapshot to restart from.*-latestTime" -case "$dir/case" -latestTime

# A pressure solve that never converges: retried with smaller steps, then a
# clean stop; every snapshot left behind must be whole.
fresh; sed -i 's/    tolerance       1e-8;/    tolerance 1e-8; maxIter 2;/' "$dir/case/system/solverDict"
expect "solve not converging" "retrying with deltaT.*retry 4 of 4" -case "$dir/case" -endTime 0.05
expect "  ... then stopping" "not converged after 2 iterations" -case "$dir/case" -endTime 0.05 -overwrite
for f in "$dir"/case/output/snapshot_*.h5; do
    if h5dump -H "$f" > /dev/null 2>&1; then passed=$((passed + 1)); else
        echo "FAIL snapshot $f is not readable after the failed run"; failed=$((failed + 1)); fi
done
[ -z "$(ls "$dir"/case/output/*.tmp 2>/dev/null)" ] || { echo "FAIL a temporary file was left"; failed=$((failed + 1)); }

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
