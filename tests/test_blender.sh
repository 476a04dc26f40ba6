#!/bin/sh
# Blender as the real client of our surface meshes (issue 6: "Blender must
# open the PLY"): the first frame of a small 3-D dam break, its free
# surface by `mpsflow surface` (blobby and levelSet), then Blender imports
# each binary PLY and must find the vertex and face counts of its header.
# Skipped (77) where Blender is not installed (apt-get install blender); it
# is not a build dependency.
# Then the whole sequence of frames through tutorials/scripts/
# mpsflowBlenderImport.py: one animation, upright in Blender's z-up axes.
# argv: mpsflow, tutorials/damBreak3D, tests/blender_check.py, the folder of
# mpsflowBlenderImport.py
command -v blender > /dev/null || { echo "blender not found: skipped"; exit 77; }
mpsflow=$1; tutorial=$2; script=$3; helpers=$4
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cp -r "$tutorial/." "$dir/"
rm -rf "$dir/output" "$dir/postProcessing"
OMP_NUM_THREADS=1 "$mpsflow" -case "$dir" -l0 0.025 -endTime 0.02 -quiet > "$dir/log" 2>&1 ||
    { cat "$dir/log"; exit 1; }
status=0
for method in blobby levelSet; do
    rm -rf "$dir/postProcessing"
    OMP_NUM_THREADS=1 "$mpsflow" surface -case "$dir" -latestTime -method $method > "$dir/log.$method" 2>&1 ||
        { cat "$dir/log.$method"; exit 1; }
    ply=$(ls "$dir"/postProcessing/surface/surface_*.ply | tail -n 1)
    nv=$(head -c 1000 "$ply" | sed -n 's/^element vertex \([0-9]*\).*/\1/p')
    nf=$(head -c 1000 "$ply" | sed -n 's/^element face \([0-9]*\).*/\1/p')
    out=$(timeout 300 blender -b --factory-startup --python "$script" -- "$ply" 2>&1)
    got=$(echo "$out" | sed -n 's/^BLENDER_PLY vertices \([0-9]*\) faces \([0-9]*\)$/\1 \2/p')
    if [ -n "$nv" ] && [ "$got" = "$nv $nf" ]; then
        echo "ok   $method: Blender imported $(basename "$ply"): $nv vertices, $nf faces"
    else
        echo "FAIL $method: header says '$nv $nf', Blender found '$got'"
        echo "$out" | tail -n 20
        status=1
    fi
done
rm -rf "$dir/postProcessing"
OMP_NUM_THREADS=1 "$mpsflow" surface -case "$dir" -method blobby > "$dir/log.sequence" 2>&1 ||
    { cat "$dir/log.sequence"; exit 1; }
n=$(ls "$dir"/postProcessing/surface/surface_*.ply | wc -l)
out=$(BLENDER_SEQUENCE=$n timeout 300 blender -b --factory-startup --python "$helpers/mpsflowBlenderImport.py" \
      --python "$script" -- "$dir" 2>&1)
echo "$out" | grep "^BLENDER_SEQUENCE\|^MPSFLOW_BLENDER"
echo "$out" | grep -q "^BLENDER_SEQUENCE ok" || { echo "$out" | tail -n 20; status=1; }
exit $status
