#!/bin/sh
# bench/compare_variants.sh: issue 13, every MPS variant at three spacings.
#
# For damBreak2D, hydrostatic2D and poiseuille2D (the tutorials as they are),
# writes a system/compareDict with one variant a line: `default` (the case
# with no scheme keys), each named scheme (paper, stabilised, robust), and
# each option of docs/topics/schemes.md on top of the default, one at a time.
# An option whose value is the default's own (read from the default's
# "MPS scheme ..." line) is left out, and so is a combination the solver
# refuses (found by `mpsflow -dryRun`); both are printed with the reason.
# Then `mpsflow compare` at each spacing, one mpsflow at a time with one
# thread, and bench/compare_variants_report.py writes the tables, the
# Pareto front on CPU (user + system) time and the plots.
#
#   bench/compare_variants.sh                 # all three cases, three spacings
#   CASES='poiseuille2D' bench/compare_variants.sh
#   L0_damBreak2D='0.04 0.02' bench/compare_variants.sh   # drop a spacing
#
# MPSFLOW (build/driver/mpsflow), WORK (build/compare_variants: removed at
# the start), FIGS (docs/figures). The spacings run coarse to fine, every
# case at a spacing before the next, so a stopped run loses the finest.
set -u
top=$(cd "$(dirname "$0")/.." && pwd)
MPSFLOW=${MPSFLOW:-$top/build/driver/mpsflow}
WORK=${WORK:-$top/build/compare_variants}
FIGS=${FIGS:-$top/docs/figures}
CASES=${CASES:-damBreak2D hydrostatic2D poiseuille2D}
# The tutorials' own l0 are 0.01 (damBreak2D, hydrostatic2D) and 0.005
# (poiseuille2D); each spacing is a factor 2 around them.
L0_damBreak2D=${L0_damBreak2D:-0.04 0.02 0.01}
L0_hydrostatic2D=${L0_hydrostatic2D:-0.04 0.02 0.01}
L0_poiseuille2D=${L0_poiseuille2D:-0.01 0.005 0.0025}
export OMP_NUM_THREADS=1
export MPSFLOW_PLUGIN_PATH=${MPSFLOW_PLUGIN_PATH:-$(dirname "$(dirname "$MPSFLOW")")/plugins}
[ -x "$MPSFLOW" ] || { echo "no mpsflow at $MPSFLOW (build first)"; exit 1; }
rm -rf "$WORK"; mkdir -p "$WORK" "$FIGS"
echo "load at start: $(cut -d' ' -f1-3 /proc/loadavg) ($(date -u '+%Y-%m-%d %H:%M:%S UTC'))"
echo "start $(date -u +%s)" > "$WORK/times"

# The options, each NAME KEYS (MPSCoeffs entries) on top of the default.
# The default's own value of each is left out below.
options() {
    cat <<'LIST'
scheme_paper            scheme paper;
scheme_stabilised       scheme stabilised;
scheme_robust           scheme robust;
source_density          source density;
source_mixed            source mixed;
source_mixedHigherOrder source mixedHigherOrder;
source_higherOrder      source higherOrder;
source_errorCompensating source errorCompensating;
gradient_paper          gradient paper;
gradient_corrected      gradient corrected;
gradient_leastSquares   gradient leastSquares;
laplacian_paper         laplacian paper;
laplacian_higherOrder   laplacian higherOrder;
laplacian_leastSquares  laplacian leastSquares;
shifting_none           shifting none;
shifting_fickian        shifting fickian;
surfaceDetection_numberDensity surfaceDetection numberDensity;
surfaceDetection_asymmetry surfaceDetection asymmetry;
wall_particles          wall particles;
wall_wallWeight         wall wallWeight;
viscosity_explicit      viscosity explicit;
viscosity_implicit      viscosity implicit;
collision_yes           collision yes;
collision_no            collision no;
LIST
}

