"""ctypes declarations of the avatarmap C API (bindings/c/include/avatarmap/avatarmap.h) and
the loading of libavatarmap_c.

Internal module: the public API is in ``avatarmap``. Struct mirrors here must match the
header field for field; tests/python/test_layout.py compiles a C check against the header.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import math
import numbers
import os
from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np

BONE_COUNT = 55
EXPRESSION_COUNT = 21
BLENDSHAPE_COUNT = 52  # ARKit's face blendshapes (0.2.0)
POSE_POINTS = 33
HAND_POINTS = 21
FACE_POINTS = 478  # with iris refinement; a 468-point face has rows 468..477 NaN
FACE_POINTS_NO_IRIS = 468

# Limits (AVM_MAX_FPS, AVM_MAX_MODEL_THREADS; include/avatarmap/core/limits.hpp): checked
# against the library's tables by tests/python/test_options.py.
MAX_FPS = 1000.0
MAX_MODEL_THREADS = 64
MAX_PEOPLE = 8  # AVM_MAX_PEOPLE: avm_estimator_options.max_people

# avm_status
OK = 0
ERROR_INVALID_ARGUMENT = 1
ERROR_IO = 2
ERROR_PARSE = 3
ERROR_END_OF_FILE = 4
ERROR_UNSUPPORTED = 5
ERROR_OUT_OF_MEMORY = 6
ERROR_INTERNAL = 7

# avm_file_filter
FILE_FILTERS = {"offline": 0, "live": 1, "none": 2}

# avm_pixel_format
PIXEL_RGB8 = 0
PIXEL_RGBA8 = 2

BOOL = "bool"  # a _kinds_ value: an int32_t field that holds 0 or 1

_I32, _F32, _F64, _I64, _U32 = (ctypes.c_int32, ctypes.c_float, ctypes.c_double,
                                ctypes.c_int64, ctypes.c_uint32)
_P = ctypes.c_void_p  # opaque handles and NumPy buffers (passed as addresses)
_FloatP = ctypes.POINTER(ctypes.c_float)


class AvmLandmark(ctypes.Structure):
    _fields_ = [(n, _F32) for n in ("x", "y", "z", "visibility", "presence")]


_LandmarkP = ctypes.POINTER(AvmLandmark)


class AvmFrame(ctypes.Structure):
    _fields_ = [("t", _F64), ("pose", _LandmarkP), ("pose_world", _LandmarkP),
                ("left_hand", _LandmarkP), ("left_hand_world", _LandmarkP),
                ("right_hand", _LandmarkP), ("right_hand_world", _LandmarkP),
                ("face", _LandmarkP), ("face_count", _I32)]


class AvmPose(ctypes.Structure):
    _fields_ = [("t", _F64), ("hips_position", _F32 * 3),
                ("rotations", (_F32 * 4) * BONE_COUNT), ("confidence", _F32 * BONE_COUNT),
                ("expressions", _F32 * EXPRESSION_COUNT), ("foot_contact", _F32 * 2),
                ("blendshapes", _F32 * BLENDSHAPE_COUNT)]


# The avm_pose array as NumPy sees it: one record per pose, same offsets as the C struct
# (align=True gives C's natural alignment; the layout test checks it against the header).
POSE_DTYPE = np.dtype([("t", "<f8"), ("hips_position", "<f4", (3,)),
                       ("rotations", "<f4", (BONE_COUNT, 4)),
                       ("confidence", "<f4", (BONE_COUNT,)),
                       ("expressions", "<f4", (EXPRESSION_COUNT,)),
                       ("foot_contact", "<f4", (2,)),
                       ("blendshapes", "<f4", (BLENDSHAPE_COUNT,))], align=True)


class AvmSolverOptions(ctypes.Structure):
    # Field order as in the header; new fields are only ever appended there. _kinds_ and
    # _ranges_ say how set_field() checks a value (see c_value()): _kinds_ marks the option
    # tables' boolean rows, _ranges_ the ranges of their integer and choice rows (the library
    # checks the numbers' ranges itself). tests/python/test_options.py checks all three
    # against `avatarmap options --json` and the C defaults.
    _fields_ = [
        ("struct_size", _U32),
        ("mirror", _I32), ("image_width", _F32), ("image_height", _F32),
        ("solve_body", _I32), ("solve_hands", _I32), ("solve_face", _I32),
        ("solve_hips_translation", _I32),
        ("confidence_lost_below", _F32), ("confidence_found_above", _F32),
        ("confidence_hold_seconds", _F32), ("confidence_ease_seconds", _F32),
        ("confidence_regain_seconds", _F32),
        ("hips_lean_share", _F32), ("forearm_twist_share", _F32),
        ("horizontal_fov_degrees", _F32), ("rest_hips_height", _F32),
        ("filter_rotations", _I32), ("rotation_min_cutoff", _F32), ("rotation_beta", _F32),
        ("rotation_d_cutoff", _F32),
        ("filter_position", _I32), ("position_min_cutoff", _F32), ("position_beta", _F32),
        ("position_d_cutoff", _F32),
        ("filter_expressions", _I32), ("expression_min_cutoff", _F32),
        ("expression_beta", _F32), ("expression_d_cutoff", _F32),
        ("max_extrapolation_seconds", _F32),
        ("file_filter", _I32), ("file_smoothing", _F32), ("file_threads", _I32),
        ("fit_hand_shape", _I32), ("fit_body_to_image", _I32),
        ("foot_contacts", _I32), ("root_follows_contacts", _I32),
        ("lower_body_rest", _I32),
        ("person", _I32),
    ]
    _kinds_ = {name: BOOL for name in (
        "mirror", "solve_body", "solve_hands", "solve_face", "solve_hips_translation",
        "filter_rotations", "filter_position", "filter_expressions", "fit_hand_shape",
        "fit_body_to_image", "foot_contacts", "root_follows_contacts")}
    _ranges_ = {"file_filter": (0, 2),  # avm_file_filter
                "lower_body_rest": (0, 2),  # standing, sitting, off
                "person": (-1, 999999),  # -1: the file's only person
                "file_threads": (1, 2)}


class AvmFrameBlock(ctypes.Structure):
    _fields_ = [("struct_size", _U32), ("count", _I64), ("t", _P), ("pose", _P),
                ("pose_world", _P), ("left_hand", _P), ("left_hand_world", _P),
                ("right_hand", _P), ("right_hand_world", _P), ("face", _P),
                ("person", _P)]  # int32_t*: one person id per row


class AvmImage(ctypes.Structure):
    _fields_ = [("data", _P), ("width", _I32), ("height", _I32), ("stride_bytes", _I32),
                ("format", _I32)]


class AvmEstimatorOptions(ctypes.Structure):
    _fields_ = [("struct_size", _U32), ("models_dir", ctypes.c_char_p),
                ("model_complexity", _I32), ("hands", _I32), ("face", _I32),
                ("hand_model_complexity", _I32), ("threads", _I32), ("mirrored", _I32),
                ("static_images", _I32), ("max_people", _I32)]
    _kinds_ = {name: BOOL for name in ("hands", "face", "mirrored", "static_images")}
    _ranges_ = {"model_complexity": (0, 2), "hand_model_complexity": (0, 1),
                "threads": (1, MAX_MODEL_THREADS), "max_people": (1, MAX_PEOPLE)}


class AvmPerson(ctypes.Structure):
    # avm_person: one person of an image (several people).
    _fields_ = [("id", _I32), ("slot", _I32), ("frame", AvmFrame), ("pose", AvmPose)]


class AvmLivePerson(ctypes.Structure):
    _fields_ = [("id", _I32), ("slot", _I32), ("seen_t", _F64)]


class AvmLiveStats(ctypes.Structure):
    _fields_ = [("pushed", _I64), ("processed", _I64), ("dropped", _I64), ("failed", _I64),
                ("latency_p50_ms", _F64), ("latency_p95_ms", _F64), ("latency_max_ms", _F64),
                ("newest_t", _F64)]


WARNING_FN = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p)


class AvmConvertOptions(ctypes.Structure):
    _fields_ = [("struct_size", _U32), ("fps", _F64), ("avatar", ctypes.c_char_p),
                ("mapping", ctypes.c_char_p), ("keep_feet_on_ground", _I32),
                ("root_motion", _I32), ("solver", ctypes.POINTER(AvmSolverOptions)),
                ("warning", WARNING_FN), ("user", _P), ("foot_lock", _I32)]
    _kinds_ = {name: BOOL for name in ("keep_feet_on_ground", "root_motion", "foot_lock")}


class AvmConvertSummary(ctypes.Structure):
    _fields_ = [("struct_size", _U32), ("input_kind", _I32), ("frames_read", _I64),
                ("frames_out_of_order", _I64), ("frames_written", _I64), ("fps", _F64),
                ("seconds", _F64)]


# avm_motion_input
MOTION_INPUTS = {1: "landmarks", 2: "poses", 3: "vrma", 4: "bvh"}


class AvmCaptureSummary(ctypes.Structure):
    _fields_ = [("struct_size", _U32), ("frames", _I64), ("body_frames", _I64),
                ("left_hand_frames", _I64), ("right_hand_frames", _I64),
                ("face_frames", _I64), ("frames_not_decoded", _I64),
                ("image_width", _I32), ("image_height", _I32), ("fps", _F64),
                ("seconds", _F64), ("people_ids", _I64), ("person_lines", _I64),
                ("frames_with_people", _I64)]


# ---- Python values into C fields and arguments --------------------------------------------
# One check for every number the package hands to C: ctypes itself stores 2**32 in an int32_t
# as 0 and 1e39 in a float as inf, without a word.

def _int_range(ctype: Any) -> Tuple[int, int]:
    bits = 8 * ctypes.sizeof(ctype)
    if ctype(-1).value == -1:  # signed
        return -(1 << (bits - 1)), (1 << (bits - 1)) - 1
    return 0, (1 << bits) - 1


_C_NAMES = {ctypes.c_int8: "int8_t", ctypes.c_int16: "int16_t", ctypes.c_int32: "int32_t",
            ctypes.c_int64: "int64_t", ctypes.c_uint8: "uint8_t", ctypes.c_uint16: "uint16_t",
            ctypes.c_uint32: "uint32_t", ctypes.c_uint64: "uint64_t", ctypes.c_float: "float",
            ctypes.c_double: "double"}
_FLOAT_MAX = {ctypes.c_float: float(np.finfo(np.float32).max),
              ctypes.c_double: float(np.finfo(np.float64).max)}
_INT_LIMITS = {t: _int_range(t) for t in (ctypes.c_int8, ctypes.c_int16, ctypes.c_int32,
                                           ctypes.c_int64, ctypes.c_uint8, ctypes.c_uint16,
                                           ctypes.c_uint32, ctypes.c_uint64, ctypes.c_size_t,
                                           ctypes.c_int)}


def _c_name(ctype: Any) -> str:
    if ctype is ctypes.c_size_t:  # an alias of c_ulong or c_ulonglong
        return "size_t"
    return _C_NAMES.get(ctype, ctype.__name__)


def _shown(value: Any) -> str:
    """A value for a message: short (a hostile int may have thousands of digits)."""
    if isinstance(value, numbers.Integral) and not isinstance(value, (bool, np.bool_)) \
            and int(value).bit_length() > 64:
        return "an integer of %d bits" % int(value).bit_length()
    try:
        text = repr(value)
    except Exception:  # noqa: BLE001 - any object's repr may fail
        text = "a %s" % type(value).__name__
    return text if len(text) <= 60 else text[:57] + "..."


def c_value(ctype: Any, value: Any, what: str, kind: Optional[str] = None,
            low: Optional[float] = None, high: Optional[float] = None) -> Any:
    """`value` as ctypes type `ctype` will hold it unchanged, or InvalidArgumentError naming
    `what` and the allowed range:

    - kind BOOL (an int32_t flag): True/False (NumPy's too) or the integers 0 and 1;
    - an integer type: an integer (int or NumPy integer; not a bool, not a float) within the
      type's range (int32_t, uint32_t, int64_t, size_t, ...) and [low, high] when given;
    - float or double: a real number (not a bool), finite, within the type's range (a float
      holds at most 3.4e38) and [low, high] when given. The C API takes no NaN or infinity in
      any scalar field or argument (non-finite landmarks are arrays, not these).
    """
    if kind is None and low is None and high is None:  # the common cases, fast
        if type(value) is float and ctype in _FLOAT_MAX and -_FLOAT_MAX[ctype] <= value <= \
                _FLOAT_MAX[ctype]:
            return value  # (NaN fails the comparison)
        if type(value) is int and ctype in _INT_LIMITS and \
                _INT_LIMITS[ctype][0] <= value <= _INT_LIMITS[ctype][1]:
            return value
    from ._errors import InvalidArgumentError
    is_bool = isinstance(value, (bool, np.bool_))
    if kind == BOOL:
        if is_bool:
            return int(bool(value))
        if isinstance(value, numbers.Integral) and int(value) in (0, 1):
            return int(value)
        raise InvalidArgumentError("%s: expected a bool (True or False, or 0 or 1), got %s"
                                   % (what, _shown(value)), 1)
    if ctype in _FLOAT_MAX:
        if is_bool or not isinstance(value, numbers.Real):
            raise InvalidArgumentError("%s: expected a number, got %s (%s)"
                                       % (what, _shown(value), type(value).__name__), 1)
        top = _FLOAT_MAX[ctype]
        try:
            v = float(value)
        except OverflowError:  # an int beyond a double's range
            v = math.inf if value > 0 else -math.inf
        lo = -top if low is None else low
        hi = top if high is None else high
        if not (math.isfinite(v) and lo <= v <= hi):
            raise InvalidArgumentError(
                "%s: expected a finite number in [%.9g, %.9g] (the C field is a %s), got %s"
                % (what, lo, hi, _c_name(ctype), _shown(value)), 1)
        return v
    if is_bool or not isinstance(value, numbers.Integral):
        raise InvalidArgumentError("%s: expected an integer, got %s (%s)"
                                   % (what, _shown(value), type(value).__name__), 1)
    v = int(value)
    t_lo, t_hi = _INT_LIMITS.get(ctype) or _int_range(ctype)
    lo = t_lo if low is None else max(t_lo, int(low))
    hi = t_hi if high is None else min(t_hi, int(high))
    if not lo <= v <= hi:
        raise InvalidArgumentError("%s: expected an integer in [%d, %d] (the C field is %s), "
                                   "got %s" % (what, lo, hi, _c_name(ctype), _shown(v)), 1)
    return v


def set_field(struct: ctypes.Structure, name: str, value: Any,
              what: Optional[str] = None) -> None:
    """struct.name = value, checked by c_value() against the field's C type and the
    struct's _kinds_ (BOOL) and _ranges_ ((low, high)); `what` names it in the error
    (default: the field's name)."""
    cls = type(struct)
    ctype = dict(cls._fields_)[name]
    low, high = getattr(cls, "_ranges_", {}).get(name, (None, None))
    setattr(struct, name, c_value(ctype, value, what or name,
                                  getattr(cls, "_kinds_", {}).get(name), low, high))


PROGRESS_FN = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_int64, ctypes.c_int64)

