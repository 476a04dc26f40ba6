#!/bin/sh
# ParaView 5.11's three XDMF readers on our output (issue 15): a 3-D dam
# break at l0 = 0.0125 m (12,800 fluid, 47,852 particles in all), 21
# snapshots; each reader opens output/particles.xdmf and reads every time,
# pvbatch off screen through mpsflowParaView. Prints seconds per reader
# (median of 3) and the snapshot size per particle.
#   bench/bench_paraview.sh [WORKDIR]     (default ${TMPDIR:-/tmp}/mpsflow-bench-paraview)
set -e
ROOT=$(cd "$(dirname "$0")/.." && pwd)
MPSFLOW=${MPSFLOW:-$ROOT/build/driver/mpsflow}
[ -x "$MPSFLOW" ] || { echo "build first: ./Allwmake"; exit 1; }
WORK=${1:-${TMPDIR:-/tmp}/mpsflow-bench-paraview}
rm -rf "$WORK"; mkdir -p "$WORK"
cp -r "$ROOT/tutorials/damBreak3D/." "$WORK/case/"
rm -rf "$WORK/case/output" "$WORK/case/postProcessing"
OMP_NUM_THREADS=${OMP_NUM_THREADS:-2} "$MPSFLOW" -case "$WORK/case" -l0 0.0125 -endTime 0.2 -quiet \
    > "$WORK/log" 2>&1
cat > "$WORK/readers.py" <<'PY'
import sys, time
from paraview.simple import Delete, OpenDataFile, XDMFReader, Xdmf3ReaderT
from paraview import servermanager
xdmf = sys.argv[1]
makers = {"Xdmf3ReaderS (default)": lambda: OpenDataFile(xdmf),
          "Xdmf3ReaderT": lambda: Xdmf3ReaderT(FileName=[xdmf]),
          "XDMFReader (legacy)": lambda: XDMFReader(FileNames=[xdmf])}
for name, make in makers.items():
    runs = []
    for _ in range(3):
        t0 = time.time()
        r = make()
        r.UpdatePipelineInformation()
        ts = r.TimestepValues
        ts = list(ts) if hasattr(ts, "__len__") else [ts]
        points = 0
        for t in ts:
            r.UpdatePipeline(t)
            points += servermanager.Fetch(r).GetNumberOfPoints()
        runs.append(time.time() - t0)
        Delete(r)
    runs.sort()
    print("BENCH %-24s %2d times, %9d points read: %.2f s (median of 3; %.2f .. %.2f)"
          % (name, len(ts), points, runs[1], runs[0], runs[2]))
PY
"$(dirname "$MPSFLOW")/mpsflowParaView" "$WORK/readers.py" "$WORK/case/output/particles.xdmf" 2>&1 |
    grep "^BENCH"
snap=$(ls "$WORK"/case/output/snapshot_*.h5 | tail -n 1)
n=$(h5dump -a /Header/NumPart_ThisFile "$snap" | sed -n 's/^ *(0): *//p' | tr ',' '\n' | awk '{ s += $1 } END { print s }')
echo "BENCH snapshot: $(stat -c %s "$snap") bytes for $n particles: $(awk -v b=$(stat -c %s "$snap") -v n=$n 'BEGIN { printf "%.1f", b / n }') bytes a particle"
echo "load: $(uptime | sed 's/.*load average: //')"
