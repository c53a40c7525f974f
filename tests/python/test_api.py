"""Vocabulary, exceptions and handle lifetimes of the Python package."""

import math
import os
import re

import numpy as np
import pytest

import avatarmap as am


def _header_text():
    here = os.path.dirname(os.path.abspath(__file__))
    include = os.environ.get("AVATARMAP_C_INCLUDE") or os.path.join(
        here, "..", "..", "bindings", "c", "include")
    return open(os.path.join(include, "avatarmap", "avatarmap.h"), encoding="utf-8").read()


def test_bones_and_expressions_follow_the_header():
    text = _header_text()
    enum = re.search(r"typedef enum avm_bone \{(.*?)\} avm_bone;", text, re.S).group(1)
    c_names = re.findall(r"AVM_BONE_([A-Z_]+)", enum)
    assert len(am.BONE_NAMES) == 55 == len(c_names)
    # AVM_BONE_LEFT_UPPER_ARM <-> "leftUpperArm", in the same order.
    for c_name, name in zip(c_names, am.BONE_NAMES):
        words = c_name.lower().split("_")
        assert name == words[0] + "".join(w.capitalize() for w in words[1:])
    assert len(am.EXPRESSION_NAMES) == 21
    assert am.EXPRESSION_NAMES[:4] == ("blink", "blinkLeft", "blinkRight", "aa")
    assert am.EXPRESSION_NAMES[16:] == ("happy", "angry", "sad", "relaxed", "surprised")
    assert am.BONE_PARENTS[0] == -1
    assert all(0 <= p < i for i, p in enumerate(am.BONE_PARENTS) if i > 0)
    assert am.BONE_NAMES[am.BONE_PARENTS[am.bone_index("leftUpperArm")]] == "leftShoulder"
    assert am.BONE_NAMES[am.BONE_PARENTS[am.bone_index("leftThumbMetacarpal")]] == "leftHand"
    assert am.bone_index("hips") == 0
    with pytest.raises(am.InvalidArgumentError, match="leftElbow"):
        am.bone_index("leftElbow")


def test_version_is_the_header_version():
    text = _header_text()
    expected = re.search(r'#define AVM_VERSION_STRING "([0-9.]+)"', text).group(1)
    assert am.version() == expected
    assert os.path.exists(am.library_path())


def test_exception_classes():
    assert issubclass(am.FileIOError, OSError) and issubclass(am.FileIOError, am.AvatarmapError)
    assert issubclass(am.InvalidArgumentError, ValueError)
    assert issubclass(am.ParseError, am.AvatarmapError)
    assert issubclass(am.UnsupportedError, am.AvatarmapError)
    assert issubclass(am.OutOfMemoryError, MemoryError)
    assert issubclass(am.InternalError, am.AvatarmapError)


def test_every_failing_status_has_its_own_exception_class():
    """One class per failing avm_status (the library's error kinds, one to one), each with
    its status; AVM_ERROR_END_OF_FILE (4) is no failure and has none."""
    from avatarmap._errors import error_for
    classes = {1: am.InvalidArgumentError, 2: am.FileIOError, 3: am.ParseError,
               5: am.UnsupportedError, 6: am.OutOfMemoryError, 7: am.InternalError}
    for status, cls in classes.items():
        e = error_for(status, "m")
        assert type(e) is cls and e.status == status and str(e) == "m"
    assert len(set(classes.values())) == len(classes)


def _t_pose_frame(t):
    """A T-pose frame as a dict: image points from made-up world points (arms out)."""
    world = np.zeros((33, 3), dtype=np.float32)
    world[11], world[12] = (0.18, -0.5, 0), (-0.18, -0.5, 0)     # shoulders
    world[13], world[14] = (0.45, -0.5, 0), (-0.45, -0.5, 0)     # elbows
    world[15], world[16] = (0.70, -0.5, 0), (-0.70, -0.5, 0)     # wrists
    world[23], world[24] = (0.10, 0, 0), (-0.10, 0, 0)           # hips
    world[25], world[26] = (0.10, 0.45, 0), (-0.10, 0.45, 0)     # knees
    world[27], world[28] = (0.10, 0.88, 0), (-0.10, 0.88, 0)     # ankles
    world[0] = (0, -0.62, -0.1)
    image = np.concatenate([0.5 + 0.4 * world, np.full((33, 2), 0.99, np.float32)], axis=1)
    world5 = np.concatenate([world, np.full((33, 2), 0.99, np.float32)], axis=1)
    return {"t": t, "pose": image, "pose_world": world5}


