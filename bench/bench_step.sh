#!/bin/sh
# bench_step.sh: one MPS step, today's main against this tree, in the same run
# (issue 12). Not a test: it prints a table and writes bench/results/.
#
#   bench/bench_step.sh            everything (about 10 minutes on an idle 2-core machine)
#   bench/bench_step.sh quick      fewer steps and repetitions (a minute or two)
#
# Measures, for both builds, with runs interleaved (main, this tree, main, ...)
# and the median of the repetitions:
#   2d      bench/cases/damBreak2D_l0_0.005 (fixed dt 4e-4): ms per step and its
#           split (neighbour search, explicit, number density + assembly, pressure
#           solve: AMG set-up (with the copy into hypre), PCG; correction), PCG
#           iterations per solve, one thread;
#   3d      bench/cases/damBreak3D at l0 = 0.009 m (99,009 particles, 49,005
#           fluid; fixed dt 6e-4): particle-steps/s, simulated seconds per wall
#           second, one thread;
#   memory  peak resident bytes per particle of both runs;
#   threads the 2-D case with OMP_NUM_THREADS=1 and 2 while a busy loop holds a
#           core (started and stopped by this script).
# Each build runs its own copy of its own bench/cases (a case's settings are
# part of what is measured). Environment: MAIN_REF (git revision, default
# main), MAIN_MPSFLOW (a built mpsflow of main: skips building it), MPSFLOW
# (this tree's, default build/driver/mpsflow).
cd "$(dirname "$0")/.." || exit 1
root=$PWD
MPSFLOW=${MPSFLOW:-$root/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
quick=$1
steps2d=1000; steps3d=20; reps=3; steps_thr=200
[ "$quick" = quick ] && { steps2d=200; steps3d=5; reps=1; steps_thr=100; }
out=$root/bench/results
mkdir -p "$out"
work=$(mktemp -d)
busy=""
cleanup() {
    [ -n "$busy" ] && kill "$busy" 2>/dev/null
    [ -n "$main_tree" ] && git -C "$root" worktree remove --force "$main_tree" >/dev/null 2>&1
    rm -rf "$work"
}
trap cleanup EXIT INT TERM

# Today's main, built in a worktree of its own.
main_tree=""
if [ -z "$MAIN_MPSFLOW" ]; then
    ref=${MAIN_REF:-main}
    main_tree=$work/main
    git -C "$root" worktree add --detach "$main_tree" "$ref" >/dev/null 2>&1 ||
        { echo "cannot check out $ref"; exit 1; }
    echo "building $ref ($(git -C "$main_tree" log --oneline -1 | cut -c1-60)) in $main_tree" >&2
    (cd "$main_tree" && meson setup build --buildtype=debugoptimized >/dev/null &&
        ninja -C build driver/mpsflow >/dev/null) || { echo "main did not build"; exit 1; }
    MAIN_MPSFLOW=$main_tree/build/driver/mpsflow
    main_cases=$main_tree/bench/cases
else
    main_cases=$root/bench/cases
fi
this_cases=$root/bench/cases

# run NAME EXE CASES CASE L0 DT STEPS THREADS: one run; appends the MPS report's
# figures to $work/NAME as "total nb ex as setup pcg co it particles peakMB".
run() {
    name=$1 exe=$2 cases=$3 case=$4 l0=$5 dt=$6 n=$7 threads=$8
    dir=$work/case.$$
    rm -rf "$dir"; cp -r "$cases/$case" "$dir"; rm -rf "$dir/output"
    sed -i "s/^deltaT .*/deltaT          $dt;/; s/^adjustTimeStep .*/adjustTimeStep  no;/" "$dir/system/controlDict"
    end=$(awk "BEGIN { printf \"%.10g\", $dt * $n }")
    OMP_NUM_THREADS=$threads "$exe" -case "$dir" -l0 "$l0" -endTime "$end" -quiet > "$dir/log" 2>&1 ||
        { echo "run failed: $name" >&2; tail -3 "$dir/log" >&2; return 1; }
    awk '
        /^Particles:/ { np = $2 }
        /^Steps/ { for (i = 1; i <= NF; i++) if ($i == "memory") mb = $(i + 1) }
        /^MPS time per step/ {
            for (i = 1; i <= NF; i++) {
                if ($i == "search") nb = $(i + 1) + 0
                if ($i == "explicit") ex = $(i + 1) + 0
                if ($i == "assembly") as = $(i + 1) + 0
                if ($i == "(AMG") se = $(i + 2) + 0
                if ($i == "PCG") pc = $(i + 1) + 0
                if ($i == "correction") co = $(i + 1) + 0
                if ($i == "total") tot = $(i + 1) + 0
            }
        }
        /^MPS pressure/ { for (i = 1; i <= NF; i++) if ($i == "iterations") it = $(i - 1) }
        END { print tot, nb, ex, as, se, pc, co, it, np, mb }' "$dir/log" >> "$work/$name"
    rm -rf "$dir"
}

# median NAME COLUMN
median() { awk -v c="$2" '{ print $c }' "$work/$1" | sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }'; }

load() { cut -d' ' -f1-3 /proc/loadavg; }
machine="$(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')), $(awk '/MemTotal/ {printf "%.0f GB", $2/1048576}' /proc/meminfo), $(uname -sr)"
load_start=$(load)
echo "machine: $machine; load at start $load_start" >&2

for r in $(seq $reps); do
    for b in main this; do
        if [ $b = main ]; then exe=$MAIN_MPSFLOW; cases=$main_cases; else exe=$MPSFLOW; cases=$this_cases; fi
        run 2d_$b "$exe" "$cases" damBreak2D_l0_0.005 0.005 0.0004 $steps2d 1
        run 3d_$b "$exe" "$cases" damBreak3D 0.009 0.0006 $steps3d 1
    done
done
# Threads with a busy core.
sh -c 'while :; do :; done' &
busy=$!
load_busy=$(load)
for r in $(seq $reps); do
    for b in main this; do
        if [ $b = main ]; then exe=$MAIN_MPSFLOW; cases=$main_cases; else exe=$MPSFLOW; cases=$this_cases; fi
        for t in 1 2; do
            run thr${t}_$b "$exe" "$cases" damBreak2D_l0_0.005 0.005 0.0004 $steps_thr $t
        done
    done
done
kill "$busy"; busy=""
load_end=$(load)

csv=$out/bench_step.csv
echo "build,case,ms_per_step,neighbours_ms,explicit_ms,assembly_ms,amg_setup_ms,pcg_ms,correction_ms,iterations_per_solve,particles,peak_MB,bytes_per_particle,particle_steps_per_s,simulated_s_per_wall_s,threads" > "$csv"
for b in main this; do
    for c in 2d 3d thr1 thr2; do
        f=${c}_$b
        [ -s "$work/$f" ] || continue
        tot=$(median $f 1); np=$(median $f 9); mb=$(median $f 10)
        dt=0.0004; [ $c = 3d ] && dt=0.0006
        threads=1; [ $c = thr2 ] && threads=2
        awk -v b=$b -v c=$c -v tot="$tot" -v nb="$(median $f 2)" -v ex="$(median $f 3)" \
            -v as="$(median $f 4)" -v se="$(median $f 5)" -v pc="$(median $f 6)" \
            -v co="$(median $f 7)" -v it="$(median $f 8)" -v np="$np" -v mb="$mb" -v dt=$dt -v th=$threads \
            'BEGIN { printf "%s,%s,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.2f,%d,%.1f,%.0f,%.0f,%.5f,%d\n",
                     b, c, tot, nb, ex, as, se, pc, co, it, np, mb, mb * 1048576 / np,
                     np / (tot / 1000), dt / (tot / 1000), th }' >> "$csv"
    done
