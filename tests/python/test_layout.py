"""The package's mirrors of the C structs against the header itself: a small C program
compiled against bindings/c/include/avatarmap/avatarmap.h prints every struct's size and
every field's offset, and they must equal ctypes' and POSE_DTYPE's."""

import ctypes
import os
import shutil
import subprocess

import numpy as np
import pytest

import avatarmap
from avatarmap import _lib

STRUCTS = {  # C name -> ctypes mirror
    "avm_landmark": _lib.AvmLandmark,
    "avm_frame": _lib.AvmFrame,
    "avm_pose": _lib.AvmPose,
    "avm_solver_options": _lib.AvmSolverOptions,
    "avm_image": _lib.AvmImage,
    "avm_estimator_options": _lib.AvmEstimatorOptions,
    "avm_live_stats": _lib.AvmLiveStats,
    "avm_frame_block": _lib.AvmFrameBlock,
    "avm_capture_summary": _lib.AvmCaptureSummary,
    "avm_convert_options": _lib.AvmConvertOptions,
    "avm_convert_summary": _lib.AvmConvertSummary,
}


def _header():
    include = os.environ.get("AVATARMAP_C_INCLUDE")
    if not include:
        here = os.path.dirname(os.path.abspath(__file__))
        include = os.path.join(here, "..", "..", "bindings", "c", "include")
    header = os.path.join(include, "avatarmap", "avatarmap.h")
    if not os.path.isfile(header):
        pytest.skip("the C header is not found (AVATARMAP_C_INCLUDE)")
    return include, open(header, encoding="utf-8").read()


def _c_layout(tmp_path):
    """{struct: (size, {field: offset})} as the C compiler sees the header."""
    include, text = _header()
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not cc or not shutil.which(cc):
        pytest.skip("no C compiler (CC) to check the layout against the header")
    lines = ['#include <stdio.h>', '#include <stddef.h>', '#include "avatarmap/avatarmap.h"',
             "int main(void) {"]
    present = {}
    for name, mirror in STRUCTS.items():
        if ("struct %s {" % name) not in text:
            continue  # not in this header yet
        present[name] = mirror
        lines.append('  printf("%s sizeof %%zu\\n", sizeof(%s));' % (name, name))
        for field, _ in mirror._fields_:
            lines.append('  printf("%s %s %%zu\\n", offsetof(%s, %s));'
                         % (name, field, name, field))
    lines += ["  return 0;", "}"]
    src = tmp_path / "layout.c"
    src.write_text("\n".join(lines) + "\n")
    exe = tmp_path / "layout"
    subprocess.run([cc, "-std=c99", "-I", include, str(src), "-o", str(exe)], check=True)
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    layout = {}
    for line in out.splitlines():
        struct, field, value = line.split()
        size, offsets = layout.setdefault(struct, [None, {}])
        if field == "sizeof":
            layout[struct][0] = int(value)
        else:
            offsets[field] = int(value)
    return present, layout


def test_ctypes_mirrors_match_the_header(tmp_path):
    present, layout = _c_layout(tmp_path)
    assert "avm_pose" in present and "avm_solver_options" in present
    for name, mirror in present.items():
        size, offsets = layout[name]
        assert ctypes.sizeof(mirror) == size, name
        for field, _ in mirror._fields_:
            assert getattr(mirror, field).offset == offsets[field], (name, field)


def test_pose_dtype_matches_the_header(tmp_path):
    _, layout = _c_layout(tmp_path)
    size, offsets = layout["avm_pose"]
    assert avatarmap.POSE_DTYPE.itemsize == size == 1424  # 1192 before 0.2.0
    for field in avatarmap.POSE_DTYPE.names:
        assert avatarmap.POSE_DTYPE.fields[field][1] == offsets[field], field
    assert avatarmap.POSE_DTYPE["rotations"].shape == (55, 4)


def test_poses_view_one_record_array():
    poses = avatarmap.Poses.empty(3)
    rec = poses.records
    assert rec.dtype == avatarmap.POSE_DTYPE
    poses.rotations[1, 5] = (0.0, 0.0, 0.6, 0.8)  # a view: the record changes too
    assert np.array_equal(rec["rotations"][1, 5], np.float32([0, 0, 0.6, 0.8]))
    assert poses.records is rec  # still views it
    copy = avatarmap.Poses(t=poses.t.copy(), hips_position=poses.hips_position.copy(),
                           rotations=poses.rotations.copy(), confidence=poses.confidence.copy(),
                           expressions=poses.expressions.copy())
    assert np.array_equal(copy.records, rec)  # assembled from plain arrays: same bytes
    assert copy.records.tobytes() == rec.tobytes()


def _example_mirrors():
    """The ctypes mirrors the standalone examples (examples/python/*_ctypes.py: ctypes only, no
    NumPy, so they keep their own) declare: {C struct: (example, mirror)}."""
    import importlib.util
    import sys
    here = os.path.dirname(os.path.abspath(__file__))
    folder = os.path.normpath(os.path.join(here, "..", "..", "examples", "python"))
    if not os.path.isdir(folder):
        pytest.skip("examples/python is not beside the tests")
    sys.path.insert(0, folder)  # capture_ctypes imports solve_ctypes
    try:
        found = {}
        for example in ("solve_ctypes", "capture_ctypes"):
            spec = importlib.util.spec_from_file_location(
                "example_" + example, os.path.join(folder, example + ".py"))
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)  # declarations only: main() is not run
            for c_name, mirror in STRUCTS.items():
                ours = getattr(module, mirror.__name__, None)
                if ours is not None and c_name not in found:
                    found[c_name] = (example, ours)
        return found
    finally:
        sys.path.remove(folder)


def test_example_mirrors_match_the_header_and_the_package(tmp_path):
    """The examples' mirrors have the header's layout and the package's field names: a field
    added to the header fails here until both are updated."""
    present, layout = _c_layout(tmp_path)
    examples = _example_mirrors()
    assert "avm_solver_options" in examples and "avm_estimator_options" in examples
    for c_name, (example, mirror) in examples.items():
        if c_name not in present:
            continue
        size, offsets = layout[c_name]
        assert ctypes.sizeof(mirror) == size, (example, c_name)
        assert [f for f, _ in mirror._fields_] == [f for f, _ in STRUCTS[c_name]._fields_], (
            example, c_name)
        for field, _ in mirror._fields_:
            assert getattr(mirror, field).offset == offsets[field], (example, c_name, field)
