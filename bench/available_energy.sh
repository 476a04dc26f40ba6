#!/bin/sh
# How close runs come to the watch's two energy criteria (core/run/mf_watch.h):
# each case run to its endTime with both held off (energyTolerance and
# availableEnergyTolerance 1e6), so that a burst does not stop it, and the
# peaks of the log's two Watch: lines printed: `energy`, (KE - KE0 - W - A)
# over the energy scale, and `availableEnergy`, (KE - budget) over the
# budget plus M |g| l0 (the budget KE0 + the potential energy above the
# fluid laid level on the floor + A + the other forces' work); the run stops
# at the first step where a peak passes the default tolerance (0.02, 0.05).
#   bench/available_energy.sh CASE[:L0] ...
# CASE a case folder (tutorials/damBreak2D), L0 a spacing (-l0; none: the
# case's). One run at a time, one thread. Prints one row a run:
#   case l0 status energy-peak (t) availableEnergy-peak (t)
# and the watch's `no availableEnergy check: why` where it does not apply.
cd "$(dirname "$0")/.." || exit 1
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
export OMP_NUM_THREADS=1
work=$(mktemp -d)
[ -n "$KEEP" ] || trap 'rm -rf "$work"' EXIT
printf '%-28s %-8s %-10s %-22s %s\n' case l0 status "energy (t)" "availableEnergy (t)"
for arg in "$@"; do
    src=${arg%%:*}; l0=""
    [ "$src" != "$arg" ] && l0=${arg#*:}
    name=$(basename "$src")
    d=$work/$name${l0:+_$l0}
    rm -rf "$d"; cp -r "$src" "$d"; rm -rf "$d/output" "$d/postProcessing" "$d"/log.*
    [ -x "$d/makeGeometry" ] && [ ! -d "$d/constant/triSurface" ] && (cd "$d" && ./makeGeometry > /dev/null 2>&1)
    python3 - "$d/system/controlDict" <<'PY'
import re, sys
p = sys.argv[1]
s = open(p).read()
keys = "energyTolerance 1e6; availableEnergyTolerance 1e6;"
m = re.search(r"^watch\s*\{", s, re.M)
if m:  # the case's own watch block: its tolerances replaced
    s = re.sub(r"^(\s*)(energyTolerance|availableEnergyTolerance)\s+[^;]*;", r"\1// \2 (held off)", s, flags=re.M)
    s = s[:m.end()] + "\n    " + keys + s[m.end():]
else:
    s += "\nwatch { " + keys + " }\n"
open(p, "w").write(s)
PY
    "$MPSFLOW" -case "$d" ${l0:+-l0 "$l0"} > "$d/log" 2>&1
    status=completed
    tail -n 1 "$d/log" | grep -q '^End$' || status="stopped@$(sed -n 's/^--> the run stops at time \([^ ]*\) .*/\1/p' "$d/log" | tail -1)"
    e=$(sed -n "s/^Watch: kinetic energy above .* by at most \([^ ]*\) of the energy scale (t = \([^;]*\);.*/\1 (\2)/p" "$d/log")
    a=$(sed -n "s/^Watch: availableEnergy: .* by at most \([^ ]*\) of them .*(t = \([^;]*\);.*/\1 (\2)/p" "$d/log")
    [ -n "$a" ] || a=$(sed -n 's/^Watch: no availableEnergy check: \(.*\)/n\/a: \1/p' "$d/log" | head -1)
    printf '%-28s %-8s %-10s %-22s %s\n' "$name" "${l0:-own}" "$status" "$e" "$a"
done
