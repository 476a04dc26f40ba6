#!/bin/sh
# ParaView as the real client of our output (issue 15): a short 3-D dam
# break and its free surface, then pvbatch (off screen: Xvfb and Mesa's
# software OpenGL, through mpsflowParaView) opens them with ParaView's
# default readers (tests/paraview_check.py) and the tutorial's own
# pvPicture.py saves its picture. ParaView is a test-only client that
# ./Alltest installs; where it is missing this test fails (it is not skipped).
# argv: mpsflow, tutorials/damBreak3D, tests/paraview_check.py, the folder
# of mpsflowParaView (the build's driver/ or an installed bin/)
mpsflow=$1; tutorial=$2; script=$3; bin=$4
command -v pvbatch > /dev/null ||
    { echo "FAIL pvbatch not found: apt-get install paraview python3-paraview xvfb (./Alltest does)"; exit 1; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cp -r "$tutorial/." "$dir/"
rm -rf "$dir/output" "$dir/postProcessing"
OMP_NUM_THREADS=1 "$mpsflow" -case "$dir" -l0 0.025 -endTime 0.04 -quiet > "$dir/log" 2>&1 ||
    { cat "$dir/log"; exit 1; }
OMP_NUM_THREADS=1 "$mpsflow" surface -case "$dir" -method blobby > "$dir/log.surface" 2>&1 ||
    { cat "$dir/log.surface"; exit 1; }
# What the files hold, for the check: exact times, counts, and the largest
# fluid pressure of one snapshot (which ParaView must give for its time).
times=""
for f in "$dir"/output/snapshot_*.h5; do
    t=$(h5dump -m %.17g -a /Header/Time "$f" | sed -n 's/^ *(0): *//p')
    times="${times:+$times,}$t"
done
last=$(ls "$dir"/output/snapshot_*.h5 | tail -n 1)
counts=$(h5dump -a /Header/NumPart_ThisFile "$last" | sed -n 's/^ *(0): *//p')
nfluid=$(echo "$counts" | cut -d, -f1 | tr -d ' ')
nwall=$(echo "$counts" | cut -d, -f2 | tr -d ' ')
k=3
snap=$(ls "$dir"/output/snapshot_*.h5 | sed -n "$((k + 1))p")
pmax=$(h5dump -m %.17g -y -w 1 -d /PartType0/Pressure "$snap" | sed -n 's/^ *\([-0-9.eE+]*\),*$/\1/p' |
       sort -g | tail -n 1)
echo "snapshots at $times; $nfluid fluid, $nwall wall; snapshot $k: largest pressure $pmax"
out=$(cd "$dir" && timeout 300 "$bin/mpsflowParaView" "$script" "$dir" "$times" "$nfluid" "$nwall" "$k" "$pmax" 2>&1)
echo "$out" | grep -E "^(ok|FAIL|timing|paraview_check|mpsflow_paraview)"
echo "$out" | grep -q "^paraview_check: 0 failures" ||
    { echo "$out" | grep -v -E "^(ok|FAIL|timing|paraview_check|mpsflow_paraview)|^ *[0-9]* *0x" | tail -n 20; exit 1; }
# The tutorial's own script, as its Allrun runs it: the picture of the last frame.
(cd "$dir" && timeout 300 "$bin/mpsflowParaView" pvPicture.py > log.paraview 2>&1) ||
    { tail -n 20 "$dir/log.paraview"; exit 1; }
png=$(ls "$dir"/postProcessing/images/paraview_*.png 2>/dev/null | head -n 1)
if [ -n "$png" ] && [ "$(stat -c %s "$png")" -gt 20000 ]; then
    echo "ok   pvPicture.py wrote $(basename "$png") ($(stat -c %s "$png") bytes)"
else
    echo "FAIL pvPicture.py: no picture"; tail -n 5 "$dir/log.paraview"; exit 1
fi
