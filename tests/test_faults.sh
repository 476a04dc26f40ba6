#!/bin/sh
# Faults: a run killed with SIGKILL at ten random moments, a full disk, and
# the time loop's landing on endTime. argv: mpsflow, tutorials/damBreak2D.
#
#  1. A fixed step lands on endTime: deltaT 10 with -endTime 0.01 ends at
#     t = 0.01 exactly in one step (the run used to take one 10 s step);
#     deltaT 1e-3 with -endTime 0.005 ends at 0.005 exactly in five (it used
#     to end at 0.006).
#  2. kill -9 at ten random moments of a small dam break (writing every
#     0.002 s), each time restarted with -latestTime: after every kill each
#     snapshot is readable, the XDMF index names only readable snapshots,
#     the next start removes and names any stale .tmp; the last restart runs
#     to the end and its final snapshot is bit-identical to a straight run's.
#  3. A full disk (a 600 KiB tmpfs, when root; skipped otherwise): rc 1, no
#     crash, every snapshot already written readable, no .tmp, a
#     runSummary; a restart on the still-full disk ends the same way.
mpsflow=$1; tutorial=$2
dir=$(mktemp -d)
full=""
cleanup() { [ -n "$full" ] && umount "$full" 2> /dev/null; rm -rf "$dir"; }
trap cleanup EXIT
failed=0; passed=0
ok() { echo "ok   $*"; passed=$((passed + 1)); }
bad() { echo "FAIL $*"; failed=$((failed + 1)); }
export OMP_NUM_THREADS=1

# fresh NAME: a copy of the tutorial writing every 0.002 s up to 0.2 s
fresh() {
    rm -rf "$dir/$1"; cp -r "$tutorial/." "$dir/$1/"; rm -rf "$dir/$1/output" "$dir/$1/postProcessing"
    sed -i 's/^writeInterval .*/writeInterval 0.002;/; s/^endTime .*/endTime 0.2;/' "$dir/$1/system/controlDict"
}
header() { h5dump -m '%.17g' -a "/Header/$2" "$1" 2> /dev/null | sed -n 's/^ *(0): //p'; }
# How to go on after a kill: restart from the newest snapshot; with none
# yet, start afresh over what the killed run began (-overwrite).
resume_args() {
    if ls "$1"/output/snapshot_*.h5 > /dev/null 2>&1; then echo -latestTime
    elif [ -d "$1/output" ]; then echo -overwrite; fi
}
# is X Y: the doubles X and Y are equal (exactly).
is() { python3 -c "import sys; sys.exit(float('$1') != float('$2'))" 2> /dev/null; }
last_snapshot() { ls "$1"/output/snapshot_*.h5 2> /dev/null | tail -1; }
all_readable() {
    for f in "$1"/output/snapshot_*.h5; do
        [ -e "$f" ] || continue
        h5dump -H "$f" > /dev/null 2>&1 || { echo "unreadable: $f"; return 1; }
    done
    return 0
}
# Every file the XDMF index names exists and is a readable snapshot.
xdmf_sound() {
    x="$1/output/particles.xdmf"
    [ -e "$x" ] || return 0
    python3 - "$x" <<'PY' || return 1
import os, subprocess, sys, xml.etree.ElementTree as ET
x = sys.argv[1]
root = ET.parse(x).getroot()          # a half-written index does not parse
files = set()
for item in root.iter("DataItem"):
    if item.get("Format") == "HDF":
        files.add(item.text.strip().split(":")[0])
for f in files:
    path = os.path.join(os.path.dirname(x), f)
    if subprocess.run(["h5dump", "-H", path], stdout=subprocess.DEVNULL,
                      stderr=subprocess.DEVNULL).returncode:
        sys.exit(f"{x} names {f}, which is not a readable snapshot")
PY
}

# ---- 1. landing on endTime --------------------------------------------------
fresh fixed
sed -i 's/^adjustTimeStep .*/adjustTimeStep no;/; s/^deltaT .*/deltaT 10;/; s/^writeInterval .*/writeInterval 1;/' "$dir/fixed/system/controlDict"
"$mpsflow" -case "$dir/fixed" -l0 0.02 -endTime 0.01 -quiet > "$dir/fixed.log" 2>&1
t=$(header "$(last_snapshot "$dir/fixed")" Time); s=$(header "$(last_snapshot "$dir/fixed")" Step)
is "$t" 0.01 && [ "$s" = "1" ] && ok "deltaT 10, -endTime 0.01: one step, ends at t = $t" ||
    bad "deltaT 10, -endTime 0.01 ends at t = $t after $s steps"
fresh fixed2
sed -i 's/^adjustTimeStep .*/adjustTimeStep no;/; s/^deltaT .*/deltaT 1e-3;/' "$dir/fixed2/system/controlDict"
"$mpsflow" -case "$dir/fixed2" -l0 0.02 -endTime 0.005 -quiet > "$dir/fixed2.log" 2>&1
t=$(header "$(last_snapshot "$dir/fixed2")" Time); s=$(header "$(last_snapshot "$dir/fixed2")" Step)
is "$t" 0.005 && [ "$s" = "5" ] && ok "deltaT 1e-3, -endTime 0.005: five steps, ends at t = $t" ||
    bad "deltaT 1e-3, -endTime 0.005 ends at t = $t after $s steps"

