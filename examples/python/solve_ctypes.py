#!/usr/bin/env python3
"""Drive the avatarmap C API from Python with ctypes only (no numpy, no build step).

Usage:
    solve_ctypes.py [--library PATH] [--mirror] [--avatar FILE [--rig auto|NAME|FILE.json]]
                    [--mappings DIR] [--output OUT [--fps N]] [FILE.landmarks.jsonl]

The shared library is taken from --library, else from the environment variable
AVATARMAP_C_LIBRARY, else from the system search path (libavatarmap_c). Without a landmark
file, a built-in synthetic T-pose is solved. Prints the hips rotation {x, y, z, w} of every
frame, then a summary. With --avatar, every pose is also retargeted onto the avatar's rig
(avm_retargeter; --rig as for `avatarmap convert`, tables from --mappings or
$AVATARMAP_MAPPINGS) and the hips joint's rotation printed. With --output, the poses are
collected in an avm_clip and written (.vrma, .bvh, .pose.jsonl, or .glb with --avatar) at the
frames' own times, or resampled at --fps N; frames whose time is not after the previous
frame's cannot go into a clip and are skipped with a warning (as `avatarmap solve --fps` does).
Every failure, of the C API (its status and message) or of the input, is reported as one
"error: ..." line, never a traceback: exits with status 1 on any error, 2 on bad usage.
"""

import argparse
import ctypes
import ctypes.util
import json
import math
import os
import sys

AVM_BONE_COUNT = 55
AVM_EXPRESSION_COUNT = 21
AVM_BLENDSHAPE_COUNT = 52
AVM_POSE_LANDMARK_COUNT = 33
AVM_HAND_LANDMARK_COUNT = 21
AVM_FACE_COUNTS = (468, 478)
AVM_OK = 0


# ---- mirrors of the C structs (bindings/c/include/avatarmap/avatarmap.h) -----------------


class AvmLandmark(ctypes.Structure):
    _fields_ = [(name, ctypes.c_float) for name in ("x", "y", "z", "visibility", "presence")]


_LandmarkPtr = ctypes.POINTER(AvmLandmark)


class AvmFrame(ctypes.Structure):
    _fields_ = [
        ("t", ctypes.c_double),
        ("pose", _LandmarkPtr),
        ("pose_world", _LandmarkPtr),
        ("left_hand", _LandmarkPtr),
        ("left_hand_world", _LandmarkPtr),
        ("right_hand", _LandmarkPtr),
        ("right_hand_world", _LandmarkPtr),
        ("face", _LandmarkPtr),
        ("face_count", ctypes.c_int32),
    ]


class AvmPose(ctypes.Structure):
    _fields_ = [
        ("t", ctypes.c_double),
        ("hips_position", ctypes.c_float * 3),
        ("rotations", (ctypes.c_float * 4) * AVM_BONE_COUNT),  # {x, y, z, w}
        ("confidence", ctypes.c_float * AVM_BONE_COUNT),
        ("expressions", ctypes.c_float * AVM_EXPRESSION_COUNT),
        ("foot_contact", ctypes.c_float * 2),  # [left, right]: 0 = free .. 1 = planted
        ("blendshapes", ctypes.c_float * AVM_BLENDSHAPE_COUNT),  # ARKit's 52 (0.2.0)
    ]


_I, _F = ctypes.c_int32, ctypes.c_float


class AvmSolverOptions(ctypes.Structure):
    # Field order must match the header exactly; new fields are only ever appended there.
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("mirror", _I), ("image_width", _F), ("image_height", _F),
        ("solve_body", _I), ("solve_hands", _I), ("solve_face", _I),
        ("solve_hips_translation", _I),
        ("confidence_lost_below", _F), ("confidence_found_above", _F),
        ("confidence_hold_seconds", _F), ("confidence_ease_seconds", _F),
        ("confidence_regain_seconds", _F),
        ("hips_lean_share", _F), ("forearm_twist_share", _F),
        ("horizontal_fov_degrees", _F), ("rest_hips_height", _F),
        ("filter_rotations", _I), ("rotation_min_cutoff", _F), ("rotation_beta", _F),
        ("rotation_d_cutoff", _F),
        ("filter_position", _I), ("position_min_cutoff", _F), ("position_beta", _F),
        ("position_d_cutoff", _F),
        ("filter_expressions", _I), ("expression_min_cutoff", _F), ("expression_beta", _F),
        ("expression_d_cutoff", _F),
        ("max_extrapolation_seconds", _F),
        ("file_filter", _I), ("file_smoothing", _F), ("file_threads", _I),
        ("fit_hand_shape", _I), ("fit_body_to_image", _I),
        ("foot_contacts", _I), ("root_follows_contacts", _I), ("lower_body_rest", _I),
        ("person", _I),
    ]


