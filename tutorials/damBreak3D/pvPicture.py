"""The damBreak3D case in ParaView: the fluid (by speed), the tank walls and,
where `mpsflow surface` made it, the free surface, saved as
postProcessing/images/paraview_<time>.png. Run: mpsflowParaView pvPicture.py
(Allrun does, where ParaView is installed); or in ParaView's Python shell,
with tutorials/scripts on sys.path."""
import mpsflow_paraview as mp

mp.picture(".", view_dir=(-0.5, -0.45, -1))
