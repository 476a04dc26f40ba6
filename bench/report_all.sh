#!/bin/sh
# bench/report_all.sh: regenerate, from a clean build, the error-against-run-
# time plots of the tutorial cases and the stability maps of issue 7, and the
# section of docs/validation-and-performance.md that shows them (between its
# "report_all" markers, section 2), with the machine and the date.
#
#   bench/report_all.sh            # build-report/ from scratch, then everything
#   bench/report_all.sh -keep      # reuse build-report/ if it is there
#
# Runs one mpsflow at a time with one thread (about 15-20 minutes on the
# project's 2-core machine). Work folders: build-report/report_work/ (copies
# of the cases, removed at the start); figures and tables: docs/figures/.
set -u
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top" || exit 1
build=$top/build-report
if [ "${1:-}" != "-keep" ] || [ ! -x "$build/driver/mpsflow" ]; then
    rm -rf "$build"
    meson setup "$build" --buildtype=debugoptimized > /dev/null || exit 1
fi
ninja -C "$build" > "$build/report_build.log" 2>&1 || { tail -20 "$build/report_build.log"; exit 1; }
mpsflow=$build/driver/mpsflow
export MPSFLOW_PLUGIN_PATH=$build/plugins OMP_NUM_THREADS=1
work=$build/report_work
figs=$top/docs/figures
rm -rf "$work"; mkdir -p "$work" "$figs"
start=$(date +%s)

# fresh SRC NAME: a clean copy of a case folder in $work/NAME.
fresh() {
    cp -r "$1" "$work/$2"
    rm -rf "$work/$2/output" "$work/$2/compare" "$work/$2/stability" "$work/$2/postProcessing" \
           "$work/$2"/log.* "$work/$2/validation/result.csv" "$work/$2/validation/result.png"
}

# compare NAME SCHEMES RESOLUTIONS
compare() {
    echo "== compare $1: $2 at $3"
    t0=$(date +%s)
    "$mpsflow" compare -case "$work/$1" -solvers "$2" -resolutions "$3" > "$work/$1.compare.log" 2>&1 ||
        { echo "   FAILED, see $work/$1.compare.log"; tail -3 "$work/$1.compare.log"; }
    grep "^Pareto" "$work/$1.compare.log" | sed 's/^/   /'
    cp "$work/$1/compare/compare.csv" "$figs/compare_$1.csv" 2>/dev/null
    cp "$work/$1/compare/compare.png" "$figs/compare_$1.png" 2>/dev/null
    echo "   $(( $(date +%s) - t0 )) s"
}

