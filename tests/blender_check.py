# Run by tests/test_blender.sh, two ways:
#   blender -b --python blender_check.py -- FILE.ply
#       imports the PLY into an empty scene and prints its vertex and face
#       counts;
#   BLENDER_SEQUENCE=N blender -b --python mpsflowBlenderImport.py
#       --python blender_check.py -- CASE
#       checks the importer's animation: N frames under the "mpsflow
#       surface" empty, each shown on its own frames only, and upright (the
#       simulation's y is Blender's z).
import os
import sys

import bpy

if os.environ.get("BLENDER_SEQUENCE"):
    want = int(os.environ["BLENDER_SEQUENCE"])
    scene = bpy.context.scene
    frames = sorted((o for o in scene.objects if o.parent and o.parent.name == "mpsflow surface"),
                    key=lambda o: o.name)
    failures = []
    if len(frames) != want:
        failures.append("%d frames imported, %d expected" % (len(frames), want))
    starts = []
    for obj in frames:
        fc = obj.animation_data.action.fcurves.find("hide_render")
        starts.append(min(int(k.co[0]) for k in fc.keyframe_points if k.co[1] == 0.0))
    for k, start in enumerate(starts):
        scene.frame_set(start)
        shown = [o.name for o in frames if not o.hide_render]
        if shown != [frames[k].name]:
            failures.append("frame %d shows %s, expected %s" % (start, shown, frames[k].name))
    if frames:
        obj = frames[-1]
        local = [v.co for v in obj.data.vertices]
        world = [obj.matrix_world @ v.co for v in obj.data.vertices]
        top_y = max(c.y for c in local)
        top_z = max(c.z for c in world)
        if abs(top_y - top_z) > 1e-4 or abs(min(c.y for c in world) + max(c.z for c in local)) > 1e-4:
            failures.append("not upright: local max y %g, world max z %g" % (top_y, top_z))
        print("BLENDER_SEQUENCE frames %d starts %s top %.4f (simulation y) = %.4f (Blender z)"
              % (len(frames), starts, top_y, top_z))
    for f in failures:
        print("BLENDER_SEQUENCE FAIL " + f)
    print("BLENDER_SEQUENCE %s" % ("ok" if not failures else "failed"))
    sys.exit(0)

path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.object.select_all(action="SELECT")
bpy.ops.object.delete()
bpy.ops.import_mesh.ply(filepath=path)
objects = bpy.context.selected_objects
if len(objects) != 1:
    sys.exit("expected one imported object, got %d" % len(objects))
mesh = objects[0].data
print("BLENDER_PLY vertices %d faces %d" % (len(mesh.vertices), len(mesh.polygons)))