done

{
    echo "bench/bench_step.sh $quick, $(date -u +%Y-%m-%d): $machine"
    # Each build as it names itself (a MAIN_MPSFLOW given from elsewhere is
    # not the checkout's main: the label said main's commit for it).
    echo "main: $("$MAIN_MPSFLOW" -version 2>&1 | head -n 1); this: $("$MPSFLOW" -version 2>&1 | head -n 1) ($(git log --oneline -1 | cut -c1-50))"
    echo "load (1, 5, 15 min): at start $load_start; with the busy core $load_busy; at the end $load_end"
    echo "medians of $reps interleaved runs; 2-D $steps2d steps, 3-D $steps3d steps, threads $steps_thr steps"
    echo
    echo "| build | case | ms/step | neighbours | explicit | assembly | AMG set-up | PCG | correction | it/solve | B/particle | particle-steps/s | sim s / wall s |"
    echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    tail -n +2 "$csv" | awk -F, '{ printf "| %s | %s%s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %d | %d | %.4f |\n",
        $1, $2, ($16 > 1 ? " (2 threads, busy core)" : ($2 == "thr1" ? " (1 thread, busy core)" : "")),
        $3, $4, $5, $6, $7, $8, $9, $10, $13, $14, $15 }'
} | tee "$out/bench_step.md"
