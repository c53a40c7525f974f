"""Brings a take (a video, a landmark file or an animation) onto a Blender armature.

The route, for every input: the avatarmap Python package (bindings/python, over the C API)
turns the input into a BVH on a skeleton - the proxy skeleton of the 55 VRM bones, or the rig
of an avatar (``avatar``) - and Blender's own BVH importer reads it, with the compatibility
shims of compat.py around the call. The scene's frame rate and frame range are then set from
the take. docs/blender.md explains the choice.

    video  --capture_file-->  landmarks  --convert_file-->  poses  --convert_file-->  BVH
    *.landmarks.jsonl, *.pose.jsonl, .vrma, .glb (animation), .bvh enter at the second step.
"""
import importlib
import json
import math
import os
import struct
import sys
import tempfile
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional

import bpy

from . import compat

# The file names capture_file() reads as video (bindings/python/avatarmap/batch.py's list).
VIDEO_SUFFIXES = (".mp4", ".mkv", ".avi", ".mov", ".webm", ".m4v", ".mpg", ".mpeg", ".ts",
                  ".wmv", ".flv", ".gif")
# Our BVH files are written in centimetres (docs/export.md); Blender works in metres.
BVH_SCALE = 0.01
# Two armatures hold the same skeleton when every bone's rest matrix agrees this closely (m).
REST_TOLERANCE = 1e-4
# A .glb whose keys are sparser than this (keys/s) has no key per frame: its take keeps the
# scene's rate instead of the keys' spacing.
MIN_KEY_RATE = 10.0

_HERE = os.path.dirname(os.path.abspath(__file__))


class TakeError(Exception):
    """A take could not be imported; the message says why and what to do."""


@dataclass
class Take:
    """What import_take() did: the armature object and action it animated, the take's
    frame count and rate, and the scene frames the motion covers."""
    source: str
    kind: str
    armature: str
    action: str
    frames: int
    fps: float
    frame_start: int
    frame_end: int

    def as_dict(self) -> Dict[str, Any]:
        return dict(self.__dict__)


# --- finding the avatarmap package -----------------------------------------------------------

def _package_candidates(package_dir: str) -> List[str]:
    """Folders that may hold the ``avatarmap`` package, in the order they are tried before
    the interpreter's own path: the preference / argument, $AVATARMAP_PYTHON_DIR, and the
    checkout this add-on sits in (bindings/blender/avatarmap_blender -> bindings/python)."""
    out = []
    for d in (package_dir, os.environ.get("AVATARMAP_PYTHON_DIR", "")):
        if d:
            out.append(os.path.abspath(os.path.expanduser(d)))
    checkout = os.path.normpath(os.path.join(_HERE, "..", "..", "python"))
    if os.path.isfile(os.path.join(checkout, "avatarmap", "__init__.py")):
        out.append(checkout)
    return out


def _prefix_candidates() -> List[str]:
    """The package folders of the install prefixes docs/python.md describes (tried after the
    interpreter's own path): ~/.local and /usr/local, lib/python3.X/dist-packages."""
    sub = os.path.join("lib", "python%d.%d" % sys.version_info[:2], "dist-packages")
    return [os.path.join(os.path.expanduser("~/.local"), sub), os.path.join("/usr/local", sub)]


def _forget_package() -> None:
    for name in [n for n in sys.modules if n == "avatarmap" or n.startswith("avatarmap.")]:
        del sys.modules[name]


