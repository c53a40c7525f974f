"""Imports a take into Blender from the command line (the add-on avatarmap_blender, run
without installing it).

  blender -b [SCENE.blend] --python bindings/blender/import_take.py -- INPUT
          [--armature NAME] [--avatar FILE] [--mapping M] [--models DIR] [--clear]
          [--out SCENE.blend] [--summary FILE.json]

INPUT: a video (captured first: needs the models), a *.landmarks.jsonl, a *.pose.jsonl, a
.vrma or animation .glb, or a .bvh. The take becomes an action on an armature (a new one
named --armature NAME or after INPUT; an existing armature of that name with the take's
skeleton gets the action), starting at scene frame 1; the scene's frame rate and frame range
become the take's. --clear removes every object of the scene first (the factory scene's
cube, camera and light). --out saves the .blend (Blender writes it beside the target and
renames it into place). --summary writes what was imported as JSON. Exit status 0, or 1 with
a message naming the problem, 2 on bad usage. docs/blender.md.
"""
import argparse
import json
import os
import sys
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

from avatarmap_blender.take import TakeError, import_take  # noqa: E402

PROG = "import_take.py"


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog=PROG, description="Import a video, landmarks or an avatarmap animation onto a "
        "Blender armature (run as: blender -b --python import_take.py -- INPUT ...)")
    p.add_argument("input", help="video, *.landmarks.jsonl, *.pose.jsonl, .vrma, .glb or .bvh")
    p.add_argument("--armature", default="", help="armature name (default: INPUT's stem); "
                   "an existing armature with the take's skeleton gets the take as an action")
    p.add_argument("--avatar", default="", help="avatar (.vrm, .glb, .bvh) whose rig the "
                   "armature takes (default: the proxy skeleton of the 55 VRM bones)")
    p.add_argument("--mapping", default="", help="mapping table for --avatar (auto|NAME|FILE)")
    p.add_argument("--models", default="", help="capture models folder (videos only)")
    p.add_argument("--clear", action="store_true", help="remove every object first")
    p.add_argument("--out", default="", help="save the scene to this .blend")
    p.add_argument("--summary", default="", help="write what was imported as JSON")
    return p.parse_args(argv)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    try:
        args = parse_args(argv)
    except SystemExit as e:  # argparse: usage printed; exit Blender with its status
        sys.stdout.flush()
        os._exit(e.code if isinstance(e.code, int) else 2)
    if args.clear:
        for obj in list(bpy.data.objects):
            bpy.data.objects.remove(obj, do_unlink=True)

    def progress(done, total):
        if total > 0:
            print("%s: capture %d/%d frames" % (PROG, done, total), flush=True)

    try:
        take = import_take(bpy.context, args.input, armature=args.armature, avatar=args.avatar,
                           mapping=args.mapping, models=args.models, progress=progress)
        if args.out:
            out = os.path.abspath(args.out)
            bpy.ops.wm.save_as_mainfile(filepath=out, check_existing=False)
        if args.summary:
            tmp = args.summary + ".tmp"
            with open(tmp, "w", encoding="utf-8") as f:
                json.dump(take.as_dict(), f, indent=1)
            os.replace(tmp, args.summary)
    except Exception as e:  # noqa: BLE001 - any failure must end Blender with status 1
        if not isinstance(e, TakeError):
            traceback.print_exc()
        print("%s: error: %s" % (PROG, e), file=sys.stderr, flush=True)
        sys.stdout.flush()
        os._exit(1)
    print("%s: %s -> armature %r, action %r: %d frames at %g fps, scene frames %d..%d%s"
          % (PROG, args.input, take.armature, take.action, take.frames, take.fps,
             take.frame_start, take.frame_end, (", saved " + args.out) if args.out else ""),
          flush=True)


main()
