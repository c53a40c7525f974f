"""Several people in Python (docs/capture-people.md): read_landmarks' person column against
files written here with the json module (version 2, and version 1 for the default),
Landmarks.person_ids() / for_person(), solve() refusing rows of several people, and
capture_file(people=N) against the ids in the file it writes (models and data needed)."""

import json
import os
import time

import numpy as np
import pytest

import avatarmap as am

# Rows of the version-2 file: (frame, person). Frame 0 has people 0 and 3, frame 1 only 3,
# frames 2 and 3 both; the ids need not be consecutive.
ROWS = [(0, 0), (0, 3), (1, 3), (2, 0), (2, 3), (3, 0), (3, 3)]


def _pose(frame, person):
    """33 points (x, y, z, visibility, presence) that differ per row, exact in binary."""
    k = np.arange(33, dtype=np.float64)
    x = 0.25 + person / 16.0 + k / 256.0
    y = 0.125 + frame / 64.0 + k / 128.0
    return np.stack([x, y, k / 512.0, np.full(33, 0.875), np.full(33, 0.75)], axis=1)


def _world(frame, person):
    k = np.arange(33, dtype=np.float64)
    return np.stack([k / 64.0 - 0.25, 1.0 - k / 32.0 + frame / 128.0, person / 32.0 + k / 1024.0,
                     np.full(33, 0.875), np.full(33, 0.75)], axis=1)


def _write(path, rows, version):
    with open(path, "w", encoding="utf-8") as f:
        f.write(json.dumps({"format": "avatarmap.landmarks", "version": version,
                            "image_size": [640, 480], "fps": 30}) + "\n")
        for frame, person in rows:
            line = {"t": frame / 30.0, "pose": _pose(frame, person).tolist(),
                    "pose_world": _world(frame, person).tolist()}
            if version == 2:
                line["person"] = person
            if person == 3 and frame == 2:
                line["left_hand"] = [[0.5, 0.5, 0.0]] * 21
            f.write(json.dumps(line) + "\n")


@pytest.fixture
def two_people(tmp_path):
    path = tmp_path / "two.landmarks.jsonl"
    _write(path, ROWS, 2)
    return path


def test_read_landmarks_gives_each_row_s_person(two_people):
    lm = am.read_landmarks(two_people)
    assert len(lm) == len(ROWS)
    assert lm.person.dtype == np.int32 and lm.person.shape == (len(ROWS),)
    assert lm.person.tolist() == [p for _, p in ROWS]
    np.testing.assert_array_equal(lm.t, [f / 30.0 for f, _ in ROWS])
    for i, (frame, person) in enumerate(ROWS):
        np.testing.assert_array_equal(lm.pose[i], _pose(frame, person).astype(np.float32))
    assert lm.person_ids() == [0, 3]
    assert (lm.image_width, lm.image_height, lm.fps) == (640, 480, 30.0)


def test_for_person_takes_one_person_s_rows(two_people):
    lm = am.read_landmarks(two_people)
    for person in (0, 3):
        one = lm.for_person(person)
        rows = [(f, p) for f, p in ROWS if p == person]
        assert len(one) == len(rows) and one.person_ids() == [person]
        np.testing.assert_array_equal(one.t, [f / 30.0 for f, _ in rows])
        for i, (frame, _) in enumerate(rows):
            np.testing.assert_array_equal(one.pose[i], _pose(frame, person).astype(np.float32))
            np.testing.assert_array_equal(one.pose_world[i],
                                          _world(frame, person).astype(np.float32))
        assert (one.image_width, one.image_height, one.fps) == (640, 480, 30.0)
        # A part no row of the file carries stays one NaN that takes no memory.
        assert not any(one.face.strides) and np.isnan(one.face).all()
    three = lm.for_person(np.int64(3))
    assert three.seen("left_hand").tolist() == [False, False, True, False]  # frames 0 .. 3
    assert lm.for_person(0).seen("left_hand").tolist() == [False, False, False]
    with pytest.raises(am.InvalidArgumentError, match=r"no row of person 1 \(the ids are 0, 3\)"):
        lm.for_person(1)
    with pytest.raises(am.InvalidArgumentError, match="integer person id"):
        lm.for_person("3")


