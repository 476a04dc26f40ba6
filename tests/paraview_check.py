"""ParaView as the real client of our output, as a user would open it: run
by pvbatch (through mpsflowParaView) from test_paraview.sh.

argv: case folder, the snapshots' exact times (comma separated, %.17g),
fluid and wall particles, the index k of the snapshot to look at and the
largest fluid pressure of that snapshot (from h5dump).

Checks, with the reader ParaView picks for output/particles.xdmf (Xdmf3ReaderS
in 5.11), and the two others for comparison:
  - the time values are the snapshots' times without rounding noise, and
    asking for a written time gives that snapshot (not the one before);
  - every particle is a point with a cell (else nothing renders), every
    field is there under its documented name;
  - mpsflow_paraview.picture (what each tutorial's pvPicture.py calls) shows
    the particles, the walls and the free surface and the PNG has them.
Ends normally and prints "paraview_check: N failures" (pvbatch aborts on a
non-zero sys.exit under Xvfb, so the shell reads that line instead)."""
import os
import sys
import time as clock

from paraview import servermanager
from paraview.simple import Delete, OpenDataFile, Threshold, XDMFReader, Xdmf3ReaderT
from vtkmodules.vtkIOImage import vtkPNGReader

import mpsflow_paraview as mp

case = sys.argv[1]
h5_times = [float(t) for t in sys.argv[2].split(",")]
nfluid, nwall, k, pmax = int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]), float(sys.argv[6])
xdmf = os.path.join(case, "output", "particles.xdmf")
failures = 0


def check(cond, what):
    global failures
    print(("ok   " if cond else "FAIL ") + what)
    sys.stdout.flush()
    failures += 0 if cond else 1


def shortest(t):
    """What mpsflow writes for t (core/base/timetext.c)."""
    for digits in range(1, 18):
        text = "%.*g" % (digits, t)
        if abs(float(text) - t) <= 1e-9 * max(abs(t), 1e-300):
            return float(text)
    return t


def leaves(data):
    it = data.NewIterator()
    it.InitTraversal()
    while not it.IsDoneWithTraversal():
        yield it.GetCurrentDataObject()
        it.GoToNextItem()


def fluid_of(reader):
    t = Threshold(Input=reader)
    t.Scalars = ["POINTS", "Kind"]
    t.LowerThreshold = t.UpperThreshold = 0
    t.ThresholdMethod = "Between"
    return t


# ---- the default reader ---------------------------------------------------
t0 = clock.time()
reader = OpenDataFile(xdmf)
check(reader is not None and reader.GetXMLName() == "Xdmf3ReaderS",
      "default reader for .xdmf: %s" % (reader.GetXMLName() if reader else None))
reader.UpdatePipelineInformation()
times = mp.timesteps(reader)
want = [shortest(t) for t in h5_times]
check(times == want, "times %s (snapshots %s)" % (times, want))
check(all(len(repr(t)) <= 8 for t in times), "no rounding noise in the time values")
tk = want[k]
reader.UpdatePipeline(tk)
data = servermanager.Fetch(reader)
pieces = list(leaves(data))
points = sum(p.GetNumberOfPoints() for p in pieces)
cells = sum(p.GetNumberOfCells() for p in pieces)
check(points > nfluid + nwall and cells == points,
      "%d points, %d cells (a vertex cell per particle)" % (points, cells))
names = set()
for p in pieces:
    pd = p.GetPointData()
    names |= {pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays())}
for a in ("Velocities [m/s]", "Pressure [Pa]", "NumberDensity", "ParticleIDs", "Flags", "Kind"):
    check(a in names, "array '%s' present" % a)
check(not any(n in names for n in ("StorageIndex", "PointIndex")),
      "no storage bookkeeping shown: %s" % sorted(names))
fluid = fluid_of(reader)
fluid.UpdatePipeline(tk)
fd = servermanager.Fetch(fluid)
check(fd.GetNumberOfPoints() == nfluid, "fluid points %d (expected %d)" % (fd.GetNumberOfPoints(), nfluid))
largest = max(p.GetPointData().GetArray("Pressure [Pa]").GetRange()[1]
              for p in leaves(fd) if p.GetNumberOfPoints() > 0)
check(abs(largest - pmax) <= 1e-9 * max(1.0, abs(pmax)),
      "at t = %g the fluid's largest pressure is snapshot %d's: %.10g (h5dump %.10g)"
      % (tk, k, largest, pmax))
print("timing Xdmf3ReaderS: open and read one time: %.2f s" % (clock.time() - t0))
Delete(fluid)
Delete(reader)

# ---- the other two readers see the same -----------------------------------
for make, label in ((lambda: Xdmf3ReaderT(FileName=[xdmf]), "Xdmf3ReaderT"),
                    (lambda: XDMFReader(FileNames=[xdmf]), "XDMFReader (legacy)")):
    t0 = clock.time()
    r = make()
    r.UpdatePipelineInformation()
    r.UpdatePipeline(tk)
    got = {}
    d = servermanager.Fetch(r)
    for i in range(d.GetNumberOfBlocks()):
        name = d.GetMetaData(i).Get(d.NAME()) or ""
        b = d.GetBlock(i)
        got[name.split("[")[0]] = (b.GetNumberOfPoints(), b.GetNumberOfCells())
    check(mp.timesteps(r) == want and got.get("fluid") == (nfluid, nfluid) and
          got.get("wall") == (nwall, nwall), "%s: blocks %s" % (label, got))
    print("timing %s: open and read one time: %.2f s" % (label, clock.time() - t0))
    Delete(r)

# ---- the picture: particles, walls and surface together -------------------
png = os.path.join(case, "postProcessing", "images", "check.png")
shown = mp.picture(case, time=tk, png=png, view_dir=(-0.5, -0.45, -1))
check(shown["time"] == tk and shown["fluid"] == nfluid and shown["wall"] == nwall,
      "picture shows the snapshot: %s" % shown)
check(shown["surface"] > 0, "picture shows the free surface (%d triangles)" % shown["surface"])
image = vtkPNGReader()
image.SetFileName(png)
image.Update()
img = image.GetOutput()
w, h, _ = img.GetDimensions()
scalars = img.GetPointData().GetScalars()
drawn = coloured = 0
for i in range(0, w * h, 3):
    c = [scalars.GetComponent(i, j) for j in range(3)]
    if min(c) < 235:
        drawn += 1
    if max(c) - min(c) > 60:
        coloured += 1
check(w == 1000 and h == 620, "PNG %dx%d" % (w, h))
check(drawn > 0.02 * w * h / 3 and coloured > 0.005 * w * h / 3,
      "PNG has the scene: %d drawn, %d coloured of %d sampled pixels" % (drawn, coloured, w * h // 3))
print("paraview_check: %d failures" % failures)
