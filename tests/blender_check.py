# Run by tests/test_blender.sh: blender -b --python blender_check.py -- FILE.ply
# Imports the PLY into an empty scene and prints its vertex and face counts.
import sys

import bpy

path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.object.select_all(action="SELECT")
bpy.ops.object.delete()
bpy.ops.import_mesh.ply(filepath=path)
objects = bpy.context.selected_objects
if len(objects) != 1:
    sys.exit("expected one imported object, got %d" % len(objects))
mesh = objects[0].data
print("BLENDER_PLY vertices %d faces %d" % (len(mesh.vertices), len(mesh.polygons)))