def test_a_version_1_file_is_person_0(tmp_path):
    path = tmp_path / "one.landmarks.jsonl"
    _write(path, [(f, 0) for f in range(4)], 1)
    lm = am.read_landmarks(path)
    assert lm.person.tolist() == [0, 0, 0, 0] and lm.person_ids() == [0]
    assert len(lm.for_person(0)) == 4
    empty = am.Landmarks.empty(3)
    assert empty.person.tolist() == [0, 0, 0] and empty.person_ids() == [0]
    assert am.Landmarks.empty(0).person_ids() == []


def test_solve_takes_one_person_at_a_time(two_people, tmp_path):
    lm = am.read_landmarks(two_people)
    with pytest.raises(am.InvalidArgumentError, match=r"2 people \(ids 0, 3\).*for_person"):
        am.solve(lm)
    # One person's rows solve as the file's person does with solve_file(person=id), and as a
    # version-1 file of that person's lines alone (written here) does.
    for person in (0, 3):
        mine = am.solve(lm.for_person(person))
        theirs = am.solve_file(two_people, person=person)
        alone = tmp_path / ("alone%d.landmarks.jsonl" % person)
        _write(alone, [r for r in ROWS if r[1] == person], 1)
        single = am.solve(am.read_landmarks(alone))
        np.testing.assert_array_equal(mine.records, theirs.records)
        np.testing.assert_array_equal(mine.records, single.records)
    assert not np.array_equal(am.solve(lm.for_person(0)).rotations[0],
                              am.solve(lm.for_person(3)).rotations[0])
    # The C API backs the rule: a person column of two ids is refused there too.
    sneaky = lm.for_person(0)
    sneaky.person = np.array([0, 1, 0, 0][:len(sneaky)], dtype=np.int32)
    with pytest.raises(am.InvalidArgumentError, match="person"):
        am.solve(sneaky)
    bad = lm.for_person(0)
    bad.person = np.array([0.5] * len(bad))
    with pytest.raises(am.InvalidArgumentError, match="landmarks.person"):
        am.solve(bad)


def _ids_in_file(path):
    """The person ids of a landmark file, read with json (None for a version-1 file)."""
    with open(path, encoding="utf-8") as f:
        lines = [json.loads(line) for line in f]
    assert lines[0].get("format") == "avatarmap.landmarks"
    if lines[0].get("version") != 2:
        return None
    return [line["person"] for line in lines[1:]]


def _three_people(data):
    path = os.path.join(data, "motion", "tfjs-models", "three_people.jpg")
    if not os.path.isfile(path):
        pytest.skip("three_people.jpg is not in AVATARMAP_TEST_DATA")
    return path


def test_capture_file_people(data, models, tmp_path):
    image = _three_people(data)
    out = tmp_path / "three.landmarks.jsonl"
    try:
        summary = am.capture_file(image, out, models=models, people=3, hands=False,
                                  face=False, threads=1)
    except am.UnsupportedError as e:
        pytest.skip(str(e))
    assert summary.frames == 1 and summary.body_frames == 3  # lines, one per person
    assert (summary.people_ids, summary.person_lines, summary.frames_with_people) == (3, 3, 1)
    ids = _ids_in_file(out)
    assert ids == [0, 1, 2]
    lm = am.read_landmarks(out)
    assert lm.person.tolist() == ids and lm.person_ids() == [0, 1, 2]
    assert len(set(lm.t.tolist())) == 1  # one frame
    # Three different bodies.
    noses = lm.pose[:, 0, :2]
    assert min(np.linalg.norm(noses[i] - noses[j]) for i in range(3) for j in range(i)) > 0.05
    # people=1 (the default) is the single-person capture: a version-1 file, one line.
    one = tmp_path / "one.landmarks.jsonl"
    summary = am.capture_file(image, one, models=models, hands=False, face=False, threads=1)
    assert _ids_in_file(one) is None and am.read_landmarks(one).person.tolist() == [0]
    assert summary.body_frames == 1 and summary.people_ids == 0


def test_capture_file_people_out_of_range(tmp_path):
    # Refused before anything is opened (no models or data needed).
    for people in (0, 9, -1):
        with pytest.raises(am.InvalidArgumentError, match=r"people.*max_people"):
            am.capture_file("nothing.mp4", tmp_path / "x.landmarks.jsonl", people=people)
    with pytest.raises(am.InvalidArgumentError, match="people"):
        am.capture_file("nothing.mp4", tmp_path / "x.landmarks.jsonl", people=2.5)
    assert not (tmp_path / "x.landmarks.jsonl").exists()