# with_keys SRC DST KEYS: a copy of case SRC whose MPSCoeffs starts with KEYS
# (later entries of the same key in the case's own MPSCoeffs win, so a key
# the case sets itself is taken out first).
with_keys() {
    rm -rf "$2"; mkdir -p "$2"
    cp -r "$1/system" "$1/constant" "$2"
    [ -d "$1/validation" ] && cp -r "$1/validation" "$2"
    rm -f "$2/validation/result.csv" "$2/validation/result.png"
    [ -n "$3" ] || return 0
    keys=$3
    for k in $(echo "$keys" | tr ';' '\n' | awk 'NF { print $1 }'); do
        sed -i "/^MPSCoeffs/,/^}/ s/^\( *\)$k \+[^;]*;/\1/" "$2/system/solverDict"
    done
    awk -v keys="$keys" '{ print } /^MPSCoeffs[ ]*$/ { want = 1; next }
        want && /^[{]/ { print "    " keys; want = 0 }' "$2/system/solverDict" > "$2/system/solverDict.new"
    mv "$2/system/solverDict.new" "$2/system/solverDict"
    grep -qF "$keys" "$2/system/solverDict" || { echo "could not add '$keys' to $2"; return 1; }
}

for case in $CASES; do
    src=$top/tutorials/$case
    eval "l0s=\$L0_$case"
    coarse=${l0s%% *}
    dict=$WORK/$case.compareDict
    # The default: what it resolves to.
    with_keys "$src" "$WORK/check/$case/default" "" || exit 1
    "$MPSFLOW" -case "$WORK/check/$case/default" -l0 "$coarse" -dryRun > "$WORK/check/$case/default.log" 2>&1 ||
        { echo "$case: the default does not start:"; grep -v '^    from' "$WORK/check/$case/default.log" | tail -2; exit 1; }
    line=$(grep -m1 '^MPS scheme' "$WORK/check/$case/default.log")
    # "MPS scheme robust: source mixed, gradient paper, ..." into "scheme robust; source mixed; ..."
    own=$(echo "$line" | sed 's/^MPS //; s/: /; /; s/, /; /g; s/$/;/')
    grep -q '^ *viscosity *implicit' "$src/system/solverDict" && own="$own viscosity implicit;" || own="$own viscosity explicit;"
    grep -q '^ *wall *wallWeight' "$src/system/solverDict" && own="$own wall wallWeight;" || own="$own wall particles;"
    echo "== $case: default is $own"
    {
        echo 'FoamFile { version 2.0; format ascii; class dictionary; object compareDict; }'
        echo "// bench/compare_variants.sh: one variant a line on top of the case ($own)."
        echo 'variants'
        echo '{'
        echo '    default {}'
    } > "$dict"
    options | while read -r name keys; do
        # A named scheme is always run (robust repeats the default: the
        # spread between the two is the timing noise).
        case $name in
            scheme_*) ;;
            *) case " $own " in *" $keys "*) echo "   left out $name: the default's own ($keys)"; continue ;; esac ;;
        esac
        with_keys "$src" "$WORK/check/$case/$name" "$keys" || continue
        if ! "$MPSFLOW" -case "$WORK/check/$case/$name" -l0 "$coarse" -dryRun > "$WORK/check/$case/$name.log" 2>&1; then
            why=$(grep -m1 'FATAL ERROR' "$WORK/check/$case/$name.log" | sed 's/^--> mpsflow FATAL ERROR: //')
            echo "   left out $name: refused: $why"
            echo "$case,$name,refused: $why" >> "$WORK/left_out.csv"
            continue
        fi
        echo "    $name { MPSCoeffs { $keys } }" >> "$dict"
    done
    echo '}' >> "$dict"
    sed -n 's/^    \([A-Za-z_]*\) {.*/\1/p' "$dict" | tr '\n' ' ' > "$WORK/$case.variants"
    echo "   variants: $(cat "$WORK/$case.variants")"
done
rm -rf "$WORK/check"

# compare CASE L0: every variant of CASE at one spacing, in its own copy.
compare() {
    run=$WORK/$1_l0_$2
    with_keys "$top/tutorials/$1" "$run" "" || return 1
    cp "$WORK/$1.compareDict" "$run/system/compareDict"
    list="($(cat "$WORK/$1.variants"))"
    echo "== $1 at l0 = $2: $(date -u +%H:%M:%S), load $(cut -d' ' -f1-3 /proc/loadavg)"
    t0=$(date +%s)
    "$MPSFLOW" compare -case "$run" -solvers "$list" -resolutions "($2)" > "$run.log" 2>&1 ||
        { echo "   compare FAILED, see $run.log"; tail -3 "$run.log"; }
    echo "   $(( $(date +%s) - t0 )) s"
}
for i in 1 2 3; do
    for case in $CASES; do
        eval "l0s=\$L0_$case"
        l0=$(echo "$l0s" | awk -v i=$i '{ print $i }')
        [ -n "$l0" ] && compare "$case" "$l0"
    done
done
echo "end $(date -u +%s)" >> "$WORK/times"
echo "load at end: $(cut -d' ' -f1-3 /proc/loadavg) ($(date -u '+%Y-%m-%d %H:%M:%S UTC'))"
python3 "$top/bench/compare_variants_report.py" "$WORK" "$FIGS" $CASES