def load_avatarmap(package_dir: str = "", library: str = ""):
    """Imports the avatarmap Python package and returns it. ``library`` (else
    $AVATARMAP_C_LIBRARY, else the package's own search: its folder, the path recorded at
    install, the source tree's build/, the system's path) is the C library it loads."""
    if library:
        os.environ["AVATARMAP_C_LIBRARY"] = os.path.abspath(os.path.expanduser(library))
    loaded = sys.modules.get("avatarmap")
    if loaded is not None and hasattr(loaded, "convert_file"):
        return loaded
    tried = []
    attempts = [(d, True) for d in _package_candidates(package_dir)]
    attempts.append(("", False))  # the interpreter's own path (an install into it)
    attempts += [(d, True) for d in _prefix_candidates()]
    for folder, add in attempts:
        if add and not os.path.isfile(os.path.join(folder, "avatarmap", "__init__.py")):
            tried.append(folder)
            continue
        if add and folder not in sys.path:
            sys.path.insert(0, folder)
        try:
            return importlib.import_module("avatarmap")
        except ModuleNotFoundError as e:
            _forget_package()
            if e.name not in ("avatarmap", None):  # the package is there, a dependency not
                raise TakeError("avatarmap add-on: the avatarmap package in %s needs the "
                                "Python module %s (Debian: sudo apt-get install python3-%s)"
                                % (folder or "Blender's Python path", e.name, e.name)) from e
            tried.append(folder or "Blender's Python path")
        except ImportError as e:  # found, but its C library did not load
            _forget_package()
            raise TakeError(
                "avatarmap add-on: the avatarmap package in %s could not load its C library:\n"
                "%s\nBuild it (cmake --build build --target avatarmap_c) and set "
                "AVATARMAP_C_LIBRARY=/path/to/libavatarmap_c.so, or the add-on's preference "
                "'C library'" % (folder or "Blender's Python path", e)) from e
        finally:
            if add and sys.path and sys.path[0] == folder and "avatarmap" not in sys.modules:
                sys.path.remove(folder)
    raise TakeError(
        "avatarmap add-on: the avatarmap Python package was not found (tried: %s). Install it "
        "(cmake --install build --prefix ~/.local), or set the add-on's preference 'Python "
        "package folder' (or AVATARMAP_PYTHON_DIR) to a checkout's bindings/python, with "
        "AVATARMAP_C_LIBRARY=/path/to/libavatarmap_c.so when the library is not in the "
        "checkout's build/ (docs/blender.md)" % ", ".join(tried))


# --- the take as a BVH -----------------------------------------------------------------------

def _stem(path: str) -> str:
    name = os.path.basename(path)
    for ext in (".landmarks.jsonl", ".pose.jsonl"):
        if name.lower().endswith(ext):
            return name[:-len(ext)] or "take"
    return os.path.splitext(name)[0] or "take"


def take_rate(pose_path: str, times) -> float:
    """The take's frame rate: the pose file's header "fps" when it names one, else the
    median spacing of the frames' times (rounded to a whole rate within 0.01), else 30."""
    with open(pose_path, "r", encoding="utf-8") as f:
        first = f.readline()
    try:
        header = json.loads(first)
        fps = float(header.get("fps", 0.0)) if "format" in header else 0.0
    except (ValueError, AttributeError, TypeError):
        fps = 0.0
    if math.isfinite(fps) and fps > 0.0:
        return fps
    return rate_of_times(times)


