#!/bin/sh
# ParaView as the real client of our output: a short dam break, then
# pvbatch opens output/particles.xdmf and checks times, blocks, counts and
# arrays, and renders a PNG. Skipped (77) where ParaView is not installed
# (apt-get install paraview); it is not a build dependency.
# argv: mpsflow, tutorials/damBreak2D, tests/paraview_check.py
command -v pvbatch > /dev/null || { echo "pvbatch not found: skipped"; exit 77; }
mpsflow=$1; tutorial=$2; script=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cp -r "$tutorial/." "$dir/"
rm -rf "$dir/output" "$dir/postProcessing"
OMP_NUM_THREADS=1 "$mpsflow" -case "$dir" -l0 0.02 -endTime 0.03 -quiet > "$dir/log" 2>&1 || { cat "$dir/log"; exit 1; }
ntimes=$(ls "$dir"/output/snapshot_*.h5 | wc -l)
nfluid=$(h5dump -a /Header/NumPart_ThisFile "$(ls "$dir"/output/snapshot_*.h5 | tail -1)" | sed -n 's/.*(0): \([0-9]*\),.*/\1/p')
# Debian's ParaView renders through X: with xvfb-run (package xvfb) the test
# also renders a frame; without it, it checks the data only.
if command -v xvfb-run > /dev/null; then
    timeout 300 xvfb-run -a pvbatch "$script" "$dir/output/particles.xdmf" "$ntimes" "$nfluid" "$dir/frame.png" &&
        test -s "$dir/frame.png" && echo "ok   rendered $dir/frame.png"
else
    timeout 300 pvbatch "$script" "$dir/output/particles.xdmf" "$ntimes" "$nfluid" -
fi