class AvmError(RuntimeError):
    pass


def set_field(struct, name, value, what=None):
    """struct.name = value, checked first against the field's C type: ctypes itself keeps the
    low 32 bits of 2**32 in an int32_t (0) and stores 1e39 in a float as inf, silently.
    Integer fields take integers within their type's range (booleans as 0 or 1), float fields
    finite numbers within theirs. Raises AvmError naming the field and the range. (The
    avatarmap package does the same for every field it fills: avatarmap._lib.c_value.)"""
    ctype = dict(type(struct)._fields_)[name]
    what = what or name
    if ctype in (ctypes.c_float, ctypes.c_double):
        top = 3.4028234663852886e38 if ctype is ctypes.c_float else sys.float_info.max
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise AvmError("%s: expected a number, got %r" % (what, value))
        try:
            v = float(value)
        except OverflowError:
            v = math.inf
        if not (math.isfinite(v) and -top <= v <= top):
            raise AvmError("%s: expected a finite number within +-%.8g (a C %s), got %.6g"
                           % (what, top, "float" if ctype is ctypes.c_float else "double", v))
    else:
        if isinstance(value, bool):
            value = int(value)
        if not isinstance(value, int):
            raise AvmError("%s: expected an integer, got %r" % (what, value))
        bits = 8 * ctypes.sizeof(ctype)
        lo, hi = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if ctype(-1).value == -1 \
            else (0, (1 << bits) - 1)
        if not lo <= value <= hi:
            raise AvmError("%s: expected an integer in [%d, %d], got %s"
                           % (what, lo, hi, value if value.bit_length() <= 64 else
                              "an integer of %d bits" % value.bit_length()))
        v = value
    setattr(struct, name, v)


def text(c_string):
    """A message from the C API as str (bytes that are not UTF-8, e.g. of a file name, shown
    as replacement characters rather than failing)."""
    return (c_string or b"").decode("utf-8", errors="replace")