# stability NAME SCHEMES [SWEEPS]
stability() {
    echo "== stability $1: $2"
    t0=$(date +%s)
    if [ $# -ge 3 ]; then
        "$mpsflow" stability -case "$work/$1" -solvers "$2" -sweeps "$3" > "$work/$1.stability.log" 2>&1
    else
        "$mpsflow" stability -case "$work/$1" -solvers "$2" > "$work/$1.stability.log" 2>&1
    fi || { echo "   FAILED, see $work/$1.stability.log"; tail -3 "$work/$1.stability.log"; }
    cp "$work/$1/stability/stability.csv" "$figs/stability_$1.csv" 2>/dev/null
    for png in "$work/$1"/stability/*.png; do
        [ -f "$png" ] && cp "$png" "$figs/stability_$1_$(basename "$png")"
    done
    echo "   $(( $(date +%s) - t0 )) s"
}

# ---- error against run time (tutorials) ---------------------------------
fresh tutorials/hydrostatic2D hydrostatic2D
compare hydrostatic2D '(MPS MPS_plain MPS_diagonalPCG)' '(0.02 0.01)'
fresh tutorials/damBreak2D damBreak2D
compare damBreak2D '(MPS MPS_plain MPS_implicitViscosity)' '(0.02 0.01)'
fresh tutorials/scalarAdvection scalarAdvection
cp bench/cases/compare/scalarAdvection.compareDict "$work/scalarAdvection/system/compareDict"
# Not 0.005: the tutorial's fixed deltaT (0.002 s) is Courant 0.4 there, where
# MPS-MAFL's error jumps (docs/validation-and-performance.md, section 2).
compare scalarAdvection '(MAFL MAFL_QUICK_noFilter MAFL_upwind)' '(0.02 0.01)'
fresh tutorials/squareDroplet squareDroplet
cp bench/cases/compare/squareDroplet.compareDict "$work/squareDroplet/system/compareDict"
compare squareDroplet '(multiFluid multiFluid_exactCurvature)' '(0.002 0.001)'
fresh tutorials/poiseuille2D poiseuille2D
compare poiseuille2D '(MPS MPS_implicitViscosity)' '(0.01 0.005 0.0025)'

# ---- stability maps -------------------------------------------------------
rm -rf "$work/damBreak2D"; fresh tutorials/damBreak2D damBreak2D
stability damBreak2D '(MPS MPS_plain MPS_implicitViscosity)'
for c in columnImpact singleParticle freeFall overlapped thinSheet cornerJet; do
    fresh "bench/cases/extreme/$c" "$c"
    stability "$c" '(MPS MPS_plain MPS_implicitViscosity)'
done
fresh bench/cases/stiff/densityRatio densityRatio
stability densityRatio '(multiFluid multiFluid_oneSolve multiFluid_implicitViscosity)'
fresh bench/cases/stiff/surfaceTension surfaceTension
stability surfaceTension '(multiFluid multiFluid_capillary10 multiFluid_pressureST)'

total=$(( $(date +%s) - start ))
echo "== all done in $total s; figures in docs/figures/"

# ---- the section of docs/validation-and-performance.md ----------------------
cpu=$(grep -m1 "model name" /proc/cpuinfo | sed 's/.*: //')
machine="$(nproc --all) cores ($cpu), $(free -g | awk '/^Mem/ {print $2}') GB, $(. /etc/os-release && echo "$PRETTY_NAME"), $(gcc -dumpfullversion 2>/dev/null | sed 's/^/gcc /'), load average $(cut -d' ' -f1-3 /proc/loadavg) at the end"
python3 - "$top/docs/validation-and-performance.md" "$figs" "$(date -u '+%Y-%m-%d %H:%M UTC')" "$machine" "$total" <<'PY'
import csv, os, sys
report, figs, date, machine, total = sys.argv[1:6]
begin, end = "<!-- report_all begin -->", "<!-- report_all end -->"

def rows(name):
    path = os.path.join(figs, name)
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return list(csv.DictReader(l for l in f if not l.startswith("#")))

out = [begin, "",
       f"Generated by `bench/report_all.sh` on {date} in {int(total) // 60} min {int(total) % 60} s; "
       f"machine: {machine}. One mpsflow at a time, one thread; wall times depend on what "
       "else the machine was doing, errors and step counts do not.", ""]
out += ["### Error against run time (generated)", "",
        "| case | scheme | l0 | error | wall s | steps | pressure it. | status | Pareto |",
        "|---|---|---|---|---|---|---|---|---|"]
cases = ["hydrostatic2D", "damBreak2D", "scalarAdvection", "squareDroplet", "poiseuille2D"]
for c in cases:
    for r in rows(f"compare_{c}.csv"):
        status = r["status"] if r["status"] == "completed" else f"{r['status']} ({r['criterion']})"
        out.append(f"| {c} | {r['scheme']} | {r['l0']} | {r['error']} | {r['wall_seconds']} | "
                   f"{r['steps']} | {r['pressure_iterations']} | {status} | {r['pareto']} |")
out.append("")
for c in cases:
    if os.path.exists(os.path.join(figs, f"compare_{c}.png")):
        out.append(f"![error against run time, {c}](figures/compare_{c}.png)")
out += ["", "### Stability maps (generated)", "",
        "Each cell: the run reached its end (stable) or the criterion that stopped it.", ""]
stab = ["damBreak2D", "columnImpact", "singleParticle", "freeFall", "overlapped", "thinSheet",
        "cornerJet", "densityRatio", "surfaceTension"]
for c in stab:
    rs = rows(f"stability_{c}.csv")
    if not rs:
        continue
    for sweep in dict.fromkeys(r["sweep"] for r in rs):
        part = [r for r in rs if r["sweep"] == sweep]
        values = list(dict.fromkeys(r["value"] for r in part))
        schemes = list(dict.fromkeys(r["scheme"] for r in part))
        out.append(f"**{c}**, sweep `{sweep}`:")
        out.append("")
        out.append("| scheme | " + " | ".join(values) + " |")
        out.append("|---|" + "---|" * len(values))
        for s in schemes:
            cell = {r["value"]: ("stable" if r["status"] == "stable" else r["criterion"])
                    for r in part if r["scheme"] == s}
            out.append(f"| {s} | " + " | ".join(cell.get(v, "") for v in values) + " |")
        out.append("")
        png = f"stability_{c}_{sweep}.png"
        if os.path.exists(os.path.join(figs, png)):
            out.append(f"![stability map, {c}, {sweep}](figures/{png})")
            out.append("")
out.append(end)
text = open(report).read()
if begin in text and end in text:
    a, b = text.index(begin), text.index(end) + len(end)
    text = text[:a] + "\n".join(out) + text[b:]
else:
    sys.exit(report + " has no report_all markers")
open(report, "w").write(text)
print(report + ": section 2 updated")
PY