_S = ctypes.c_int  # avm_status
_STR = ctypes.c_char_p
_SIZE = ctypes.c_size_t
_PP = ctypes.POINTER(ctypes.c_void_p)
_IntP = ctypes.POINTER(ctypes.c_int)

# name: (restype, argtypes). Functions of 0.1.0 and of issue 12; a library without one of
# them fails only when that function is used (see fn()).
_SIGNATURES: Dict[str, Tuple[object, List[object]]] = {
    "avm_version": (None, [_IntP, _IntP, _IntP]),
    "avm_version_string": (_STR, []),
    "avm_status_string": (_STR, [_S]),
    "avm_bone_name": (_STR, [ctypes.c_int]),
    "avm_bone_parent": (ctypes.c_int, [ctypes.c_int]),
    "avm_bone_from_name": (ctypes.c_int, [_STR]),
    "avm_expression_name": (_STR, [ctypes.c_int]),
    "avm_blendshape_name": (_STR, [ctypes.c_int]),
    "avm_solver_options_init_sized": (_S, [ctypes.POINTER(AvmSolverOptions), _SIZE]),
    "avm_solver_create": (_S, [ctypes.POINTER(AvmSolverOptions), _PP]),
    "avm_last_create_error": (_STR, []),
    "avm_solver_destroy": (None, [_P]),
    "avm_solver_reset": (_S, [_P]),
    "avm_solver_push": (_S, [_P, ctypes.POINTER(AvmFrame)]),
    "avm_solver_get_pose": (_S, [_P, _P]),
    "avm_solver_sample": (_S, [_P, _F64, _P]),
    "avm_solver_last_error": (_STR, [_P]),
    "avm_solve_file": (_S, [_STR, _STR, ctypes.POINTER(AvmSolverOptions), _P, _SIZE]),
    "avm_solve_file_to_clip": (_S, [_STR, ctypes.POINTER(AvmSolverOptions), _PP, _P, _SIZE]),
    "avm_set_mappings_folder": (_S, [_STR]),
    "avm_find_resource": (_S, [ctypes.c_int, _STR, _P, _SIZE, _P, _SIZE, _P, _SIZE]),
    "avm_retargeter_create": (_S, [_STR, _STR, _PP]),
    "avm_retargeter_destroy": (None, [_P]),
    "avm_retargeter_joint_count": (ctypes.c_int, [_P]),
    "avm_retargeter_joint_name": (_STR, [_P, ctypes.c_int]),
    "avm_retargeter_joint_parent": (ctypes.c_int, [_P, ctypes.c_int]),
    "avm_retargeter_bone_joint": (ctypes.c_int, [_P, ctypes.c_int]),
    "avm_retargeter_binding_description": (_STR, [_P]),
    "avm_retargeter_apply": (_S, [_P, _P, _P, _P]),
    "avm_retargeter_last_error": (_STR, [_P]),
    "avm_clip_create": (_S, [_PP]),
    "avm_clip_destroy": (None, [_P]),
    "avm_clip_add": (_S, [_P, _P]),
    "avm_clip_frame_count": (ctypes.c_int, [_P]),
    "avm_clip_write": (_S, [_P, _STR, _F64, _STR, _STR, _P, _SIZE]),
    "avm_clip_last_error": (_STR, [_P]),
    "avm_estimator_options_init_sized": (_S, [ctypes.POINTER(AvmEstimatorOptions), _SIZE]),
    "avm_estimator_create": (_S, [ctypes.POINTER(AvmEstimatorOptions),
                                  ctypes.POINTER(AvmSolverOptions), _PP]),
    "avm_estimator_destroy": (None, [_P]),
    "avm_estimator_process": (_S, [_P, ctypes.POINTER(AvmImage), _F64,
                                   ctypes.POINTER(AvmFrame), _P]),
    "avm_estimator_last_error": (_STR, [_P]),
    "avm_estimator_process_people": (_S, [_P, ctypes.POINTER(AvmImage), _F64,
                                          ctypes.POINTER(AvmPerson), _I32,
                                          ctypes.POINTER(_I32)]),
    "avm_live_create": (_S, [ctypes.POINTER(AvmEstimatorOptions),
                             ctypes.POINTER(AvmSolverOptions), _PP]),
    "avm_live_destroy": (None, [_P]),
    "avm_live_push": (_S, [_P, ctypes.POINTER(AvmImage), _F64]),
    "avm_live_sample": (_S, [_P, _F64, _P]),
    "avm_live_latest": (_S, [_P, _P]),
    "avm_live_get_stats": (_S, [_P, ctypes.POINTER(AvmLiveStats)]),
    "avm_live_last_error": (_STR, [_P, _P, _SIZE]),
    "avm_live_people": (_S, [_P, ctypes.POINTER(AvmLivePerson), _I32, ctypes.POINTER(_I32)]),
    "avm_live_sample_person": (_S, [_P, _I32, _F64, _P]),
    # issue 12
    "avm_landmark_reader_open": (_S, [_STR, _PP]),
    "avm_landmark_reader_header": (_S, [_P, ctypes.POINTER(_I32), ctypes.POINTER(_I32),
                                        ctypes.POINTER(_F64)]),
    "avm_landmark_reader_read": (_S, [_P, ctypes.POINTER(AvmFrameBlock),
                                      ctypes.POINTER(_I64)]),
    "avm_landmark_reader_last_error": (_STR, [_P]),
    "avm_landmark_reader_destroy": (None, [_P]),
    "avm_solve_frames": (_S, [ctypes.POINTER(AvmFrameBlock), ctypes.POINTER(AvmSolverOptions),
                              _P, _P, _SIZE]),
    "avm_clip_read": (_S, [_STR, _PP, _P, _SIZE]),
    "avm_clip_get_poses": (_S, [_P, _I64, _I64, _P]),
    "avm_clip_add_poses": (_S, [_P, _P, _I64]),
    "avm_retargeter_apply_poses": (_S, [_P, _P, _I64, _P, _P]),
    "avm_capture_file": (_S, [_STR, _STR, ctypes.POINTER(AvmEstimatorOptions),
                              ctypes.POINTER(AvmCaptureSummary), PROGRESS_FN, _P, _P, _SIZE]),
    # issue 21
    "avm_motion_input_kind": (ctypes.c_int, [_STR, ctypes.POINTER(_SIZE)]),
    "avm_convert_options_init_sized": (_S, [ctypes.POINTER(AvmConvertOptions), _SIZE]),
    "avm_convert_file": (_S, [_STR, _STR, ctypes.POINTER(AvmConvertOptions),
                              ctypes.POINTER(AvmConvertSummary), _P, _SIZE]),
}

