"""Open a case's particles.xdmf with ParaView's XDMF reader, as a user
would, and check what it sees against the snapshots: run by pvbatch from
test_paraview.sh. argv: xdmf path, expected number of times, expected fluid
particles, PNG to write."""
import sys
from paraview.simple import XDMFReader, Show, Render, SaveScreenshot, GetActiveViewOrCreate, ColorBy
from paraview import servermanager

xdmf, ntimes, nfluid, png = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
failures = 0

def check(cond, what):
    global failures
    print(("ok   " if cond else "FAIL ") + what)
    failures += 0 if cond else 1

reader = XDMFReader(FileNames=[xdmf])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
check(len(times) == ntimes, "time steps: %d (snapshots: %d)" % (len(times), ntimes))
check(times == sorted(times), "times increase")
reader.UpdatePipeline(times[-1])
data = servermanager.Fetch(reader)
names = [data.GetMetaData(i).Get(data.NAME()) for i in range(data.GetNumberOfBlocks())]
# ParaView names a grid "fluid[k]" (k: the time step it came from).
fluid_blocks = [i for i, n in enumerate(names) if n.split("[")[0] == "fluid"]
check(len(fluid_blocks) == 1, "blocks: %s" % names)
fluid = data.GetBlock(fluid_blocks[0])
check(fluid.GetNumberOfPoints() == nfluid, "fluid points: %d (expected %d)" % (fluid.GetNumberOfPoints(), nfluid))
arrays = [fluid.GetPointData().GetArrayName(i) for i in range(fluid.GetPointData().GetNumberOfArrays())]
for a in ("Velocities", "Pressure", "NumberDensity", "ParticleIDs"):
    check(a in arrays, "array %s present" % a)
rng = fluid.GetPointData().GetArray("Pressure").GetRange()
check(rng[1] > 0, "pressure range %g .. %g" % rng)
if png == "-":  # no X display to render with (see test_paraview.sh)
    sys.exit(1 if failures else 0)
view = GetActiveViewOrCreate("RenderView")
display = Show(reader, view)
ColorBy(display, ("POINTS", "Pressure"))
view.ViewTime = times[-1]
view.ResetCamera()
Render(view)
SaveScreenshot(png, view, ImageResolution=[640, 400])
sys.exit(1 if failures else 0)
