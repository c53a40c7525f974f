"""read_landmarks, solve and solve_file against independent references: the file's JSON
text, the CLI's `avatarmap solve` output, and the per-frame Solver."""

import numpy as np
import pytest

import avatarmap as am
from jsonl import PARTS, read_landmarks_json, read_poses_json


def test_read_landmarks_known_answer(tmp_path):
    """A hand-written file: absent parts, null coordinates, 3-value points, a 468-point face."""
    face = [[0.5, 0.4, 0.01 * i] for i in range(468)]
    pose = [[0.1 * (i % 10), 0.2, -0.3, 0.9, 0.8] for i in range(33)]
    hand = [[0.3, 0.3, 0.0]] * 21
    hand[4] = [None, 0.25, 0.5]
    path = tmp_path / "small.landmarks.jsonl"
    import json
    lines = [{"format": "avatarmap.landmarks", "version": 1, "image_size": [640, 480], "fps": 25},
             {"t": 0.0, "pose": pose, "face": face},
             {"t": 0.04, "left_hand": hand},
             {"t": 0.08}]
    path.write_text("".join(json.dumps(x) + "\n" for x in lines))
    lm = am.read_landmarks(path)
    assert len(lm) == 3
    assert (lm.image_width, lm.image_height, lm.fps) == (640, 480, 25.0)
    np.testing.assert_array_equal(lm.t, [0.0, 0.04, 0.08])
    np.testing.assert_array_equal(lm.pose[0], np.float32(pose))
    assert np.isnan(lm.pose[1:]).all() and np.isnan(lm.pose_world).all()
    np.testing.assert_array_equal(lm.face[0, :468, :3], np.float32(face))
    np.testing.assert_array_equal(lm.face[0, :468, 3:], 1.0)
    assert np.isnan(lm.face[0, 468:]).all() and np.isnan(lm.face[1:]).all()
    assert np.isnan(lm.left_hand[1, 4, 0]) and lm.left_hand[1, 4, 1] == np.float32(0.25)
    assert lm.left_hand[1, 0].tolist() == pytest.approx([0.3, 0.3, 0.0, 1.0, 1.0])
    assert lm.seen("pose").tolist() == [True, False, False]
    assert lm.seen("left_hand").tolist() == [False, True, False]
    assert lm.pose.dtype == np.float32 and lm.t.dtype == np.float64


def test_read_landmarks_matches_the_json(synth_file):
    lm = am.read_landmarks(synth_file)
    ref = read_landmarks_json(synth_file)
    assert len(lm) == len(ref["t"]) == 120
    assert (lm.image_width, lm.image_height) == tuple(ref["header"]["image_size"])
    np.testing.assert_array_equal(lm.t, ref["t"])
    for name, points in PARTS:
        assert getattr(lm, name).shape == (120, points, 5)
        np.testing.assert_array_equal(getattr(lm, name), ref[name], err_msg=name)


def _poses_equal(poses, ref, with_confidence=True):
    np.testing.assert_array_equal(poses.t, ref["t"])
    np.testing.assert_array_equal(poses.hips_position, ref["hips_position"])
    np.testing.assert_array_equal(poses.rotations, ref["rotations"])
    np.testing.assert_array_equal(poses.expressions, ref["expressions"])
    if with_confidence:
        np.testing.assert_array_equal(poses.confidence, ref["confidence"])


@pytest.mark.parametrize("cli_args,options", [
    ((), {}),
    (("--filter", "live"), {"file_filter": "live"}),
    (("--filter", "none", "--mirror"), {"file_filter": "none", "mirror": True}),
    (("--smoothing", "2"), {"file_smoothing": 2.0}),
    (("--no-hand-fit",), {"fit_hand_shape": False}),
])
def test_solve_equals_the_cli(synth_file, cli, tmp_path, cli_args, options):
    """Python solve() == `avatarmap solve` read back from its text, bit for bit (the writer
    prints the shortest text that reads back to the same float)."""
    out = tmp_path / "cli.pose.jsonl"
    cli("solve", synth_file, "-o", out, "--confidence", *cli_args)
    poses = am.solve(am.read_landmarks(synth_file), **options)
    assert len(poses) == 120
    _poses_equal(poses, read_poses_json(out, am.BONE_NAMES, am.EXPRESSION_NAMES))