def test_solver_handle_errors_carry_the_c_message():
    with am.Solver() as solver:
        pose = solver.push(_t_pose_frame(0.0))
        assert len(pose) == 1 and pose.rotations.shape == (1, 55, 4)
        assert np.all(np.isfinite(pose.rotations))
        with pytest.raises(am.InvalidArgumentError) as e:
            solver.push(_t_pose_frame(float("nan")))
        assert "finite" in str(e.value) and e.value.status == 1
        assert e.value.status_name == "invalid argument"
        with pytest.raises(am.InvalidArgumentError, match="pose.*shape"):
            solver.push({"t": 1.0, "pose": np.zeros((32, 5))})
        with pytest.raises(am.InvalidArgumentError, match="unknown frame keys"):
            solver.push({"t": 1.0, "pos": np.zeros((33, 5))})
        sample = solver.sample(0.01)
        assert sample.t[0] == 0.01
        solver.reset()
        rest = solver.sample(0.5)  # rest pose after a reset
        assert np.array_equal(rest.rotations[0, :, 3], np.ones(55, np.float32))
    assert solver.closed
    with pytest.raises(am.InvalidArgumentError, match="closed"):
        solver.push(_t_pose_frame(1.0))
    solver.close()  # twice: nothing


def test_solver_options_are_checked():
    with pytest.raises(am.InvalidArgumentError, match="rotation_beta"):
        am.Solver(rotation_beta=-1.0)
    with pytest.raises(TypeError, match="unknown solver option 'rotation_bta'"):
        am.Solver(rotation_bta=1.0)
    with pytest.raises(am.InvalidArgumentError, match="file_filter"):
        am.Solver(file_filter="sometimes")
    with pytest.raises(am.InvalidArgumentError, match="mirror"):
        am.Solver(mirror="yes")
    am.Solver(mirror=True, file_filter="none").close()


def test_mirror_option_reaches_the_solver():
    """A frame with the left arm raised: mirror=True swaps sides (known answer: the left
    upper arm's rotation without mirror is the right's with it, up to the X flip)."""
    frame = _t_pose_frame(0.0)
    world = frame["pose_world"].copy()
    world[13, :3] = (0.18, -0.77, 0)   # left elbow straight up over the shoulder
    world[15, :3] = (0.18, -1.02, 0)   # left wrist
    frame["pose_world"] = world
    frame["pose"] = frame["pose"].copy()
    frame["pose"][:, :3] = 0.5 + 0.4 * world[:, :3]
    lu, ru = am.bone_index("leftUpperArm"), am.bone_index("rightUpperArm")
    with am.Solver(filter_rotations=False) as plain, am.Solver(mirror=True,
                                                              filter_rotations=False) as mirrored:
        a = plain.push(frame).rotations[0]
        b = mirrored.push(frame).rotations[0]
    # Mirroring across the YZ plane: (x, y, z, w) -> (x, -y, -z, w).
    np.testing.assert_allclose(b[ru], a[lu] * np.float32([1, -1, -1, 1]), atol=1e-5)
    angle = 2 * math.degrees(math.acos(min(1.0, abs(float(a[lu][3])))))
    assert angle > 45  # the raised arm really turned


def test_missing_files_raise_file_io_errors(tmp_path):
    missing = tmp_path / "nope.landmarks.jsonl"
    with pytest.raises(am.FileIOError) as e:
        am.solve_file(missing, tmp_path / "out.pose.jsonl")
    assert "nope.landmarks.jsonl" in str(e.value)
    assert isinstance(e.value, OSError)
    assert not (tmp_path / "out.pose.jsonl").exists()
    with pytest.raises(am.FileIOError, match="nope.landmarks.jsonl"):
        am.read_landmarks(missing)
    with pytest.raises(am.FileIOError, match="nope.pose.jsonl"):
        am.read_poses(tmp_path / "nope.pose.jsonl")
    with pytest.raises(am.FileIOError):
        am.Retargeter(tmp_path / "nope.vrm")
    with pytest.raises(am.InvalidArgumentError, match="path"):
        am.read_poses(42)


def test_corrupt_files_raise_parse_errors_with_file_and_line(tmp_path):
    bad = tmp_path / "bad.landmarks.jsonl"
    bad.write_text('{"t":0.0}\n{"t":0.1,"pose":[[1,2,3]]}\n')
    with pytest.raises(am.ParseError) as e:
        am.read_landmarks(bad)
    assert "bad.landmarks.jsonl:2" in str(e.value)
    with pytest.raises(am.ParseError, match="bad.landmarks.jsonl:2"):
        am.solve_file(bad, tmp_path / "out.pose.jsonl")
    assert not (tmp_path / "out.pose.jsonl").exists()
    bad_pose = tmp_path / "bad.pose.jsonl"
    bad_pose.write_text('{"t":0.0,"bones":{"hips":[0,0,0,1]}}\n'
                        '{"t":0.1,"bones":{"elbow":[0,0,0,1]}}\n')
    with pytest.raises(am.ParseError, match="bad.pose.jsonl:2"):
        am.read_poses(bad_pose)
    with pytest.raises(am.ParseError, match="bad.pose.jsonl:2"):
        am.convert_file(bad_pose, tmp_path / "out.vrma")
    assert not (tmp_path / "out.vrma").exists()
    garbage = tmp_path / "garbage.vrm"
    garbage.write_bytes(b"\x00\x01 not a glTF")
    with pytest.raises(am.ParseError, match="garbage.vrm"):
        am.Retargeter(garbage)


