"""The waterEntry case in ParaView: the water by pressure, the tank and the
cylinder, saved as postProcessing/images/paraview_<time>.png. Run:
mpsflowParaView pvPicture.py (Allrun does, where ParaView is installed); or
in ParaView's Python shell, with tutorials/scripts on sys.path."""
import mpsflow_paraview as mp

mp.picture(".", color="Pressure [Pa]")