def test_hand_fit_is_on_by_default_and_can_be_turned_off(synth_file):
    """fit_hand_shape (on by default) changes the noisy recording's fingers (off equals the
    CLI's --no-hand-fit bit for bit: the parametrised test above)."""
    lm = am.read_landmarks(synth_file)
    fitted, raw = am.solve(lm), am.solve(lm, fit_hand_shape=False)
    fingers = [i for i, n in enumerate(am.BONE_NAMES) if any(
        f in n for f in ("Thumb", "Index", "Middle", "Ring", "Little"))]
    assert len(fingers) == 30
    assert not np.array_equal(fitted.rotations[:, fingers], raw.rotations[:, fingers])
    np.testing.assert_array_equal(fitted.rotations, am.solve(lm, fit_hand_shape=True).rotations)


def test_solve_file_equals_solve(synth_file, tmp_path):
    out = tmp_path / "py.pose.jsonl"
    am.solve_file(synth_file, out, file_filter="offline")
    back = am.read_poses(out)
    poses = am.solve(am.read_landmarks(synth_file))
    # (solve_file writes no confidence, as `avatarmap solve` without --confidence.)
    for name in ("t", "hips_position", "rotations", "expressions"):
        np.testing.assert_array_equal(getattr(back, name), getattr(poses, name), err_msg=name)


@pytest.mark.parametrize("file_filter", ["offline", "live", "none"])
def test_solve_file_without_output_returns_the_poses_of_solve(synth_file, file_filter):
    """solve_file(IN) (avm_solve_file_to_clip: the file parsed on a second thread) gives
    solve(read_landmarks(IN))'s poses bit for bit, confidence included."""
    kept = am.solve_file(synth_file, file_filter=file_filter)
    poses = am.solve(am.read_landmarks(synth_file), file_filter=file_filter)
    assert len(kept) == len(poses) > 0
    for name in ("t", "hips_position", "rotations", "confidence", "expressions"):
        np.testing.assert_array_equal(getattr(kept, name), getattr(poses, name), err_msg=name)
    with pytest.raises(am.FileIOError, match="nothing.landmarks.jsonl"):
        am.solve_file(str(synth_file) + ".nothing.landmarks.jsonl")


def test_live_filter_equals_the_per_frame_solver(synth_file):
    """file_filter="live" is avm_solver_push's filtering: solve() over the arrays equals a
    Solver pushed frame by frame (another C path: avm_frame, one call per frame). Without the
    face: a file's face is calibrated over the whole take first, the Solver's live
    (docs/expressions.md, "Calibration over a take")."""
    lm = am.read_landmarks(synth_file)
    lm = am.Landmarks(**{**lm.__dict__, "face": np.full_like(lm.face, np.nan)})
    lm.image_width, lm.image_height = 1280, 720
    poses = am.solve(lm, file_filter="live")
    with am.Solver(image_width=1280, image_height=720) as solver:
        for i in range(len(lm)):
            frame = am.Landmarks(t=lm.t[i:i + 1], **{n: getattr(lm, n)[i:i + 1] for n, _ in PARTS})
            one = solver.push(frame)
            np.testing.assert_array_equal(one.rotations[0], poses.rotations[i])
            np.testing.assert_array_equal(one.hips_position[0], poses.hips_position[i])
            np.testing.assert_array_equal(one.expressions[0], poses.expressions[i])


