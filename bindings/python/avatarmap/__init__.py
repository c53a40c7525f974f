"""avatarmap: video of a person -> avatar animation, from Python.

A thin layer over the avatarmap C API (libavatarmap_c, through ctypes) with NumPy arrays in
and out: read landmark and pose files, solve landmarks into proxy poses of the 55 VRM 1.0
humanoid bones (whole arrays in one call, or frame by frame), retarget onto an avatar's rig,
capture landmarks from images and videos, and write .vrma, .glb, .bvh and .pose.jsonl files.
See docs/python.md.

    import avatarmap as am
    lm = am.read_landmarks("take.landmarks.jsonl")
    poses = am.solve(lm)                       # offline smoothing, as `avatarmap solve`
    am.write_animation(poses, "take.vrma")

Errors raise AvatarmapError subclasses carrying the C API's message; values that do not fit
the C field they fill raise InvalidArgumentError before any call. Handles (Solver,
Retargeter, Estimator, Live) close with ``with`` blocks or close(), from any thread: close()
waits for the calls in flight, later calls raise "... is closed". Calls into the library
release the GIL, so different handles work in parallel from different threads.
"""

from __future__ import annotations

from typing import Tuple

from . import _lib
from ._data import (Landmarks, Poses, SOLVER_OPTION_NAMES, convert_file, motion_input_kind,
                    read_landmarks, read_poses, solve, solve_file, write_animation)
from ._errors import (AvatarmapError, FileIOError, InternalError, InvalidArgumentError,
                      OutOfMemoryError, ParseError, UnsupportedError)
from ._handles import (CaptureSummary, Estimator, Live, LivePerson, LiveStats, Person,
                       Retargeter, Solver, capture_file)
from ._lib import POSE_DTYPE

__all__ = [
    "AvatarmapError", "InvalidArgumentError", "FileIOError", "ParseError", "UnsupportedError",
    "OutOfMemoryError", "InternalError",
    "BONE_NAMES", "BONE_PARENTS", "EXPRESSION_NAMES", "BLENDSHAPE_NAMES", "POSE_DTYPE", "SOLVER_OPTION_NAMES",
    "bone_index", "version",
    "Landmarks", "Poses", "read_landmarks", "read_poses", "solve", "solve_file",
    "write_animation", "convert_file", "motion_input_kind",
    "Solver", "Retargeter", "Estimator", "Live", "LiveStats", "Person", "LivePerson",
    "CaptureSummary", "capture_file",
]

__version__ = "0.2.0"

#: VRM 1.0 names of the 55 proxy bones, in the order of Poses' arrays (parents first).
BONE_NAMES: Tuple[str, ...] = tuple(_lib.text(_lib.fn("avm_bone_name")(b))
                                    for b in range(_lib.BONE_COUNT))
#: Parent index of each bone (-1 for hips, the root).
BONE_PARENTS: Tuple[int, ...] = tuple(int(_lib.fn("avm_bone_parent")(b))
                                      for b in range(_lib.BONE_COUNT))
#: Names of the 21 expressions, in the order of Poses.expressions (VRM 1.0 presets, four
#: custom brows, and since 0.2.0 the emotions happy, angry, sad, relaxed, surprised).
EXPRESSION_NAMES: Tuple[str, ...] = tuple(_lib.text(_lib.fn("avm_expression_name")(e))
                                          for e in range(_lib.EXPRESSION_COUNT))
#: ARKit's 52 blendshape names ("browDownLeft" .. "tongueOut"), in the order of
#: Poses.blendshapes (Apple's alphabetical order; "Left" is the person's left).
BLENDSHAPE_NAMES: Tuple[str, ...] = tuple(_lib.text(_lib.fn("avm_blendshape_name")(s))
                                          for s in range(_lib.BLENDSHAPE_COUNT))

_BONE_INDEX = {name: i for i, name in enumerate(BONE_NAMES)}


def bone_index(name: str) -> int:
    """Index of a bone from its exact VRM 1.0 name ("hips", "leftUpperArm", ...).
    Raises InvalidArgumentError for an unknown name."""
    try:
        return _BONE_INDEX[name]
    except (KeyError, TypeError):
        raise InvalidArgumentError("unknown bone %r (VRM 1.0 humanoid names such as \"hips\" "
                                   "or \"leftUpperArm\"; see avatarmap.BONE_NAMES)" % (name,),
                                   1) from None


def version() -> str:
    """Version of the loaded C library ("MAJOR.MINOR.PATCH")."""
    return _lib.version()


def library_path() -> str:
    """Path of the libavatarmap_c that was loaded."""
    return _lib.LIBRARY_PATH
