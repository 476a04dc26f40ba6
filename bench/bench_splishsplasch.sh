#!/bin/sh
# mpsflow against SPlisHSPlasH (DFSPH, the code a graphics user picks) on
# the same 3-D dam break (issue 12): bench/cases/damBreak3D (a column
# 0.25 x 0.5 x 0.3 m in a 0.6 x 0.6 x 0.3 m tank, spacing 0.009 m, about
# 52,000 fluid particles) as a SPlisHSPlasH scene with particle radius
# l0/2, its density-based wall volume maps (Bender et al. 2019) instead of
# wall particles, and its adaptive CFL step; mpsflow with the case's
# settings and an adaptive step (maxCo of the case). Both to the same
# simulated time, no output; hyperfine times the whole processes and the
# script prints simulated seconds per wall second and particle-steps/s.
#
#   bench/bench_splishsplasch.sh SPHSimulator [END_TIME [RUNS [THREADS]]]
#
# SPHSimulator is SPlisHSPlasH's console simulator (github.com/
# InteractiveComputerGraphics/SPlisHSPlasH, built by the user: it is not a
# Debian package and nothing here downloads it). Defaults: END_TIME 0.05 s,
# RUNS 3, THREADS 2 (OMP_NUM_THREADS for both codes).
cd "$(dirname "$0")/.." || exit 1
sph=$1; end=${2:-0.05}; runs=${3:-3}; threads=${4:-2}
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$sph" ] || { echo "usage: $0 path/to/SPHSimulator [END_TIME [RUNS [THREADS]]]"; exit 2; }
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 2; }
command -v hyperfine > /dev/null || { echo "apt-get install hyperfine"; exit 2; }
root=$(cd "$(dirname "$sph")/../.." && pwd)
box=$(find "$root" "$(dirname "$sph")/.." -name UnitBox.obj -path '*models*' 2>/dev/null | head -n 1)
[ -n "$box" ] || { echo "cannot find SPlisHSPlasH's data/models/UnitBox.obj near $sph"; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
l0=0.009; r=0.0045
# The scene: the tank as an inverted box (walls inside, as SPlisHSPlasH's
# own DamBreakModel scene), the column's particles where mpsflow puts them
# (centres l0/2 from the walls, 27 x 55 x 33: SPlisHSPlasH fits a block's
# particles one diameter inside its bounds, hence the bounds one l0 out).
cat > "$tmp/scene.json" <<EOF
{
  "Configuration": {
    "particleRadius": $r, "simulationMethod": 4, "gravitation": [0, -9.81, 0],
    "timeStepSize": 0.0001, "cflMethod": 1, "cflFactor": 1, "cflMaxTimeStepSize": 0.001,
    "boundaryHandlingMethod": 2, "stopAt": $end, "enablePartioExport": false,
    "enableVTKExport": false, "enableRigidBodyExport": false, "dataExportFPS": 0,
    "DFSPH": { "minIterations": 2, "maxIterations": 100, "maxError": 0.05,
               "maxIterationsV": 100, "maxErrorV": 0.1, "enableDivergenceSolver": true }
  },
  "Materials": [ { "id": "Fluid", "density0": 1000, "viscosityMethod": 1,
                   "Standard viscosity": { "viscosity": 0.000001 } } ],
  "RigidBodies": [ { "geometryFile": "$box", "translation": [0.3, 0.3, 0.15],
                     "scale": [0.6, 0.6, 0.3], "isDynamic": false, "isWall": true,
                     "mapInvert": true, "mapThickness": 0.0, "mapResolution": [30, 30, 15] } ],
  "FluidBlocks": [ { "denseMode": 0, "start": [0, 0, 0], "end": [0.252, 0.504, 0.306] } ]
}
EOF
cp -r bench/cases/damBreak3D "$tmp/mps"
sed -i 's/^adjustTimeStep .*/adjustTimeStep  yes;/' "$tmp/mps/system/controlDict"
export OMP_NUM_THREADS=$threads
# One run of each for the counts (and SPlisHSPlasH's wall maps, cached).
"$sph" --no-gui --no-initial-pause --stopAt "$end" --output-dir "$tmp/sph" "$tmp/scene.json" > "$tmp/sph.log" 2>&1 ||
    { tail -n 20 "$tmp/sph.log"; exit 1; }
"$MPSFLOW" -case "$tmp/mps" -l0 $l0 -endTime "$end" -overwrite > "$tmp/mps.log" 2>&1 ||
    { tail -n 20 "$tmp/mps.log"; exit 1; }
sph_n=$(sed -n 's/^Number of fluid particles: *\([0-9]*\).*/\1/p' "$tmp/sph.log" | head -n 1)
sph_steps=$(awk '/^Time sum: SimStep/ { s = $4 } /^Average time: SimStep/ { a = $4 } END { if (a > 0) printf "%.0f", s / a }' "$tmp/sph.log")
mps_fluid=$(awk '/^    fluid/ { print $2; exit }' "$tmp/mps.log")
mps_n=$(awk '/^Particles:/ { print $2; exit }' "$tmp/mps.log")
mps_steps=$(awk '/^Steps/ { print $2; exit }' "$tmp/mps.log")
echo "machine: $(nproc) cores ($(sed -n 's/^model name.*: //p' /proc/cpuinfo | head -n 1)), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "SPlisHSPlasH: $sph_n fluid particles, $sph_steps steps; mpsflow: $mps_fluid fluid of $mps_n particles, $mps_steps steps to $end s"
hyperfine -N -r "$runs" --export-json "$tmp/h.json" \
    -n SPlisHSPlasH "$sph --no-gui --no-initial-pause --stopAt $end --output-dir $tmp/sph $tmp/scene.json" \
    -n mpsflow "$MPSFLOW -case $tmp/mps -l0 $l0 -endTime $end -overwrite -quiet"
python3 - "$tmp/h.json" "$end" "$mps_n" "$mps_steps" <<'EOF'
import json, statistics, sys
h = json.load(open(sys.argv[1])); end = float(sys.argv[2])
for r in h["results"]:
    med = statistics.median(r["times"])
    line = f"{r.get('command_name', r['command'])[:14]:14s}"
    extra = ""
    if "mpsflow" in line:
        extra = f", {int(sys.argv[3]) * int(sys.argv[4]) / med:,.0f} particle-steps/s (all particles)"
    print(f"{line} median {med:.2f} s: {end / med:.4f} simulated s per wall s{extra}")
print("load at the end:", open("/proc/loadavg").read().split()[:3])
EOF