def test_solve_accepts_absent_parts_and_three_columns(synth_file):
    lm = am.read_landmarks(synth_file)
    no_face = am.Landmarks(**{**lm.__dict__, "face": None})
    nan_face = am.Landmarks(**{**lm.__dict__, "face": np.full_like(lm.face, np.nan)})
    np.testing.assert_array_equal(am.solve(no_face).rotations, am.solve(nan_face).rotations)
    # Hands as (N, 21, 3): visibility and presence 1, as the file's [x, y, z] points are.
    three = am.Landmarks(**{**lm.__dict__, "left_hand": lm.left_hand[:, :, :3].astype(np.float64)})
    np.testing.assert_array_equal(am.solve(three).rotations, am.solve(lm).rotations)
    assert len(am.solve(am.Landmarks.empty(0))) == 0


def test_solve_rejects_bad_input(synth_file):
    lm = am.read_landmarks(synth_file)
    bad_t = am.Landmarks(**{**lm.__dict__, "t": lm.t.copy()})
    bad_t.t[7] = np.nan
    with pytest.raises(am.InvalidArgumentError) as e:
        am.solve(bad_t)
    assert "7" in str(e.value) and "finite" in str(e.value)
    with pytest.raises(am.InvalidArgumentError, match="pose_world: shape"):
        am.solve(am.Landmarks(**{**lm.__dict__, "pose_world": lm.pose_world[:, :20]}))
    with pytest.raises(am.InvalidArgumentError, match="face: shape"):
        am.solve(am.Landmarks(**{**lm.__dict__, "face": lm.face[:-1]}))
    with pytest.raises(am.InvalidArgumentError, match="landmarks.t"):
        am.solve(am.Landmarks(**{**lm.__dict__, "t": lm.t.reshape(2, -1)}))
    with pytest.raises(am.InvalidArgumentError, match="Landmarks"):
        am.solve({"t": lm.t})
    with pytest.raises(am.InvalidArgumentError, match="found_above"):
        am.solve(lm, confidence_found_above=2.0)
    # NaN landmarks are "not seen", never an error or a NaN pose.
    noisy = am.Landmarks(**{**lm.__dict__, "pose": lm.pose.copy()})
    noisy.pose[::3, 5:9] = np.nan
    assert np.isfinite(am.solve(noisy).rotations).all()


def test_read_landmarks_beyond_the_size_guess(tmp_path):
    """Long lines first, then many short ones: the reader outgrows its first arrays (their
    size is guessed from the first MiB) and goes on in further chunks, joined in order."""
    import json
    face = [[0.5, 0.5, 0.0]] * 478
    path = tmp_path / "uneven.landmarks.jsonl"
    with open(path, "w") as f:
        for i in range(150):  # ~1.5 MB of face frames
            f.write(json.dumps({"t": i / 30, "face": face}) + "\n")
        for i in range(150, 30000):  # then frames with nothing seen
            f.write('{"t":%r}\n' % (i / 30))
    lm = am.read_landmarks(path)
    assert len(lm) == 30000
    np.testing.assert_array_equal(lm.t, np.arange(30000) / 30)
    assert lm.seen("face").sum() == 150 and lm.seen("face")[:150].all()
    assert not np.isnan(lm.face[149]).any() and np.isnan(lm.face[150:]).all()
    # Header only, and empty.
    (tmp_path / "header.landmarks.jsonl").write_text(
        '{"format":"avatarmap.landmarks","version":1}\n')
    assert len(am.read_landmarks(tmp_path / "header.landmarks.jsonl")) == 0
    (tmp_path / "empty.landmarks.jsonl").write_text("")
    assert len(am.read_landmarks(tmp_path / "empty.landmarks.jsonl")) == 0


def test_solves_from_several_threads_agree(synth_file):
    """The C calls release the GIL: four threads solving at once get the poses of one."""
    from concurrent.futures import ThreadPoolExecutor
    lm = am.read_landmarks(synth_file)
    expected = am.solve(lm).rotations
    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda _: am.solve(lm).rotations, range(8)))
    for r in results:
        np.testing.assert_array_equal(r, expected)
