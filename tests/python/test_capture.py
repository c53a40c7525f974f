"""Capture from Python: capture_file == `avatarmap capture`, Estimator and Live on images.
Needs the capture models (AVATARMAP_MODELS) and the shared data; skips without them."""

import os
import time

import numpy as np
import pytest

import avatarmap as am
from jsonl import read_landmarks_json


def _library_captures(models, data, tmp_path):
    """Skips when this library cannot capture files (built without ONNX Runtime or FFmpeg)."""
    try:
        am.capture_file(os.path.join(data, "motion", "tfjs-models", "pose.jpg"),
                        tmp_path / "probe.landmarks.jsonl", models=models, hands=False,
                        face=False, threads=1)
    except am.UnsupportedError as e:
        pytest.skip(str(e))


def _open(cls, *args, **kwargs):
    """An Estimator or Live; skips in a build without ONNX Runtime."""
    try:
        return cls(*args, **kwargs)
    except am.UnsupportedError as e:
        pytest.skip(str(e))


def _image(data, name):
    pil = pytest.importorskip("PIL.Image", reason="python3-pil decodes the test photo")
    with pil.open(os.path.join(data, "motion", "tfjs-models", name)) as im:
        return np.asarray(im.convert("RGB"))


def test_capture_file_equals_the_cli(data, models, cli, tmp_path):
    _library_captures(models, data, tmp_path)
    video = os.path.join(data, "motion", "tfjs-models", "pose_squats.mp4")
    ref = tmp_path / "cli.landmarks.jsonl"
    cli("capture", video, "-o", ref, "--hands", "--face", "--models", models, "--quiet")
    calls = []
    out = tmp_path / "py.landmarks.jsonl"
    summary = am.capture_file(video, out, models=models,
                              progress=lambda done, total: calls.append((done, total)))
    assert summary.frames == 65 and summary.body_frames > 60
    assert (summary.image_width, summary.image_height) == (720, 1280)
    assert summary.seconds > 0 and summary.frames_not_decoded == 0
    done = [d for d, _ in calls]
    assert calls and done == sorted(done) and 0 < done[-1] <= 65  # about twice a second
    assert all(t in (0, 65) for _, t in calls)
    mine, theirs = read_landmarks_json(out), read_landmarks_json(ref)
    for key in ("t", "pose", "pose_world", "left_hand", "right_hand", "face"):
        np.testing.assert_array_equal(mine[key], theirs[key], err_msg=key)


def test_capture_file_errors(data, models, tmp_path):
    _library_captures(models, data, tmp_path)
    with pytest.raises(am.FileIOError, match="nope.mp4"):
        am.capture_file(tmp_path / "nope.mp4", tmp_path / "x.landmarks.jsonl", models=models)
    with pytest.raises(am.InvalidArgumentError):
        am.capture_file("lavfi:testsrc", tmp_path / "x.landmarks.jsonl", models=models)
    with pytest.raises(am.AvatarmapError, match="no_models_here"):
        am.capture_file(os.path.join(data, "motion", "tfjs-models", "pose.jpg"),
                        tmp_path / "x.landmarks.jsonl", models=tmp_path / "no_models_here")
    with pytest.raises(am.InvalidArgumentError, match="model"):
        am.capture_file("a.mp4", tmp_path / "x.landmarks.jsonl", model="huge")
    assert not (tmp_path / "x.landmarks.jsonl").exists()

    def stop(done, total):
        raise KeyboardInterrupt("stop")
    with pytest.raises(KeyboardInterrupt):  # the callback's exception, after the call
        am.capture_file(os.path.join(data, "motion", "tfjs-models", "pose_squats.mp4"),
                        tmp_path / "y.landmarks.jsonl", models=models, threads=1, face=False,
                        progress=stop)


def test_estimator_on_a_photo(data, models):
    image = _image(data, "pose.jpg")
    with _open(am.Estimator, models, static_images=True, face=False) as est:
        lm, pose = est.process(image, 0.0)
        assert len(lm) == 1 and len(pose) == 1
        assert lm.seen("pose")[0] and not lm.seen("face")[0]
        assert (lm.image_width, lm.image_height) == (image.shape[1], image.shape[0])
        assert np.all((lm.pose[0, :, :2] > -0.5) & (lm.pose[0, :, :2] < 1.5))
        assert np.isfinite(pose.rotations).all()
        # RGBA and a padded (non-contiguous) view give the same landmarks.
        rgba = np.concatenate([image, np.full(image.shape[:2] + (1,), 255, np.uint8)], axis=2)
        lm2, _ = est.process(rgba, 1.0)
        np.testing.assert_array_equal(lm2.pose, lm.pose)
        with pytest.raises(am.InvalidArgumentError, match="uint8"):
            est.process(image.astype(np.float32), 2.0)
        with pytest.raises(am.InvalidArgumentError):
            est.process(image, float("nan"))
    with pytest.raises(am.AvatarmapError, match="no_models_here"):
        am.Estimator("/no_models_here")


def test_live_on_a_photo(data, models):
    image = _image(data, "pose.jpg")
    with _open(am.Live, models, static_images=True, face=False, hands=False) as live:
        assert live.latest() is None and live.sample(0.0) is None
        for i in range(5):
            live.push(image, i / 30)
            time.sleep(0.05)
        deadline = time.time() + 30
        while live.stats().processed == 0 and time.time() < deadline:
            time.sleep(0.05)
        stats = live.stats()
        assert stats.pushed == 5 and stats.processed >= 1 and stats.failed == 0
        pose = live.sample(4 / 30)
        assert pose is not None and pose.t[0] == pytest.approx(4 / 30)
        assert live.latest() is not None
        with pytest.raises(am.InvalidArgumentError):
            live.push(image[:, :, :2], 1.0)
    assert live.closed
