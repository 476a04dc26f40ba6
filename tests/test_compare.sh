#!/bin/sh
# A small `mpsflow compare` on hydrostatic2D and scalarAdvection: two schemes
# at two particle spacings each. The CSV and the PNG are written, every run
# completes, and each scheme's error falls from the coarse to the fine
# spacing. argv: mpsflow, tutorials/ (the source tree's), folder of the plugins.
mpsflow=$1; tutorials=$2; export MPSFLOW_PLUGIN_PATH=$3
export OMP_NUM_THREADS=1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
passed=0; failed=0
fail() { echo "FAIL $*"; failed=$((failed + 1)); }
ok() { echo "ok   $*"; passed=$((passed + 1)); }

# compare_case NAME SCHEMES: run the compare on $dir/NAME and check its output.
compare_case() {
    name=$1; schemes=$2
    "$mpsflow" compare -case "$dir/$name" -solvers "$schemes" -resolutions '(0.02 0.01)' \
        > "$dir/$name.log" 2>&1 || { fail "$name: compare exited with $?"; tail -5 "$dir/$name.log"; return; }
    csv=$dir/$name/compare/compare.csv png=$dir/$name/compare/compare.png
    [ -s "$csv" ] || { fail "$name: no compare.csv"; return; }
    # A PNG starts with \211PNG.
    [ "$(head -c 4 "$png" 2>/dev/null | tail -c 3)" = "PNG" ] || { fail "$name: compare.png is not a PNG"; return; }
    rows=$(grep -vc -e '^#' -e '^scheme,' "$csv")
    [ "$rows" -eq 4 ] || { fail "$name: $rows rows in compare.csv, expected 4"; cat "$csv"; return; }
    # Per scheme: completed at both spacings, error(0.01) < error(0.02).
    verdict=$(awk -F, '!/^#/ && !/^scheme,/ {
            if ($9 != "completed") bad = bad " " $1 "@" $2 ":" $9;
            err[$1 "," $2] = $4; seen[$1] = 1 }
        END { for (s in seen) {
                c = err[s ",0.02"]; f = err[s ",0.01"];
                printf "%s %s -> %s; ", s, c, f;
                if (!(f + 0 < c + 0) || c == "" || f == "" || c == "nan" || f == "nan") bad = bad " " s ":not-falling" }
              if (bad != "") printf "BAD%s", bad }' "$csv")
    case "$verdict" in
        *BAD*) fail "$name: $verdict"; cat "$csv" ;;
        *) ok "$name: error falls with resolution: $verdict" ;;
    esac
    # CPU time (column 12): positive and, with one thread, not above the
    # wall time; pareto_cpu (13) is yes exactly when no other run is at least
    # as accurate and as cheap in CPU time and better in one.
    cpu=$(awk -F, '!/^#/ && !/^scheme,/ { n++; e[n] = $4; w[n] = $5; c[n] = $12; p[n] = $13; s[n] = $1 "@" $2 }
        END { for (i = 1; i <= n; i++) {
                if (!(c[i] + 0 > 0) || c[i] + 0 > 1.1 * w[i] + 0.1) bad = bad " " s[i] ":cpu=" c[i] ",wall=" w[i];
                front = (e[i] != "nan");
                for (j = 1; j <= n && front; j++)
                    if (j != i && e[j] != "nan" && e[j] + 0 <= e[i] + 0 && c[j] + 0 <= c[i] + 0 &&
                        (e[j] + 0 < e[i] + 0 || c[j] + 0 < c[i] + 0)) front = 0;
                if ((front ? "yes" : "no") != p[i]) bad = bad " " s[i] ":pareto_cpu=" p[i];
                printf "%s cpu %s wall %s; ", s[i], c[i], w[i] }
              if (bad != "") printf "BAD%s", bad }' "$csv")
    case "$cpu" in
        *BAD*) fail "$name: $cpu"; cat "$csv" ;;
        *) ok "$name: CPU time recorded, its Pareto front consistent: $cpu" ;;
    esac
}

# hydrostatic2D, shortened: 1 s, averaged after 0.5 s.
cp -r "$tutorials/hydrostatic2D" "$dir/hydrostatic2D"
rm -rf "$dir/hydrostatic2D/output" "$dir/hydrostatic2D/compare" "$dir/hydrostatic2D/postProcessing"
sed -i 's/^endTime .*/endTime 1.0;/' "$dir/hydrostatic2D/system/controlDict"
sed -i 's/^settleTime .*/settleTime 0.5;/' "$dir/hydrostatic2D/validation/metric"
# The paper's scheme with the Koshizuka lab's stabilisations (relaxation
# 0.2, collision), whose resting-tank error falls from l0 0.02 to 0.01.
# The MPS default (`scheme robust`, a mixed source) does not converge on a
# resting tank yet (0.0144 -> 0.0163 here): an open item of issue 13, in
# docs/validation-and-performance.md; this test is about compare itself.
awk '{ print } /^MPSCoeffs[ ]*$/ { want = 1; next } want && /^[{]/ { print "    scheme paper; relaxation 0.2; collision yes;"; want = 0 }' \
    "$tutorials/hydrostatic2D/system/solverDict" > "$dir/hydrostatic2D/system/solverDict"
grep -q "scheme paper;" "$dir/hydrostatic2D/system/solverDict" || { echo "FAIL could not add scheme paper"; exit 1; }
compare_case hydrostatic2D '(MPS MPS_diagonalPCG)'

# scalarAdvection: QUICK + filter (the case as it is) against upwind.
cp -r "$tutorials/scalarAdvection" "$dir/scalarAdvection"
rm -rf "$dir/scalarAdvection/output" "$dir/scalarAdvection/compare"
cat > "$dir/scalarAdvection/system/compareDict" <<'DICT'
FoamFile { version 2.0; format ascii; class dictionary; object compareDict; }
variants { MAFL_upwind { MAFLCoeffs { convection { scheme upwind; } } } }
DICT
compare_case scalarAdvection '(MAFL MAFL_upwind)'

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