# ---- 2. SIGKILL at random moments -------------------------------------------
fresh straight
start=$(date +%s.%N)
"$mpsflow" -case "$dir/straight" -l0 0.02 -quiet > "$dir/straight.log" 2>&1 || bad "the straight run failed"
span=$(python3 -c "print('%.3f' % ($(date +%s.%N) - $start))")
seed=${MF_FAULT_SEED:-$(date +%s)}
echo "     straight run: $span s; kill moments from seed $seed"
fresh killed
python3 -c "
import random; r = random.Random($seed)
print(' '.join('%.3f' % r.uniform(0.05, $span) for _ in range(10)))" > "$dir/moments"
k=0
for moment in $(cat "$dir/moments"); do
    k=$((k + 1))
    args=$(resume_args "$dir/killed")
    "$mpsflow" -case "$dir/killed" -l0 0.02 $args > "$dir/killed$k.log" 2>&1 &
    pid=$!
    sleep "$moment"
    kill -9 $pid 2> /dev/null
    wait $pid 2> /dev/null
    n=$(ls "$dir"/killed/output/snapshot_*.h5 2> /dev/null | wc -l)
    tmp=$(ls "$dir"/killed/output/*.tmp 2> /dev/null | wc -l)
    if all_readable "$dir/killed" && xdmf_sound "$dir/killed"; then
        ok "kill $k at $moment s: $n snapshots readable, the XDMF index sound, $tmp stale .tmp"
    else
        bad "kill $k at $moment s: a snapshot or the XDMF index is broken"
    fi
done
stale=$(ls "$dir"/killed/output/*.tmp 2> /dev/null | wc -l)
args=$(resume_args "$dir/killed")
"$mpsflow" -case "$dir/killed" -l0 0.02 $args > "$dir/killed-final.log" 2>&1; rc=$?
[ $rc -eq 0 ] && ok "the last restart ran to the end" || { bad "the last restart exited with $rc"; tail -5 "$dir/killed-final.log"; }
if [ "$stale" -gt 0 ] && [ "$args" = -latestTime ]; then
    said=$(grep -c "^Removed output/.*\.tmp: a temporary file left by a run stopped while writing it" "$dir/killed-final.log")
    [ "$said" -eq "$stale" ] && ok "the $stale stale .tmp file(s) removed and named at start" ||
        bad "$stale stale .tmp file(s), $said removal(s) said"
fi
[ -z "$(ls "$dir"/killed/output/*.tmp 2> /dev/null)" ] && ok "no .tmp left after the last run" || bad "a .tmp is left"
a=$(last_snapshot "$dir/straight"); b=$(last_snapshot "$dir/killed")
if h5diff -q "$a" "$b" /PartType0 > /dev/null 2>&1 && h5diff -q "$a" "$b" /PartType1 > /dev/null 2>&1 &&
    [ "$(header "$a" Time)" = "$(header "$b" Time)" ] && [ "$(header "$a" Step)" = "$(header "$b" Step)" ]; then
    ok "after ten kills and restarts the final snapshot is bit-identical to the straight run's (t = $(header "$b" Time))"
else
    bad "the final snapshot after the kills differs from the straight run's"
fi

# ---- 3. a full disk ---------------------------------------------------------
if [ "$(id -u)" -ne 0 ]; then
    echo "skip full disk: needs root to mount a small tmpfs"
else
    full="$dir/full"; mkdir -p "$full"
    if mount -t tmpfs -o size=600k tmpfs "$full" 2> /dev/null; then
        cp -r "$tutorial/." "$full/case/"; rm -rf "$full/case/output" "$full/case/postProcessing"
        for attempt in first restart; do
            args=""; [ $attempt = restart ] && args="-latestTime"
            "$mpsflow" -case "$full/case" -l0 0.02 -endTime 0.3 -quiet $args > "$dir/full-$attempt.log" 2>&1; rc=$?
            msg=$(grep -m1 "FATAL ERROR" "$dir/full-$attempt.log")
            [ $rc -eq 1 ] && ok "full disk ($attempt run): rc 1" || bad "full disk ($attempt run): rc $rc (139 is a segfault)"
            short=$(echo "${msg#--> mpsflow FATAL ERROR: }" | cut -c1-160)
            echo "$msg" | grep -q "No space left on device (errno 28)" && ok "  says: $short" ||
                bad "  no errno 28 in: $msg"
            all_readable "$full/case" && ok "  every snapshot readable ($(ls "$full"/case/output/snapshot_*.h5 | wc -l))" || bad "  a snapshot is unreadable"
            [ -z "$(ls "$full"/case/output/*.tmp 2> /dev/null)" ] && ok "  no .tmp left" || bad "  a .tmp is left"
            [ -s "$full/case/output/runSummary" ] && ok "  runSummary: $(grep '^status' "$full/case/output/runSummary")" || bad "  no runSummary"
        done
    else
        echo "skip full disk: cannot mount a tmpfs here"
    fi
fi

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