_LIBRARY_NAME = "libavatarmap_c.so"


def _config() -> Dict[str, Optional[str]]:
    """The library's path recorded when the package was installed (the generated _config.py),
    or {}. The mapping tables and the models are found by the library (find_resource())."""
    try:
        from . import _config as cfg  # type: ignore[attr-defined]
    except ImportError:
        return {}
    return {k: getattr(cfg, k, None) for k in ("LIBRARY",)}


def _source_root() -> Optional[str]:
    """The repository root when the package runs from the source tree (bindings/python)."""
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.normpath(os.path.join(here, "..", "..", ".."))
    if os.path.isfile(os.path.join(root, "bindings", "c", "include", "avatarmap", "avatarmap.h")):
        return root
    return None


def _candidates() -> List[Tuple[str, str]]:
    """(path, where it came from) in the order the library is looked for."""
    out: List[Tuple[str, str]] = []
    env = os.environ.get("AVATARMAP_C_LIBRARY")
    if env:
        out.append((env, "$AVATARMAP_C_LIBRARY"))
    here = os.path.dirname(os.path.abspath(__file__))
    out.append((os.path.join(here, _LIBRARY_NAME), "the package folder"))
    recorded = _config().get("LIBRARY")
    if recorded:
        out.append((recorded, "recorded at install time"))
    root = _source_root()
    if root:
        out.append((os.path.join(root, "build", "bindings", "c", _LIBRARY_NAME),
                    "the source tree's build/"))
    found = ctypes.util.find_library("avatarmap_c")
    if found:
        out.append((found, "the system's library path"))
    return out


