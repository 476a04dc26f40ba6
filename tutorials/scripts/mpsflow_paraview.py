"""mpsflow_paraview.py: a case's particles, walls and free surface in one
ParaView picture, through ParaView's default readers.

Used by each tutorial's paraview.py (run with `mpsflowParaView paraview.py`,
which puts this module on the path and renders off screen), and usable from
ParaView's own Python shell:

    import mpsflow_paraview as mp
    mp.picture(".", time=0.3, png="postProcessing/images/paraview.png")

What it opens, each with the reader ParaView picks for the file:
  output/particles.xdmf                 particles (Xdmf3ReaderS in 5.11): the
                                        kinds are told apart by the Kind
                                        array (0 fluid, 1 wall, 2 dummy,
                                        3 inlet, 4 outlet)
  postProcessing/surface/surface.xdmf   the free surface, if `mpsflow surface`
                                        (or the surface function object) made it
  constant/triSurface/*.obj             polygon walls of 3-D scenes, if any
"""
import glob
import math
import os

from paraview import servermanager
from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetColorTransferFunction,
                             GetScalarBar,
                             OpenDataFile, Render, SaveScreenshot, Show, Text, Threshold,
                             Delete)

KINDS = {"fluid": 0, "wall": 1, "dummy": 2, "inlet": 3, "outlet": 4}
VELOCITY = "Velocities [m/s]"


def timesteps(source):
    """The source's time values as a list (ParaView gives a float for one)."""
    t = source.TimestepValues
    if t is None:
        return []
    return list(t) if hasattr(t, "__len__") else [t]


def nearest(times, want):
    """The time of `times` nearest to `want` (the last one for None)."""
    if not times:
        return 0.0
    if want is None:
        return times[-1]
    return min(times, key=lambda t: abs(t - want))


def kind_of(reader, name):
    """The particles of one kind (a Threshold on Kind)."""
    k = KINDS[name]
    t = Threshold(Input=reader)
    t.Scalars = ["POINTS", "Kind"]
    t.LowerThreshold = k
    t.UpperThreshold = k
    t.ThresholdMethod = "Between"
    return t


def count_points(source, time):
    source.UpdatePipeline(time)
    data = servermanager.Fetch(source)
    return data.GetNumberOfPoints() if data else 0


def picture(case=".", time=None, png=None, size=(1000, 620), view_dir=None, view_up=(0, 1, 0),
            point_size=None, title=None, color=VELOCITY):
    """Render the case at the snapshot nearest `time` (default: the last).

    view_dir: direction the camera looks along (default (0, 0, -1): a 2-D
    case from the front; 3-D cases pass e.g. (-0.6, -0.5, -1)). Returns a
    dict of what was shown (time, points per kind, surface triangles) for
    tests. color: the fluid's point array (vectors by magnitude), e.g.
    "FluidId" for several fluids or a transported scalar's name. png
    defaults to postProcessing/images/paraview_<time>.png."""
    case = os.path.abspath(case)
    particles = OpenDataFile(os.path.join(case, "output", "particles.xdmf"))
    if particles is None:
        raise RuntimeError("%s/output/particles.xdmf: no reader (run the case first)" % case)
    particles.UpdatePipelineInformation()
    times = timesteps(particles)
    t = nearest(times, time)
    view = GetActiveViewOrCreate("RenderView")
    view.ViewSize = list(size)
    view.ViewTime = t
    view.OrientationAxesVisibility = 0
    view.Background = [1, 1, 1]
    try:  # 5.11: the palette's background would override ours
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    shown = {"time": t, "reader": particles.GetXMLName()}
    proxies = []

    fluid = kind_of(particles, "fluid")
    proxies.append(fluid)
    shown["fluid"] = count_points(fluid, t)
    d = Show(fluid, view)
    d.SetRepresentationType("Points")
    d.RenderPointsAsSpheres = 1
    d.PointSize = point_size or 6
    ColorBy(d, ("POINTS", color, "Magnitude") if color == VELOCITY else ("POINTS", color))
    d.RescaleTransferFunctionToDataRange(True, False)
    lut = GetColorTransferFunction(color)
    lut.ApplyPreset("Viridis (matplotlib)", True)
    d.SetScalarBarVisibility(view, True)
    bar = GetScalarBar(lut, view)
    bar.Title = "speed [m/s]" if color == VELOCITY else color
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0, 0, 0]

    for name, colour in (("wall", [0.45, 0.45, 0.45]), ("inlet", [0.2, 0.6, 0.2]),
                         ("outlet", [0.8, 0.3, 0.2])):
        part = kind_of(particles, name)
        proxies.append(part)
        n = count_points(part, t)
        shown[name] = n
        if n == 0:
            continue
        d = Show(part, view)
        d.SetRepresentationType("Points")
        d.PointSize = max(2, (point_size or 6) // 2)
        d.ColorArrayName = ["POINTS", ""]
        d.AmbientColor = colour
        d.DiffuseColor = colour

    surface_file = os.path.join(case, "postProcessing", "surface", "surface.xdmf")
    shown["surface"] = 0
    if os.path.exists(surface_file):
        surface = OpenDataFile(surface_file)
        proxies.append(surface)
        surface.UpdatePipelineInformation()
        ts = timesteps(surface)
        if ts and abs(nearest(ts, t) - t) <= 1e-9 * max(1.0, abs(t)):
            surface.UpdatePipeline(t)
            shown["surface"] = servermanager.Fetch(surface).GetNumberOfCells()
            d = Show(surface, view)
            d.ColorArrayName = ["POINTS", ""]
            d.DiffuseColor = [0.35, 0.6, 0.9]
            d.Opacity = 0.6

    for obj in sorted(glob.glob(os.path.join(case, "constant", "triSurface", "*.obj"))):
        mesh = OpenDataFile(obj)
        proxies.append(mesh)
        d = Show(mesh, view)
        d.SetRepresentationType("Wireframe")
        d.ColorArrayName = ["POINTS", ""]
        d.AmbientColor = [0.3, 0.3, 0.3]
        d.DiffuseColor = [0.3, 0.3, 0.3]

    label = Text(Text="%s   t = %s s" % (title or os.path.basename(case), "%.4g" % t))
    proxies.append(label)
    d = Show(label, view)
    d.Color = [0, 0, 0]
    d.FontSize = 14
    d.WindowLocation = "Upper Left Corner"

    view.ResetCamera()
    camera = view.GetActiveCamera()
    fp = camera.GetFocalPoint()
    direction = view_dir or (0, 0, -1)
    norm = math.sqrt(sum(c * c for c in direction))
    dist = camera.GetDistance()
    camera.SetPosition(*[fp[i] - dist * direction[i] / norm for i in range(3)])
    camera.SetViewUp(*view_up)
    view.ResetCamera()
    Render(view)
    if png is None:
        png = os.path.join(case, "postProcessing", "images", "paraview_%s.png" % ("%.4g" % t))
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    SaveScreenshot(png, view, ImageResolution=list(size))
    shown["png"] = png
    # Leave nothing for pvbatch's exit to tear down: with a view still alive
    # at exit it reports GLXBadContext under Xvfb.
    for p in reversed(proxies):
        Delete(p)
    Delete(particles)
    Delete(view)
    print("mpsflow_paraview: %s at t = %g: %d fluid, %d wall points, %d surface triangles -> %s"
          % (os.path.basename(case), t, shown["fluid"], shown["wall"], shown["surface"], png))
    return shown

