#!/bin/sh
# Issue 13's stability-map item: the largest Courant number at which each MPS
# scheme survives damBreak2D (l0 0.02, 0.01; 0.005 on request) and the
# extreme cases cornerJet and columnImpact. Not a test: the table of
# docs/topics/schemes.md ("Courant thresholds", 2026-12-03).
#   bench/courant_map.sh [CASE ...]
# CASE: dam02 dam01 dam005 jet col (default: all but dam005, the tutorial's
# fine spacing, 4 times dam01's particles).
# SCHEMES (default '(MPS stab)') is the -solvers list; VARIANTS adds
# compareDict variants, one 'NAME { MPSCoeffs { ... } }' per line; VALUES
# the maxCo values (default the fine sweep below). Each case is a copy in
# WORK (default /tmp/courant_map) with its own stabilityDict (maxDeltaT 1,
# maxDi 0: the Courant number alone sets the step, as in the tutorial's
# stabilityDict) and `mpsflow stability` runs the sweep; the table is
# WORK/CASE/stability/stability.csv, the map WORK/CASE/stability/courant.png.
# One thread a run, the runs of a case one after the other.
cd "$(dirname "$0")/.." || exit 1
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: meson setup build && ninja -C build"; exit 1; }
export OMP_NUM_THREADS=1 MPSFLOW_PLUGIN_PATH=${MPSFLOW_PLUGIN_PATH:-$PWD/build/plugins}
work=${WORK:-/tmp/courant_map}
schemes=${SCHEMES:-(MPS stab)}
values=${VALUES:-0.1 0.15 0.2 0.25 0.3 0.4 0.5 0.6 0.8 1 1.2 1.6 2}
[ $# -gt 0 ] || set -- dam02 dam01 jet col

for c in "$@"; do
    case $c in
    dam02) src=tutorials/damBreak2D l0=0.02 end='endTime 0.4;' ;;
    dam01) src=tutorials/damBreak2D l0=0.01 end='endTime 0.4;' ;;
    dam005) src=tutorials/damBreak2D l0=0.005 end='endTime 0.4;' ;;
    jet) src=bench/cases/extreme/cornerJet l0= end= ;;
    col) src=bench/cases/extreme/columnImpact l0= end= ;;
    *) echo "unknown case $c"; exit 1 ;;
    esac
    d=$work/$c
    rm -rf "$d"; mkdir -p "$work"; cp -r "$src" "$d"; rm -rf "$d/output" "$d"/log.*
    cat > "$d/system/stabilityDict" <<EOF
FoamFile { version 2.0; format ascii; class dictionary; object stabilityDict; }
$end
overrides { system/controlDict { maxDeltaT 1; maxDi 0; } }
sweeps { courant { file "system/controlDict"; key maxCo; values ($values); } }
EOF
    # stab: today's stabilised scheme (docs/topics/schemes.md); MPS is the
    # module's default, robust (the extreme cases' relaxation and collision
    # lines do nothing under robust)
    cat > "$d/system/compareDict" <<EOF
FoamFile { version 2.0; format ascii; class dictionary; object compareDict; }
variants
{
    stab { MPSCoeffs { scheme stabilised; } }
$VARIANTS
}
EOF
    echo "== $c (l0 ${l0:-case's})"
    (cd "$d" && "$MPSFLOW" stability -case . -solvers "$schemes" -sweeps '(courant)' ${l0:+-l0 $l0})
done