def _load() -> Tuple[ctypes.CDLL, str]:
    tried = []
    for path, where in _candidates():
        if "/" in path and not os.path.exists(path):
            tried.append("%s (%s): no such file" % (path, where))
            continue
        try:
            return ctypes.CDLL(path), path
        except OSError as e:
            tried.append("%s (%s): %s" % (path, where, e))
    raise ImportError(
        "avatarmap: cannot load the C library libavatarmap_c.so. Tried:\n  " +
        "\n  ".join(tried or ["(nothing)"]) +
        "\nBuild it (cmake --build build --target avatarmap_c) and install the package again "
        "(pip install --no-build-isolation ./bindings/python, or cmake --install build), or "
        "set AVATARMAP_C_LIBRARY=/path/to/libavatarmap_c.so.")


lib, LIBRARY_PATH = _load()
_declared: Dict[str, Callable] = {}


def fn(name: str) -> Callable:
    """The C function `name`, declared; UnsupportedError when the loaded library lacks it
    (a library older than this package)."""
    f = _declared.get(name)
    if f is None:
        try:
            f = getattr(lib, name)
        except AttributeError:
            from ._errors import UnsupportedError
            raise UnsupportedError(
                "%s is not in the loaded C library %s (version %s): rebuild libavatarmap_c "
                "from the same source as this package" % (name, LIBRARY_PATH, version()),
                ERROR_UNSUPPORTED) from None
        restype, argtypes = _SIGNATURES[name]
        f.restype = restype
        f.argtypes = argtypes
        _declared[name] = f
    return f


