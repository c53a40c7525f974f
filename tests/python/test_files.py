"""read_poses, write_animation and convert_file against the CLI's own files."""

import json
import os

import numpy as np
import pytest

import avatarmap as am
from jsonl import read_poses_json


@pytest.fixture(scope="module")
def pose_file(synth_file, cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("poses") / "take.pose.jsonl"
    cli("solve", synth_file, "-o", out, "--confidence")
    return out


def test_read_poses_matches_the_json(pose_file):
    poses = am.read_poses(pose_file)
    ref = read_poses_json(pose_file, am.BONE_NAMES, am.EXPRESSION_NAMES, am.BLENDSHAPE_NAMES)
    assert len(poses) == 120
    for name in ("t", "hips_position", "rotations", "confidence", "expressions", "foot_contact",
                 "blendshapes"):
        np.testing.assert_array_equal(getattr(poses, name), ref[name], err_msg=name)


def _glb_chunks(data):
    """(JSON dict, BIN bytes) of a GLB (a .vrma is one)."""
    assert data[:4] == b"glTF"
    n = int.from_bytes(data[12:16], "little")
    doc = json.loads(data[20:20 + n])
    rest = data[20 + n:]
    return doc, rest[8:] if rest else b""


def _same_within_float_precision(a, b, ext):
    """Files of the same poses whose quaternions may differ in the last bit (avm_clip_add
    normalises every rotation it is given, the CLI's own path does not: see docs/python.md).
    Foot locking's leg IK (docs/foot-locking.md) turns that bit into up to ~100 ulps: near a
    straight knee the knee's offset moves ~20x faster than the hip-ankle distance."""
    if ext in (".vrma", ".glb"):
        (ja, ba), (jb, bb) = _glb_chunks(a), _glb_chunks(b)
        assert ja == jb and len(ba) == len(bb)
        fa = np.frombuffer(ba[:len(ba) // 4 * 4], dtype=np.float32)
        fb = np.frombuffer(bb[:len(bb) // 4 * 4], dtype=np.float32)
        same = (fa.view(np.uint32) == fb.view(np.uint32)) | np.isclose(fa, fb, rtol=1e-5, atol=1e-5)
        assert same.all(), "%d floats differ" % (~same).sum()
    else:  # text: the same words, numbers within print precision of what a quaternion's last
        # bit moves (BVH: Euler degrees to 6 decimals; one float ulp of a quaternion turns a
        # rotation by up to ~1e-7 rad, ~7e-6 degrees)
        wa, wb = a.decode().split(), b.decode().split()
        assert len(wa) == len(wb)
        for x, y in zip(wa, wb):
            if x != y:
                x, y = x.strip("[],{}"), y.strip("[],{}")
                assert float(x.split(":")[-1]) == pytest.approx(float(y.split(":")[-1]),
                                                                rel=1e-4, abs=1e-4), (x, y)


@pytest.mark.parametrize("ext,fps", [(".vrma", 30), (".bvh", 30), (".bvh", 24),
                                     (".pose.jsonl", 0)])
def test_convert_file_equals_cli_convert(pose_file, cli, tmp_path, ext, fps):
    """convert_file(P) writes the bytes of `avatarmap convert P -o OUT --fps N`."""
    ref = tmp_path / ("cli" + ext)
    cli("convert", pose_file, "-o", ref, *(("--fps", fps) if fps else ()))
    mine = tmp_path / ("py" + ext)
    am.convert_file(pose_file, mine, fps=fps)
    # .pose.jsonl at fps 0 too: the clip keeps the input's nominal rate for the header.
    assert mine.read_bytes() == ref.read_bytes()


@pytest.mark.parametrize("ext", [".vrma", ".bvh", ".pose.jsonl"])
def test_convert_file_of_landmarks_equals_cli_convert(synth_file, cli, tmp_path, ext):
    """convert_file(LANDMARKS) solves in memory (avm_solve_file_to_clip) and writes the bytes
    of `avatarmap convert LANDMARKS -o OUT` (CLI default 30 frames/s; .pose.jsonl: its frames,
    header included), on one thread or two."""
    ref = tmp_path / ("cli" + ext)
    cli("convert", synth_file, "-o", ref)
    fps = 0 if ext == ".pose.jsonl" else 30
    for threads in (1, 2):
        mine = tmp_path / ("py%d%s" % (threads, ext))
        n = am.convert_file(synth_file, mine, fps=fps, file_threads=threads)
        assert n == len(am.read_landmarks(synth_file))
        assert mine.read_bytes() == ref.read_bytes()
    with pytest.raises(am.InvalidArgumentError, match="file_threads"):
        am.convert_file(synth_file, tmp_path / "x.vrma", file_threads=3)
    with pytest.raises(am.InvalidArgumentError, match="landmarks.jsonl input only"):
        am.convert_file(ref if ext == ".pose.jsonl" else tmp_path / "py1.pose.jsonl",
                        tmp_path / "y.vrma", mirror=True)


def _out_of_order(pose_file, path):
    """`pose_file` with frames 2 and 3 swapped (lines 4 and 5: line 1 is the header)."""
    lines = pose_file.read_bytes().split(b"\n")
    lines[3], lines[4] = lines[4], lines[3]
    path.write_bytes(b"\n".join(lines))
    return path


@pytest.mark.parametrize("ext,fps,avatar", [(".pose.jsonl", 0, False), (".vrma", 30, False),
                                            (".vrma", 0, False), (".bvh", 30, False),
                                            (".glb", 30, True)])
def test_convert_file_sorts_an_out_of_order_pose_file_as_the_cli_does(
        pose_file, cli, tmp_path, ext, fps, avatar):
    """A pose file whose frames are out of time order: sorted, with a warning that counts
    them, for every output; the CLI's bytes (it used to raise ParseError)."""
    ooo = _out_of_order(pose_file, tmp_path / "ooo.pose.jsonl")
    extra = []
    if avatar:
        cli("avatar", "-o", tmp_path / "builtin.vrm")
        extra = ["--avatar", tmp_path / "builtin.vrm"]
    ref = tmp_path / ("cli" + ext)
    cli("convert", ooo, "-o", ref, *(("--fps", fps) if fps else ()), *extra)
    mine = tmp_path / ("py" + ext)
    with pytest.warns(UserWarning, match="1 frame\\(s\\) of .*ooo.pose.jsonl were out of time "
                                         "order; sorted by time"):
        n = am.convert_file(ooo, mine, fps=fps,
                            avatar=tmp_path / "builtin.vrm" if avatar else None)
    assert n == 120
    if fps or ext in (".pose.jsonl", ".glb"):  # the CLI's default is 30 but for .pose.jsonl
        assert mine.read_bytes() == ref.read_bytes()
    # Sorted, the poses are the in-order file's (read_poses reads with the same reader), and
    # the output is what the in-order file converts to.
    np.testing.assert_array_equal(am.read_poses(ooo).rotations, am.read_poses(pose_file).rotations)
    in_order = tmp_path / ("in_order" + ext)
    cli("convert", pose_file, "-o", in_order, *(("--fps", fps) if fps else ()), *extra)
    assert ref.read_bytes() == in_order.read_bytes()


@pytest.mark.parametrize("ext,fps", [(".pose.jsonl", 0), (".bvh", 30), (".vrma", 24)])
def test_convert_file_reads_the_vrma_the_cli_wrote(pose_file, cli, tmp_path, ext, fps):
    """A .vrma written by `avatarmap convert` converts again, to the CLI's bytes (it used to
    raise ParseError)."""
    vrma = tmp_path / "take.vrma"
    cli("convert", pose_file, "-o", vrma)
    ref = tmp_path / ("cli" + ext)
    cli("convert", vrma, "-o", ref, *(("--fps", fps) if fps else ()))
    mine = tmp_path / ("py" + ext)
    n = am.convert_file(vrma, mine, fps=fps)
    assert n == len(am.read_poses(vrma))  # read_poses reads a .vrma with the same reader
    assert mine.read_bytes() == ref.read_bytes()


def test_motion_input_kind_is_the_librarys_rule(pose_file, cli, tmp_path):
    assert am.motion_input_kind("a/take.landmarks.jsonl") == "landmarks"
    assert am.motion_input_kind("TAKE.POSE.JSONL") == "poses"
    assert am.motion_input_kind("clip.Vrma") == "vrma"
    assert am.motion_input_kind("walk.bvh") == "bvh"
    # A name that says nothing: the content does.
    odd = tmp_path / "take.json"
    odd.write_bytes(pose_file.read_bytes())
    assert am.motion_input_kind(odd) == "poses"
    out, ref = tmp_path / "again.pose.jsonl", tmp_path / "cli.pose.jsonl"
    am.convert_file(odd, out)
    cli("convert", pose_file, "-o", ref)
    assert out.read_bytes() == ref.read_bytes()
    with pytest.raises(am.InvalidArgumentError, match="unknown input type"):
        am.convert_file(tmp_path / "notes.txt", tmp_path / "x.vrma")


def test_bvh_motion_converts_as_the_cli_does(data, cli, tmp_path):
    # Motion capture read on its own skeleton (the library's read_bvh_motion), same bytes.
    walk = os.path.join(data, "motion", "cmu-bvh", "131_02.bvh")
    out, ref = tmp_path / "walk.pose.jsonl", tmp_path / "cli.pose.jsonl"
    am.convert_file(walk, out)
    cli("convert", walk, "-o", ref)
    assert out.read_bytes() == ref.read_bytes()
    assert len(am.read_poses(out)) == 1247


@pytest.mark.parametrize("ext", [".vrma", ".bvh"])
def test_write_animation_equals_cli_convert(synth_file, cli, tmp_path, ext):
    """Python solve() + write_animation() against `avatarmap convert LANDMARKS -o OUT`."""
    ref = tmp_path / ("cli" + ext)
    cli("convert", synth_file, "-o", ref, "--quiet")
    mine = tmp_path / ("py" + ext)
    am.write_animation(am.solve(am.read_landmarks(synth_file)), mine, fps=30)
    _same_within_float_precision(mine.read_bytes(), ref.read_bytes(), ext)
    if ext == ".vrma":  # both read back by the CLI: the same motion
        cli("convert", mine, "-o", tmp_path / "mine.pose.jsonl", "--fps", 30)
        cli("convert", ref, "-o", tmp_path / "ref.pose.jsonl", "--fps", 30)
        a = am.read_poses(tmp_path / "mine.pose.jsonl")
        b = am.read_poses(tmp_path / "ref.pose.jsonl")
        assert len(a) == len(b) == 120
        np.testing.assert_allclose(a.rotations, b.rotations, rtol=0, atol=1e-5)  # see above
        np.testing.assert_allclose(a.hips_position, b.hips_position, rtol=0, atol=1e-6)


def test_write_animation_glb_with_an_avatar(pose_file, cli, data, tmp_path):
    avatar = os.path.join(data, "avatars", "vrm1_debug_robot.vrm")
    ref = tmp_path / "cli.glb"
    cli("convert", pose_file, "-o", ref, "--avatar", avatar)
    converted = tmp_path / "conv.glb"
    am.convert_file(pose_file, converted, fps=30, avatar=avatar)
    assert converted.read_bytes() == ref.read_bytes()
    mine = tmp_path / "py.glb"
    am.write_animation(am.read_poses(pose_file), mine, fps=30, avatar=avatar)
    _same_within_float_precision(mine.read_bytes(), ref.read_bytes(), ".glb")
    with pytest.raises(am.InvalidArgumentError, match="avatar"):
        am.write_animation(am.read_poses(pose_file), tmp_path / "x.glb")
    assert not (tmp_path / "x.glb").exists()


def test_pose_jsonl_round_trip(pose_file, tmp_path):
    poses = am.read_poses(pose_file)
    out = tmp_path / "again.pose.jsonl"
    # foot_contact travels too (a view of the records: writing to it changes them).
    poses.foot_contact[:, 0] = np.linspace(0.0, 1.0, len(poses), dtype=np.float32)
    poses.foot_contact[:, 1] = (np.arange(len(poses)) % 2).astype(np.float32)
    # So do the blendshapes and the emotions (frames 0..59 none: the key is left out).
    rng = np.random.default_rng(3)
    poses.blendshapes[:60] = 0
    poses.blendshapes[60:] = rng.random((len(poses) - 60, 52), dtype=np.float32)
    poses.expressions[:, am.EXPRESSION_NAMES.index("surprised")] = 0.5
    am.write_animation(poses, out)
    back = am.read_poses(out)
    # (The clip writer writes no confidence, as `avatarmap convert` to .pose.jsonl.)
    for name in ("t", "hips_position", "expressions", "foot_contact", "blendshapes"):
        np.testing.assert_array_equal(getattr(back, name), getattr(poses, name), err_msg=name)
    # ... as the file format says, by ARKit name (an independent JSON reader).
    ref = read_poses_json(out, am.BONE_NAMES, am.EXPRESSION_NAMES, am.BLENDSHAPE_NAMES)
    np.testing.assert_array_equal(ref["blendshapes"], poses.blendshapes)
    lines = out.read_text().splitlines()
    assert '"blendshapes"' not in lines[1] and '"blendshapes":{"browDownLeft":' in lines[61]
    # avm_clip_add normalises each rotation again: the last bit may change.
    np.testing.assert_allclose(back.rotations, poses.rotations, rtol=0, atol=2.5e-7)
    # Poses built from plain arrays (not views of records) write the same file.
    plain = am.Poses(t=np.array(poses.t), hips_position=np.array(poses.hips_position),
                     rotations=np.array(poses.rotations), confidence=np.array(poses.confidence),
                     expressions=np.array(poses.expressions),
                     foot_contact=np.array(poses.foot_contact),
                     blendshapes=np.array(poses.blendshapes))
    out2 = tmp_path / "plain.pose.jsonl"
    am.write_animation(plain, out2)
    assert out2.read_bytes() == out.read_bytes()
    # Slices and single poses are views too.
    assert len(poses[10:20]) == 10 and poses[5].t[0] == poses.t[5] and poses[-1].t[0] == poses.t[-1]
    with pytest.raises(IndexError):
        poses[120]


def test_write_animation_rejects_bad_poses(pose_file, tmp_path):
    poses = am.read_poses(pose_file)
    out = tmp_path / "bad.vrma"
    backwards = am.Poses(**{**poses.__dict__, "t": poses.t[::-1].copy(), "_records": None})
    with pytest.raises(am.InvalidArgumentError):
        am.write_animation(backwards, out)
    nan_t = am.Poses(**{**poses.__dict__, "t": poses.t.copy(), "_records": None})
    nan_t.t[3] = np.nan
    with pytest.raises(am.InvalidArgumentError):
        am.write_animation(nan_t, out)
    with pytest.raises(am.InvalidArgumentError, match="rotations"):
        am.write_animation(am.Poses(**{**poses.__dict__, "rotations": poses.rotations[:, :54],
                                       "_records": None}), out)
    with pytest.raises(am.InvalidArgumentError, match="fps"):
        am.write_animation(poses, out, fps=-1)
    with pytest.raises(am.InvalidArgumentError):
        am.write_animation(poses, tmp_path / "x.mp4")
    with pytest.raises(am.InvalidArgumentError):
        am.write_animation(am.Poses.empty(0), out)
    with pytest.raises(am.FileIOError):
        am.write_animation(poses, tmp_path / "no" / "such" / "dir.vrma")
    assert not out.exists()
    # NaN rotations are "missing" (previous frame's), never written as NaN.
    holes = am.Poses(**{**poses.__dict__, "rotations": poses.rotations.copy(), "_records": None})
    holes.rotations[4:8] = np.nan
    am.write_animation(holes, tmp_path / "holes.pose.jsonl")
    back = am.read_poses(tmp_path / "holes.pose.jsonl")
    assert np.isfinite(back.rotations).all()
    np.testing.assert_array_equal(back.rotations[4:8], np.repeat(back.rotations[3:4], 4, axis=0))


def test_solve_file_takes_one_person_of_several(cli, tmp_path):
    """A landmark file of two people (version 2): person=ID solves that person's lines as the
    CLI's --person does; without it the file is refused with the ids."""
    a, b = tmp_path / "a.landmarks.jsonl", tmp_path / "b.landmarks.jsonl"
    cli("synth", "-o", a, "--seconds", "1", "--seed", "3")
    cli("synth", "-o", b, "--seconds", "1", "--seed", "4", "--scenario", "clean")
    la, lb = a.read_text().splitlines(), b.read_text().splitlines()
    header = json.loads(la[0])
    header["version"] = 2
    lines = [json.dumps(header)]
    for x, y in zip(la[1:], lb[1:]):
        for pid, line in ((0, x), (5, y)):
            d = json.loads(line)
            d["person"] = pid
            lines.append(json.dumps(d))
    two = tmp_path / "two.landmarks.jsonl"
    two.write_text("\n".join(lines) + "\n")
    cli("solve", two, "-o", tmp_path / "cli.pose.jsonl", "--person", "5")
    want = am.read_poses(tmp_path / "cli.pose.jsonl")
    got = am.solve_file(two, person=5)
    np.testing.assert_array_equal(got.rotations, want.rotations)
    np.testing.assert_array_equal(got.hips_position, want.hips_position)
    alone = am.solve_file(b)
    np.testing.assert_array_equal(got.rotations, alone.rotations)
    with pytest.raises(am.AvatarmapError, match=r"has 2 people \(0, 5\)"):
        am.solve_file(two)
