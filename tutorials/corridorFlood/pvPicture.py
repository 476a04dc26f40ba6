"""The corridorFlood case in ParaView: the fluid (by speed), the corridor mesh
and the free surface of the last frame, saved as
postProcessing/images/paraview_<time>.png. Run: mpsflowParaView pvPicture.py
(Allrun does, where ParaView is installed); or in ParaView's Python shell,
with tutorials/scripts on sys.path."""
import mpsflow_paraview as mp

mp.picture(".", view_dir=(-0.5, -1, -0.7), view_up=(0, 0, -1))
