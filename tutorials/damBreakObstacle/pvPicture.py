"""The damBreakObstacle case in ParaView: the fluid by speed, the tank walls and the obstacle at
the last snapshot, saved as postProcessing/images/paraview_<time>.png. Run:
mpsflowParaView pvPicture.py (Allrun does, where ParaView is installed); or
in ParaView's Python shell, with tutorials/scripts on sys.path."""
import mpsflow_paraview as mp

mp.picture(".")
