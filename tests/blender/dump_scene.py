"""Blender side of tests/blender/test_import.py: dumps a saved scene's timing and the world
positions of some bones of one armature (or of some objects: a .glb without skin comes in as
empties) at some scene frames, as JSON.

  blender -b SCENE.blend --python tests/blender/dump_scene.py -- --armature NAME \
      --bones leftHand,leftFoot --frames 1,30,60 --out dump.json

{"fps": int, "fps_base": float, "frame_start": int, "frame_end": int, "action": str,
 "action_range": [first, last], "frames": {"F": {"bone": [x, y, z]}}}: Blender's world axes
(Z up), metres, the bone heads (the BVH joints). Exits 1 with a message on any error.
"""
import argparse
import json
import os
import sys
import traceback

import bpy


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="dump_scene.py")
    p.add_argument("--armature", required=True)
    p.add_argument("--bones", required=True)
    p.add_argument("--frames", required=True)
    p.add_argument("--out", required=True)
    args = p.parse_args(argv)
    scene = bpy.context.scene
    obj = bpy.data.objects[args.armature]
    if obj.animation_data and obj.animation_data.action:
        action = obj.animation_data.action
        name, first, last = action.name, *action.frame_range
    else:  # a hierarchy of empties (a .glb without skin): every action's span
        spans = [a.frame_range for a in bpy.data.actions]
        name, first, last = "", min(s[0] for s in spans), max(s[1] for s in spans)
    out = {"fps": scene.render.fps, "fps_base": scene.render.fps_base,
           "frame_start": scene.frame_start, "frame_end": scene.frame_end,
           "action": name, "action_range": [first, last], "frames": {}}

    def where(b):  # a bone's head, or an object's origin (empties)
        if obj.type == 'ARMATURE' and b in obj.pose.bones:
            return list(obj.matrix_world @ obj.pose.bones[b].head)
        return list(bpy.data.objects[b].matrix_world.translation)

    for f in (int(s) for s in args.frames.split(",")):
        scene.frame_set(f)
        bpy.context.view_layer.update()
        out["frames"][str(f)] = {b: where(b) for b in args.bones.split(",")}
    with open(args.out, "w", encoding="utf-8") as f:
        json.dump(out, f, indent=1)


try:
    main()
except BaseException:  # noqa: BLE001 - Blender would exit 0 after a script's exception
    traceback.print_exc()
    sys.stderr.flush()
    os._exit(1)