def text(c_string: Optional[bytes]) -> str:
    """A C string as str (bytes that are not UTF-8, e.g. in a file name, replaced)."""
    return (c_string or b"").decode("utf-8", errors="replace")


def version() -> str:
    return text(fn("avm_version_string")())


def status_name(status: int) -> str:
    return text(fn("avm_status_string")(status))


# avm_resource
RESOURCE_MAPPINGS = 0
RESOURCE_MODELS = 1
RESOURCE_VIEWER_PAGE = 2
RESOURCE_VIEWER_MODULES = 3


def find_resource(kind: int, folder: Optional[str] = None) -> Tuple[Optional[str], str]:
    """(folder, rule) as the library finds the shipped folder `kind` (avm_find_resource: the
    explicit `folder`, else the environment, else the installed location beside the library,
    else its source tree; docs/architecture.md "Resources"), or (None, the message listing
    every place looked at) when none was found."""
    out_folder = ctypes.create_string_buffer(4096)
    out_rule = ctypes.create_string_buffer(64)
    err = ctypes.create_string_buffer(4096)
    explicit = os.fsencode(folder) if folder else None
    status = fn("avm_find_resource")(kind, explicit, out_folder, len(out_folder), out_rule,
                                     len(out_rule), err, len(err))
    if status != OK:
        return None, text(err.value)
    return os.fsdecode(out_folder.value), text(out_rule.value)


def models_dir_default() -> Optional[str]:
    """The models folder to use when none is given (find_resource(RESOURCE_MODELS)), or None
    (the C library then says where it looked)."""
    return find_resource(RESOURCE_MODELS)[0]