def load_library(path):
    if not path:
        path = os.environ.get("AVATARMAP_C_LIBRARY") or ctypes.util.find_library("avatarmap_c")
    if not path:
        raise AvmError("no library: pass --library PATH or set AVATARMAP_C_LIBRARY")
    lib = ctypes.CDLL(path)
    c_int_p = ctypes.POINTER(ctypes.c_int)
    solver_p = ctypes.c_void_p  # opaque avm_solver*
    sigs = {
        "avm_version": (None, [c_int_p, c_int_p, c_int_p]),
        "avm_version_string": (ctypes.c_char_p, []),
        "avm_status_string": (ctypes.c_char_p, [ctypes.c_int]),
        "avm_bone_name": (ctypes.c_char_p, [ctypes.c_int]),
        "avm_bone_from_name": (ctypes.c_int, [ctypes.c_char_p]),
        "avm_solver_options_init_sized": (ctypes.c_int, [ctypes.POINTER(AvmSolverOptions),
                                                         ctypes.c_size_t]),
        "avm_solver_create": (ctypes.c_int, [ctypes.POINTER(AvmSolverOptions),
                                             ctypes.POINTER(solver_p)]),
        "avm_last_create_error": (ctypes.c_char_p, []),
        "avm_solver_destroy": (None, [solver_p]),
        "avm_solver_push": (ctypes.c_int, [solver_p, ctypes.POINTER(AvmFrame)]),
        "avm_solver_get_pose": (ctypes.c_int, [solver_p, ctypes.POINTER(AvmPose)]),
        "avm_solver_sample": (ctypes.c_int, [solver_p, ctypes.c_double,
                                             ctypes.POINTER(AvmPose)]),
        "avm_solver_last_error": (ctypes.c_char_p, [solver_p]),
        "avm_set_mappings_folder": (ctypes.c_int, [ctypes.c_char_p]),
        "avm_retargeter_create": (ctypes.c_int, [ctypes.c_char_p, ctypes.c_char_p,
                                                 ctypes.POINTER(ctypes.c_void_p)]),
        "avm_retargeter_destroy": (None, [ctypes.c_void_p]),
        "avm_retargeter_joint_count": (ctypes.c_int, [ctypes.c_void_p]),
        "avm_retargeter_joint_name": (ctypes.c_char_p, [ctypes.c_void_p, ctypes.c_int]),
        "avm_retargeter_bone_joint": (ctypes.c_int, [ctypes.c_void_p, ctypes.c_int]),
        "avm_retargeter_binding_description": (ctypes.c_char_p, [ctypes.c_void_p]),
        "avm_retargeter_apply": (ctypes.c_int, [ctypes.c_void_p, ctypes.POINTER(AvmPose),
                                                ctypes.POINTER(ctypes.c_float),
                                                ctypes.POINTER(ctypes.c_float)]),
        "avm_retargeter_last_error": (ctypes.c_char_p, [ctypes.c_void_p]),
        "avm_clip_create": (ctypes.c_int, [ctypes.POINTER(ctypes.c_void_p)]),
        "avm_clip_destroy": (None, [ctypes.c_void_p]),
        "avm_clip_add": (ctypes.c_int, [ctypes.c_void_p, ctypes.POINTER(AvmPose)]),
        "avm_clip_frame_count": (ctypes.c_int, [ctypes.c_void_p]),
        "avm_clip_write": (ctypes.c_int, [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_double,
                                          ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p,
                                          ctypes.c_size_t]),
        "avm_clip_last_error": (ctypes.c_char_p, [ctypes.c_void_p]),
    }
    for name, (restype, argtypes) in sigs.items():
        fn = getattr(lib, name)
        fn.restype = restype
        fn.argtypes = argtypes
    return lib


class Solver:
    """Owns one avm_solver handle; raises AvmError on any non-OK status."""

    def __init__(self, lib, options):
        self.lib = lib
        self.handle = ctypes.c_void_p()
        st = lib.avm_solver_create(ctypes.byref(options), ctypes.byref(self.handle))
        if st != AVM_OK:
            raise AvmError("avm_solver_create: %s: %s" % (
                self._status(st), text(lib.avm_last_create_error())))

    def _status(self, st):
        return text(self.lib.avm_status_string(st))

    def _check(self, st, what):
        if st != AVM_OK:
            msg = text(self.lib.avm_solver_last_error(self.handle))
            raise AvmError("%s: %s: %s" % (what, self._status(st), msg))

    def push(self, frame):
        self._check(self.lib.avm_solver_push(self.handle, ctypes.byref(frame)), "push")

    def pose(self):
        out = AvmPose()
        self._check(self.lib.avm_solver_get_pose(self.handle, ctypes.byref(out)), "get_pose")
        return out

    def sample(self, t):
        out = AvmPose()
        self._check(self.lib.avm_solver_sample(self.handle, t, ctypes.byref(out)), "sample")
        return out

    def close(self):
        if self.handle:
            self.lib.avm_solver_destroy(self.handle)
            self.handle = ctypes.c_void_p()