def test_hostile_arguments_raise_clear_errors(tmp_path):
    with pytest.raises(am.InvalidArgumentError, match="NUL"):
        am.read_landmarks(str(tmp_path / "a\0b.landmarks.jsonl"))  # would be cut at the NUL
    with pytest.raises(am.InvalidArgumentError, match="empty path"):
        am.read_poses("")
    with pytest.raises(am.InvalidArgumentError, match="landmarks.t: not an array of numbers"):
        am.solve(am.Landmarks(**{**am.Landmarks.empty(2).__dict__, "t": ["a", "b"]}))
    with pytest.raises(am.InvalidArgumentError, match="landmarks.pose: not an array"):
        am.solve(am.Landmarks(**{**am.Landmarks.empty(1).__dict__, "pose": [[["x"] * 5] * 33]}))
    with pytest.raises(am.AvatarmapError, match=str(tmp_path)):
        am.read_landmarks(tmp_path)  # a folder
    with pytest.raises(am.InvalidArgumentError, match="fps"):
        am.write_animation(am.Poses.empty(1), tmp_path / "x.vrma", fps=float("nan"))
    with pytest.raises(am.InvalidArgumentError, match="fps: expected a number"):
        am.write_animation(am.Poses.empty(1), tmp_path / "x.vrma", fps="fast")
    with pytest.raises(am.InvalidArgumentError, match="rotation_beta"):
        am.solve(am.Landmarks.empty(1), rotation_beta=float("nan"))
    # Rest poses at t = 0 (Poses.empty) write fine; all-zero rotations are identity.
    zeros = am.Poses.empty(1)
    zeros.rotations[:] = 0
    am.write_animation(zeros, tmp_path / "zeros.pose.jsonl")
    assert np.array_equal(am.read_poses(tmp_path / "zeros.pose.jsonl").rotations[0, :, 3],
                          np.ones(55, np.float32))


def test_close_while_another_thread_pushes():
    """close() waits for the call in flight; later calls raise "closed", never crash."""
    import threading
    solver = am.Solver()
    outcome, pushed = [], []

    def push_many():
        try:
            for i in range(100000):
                solver.push(_t_pose_frame(i / 30))
                pushed.append(i)
            outcome.append("finished")
        except am.InvalidArgumentError as e:
            outcome.append(str(e))

    worker = threading.Thread(target=push_many)
    worker.start()
    while len(pushed) < 20 and worker.is_alive():
        pass
    solver.close()
    worker.join()
    assert outcome and (outcome[0] == "finished" or "closed" in outcome[0])
    assert len(pushed) >= 20


def _camel(c_name):
    words = c_name.lower().split("_")
    return words[0] + "".join(w.capitalize() for w in words[1:])


def test_expressions_and_blendshapes_follow_the_header():
    text = _header_text()
    enum = re.search(r"typedef enum avm_expression \{(.*?)\} avm_expression;", text, re.S).group(1)
    assert tuple(_camel(n) for n in re.findall(r"AVM_EXPRESSION_([A-Z_]+)", enum)) == \
        am.EXPRESSION_NAMES
    enum = re.search(r"typedef enum avm_blendshape \{(.*?)\} avm_blendshape;", text, re.S).group(1)
    c_names = re.findall(r"AVM_BLENDSHAPE_([A-Z_]+)", enum)
    assert len(am.BLENDSHAPE_NAMES) == 52 == len(c_names)
    # AVM_BLENDSHAPE_EYE_BLINK_LEFT <-> "eyeBlinkLeft", in the same order.
    assert tuple(_camel(n) for n in c_names) == am.BLENDSHAPE_NAMES
    # ARKit's names in Apple's alphabetical order, a few checked by hand.
    assert list(am.BLENDSHAPE_NAMES) == sorted(am.BLENDSHAPE_NAMES)
    assert am.BLENDSHAPE_NAMES[0] == "browDownLeft" and am.BLENDSHAPE_NAMES[-1] == "tongueOut"
    assert am.BLENDSHAPE_NAMES.index("jawOpen") == 24
    assert am.POSE_DTYPE["blendshapes"].shape == (52,)
    assert am.POSE_DTYPE["expressions"].shape == (21,)
    poses = am.Poses.empty(3)
    assert poses.blendshapes.shape == (3, 52) and not poses.blendshapes.any()