def test_capture_file_people_c_range(tmp_path):
    """The C API refuses max_people out of 1 .. AVM_MAX_PEOPLE itself, naming the field."""
    from avatarmap import _handles, _lib
    eo = _handles._estimator_options(None, False, False, 1, "full", "full")
    err = _lib.ctypes.create_string_buffer(2048)
    summary = _lib.AvmCaptureSummary(struct_size=_lib.ctypes.sizeof(_lib.AvmCaptureSummary))
    for value in (0, 9):
        eo.max_people = value
        st = _lib.fn("avm_capture_file")(b"nothing.mp4", str(tmp_path / "x.jsonl").encode(), eo,
                                         _lib.ctypes.byref(summary), _lib.PROGRESS_FN(), None,
                                         err, 2048)
        assert st == _lib.ERROR_INVALID_ARGUMENT, err.value
        assert b"avm_estimator_options.max_people" in err.value


def test_read_landmarks_of_the_cli_s_capture(data, models, cli, tmp_path):
    """A file `avatarmap capture --people 2` writes, read by read_landmarks and by json."""
    image = _three_people(data)
    out = tmp_path / "cli.landmarks.jsonl"
    try:  # the library and the tool are one build: without ONNX Runtime neither captures
        am.capture_file(image, tmp_path / "probe.landmarks.jsonl", models=models, hands=False,
                        face=False, threads=1)
    except am.UnsupportedError as e:
        pytest.skip(str(e))
    cli("capture", image, "-o", out, "--people", "2", "--models", models, "--threads", "1",
        "--quiet")
    lm = am.read_landmarks(out)
    with open(out, encoding="utf-8") as f:
        lines = [json.loads(line) for line in f][1:]
    assert [line["person"] for line in lines] == lm.person.tolist() == [0, 1]
    for i, line in enumerate(lines):
        np.testing.assert_array_equal(lm.pose[i], np.float32(line["pose"]))
        one = lm.for_person(line["person"])
        assert len(one) == 1 and one.t[0] == line["t"]
        np.testing.assert_array_equal(one.pose[0], np.float32(line["pose"]))


def _image(data, name):
    pil = pytest.importorskip("PIL.Image", reason="python3-pil decodes the test photo")
    with pil.open(os.path.join(data, "motion", "tfjs-models", name)) as im:
        return np.asarray(im.convert("RGB"))


def _open(cls, *args, **kwargs):
    try:
        return cls(*args, **kwargs)
    except am.UnsupportedError as e:
        pytest.skip(str(e))


def test_estimator_and_live_give_every_person(data, models):
    """three_people.jpg through Estimator.process_people and Live.people/sample_person with
    people=3: three people with ids and slots 0-2, the single-person Estimator's person among
    them point for point, each person's pose its own."""
    image = _image(data, "three_people.jpg")
    with _open(am.Estimator, models, static_images=True) as one:
        lm, _ = one.process(image, 0.0)
        alone = one.process_people(image, 1.0)
    assert [(p.id, p.slot) for p in alone] == [(0, 0)]
    with pytest.raises(am.InvalidArgumentError, match="people"):
        am.Estimator(models, people=9)
    with _open(am.Estimator, models, static_images=True, people=3) as est:
        people = est.process_people(image, 0.0)
    assert [p.id for p in people] == [0, 1, 2]
    assert sorted(p.slot for p in people) == [0, 1, 2]
    same = [p for p in people if np.array_equal(p.landmarks.pose, lm.pose)]
    assert len(same) == 1
    for p in people:
        assert list(p.landmarks.person) == [p.id]
        assert p.landmarks.image_width == image.shape[1]
        assert len(p.pose) == 1 and p.pose.t[0] == 0.0
    arms = [p.pose.rotations[0, am.bone_index("leftUpperArm")] for p in people]
    assert min(np.abs(a - b).max() for i, a in enumerate(arms) for b in arms[i + 1:]) > 0.02

    with _open(am.Live, models, static_images=True, people=3) as live:
        assert live.people() == []
        for i in range(3):
            live.push(image, i / 30.0)
            deadline = time.time() + 20
            while live.stats().processed < i + 1 and time.time() < deadline:
                time.sleep(0.01)
        held = live.people()
        assert [p.id for p in held] == [0, 1, 2]
        assert all(p.seen_t == 2 / 30.0 for p in held)
        poses = [live.sample_person(p.id, 2 / 30.0) for p in held]
        assert all(p is not None and len(p) == 1 for p in poses)
        assert live.sample_person(99, 2 / 30.0) is None