class Retargeter:
    """Owns one avm_retargeter handle: proxy poses -> the avatar's joint rotations."""

    def __init__(self, lib, avatar, rig):
        self.lib = lib
        self.handle = ctypes.c_void_p()
        st = lib.avm_retargeter_create(os.fsencode(avatar), rig.encode() if rig else None,
                                       ctypes.byref(self.handle))
        if st != AVM_OK:
            raise AvmError("avm_retargeter_create: %s: %s" % (
                text(lib.avm_status_string(st)), text(lib.avm_last_create_error())))
        self.joints = lib.avm_retargeter_joint_count(self.handle)
        self.rotations = (ctypes.c_float * (4 * self.joints))()
        self.hips_translation = (ctypes.c_float * 3)()

    def description(self):
        return text(self.lib.avm_retargeter_binding_description(self.handle))

    def apply(self, pose):
        """Returns (rotations as a flat list of x, y, z, w per joint, hips translation)."""
        st = self.lib.avm_retargeter_apply(self.handle, ctypes.byref(pose), self.rotations,
                                           self.hips_translation)
        if st != AVM_OK:
            raise AvmError("retarget: %s" % text(self.lib.avm_retargeter_last_error(self.handle)))
        return list(self.rotations), list(self.hips_translation)

    def close(self):
        if self.handle:
            self.lib.avm_retargeter_destroy(self.handle)
            self.handle = ctypes.c_void_p()


class Clip:
    """Owns one avm_clip handle: poses collected, then written as an animation file."""

    def __init__(self, lib):
        self.lib = lib
        self.handle = ctypes.c_void_p()
        if lib.avm_clip_create(ctypes.byref(self.handle)) != AVM_OK:
            raise AvmError("avm_clip_create: %s" % text(lib.avm_last_create_error()))

    def add(self, pose):
        if self.lib.avm_clip_add(self.handle, ctypes.byref(pose)) != AVM_OK:
            raise AvmError("clip: %s" % text(self.lib.avm_clip_last_error(self.handle)))

    def write(self, path, fps=0.0, avatar=None, rig=None):
        err = ctypes.create_string_buffer(1024)
        st = self.lib.avm_clip_write(self.handle, os.fsencode(path), fps,
                                     os.fsencode(avatar) if avatar else None,
                                     rig.encode() if rig else None, err, len(err))
        if st != AVM_OK:
            raise AvmError("write: %s: %s" % (text(self.lib.avm_status_string(st)),
                                              text(err.value)))

    def close(self):
        if self.handle:
            self.lib.avm_clip_destroy(self.handle)
            self.handle = ctypes.c_void_p()


# ---- frames -------------------------------------------------------------------------------

# A person facing a non-mirrored camera in a T-pose, MediaPipe world coordinates (metres,
# origin at the hip midpoint, x toward image right, y down, z away from the camera).
T_POSE_WORLD = [
    (0.0, -0.62, -0.10), (0.015, -0.65, -0.08), (0.03, -0.65, -0.08), (0.045, -0.65, -0.07),
    (-0.015, -0.65, -0.08), (-0.03, -0.65, -0.08), (-0.045, -0.65, -0.07),
    (0.075, -0.63, 0.0), (-0.075, -0.63, 0.0), (0.025, -0.57, -0.09), (-0.025, -0.57, -0.09),
    (0.18, -0.50, 0.0), (-0.18, -0.50, 0.0), (0.45, -0.50, 0.0), (-0.45, -0.50, 0.0),
    (0.70, -0.50, 0.0), (-0.70, -0.50, 0.0), (0.78, -0.50, 0.03), (-0.78, -0.50, 0.03),
    (0.80, -0.50, -0.02), (-0.80, -0.50, -0.02), (0.75, -0.50, -0.05), (-0.75, -0.50, -0.05),
    (0.10, 0.0, 0.0), (-0.10, 0.0, 0.0), (0.10, 0.45, 0.0), (-0.10, 0.45, 0.0),
    (0.10, 0.88, 0.0), (-0.10, 0.88, 0.0), (0.10, 0.92, 0.05), (-0.10, 0.92, 0.05),
    (0.10, 0.95, -0.12), (-0.10, 0.95, -0.12),
]


def synthetic_frames(count=10, fps=30.0):
    """The T-pose, turning slowly about the vertical axis (a frame dict per sample)."""
    frames = []
    for i in range(count):
        yaw = 0.03 * i
        c, s = math.cos(yaw), math.sin(yaw)
        world = [[c * x + s * z, y, -s * x + c * z, 0.99, 0.99] for x, y, z in T_POSE_WORLD]
        image = [[0.5 + 0.4 * p[0], 0.5 + 0.4 * p[1], 0.4 * p[2], 0.99, 0.99] for p in world]
        frames.append({"t": i / fps, "pose": image, "pose_world": world})
    return frames


