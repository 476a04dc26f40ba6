#!/bin/sh
# Benchmarks of the MPS solver (issue 3); not tests. Prints a table and
# writes bench/results/mps.csv. Run on an otherwise idle machine:
#   bench/run_mps.sh          2-D damBreak2D_l0_0.005, 3-D at ~16k, ~100k, ~930k particles
#   bench/run_mps.sh quick    2-D (200 steps) and 3-D at ~16k only
cd "$(dirname "$0")/.." || exit 1
MPSFLOW=${MPSFLOW:-$PWD/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
out=bench/results
mkdir -p "$out"
csv=$out/mps.csv
echo "case,particles,fluid,steps,ms_per_step,particle_steps_per_s,iterations_per_solve,neighbours_ms,explicit_ms,assembly_ms,solve_ms,amg_setup_ms,pcg_ms,correction_ms,peak_MB,bytes_per_particle" > "$csv"

# run CASE L0 DT STEPS: a copy of bench/cases/CASE with spacing L0 and fixed step DT.
run() {
    tmp=$(mktemp -d)
    cp -r "bench/cases/$1/." "$tmp/"
    sed -i "s/^deltaT .*/deltaT          $3;/; s/^adjustTimeStep .*/adjustTimeStep  no;/" "$tmp/system/controlDict"
    end=$(awk "BEGIN { printf \"%.10g\", $3 * $4 }")
    "$MPSFLOW" -case "$tmp" -l0 "$2" -endTime "$end" -quiet > "$tmp/log" 2>&1 || { echo "run failed: $1 l0=$2"; tail -5 "$tmp/log"; rm -rf "$tmp"; return 1; }
    awk -v name="$1 l0=$2" '
        /^Particles:/ { np = $2 }
        /^    fluid/ { nf = $2 }
        /^Steps/ { steps = $2; for (i = 1; i <= NF; i++) if ($i == "memory") mb = $(i + 1) }
        /^MPS time per step/ {
            for (i = 1; i <= NF; i++) {
                if ($i == "search") nb = $(i + 1) + 0
                if ($i == "explicit") ex = $(i + 1) + 0
                if ($i == "assembly") as = $(i + 1) + 0
                if ($i == "solve") so = $(i + 1) + 0
                if ($i == "(AMG") se = $(i + 2) + 0
                if ($i == "PCG") pc = $(i + 1) + 0
                if ($i == "correction") co = $(i + 1) + 0
                if ($i == "total") tot = $(i + 1) + 0
            }
        }
        /^MPS pressure/ { for (i = 1; i <= NF; i++) if ($i == "iterations") it = $(i - 1) }
        END {
            pps = tot > 0 ? np / (tot / 1000) : 0
            printf "%-26s %9d particles %8d fluid %5d steps %9.2f ms/step %10.0f particle-steps/s %6.2f it/solve  peak %7.1f MB (%5.0f B/particle)\n", name, np, nf, steps, tot, pps, it, mb, mb * 1048576 / np > "/dev/stderr"
            printf "%s,%d,%d,%d,%.3f,%.0f,%.2f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.1f,%.0f\n", name, np, nf, steps, tot, pps, it, nb, ex, as, so, se, pc, co, mb, mb * 1048576 / np
        }' "$tmp/log" >> "$csv"
    grep "^MPS time" "$tmp/log" >&2
    rm -rf "$tmp"
}

echo "machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GB", $2/1048576}' /proc/meminfo), $(uname -sr); OMP_NUM_THREADS=${OMP_NUM_THREADS:-all}; $(date -u +%Y-%m-%d)" >&2
if [ "$1" = quick ]; then
    run damBreak2D_l0_0.005 0.005 0.0004 200
    run damBreak3D 0.02 0.0013 20
else
    run damBreak2D_l0_0.005 0.005 0.0004 1000
    run damBreak3D 0.02 0.0013 40
    run damBreak3D 0.009 0.0006 20
    run damBreak3D 0.0038 0.00025 5
fi
echo "table: $csv" >&2
