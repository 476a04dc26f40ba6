"""first_picture.py: the README's first picture, made as ParaView's window
makes it (open output/particles.xdmf with the XDMF reader, draw points,
colour by the magnitude of Velocities), without a window:

    build/driver/mpsflowParaView docs/scripts/first_picture.py \
        tutorials/damBreak2D/output/particles.xdmf 0.3 damBreak2D.png

(mpsflowParaView runs pvbatch, under an Xvfb of its own with a 24-bit
screen and software OpenGL where there is no display.) argv: the XDMF index, the time
to show (the nearest snapshot is used), the PNG to write. Needs ParaView
(apt-get install paraview python3-paraview xvfb xauth libgl1-mesa-dri)."""
import sys

from paraview.simple import (ColorBy, Delete, GetActiveViewOrCreate, GetColorTransferFunction,
                             GetScalarBar, Render, SaveScreenshot, Show, XDMFReader)

xdmf, when, png = sys.argv[1], float(sys.argv[2]), sys.argv[3]
reader = XDMFReader(FileNames=[xdmf])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
t = min(times, key=lambda x: abs(x - when))
reader.UpdatePipeline(t)
(x0, x1, y0, y1, _, _) = reader.GetDataInformation().GetBounds()

view = GetActiveViewOrCreate("RenderView")
view.ViewTime = t
view.OrientationAxesVisibility = 0
view.Background = [1, 1, 1]
try:  # ParaView >= 5.10 keeps a palette that overrides Background
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
display = Show(reader, view)
display.SetRepresentationType("Points")
display.PointSize = 3
ColorBy(display, ("POINTS", "Velocities [m/s]", "Magnitude"))
lut = GetColorTransferFunction("Velocities [m/s]")
lut.ApplyPreset("Viridis (matplotlib)", True)
lut.RescaleTransferFunction(0.0, 3.0)
bar = GetScalarBar(lut, view)
bar.Title = "speed (m/s)"
bar.ComponentTitle = ""
bar.TitleColor = bar.LabelColor = [0, 0, 0]
bar.Orientation = "Horizontal"
bar.WindowLocation = "Upper Right Corner"
bar.TitleFontSize = bar.LabelFontSize = 14
bar.RangeLabelFormat = "%.1f"
bar.ScalarBarLength = 0.3
display.SetScalarBarVisibility(view, True)

# Look at the whole tank from the front, with a small margin (the first
# Render resets the camera, so it comes before the camera is placed).
width, height = 1000, 2 * int(500 * (y1 - y0) / (x1 - x0) * 1.15) + 60
view.ViewSize = [width, height]
Render(view)
view.CameraPosition = [(x0 + x1) / 2, (y0 + y1) / 2, 10]
view.CameraFocalPoint = [(x0 + x1) / 2, (y0 + y1) / 2, 0]
view.CameraViewUp = [0, 1, 0]
view.CameraParallelProjection = 1
view.CameraParallelScale = 0.55 * max(y1 - y0, (x1 - x0) * height / width)
Render(view)
SaveScreenshot(png, view, ImageResolution=[width, height])
# Leave nothing for pvbatch's exit to tear down: with a view still alive at
# exit it aborts under Xvfb (GLXBadContext, "bad X server connection").
Delete(display)
Delete(reader)
Delete(view)
print("%s: t = %g s" % (png, t))