def read_landmark_file(path):
    """(header dict or None, iterator of frame dicts) of a *.landmarks.jsonl file."""
    header = None
    frames = []
    with open(path, "r", encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            try:
                obj = json.loads(line)
            except ValueError as e:  # json.JSONDecodeError, or a number Python cannot hold
                raise AvmError("%s:%d: not valid JSON: %s" % (path, number, e))
            except RecursionError:
                raise AvmError("%s:%d: JSON nested too deeply" % (path, number))
            if not isinstance(obj, dict):
                raise AvmError("%s:%d: expected a JSON object (a frame)" % (path, number))
            if number == 1 and obj.get("format") == "avatarmap.landmarks":
                header = obj
                continue
            if not isinstance(obj.get("t"), (int, float)) or isinstance(obj.get("t"), bool):
                raise AvmError('%s:%d: missing "t" or not a number (the frame time in seconds)'
                               % (path, number))
            frames.append(obj)
    return header, frames


PARTS = (("pose", AVM_POSE_LANDMARK_COUNT), ("pose_world", AVM_POSE_LANDMARK_COUNT),
         ("left_hand", AVM_HAND_LANDMARK_COUNT), ("left_hand_world", AVM_HAND_LANDMARK_COUNT),
         ("right_hand", AVM_HAND_LANDMARK_COUNT), ("right_hand_world", AVM_HAND_LANDMARK_COUNT),
         ("face", None))


def _num(v):
    return float("nan") if v is None else float(v)


def to_avm_frame(obj):
    """An AvmFrame plus the arrays it points to (keep both alive while the frame is used)."""
    frame = AvmFrame()
    frame.t = float(obj["t"])
    keep = []
    for key, count in PARTS:
        points = obj.get(key)
        if points is None:
            continue  # absent part: NULL pointer
        n = len(points)
        if count is not None and n != count:
            raise AvmError("frame t=%s: %s has %d points, expected %d" % (frame.t, key, n, count))
        if count is None and n not in AVM_FACE_COUNTS:
            raise AvmError("frame t=%s: face has %d points, expected 468 or 478" % (frame.t, n))
        array = (AvmLandmark * n)()
        for i, p in enumerate(points):
            vals = [_num(v) for v in p] + [1.0] * (5 - len(p))  # hand/face: [x, y, z]
            array[i] = AvmLandmark(*vals[:5])
        keep.append(array)
        setattr(frame, key, ctypes.cast(array, _LandmarkPtr))
        if key == "face":
            frame.face_count = n
    return frame, keep


def angle_deg(q):
    w = min(1.0, abs(q[3]))
    return math.degrees(2.0 * math.acos(w))


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("landmarks", nargs="?", help="*.landmarks.jsonl (default: synthetic)")
    parser.add_argument("--library", help="path of libavatarmap_c (or AVATARMAP_C_LIBRARY)")
    parser.add_argument("--mirror", action="store_true", help="mirrored (selfie) input")
    parser.add_argument("--avatar", help="retarget onto this avatar (.vrm, .glb, .gltf)")
    parser.add_argument("--rig", help="auto (default), a mapping table name or FILE.json")
    parser.add_argument("--mappings", help="folder of the mapping tables (or AVATARMAP_MAPPINGS)")
    parser.add_argument("--output", help="write the poses: .vrma, .bvh, .pose.jsonl, .glb")
    parser.add_argument("--fps", type=float, default=0.0,
                        help="resample the written clip at N frames per second (0: own times)")
    args = parser.parse_args(argv)
    if args.output and args.output.lower().endswith(".glb") and not args.avatar:
        parser.error("--output *.glb needs --avatar")

    try:
        lib = load_library(args.library)
    except (OSError, AvmError) as e:
        print("error: cannot load the avatarmap C library: %s" % e, file=sys.stderr)
        return 1
    major, minor, patch = ctypes.c_int(), ctypes.c_int(), ctypes.c_int()
    lib.avm_version(ctypes.byref(major), ctypes.byref(minor), ctypes.byref(patch))
    print("avatarmap %s (%d.%d.%d)" % (lib.avm_version_string().decode(), major.value,
                                       minor.value, patch.value))

    solver = retargeter = clip = None
    try:
        options = AvmSolverOptions()
        # Sized: the library writes no more than this mirror of the struct holds.
        if lib.avm_solver_options_init_sized(ctypes.byref(options),
                                             ctypes.sizeof(options)) != AVM_OK:
            raise AvmError("avm_solver_options_init_sized failed")
        options.struct_size = ctypes.sizeof(AvmSolverOptions)  # what this script knows
        set_field(options, "mirror", 1 if args.mirror else 0)
        if args.landmarks:
            header, frames = read_landmark_file(args.landmarks)
            size = header.get("image_size") if header else None
            if size:
                if not isinstance(size, list) or len(size) != 2:
                    raise AvmError("%s: header image_size: expected [width, height], got %r"
                                   % (args.landmarks, size))
                set_field(options, "image_width", size[0], "header image_size[0]")
                set_field(options, "image_height", size[1], "header image_size[1]")
        else:
            frames = synthetic_frames()
        solver = Solver(lib, options)
        hips = lib.avm_bone_from_name(b"hips")
        if args.mappings and lib.avm_set_mappings_folder(os.fsencode(args.mappings)) != AVM_OK:
            raise AvmError("avm_set_mappings_folder failed")
        if args.avatar:
            retargeter = Retargeter(lib, args.avatar, args.rig)
            hips_joint = lib.avm_retargeter_bone_joint(retargeter.handle, hips)
            print("avatar %s: %d joints; %s" % (args.avatar, retargeter.joints,
                                                retargeter.description()))
        if args.output:
            clip = Clip(lib)
        max_angle, last_t, clip_last_t, skipped = 0.0, None, None, 0
        for obj in frames:
            frame, _keep = to_avm_frame(obj)
            solver.push(frame)
            pose = solver.pose()
            q = list(pose.rotations[hips])
            if not all(math.isfinite(v) for v in q):
                raise AvmError("non-finite hips rotation at t=%g" % pose.t)
            max_angle = max(max_angle, angle_deg(q))
            print("t=%8.4f hips [x y z w] = [% .4f % .4f % .4f % .4f]  position = [% .3f % .3f % .3f]"
                  % (pose.t, q[0], q[1], q[2], q[3], *pose.hips_position))
            if retargeter is not None:
                rotations, _ = retargeter.apply(pose)
                j = rotations[4 * hips_joint:4 * hips_joint + 4]
                if not all(math.isfinite(v) for v in rotations):
                    raise AvmError("non-finite joint rotation at t=%g" % pose.t)
                print("           avatar hips joint [x y z w] = [% .4f % .4f % .4f % .4f]" % tuple(j))
            if clip is not None:
                if clip_last_t is not None and not pose.t > clip_last_t:
                    skipped += 1
                    if skipped <= 5:
                        print("warning: t=%g is not after the previous frame's t=%g: not added to "
                              "the clip" % (pose.t, clip_last_t), file=sys.stderr)
                else:
                    clip.add(pose)
                    clip_last_t = pose.t
            if last_t is not None:  # a render time between the last two captures
                mid = solver.sample(0.5 * (last_t + pose.t))
                if not all(math.isfinite(v) for v in mid.rotations[hips]):
                    raise AvmError("non-finite sampled hips rotation at t=%g" % mid.t)
            last_t = pose.t
        print("summary: %d frame(s), largest hips rotation %.2f deg" % (len(frames), max_angle))
        if clip is not None:
            if skipped:
                print("skipped %d frame(s) out of time order" % skipped, file=sys.stderr)
            clip.write(args.output, args.fps, args.avatar, args.rig)
            print("wrote %s (%d frames)" % (args.output, lib.avm_clip_frame_count(clip.handle)))
        return 0
    except (AvmError, OSError, ValueError, KeyError, TypeError) as e:
        print("error: %s" % e, file=sys.stderr)
        return 1
    except MemoryError:
        print("error: out of memory (is the input file far larger than a capture?)",
              file=sys.stderr)
        return 1
    finally:
        for handle in (solver, retargeter, clip):
            if handle is not None:
                handle.close()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
