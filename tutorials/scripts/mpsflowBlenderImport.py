"""mpsflowBlenderImport.py: a case's free-surface frames into Blender as one
animation.

    blender --python mpsflowBlenderImport.py -- CASE [--fps 30] [--save out.blend]
    blender -b --python mpsflowBlenderImport.py -- CASE --save out.blend

CASE is a case folder (its postProcessing/surface/surface_*.ply, written by
`mpsflow surface` or the surface function object) or a folder of PLY frames.

mpsflow writes meshes in the simulation's axes: y is up (gravity along -y),
as in the case files. Blender's z is up, so the frames are put under one
empty, "mpsflow surface", turned +90 degrees about x (x stays x, the
simulation's y becomes Blender's z, its z becomes Blender's -y): the fluid
stands upright. Each frame's simulation time (the PLY header's "comment
mpsflow surface, time T") sets its Blender frame, round(T * fps) + 1, and
each mesh is shown from its frame until the next one's (hide_viewport and
hide_render keyed). Prints "MPSFLOW_BLENDER frames N start S end E"."""
import glob
import math
import os
import re
import sys

import bpy


def arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    opts = {"fps": 30, "save": None, "path": "."}
    k = 0
    while k < len(argv):
        if argv[k] == "--fps":
            opts["fps"] = int(argv[k + 1])
            k += 2
        elif argv[k] == "--save":
            opts["save"] = argv[k + 1]
            k += 2
        else:
            opts["path"] = argv[k]
            k += 1
    return opts


def ply_time(path):
    """The time in the PLY header (mpsflow writes it as a comment)."""
    with open(path, "rb") as f:
        for _ in range(20):
            line = f.readline().decode("ascii", "replace")
            m = re.match(r"comment mpsflow surface, time (\S+)", line)
            if m:
                return float(m.group(1))
            if line.startswith("end_header"):
                break
    return None


def frames_of(path):
    folder = path
    if os.path.isdir(os.path.join(path, "postProcessing", "surface")):
        folder = os.path.join(path, "postProcessing", "surface")
    files = sorted(glob.glob(os.path.join(folder, "*.ply")))
    if not files:
        raise SystemExit("mpsflowBlenderImport: no PLY frames in %s (run mpsflow surface)" % folder)
    frames = []
    for k, f in enumerate(files):
        t = ply_time(f)
        frames.append((t if t is not None else float(k), f))
    frames.sort()
    return frames


def set_shown(obj, frame, shown):
    obj.hide_viewport = not shown
    obj.hide_render = not shown
    obj.keyframe_insert("hide_viewport", frame=frame)
    obj.keyframe_insert("hide_render", frame=frame)


def main():
    opts = arguments()
    frames = frames_of(opts["path"])
    fps = opts["fps"]
    scene = bpy.context.scene
    root = bpy.data.objects.new("mpsflow surface", None)
    scene.collection.objects.link(root)
    root.rotation_euler = (math.radians(90), 0, 0)  # simulation y up -> Blender z up
    starts = [int(round(t * fps)) + 1 for t, _ in frames]
    for k in range(1, len(starts)):  # two frames nearer than 1/fps: keep them apart
        starts[k] = max(starts[k], starts[k - 1] + 1)
    objects = []
    for k, (t, path) in enumerate(frames):
        bpy.ops.object.select_all(action="DESELECT")
        bpy.ops.import_mesh.ply(filepath=path)
        obj = bpy.context.selected_objects[0]
        obj.name = os.path.splitext(os.path.basename(path))[0]
        obj.parent = root
        for poly in obj.data.polygons:
            poly.use_smooth = True
        objects.append(obj)
    for k, obj in enumerate(objects):
        if k > 0:
            set_shown(obj, 1, False)
        set_shown(obj, starts[k], True)
        if k + 1 < len(objects):
            set_shown(obj, starts[k + 1], False)
    scene.render.fps = fps
    scene.frame_start = starts[0]
    scene.frame_end = starts[-1]
    scene.frame_set(starts[0])
    print("MPSFLOW_BLENDER frames %d start %d end %d" % (len(objects), starts[0], starts[-1]))
    if opts["save"]:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(opts["save"]))


main()