def rate_of_times(times) -> float:
    """The median spacing of increasing times as a rate (a whole rate when within 0.01), 30
    for fewer than two."""
    if len(times) >= 2:
        steps = sorted(b - a for a, b in zip(times[:-1], times[1:]) if b > a)
        if steps:
            fps = 1.0 / steps[len(steps) // 2]
            return float(round(fps)) if abs(fps - round(fps)) < 0.01 else fps
    return 30.0


def bvh_frame_count(path: str) -> int:
    """The "Frames:" count of a BVH's MOTION section."""
    with open(path, "r", encoding="utf-8") as f:
        for line in f:
            if line.strip().startswith("Frames:"):
                return int(line.split(":", 1)[1])
    raise TakeError("%s: no 'Frames:' line (not a BVH the library wrote?)" % path)


def take_to_bvh(am, path: str, work: str, *, avatar: str = "", mapping: str = "",
                models: str = "", solver: Optional[Dict[str, Any]] = None,
                progress: Optional[Callable[[int, int], Any]] = None):
    """Writes the take at ``path`` as a BVH into the folder ``work``; returns
    (bvh path, input kind, frame rate)."""
    src = os.path.abspath(os.path.expanduser(path))
    if not os.path.isfile(src):
        raise TakeError("%s: no such file" % path)
    name = _stem(src)
    kind = None
    if src.lower().endswith(".vrm"):
        raise TakeError("%s is an avatar, not a take: import a take onto its rig with "
                        "--avatar %s" % (path, path))
    if src.lower().endswith(VIDEO_SUFFIXES):
        landmarks = os.path.join(work, name + ".landmarks.jsonl")
        try:
            am.capture_file(src, landmarks, models=models or None, progress=progress)
        except am.UnsupportedError as e:
            raise TakeError("%s: capturing a video needs a library built with ONNX Runtime "
                            "and the models (scripts/prepare_capture.sh; docs/models.md): %s"
                            % (path, e)) from e
        except am.AvatarmapError as e:
            raise TakeError("%s: capture failed: %s" % (path, e)) from e
        src, kind = landmarks, "video"
    try:
        found = am.motion_input_kind(src)
    except am.AvatarmapError as e:
        raise TakeError("%s: %s" % (path, e)) from e
    if found is None:
        raise TakeError("%s: not a take avatarmap reads; give a video, a *.landmarks.jsonl, "
                        "a *.pose.jsonl, a .vrma/.glb animation or a .bvh" % path)
    kind = kind or found
    poses = os.path.join(work, name + ".pose.jsonl")
    bvh = os.path.join(work, name + ".bvh")
    try:
        options = dict(solver or {}) if found == "landmarks" else {}
        am.convert_file(src, poses, fps=0.0, **options)  # the frames' own times
        fps = take_rate(poses, [float(t) for t in am.read_poses(poses).t])
        am.convert_file(poses, bvh, fps=fps, avatar=avatar or None, mapping=mapping or None)
    except am.AvatarmapError as e:
        message = str(e)
        raise TakeError(message if src in message else "%s: %s" % (path, message)) from e
    return bvh, kind, fps


def _glb_document(path: str):
    """(JSON document, BIN chunk bytes) of a binary glTF file, or (None, b"") when it is not
    one."""
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 20 or data[:4] != b"glTF":
        return None, b""
    length, kind = struct.unpack_from("<I4s", data, 12)
    if kind != b"JSON" or 20 + length > len(data):
        return None, b""
    try:
        doc = json.loads(data[20:20 + length].decode("utf-8"))
    except (UnicodeDecodeError, ValueError):
        return None, b""
    rest = 20 + length
    blob = b""
    if rest + 8 <= len(data):
        blob_length, blob_kind = struct.unpack_from("<I4s", data, rest)
        if blob_kind == b"BIN\0":
            blob = data[rest + 8:rest + 8 + blob_length]
    return doc, blob


def glb_key_times(doc, blob: bytes) -> List[float]:
    """The key times of the first animation of a glTF document: its sampler with the most
    keys (FLOAT seconds). Empty when there is no animation or the times cannot be read."""
    try:
        samplers = doc["animations"][0]["samplers"]
        acc = max((doc["accessors"][s["input"]] for s in samplers), key=lambda a: a["count"])
        view = doc["bufferViews"][acc["bufferView"]]
        if acc.get("componentType") != 5126 or view.get("buffer", 0) != 0:
            return []
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        stride = view.get("byteStride") or 4
        count = int(acc["count"])
        if start + stride * (count - 1) + 4 > len(blob):
            return []
        return [struct.unpack_from("<f", blob, start + i * stride)[0] for i in range(count)]
    except (KeyError, IndexError, TypeError, ValueError):
        return []


def _import_glb(context, path: str, doc, blob: bytes, armature: str) -> "Take":
    """An animated .glb (an avatar with its motion, as `avatarmap convert --avatar` writes)
    through Blender's glTF importer, its keys moved to scene frames 1..N at the take's rate."""
    times = glb_key_times(doc, blob)
    if not times:
        raise TakeError("%s: a glTF file without an animation; to animate this avatar, import "
                        "a take with --avatar %s" % (path, path))
    if armature and bpy.data.objects.get(armature) is not None:
        raise TakeError("%s: an object %r exists; a .glb brings its own armature and mesh, "
                        "give another --armature name" % (path, armature))
    scene = context.scene
    fps = rate_of_times(times)
    frames = len(times)
    if fps < MIN_KEY_RATE:  # sparse keys (not one per frame): the scene's rate, the keys' span
        fps = scene.render.fps / scene.render.fps_base
        frames = int(round((times[-1] - times[0]) * fps)) + 1
    scene.render.fps = max(1, int(round(fps)))  # the importer puts key time t at t * fps
    importer_fps = scene.render.fps
    before = set(bpy.data.objects)
    actions_before = set(bpy.data.actions)
    try:
        with compat.importer_shims():
            result = bpy.ops.import_scene.gltf(filepath=os.path.abspath(path))
    except (RuntimeError, AttributeError) as e:
        raise TakeError("Blender's glTF importer failed on %s: %s" % (path, e)) from e
    if 'FINISHED' not in result:
        raise TakeError("Blender's glTF importer did not finish on %s" % path)
    t0 = times[0]
    for action in (a for a in bpy.data.actions if a not in actions_before):
        for fc in action.fcurves:
            for kp in fc.keyframe_points:
                for point in (kp.co, kp.handle_left, kp.handle_right):
                    point.x = 1.0 + (point.x / importer_fps - t0) * fps
    new = [o for o in bpy.data.objects if o not in before]
    animated = [o for o in new if o.animation_data and o.animation_data.action]
    if not animated:
        raise TakeError("Blender's glTF importer made no animated object from %s" % path)
    # A skinned avatar comes in as an armature whose action moves its bones; one without
    # skin as a hierarchy of empties, each with its own action: then the hierarchy's root
    # stands for the take.
    armatures = [o for o in animated if o.type == 'ARMATURE']
    obj = armatures[0] if armatures else next(o for o in new if o.parent is None)
    if armature:
        obj.name = armature
        if obj.data is not None:
            obj.data.name = armature
    set_scene_timing(scene, fps, 1, frames)
    action = obj.animation_data.action.name if armatures else "%d actions" % len(
        [o for o in animated])
    return Take(source=os.path.abspath(path), kind="glb", armature=obj.name, action=action,
                frames=frames, fps=fps, frame_start=1, frame_end=frames)


# --- into Blender ----------------------------------------------------------------------------

def _same_skeleton(a, b) -> str:
    """'' when armature objects a and b have the same bones with the same rest matrices,
    else what differs."""
    names_a = [bone.name for bone in a.data.bones]
    names_b = set(bone.name for bone in b.data.bones)
    if set(names_a) != names_b:
        missing = sorted(names_b - set(names_a))[:3]
        extra = sorted(set(names_a) - names_b)[:3]
        return "bones differ (missing %s, not in the take %s)" % (missing, extra)
    for name in names_a:
        ma = a.data.bones[name].matrix_local
        mb = b.data.bones[name].matrix_local
        worst = max(abs(ma[i][j] - mb[i][j]) for i in range(4) for j in range(4))
        if worst > REST_TOLERANCE:
            return "bone %s rests elsewhere (%.4g apart)" % (name, worst)
    return ""


def _onto(new_obj, name: str):
    """The take's armature object under ``name``: the new one renamed, or - when an armature
    of that name exists and has the take's skeleton - that one, given the take's action (the
    new object is removed)."""
    existing = bpy.data.objects.get(name)
    if existing is None:
        new_obj.name = name
        new_obj.data.name = name
        return new_obj
    if existing.type != 'ARMATURE':
        raise TakeError("object %r is a %s, not an armature; give another --armature name"
                        % (name, existing.type.lower()))
    differs = _same_skeleton(existing, new_obj)
    if differs:
        raise TakeError(
            "armature %r does not have the take's skeleton: %s. A take goes onto an armature "
            "that an earlier import made with the same skeleton (the proxy skeleton, or the "
            "same --avatar); give a new --armature name to import a new one" % (name, differs))
    action = new_obj.animation_data.action
    for pb in existing.pose.bones:
        pb.rotation_mode = new_obj.pose.bones[pb.name].rotation_mode
    if existing.animation_data is None:
        existing.animation_data_create()
    existing.animation_data.action = action
    data = new_obj.data
    bpy.data.objects.remove(new_obj, do_unlink=True)
    if data.users == 0:
        bpy.data.armatures.remove(data)
    return existing


def set_scene_timing(scene, fps: float, frame_start: int, frame_end: int) -> None:
    """Scene rate fps (Blender: an integer rate over fps_base, so 29.97 = 30 / 1.001) and the
    frame range."""
    whole = max(1, int(round(fps)))
    scene.render.fps = whole
    scene.render.fps_base = whole / fps
    scene.frame_start = frame_start
    scene.frame_end = frame_end
    scene.frame_set(frame_start)


def import_take(context, path: str, *, armature: str = "", avatar: str = "", mapping: str = "",
                models: str = "", solver: Optional[Dict[str, Any]] = None,
                package_dir: str = "", library: str = "",
                progress: Optional[Callable[[int, int], Any]] = None) -> Take:
    """Imports the take at ``path`` onto an armature (a new one named ``armature`` or after
    the file, or the existing armature of that name when it has the take's skeleton) as one
    action starting at scene frame 1, and sets the scene's rate and frame range to the take's.
    Raises TakeError with the reason."""
    if path.lower().endswith(".glb") and os.path.isfile(path):
        doc, blob = _glb_document(path)
        if doc is not None and "VRMC_vrm_animation" not in doc.get("extensionsUsed", []):
            return _import_glb(context, path, doc, blob, armature)
    am = load_avatarmap(package_dir, library)
    with tempfile.TemporaryDirectory(prefix="avatarmap-blender-") as work:
        bvh, kind, fps = take_to_bvh(am, path, work, avatar=avatar, mapping=mapping,
                                     models=models, solver=solver, progress=progress)
        frames = bvh_frame_count(bvh)
        before = set(bpy.data.objects)
        try:
            with compat.importer_shims():
                result = bpy.ops.import_anim.bvh(
                    filepath=bvh, target='ARMATURE', global_scale=BVH_SCALE, frame_start=1,
                    use_fps_scale=False, update_scene_fps=False, update_scene_duration=False,
                    use_cyclic=False, rotate_mode='NATIVE', axis_forward='-Z', axis_up='Y')
        except (RuntimeError, AttributeError) as e:
            raise TakeError("Blender's BVH importer failed on the take of %s: %s (is the "
                            "add-on 'Import-Export: BioVision Motion Capture (BVH) format' "
                            "available?)" % (path, e)) from e
    if 'FINISHED' not in result:
        raise TakeError("Blender's BVH importer did not finish on the take of %s" % path)
    new = [o for o in bpy.data.objects if o not in before and o.type == 'ARMATURE']
    if len(new) != 1 or new[0].animation_data is None or new[0].animation_data.action is None:
        raise TakeError("Blender's BVH importer made no animated armature from %s" % path)
    obj = new[0]
    action = obj.animation_data.action
    action.name = _stem(os.path.abspath(path))
    action.use_fake_user = True  # kept in the .blend when another take replaces it
    if armature:
        obj = _onto(obj, armature)
    scene = context.scene
    set_scene_timing(scene, fps, 1, frames)
    return Take(source=os.path.abspath(path), kind=kind, armature=obj.name, action=action.name,
                frames=frames, fps=fps, frame_start=1, frame_end=frames)
