"""Blender side of the interoperability check (tools/interop/check_blender.sh).

Run:  blender -b --factory-startup -P tools/interop/blender_check.py -- \
          --input FILE.bvh|FILE.glb --frames 0,10,20 [--fps 30] [--bvh-scale 0.01] \
          [--out positions.json]

Imports FILE with Blender's own importer (BVH: bpy.ops.import_anim.bvh, the motion starting
at scene frame 1; glTF: bpy.ops.import_scene.gltf, key time t at scene frame t * fps), then
for every requested motion frame k (0-based) prints the world position of every bone's head
(and of every other imported object) as JSON:
  {"unit": "m", "frames": {"k": {"name": [x, y, z], ...}, ...}}
Positions are converted back from Blender's Z-up to the files' Y-up axes:
(x, y, z)_blender -> (x, z, -y), the inverse of both importers' default axis conversion
(forward -Z, up Y). --bvh-scale is the importer's global_scale (0.01 for a centimetre BVH)
so that the result is in metres.
"""
import argparse
import builtins
import json
import sys

import bpy


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="blender_check.py")
    p.add_argument("--input", required=True)
    p.add_argument("--frames", required=True, help="comma-separated 0-based motion frames")
    p.add_argument("--fps", type=float, default=30.0)
    p.add_argument("--bvh-scale", type=float, default=0.01)
    p.add_argument("--out", default="")
    return p.parse_args(argv)


def patch_bvh_importer():
    """Blender 3.4's BVH importer opens files with mode 'rU', which Python 3.11 rejects
    (Debian bookworm builds Blender 3.4 against Python 3.11). Newer importers open with 'r';
    shadow `open` in the importer's module so both work."""
    try:
        from io_anim_bvh import import_bvh
    except ImportError:
        return

    def open_without_u(file, mode="r", *args, **kwargs):
        return builtins.open(file, mode.replace("U", ""), *args, **kwargs)

    import_bvh.open = open_without_u


def patch_gltf_importer():
    """Blender 3.4's glTF importer uses `np.bool`, removed in NumPy 1.24 (which Debian bookworm
    ships beside Blender 3.4). Restore the alias; newer importers no longer use it."""
    try:
        import numpy
    except ImportError:
        return
    if "bool" not in numpy.__dict__:
        numpy.bool = numpy.bool_


def y_up(v):
    return [v.x, v.z, -v.y]


def main():
    args = parse_args()
    scene = bpy.context.scene
    # Factory startup brings a cube, a camera and a light: start from an empty scene.
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    scene.render.fps = int(round(args.fps))
    scene.render.fps_base = scene.render.fps / args.fps
    path = args.input
    if path.lower().endswith(".bvh"):
        patch_bvh_importer()
        bpy.ops.import_anim.bvh(filepath=path, global_scale=args.bvh_scale, frame_start=1,
                                use_fps_scale=False, update_scene_fps=False,
                                update_scene_duration=True, rotate_mode='NATIVE',
                                axis_forward='-Z', axis_up='Y')
        first_frame = 1
    else:
        patch_gltf_importer()
        bpy.ops.import_scene.gltf(filepath=path)
        first_frame = 0
    frames = {}
    for k in (int(s) for s in args.frames.split(",") if s.strip()):
        scene.frame_set(first_frame + k)
        bpy.context.view_layer.update()
        out = {}
        for obj in scene.objects:
            if obj.type == 'ARMATURE':
                for pb in obj.pose.bones:
                    out[pb.name] = y_up(obj.matrix_world @ pb.head)
            elif obj.name not in out:
                out[obj.name] = y_up(obj.matrix_world.translation)
        frames[str(k)] = out
    text = json.dumps({"unit": "m", "frames": frames})
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)
    else:
        print(text)


main()
