"""`python3 -m avatarmap.batch` on Dask distributed: a local cluster, an existing scheduler with
two workers started as separate processes (one of them killed mid-batch), resuming, and bad
input. References are the CLI's own `avatarmap convert` outputs of the same files."""

import os
import shutil
import signal
import socket
import subprocess
import sys
import time

import pytest

pytest.importorskip("distributed")

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
PACKAGE_DIR = os.path.join(ROOT, "bindings", "python")
sys.path.insert(0, PACKAGE_DIR)
from avatarmap import batch  # noqa: E402


def cli():
    path = os.environ.get("AVATARMAP_CLI") or os.path.join(ROOT, "build", "avatarmap")
    if not os.path.isfile(path):
        pytest.skip("no avatarmap CLI at %s (set AVATARMAP_CLI)" % path)
    return path


def env():
    e = dict(os.environ)
    e["PYTHONPATH"] = PACKAGE_DIR + os.pathsep + e.get("PYTHONPATH", "")
    return e


def synth(path, seconds, seed):
    subprocess.run([cli(), "synth", "-o", str(path), "--seconds", str(seconds), "--seed",
                    str(seed), "--scenario", "noisy"], check=True, capture_output=True)


def run_batch(args, timeout=300):
    return subprocess.run([sys.executable, "-m", "avatarmap.batch", "--no-progress"] + args,
                          capture_output=True, text=True, env=env(), timeout=timeout)


def reference(src, out):
    subprocess.run([cli(), "convert", str(src), "-o", str(out), "--quiet"], check=True)
    with open(out, "rb") as f:
        return f.read()


def read(path):
    with open(path, "rb") as f:
        return f.read()


def test_plan_names_outputs_and_refuses_what_it_cannot_read(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    for p in ["a/take.landmarks.jsonl", "b/take.mp4", "a/notes.txt", "a/clip.pose.jsonl"]:
        (tmp_path / p).write_text("x")
    tasks, bad = batch.plan([str(tmp_path / "a"), str(tmp_path / "b" / "take.mp4"),
                             str(tmp_path / "a" / "notes.txt"), str(tmp_path / "missing.mp4")],
                            str(tmp_path / "out"), "vrma")
    assert [(os.path.basename(t.input), t.kind, os.path.basename(t.output)) for t in tasks] == [
        ("clip.pose.jsonl", "poses", "clip.vrma"), ("take.landmarks.jsonl", "landmarks",
                                                   "take.vrma")]
    reasons = {os.path.basename(r.input): r.reason for r in bad}
    assert "also" in reasons["take.mp4"]  # both takes would write out/take.vrma
    assert "not a video" in reasons["notes.txt"]
    assert reasons["missing.mp4"] == "no such file"
    # OUTDIR read back as input with --to pose: its *.pose.jsonl are their own outputs.
    (tmp_path / "a" / "take.pose.jsonl").write_text("x")  # take.landmarks.jsonl's, done
    tasks, bad = batch.plan([str(tmp_path / "a")], str(tmp_path / "a"), "pose")
    assert [os.path.basename(t.input) for t in tasks] == ["take.landmarks.jsonl"]
    assert [(os.path.basename(r.input), r.status) for r in bad] == [
        ("clip.pose.jsonl", "skipped"), ("take.pose.jsonl", "skipped")]


def test_local_cluster_converts_reports_a_corrupt_file_and_resumes(tmp_path):
    inputs = tmp_path / "in"
    inputs.mkdir()
    for i in range(3):
        synth(inputs / ("take%d.landmarks.jsonl" % i), 8, 11 + i)
    good = read(inputs / "take0.landmarks.jsonl").split(b"\n")
    # A corrupt file: a good header and first frame, then a line cut in half.
    (inputs / "corrupt.landmarks.jsonl").write_bytes(b"\n".join(good[:2] + [good[2][:100]]))
    out = tmp_path / "out"
    r = run_batch([str(inputs), "-o", str(out), "--to", "vrma", "--workers", "2"])
    assert r.returncode == 1, r.stdout + r.stderr
    assert "3 converted, 0 skipped (already done), 1 failed" in r.stdout
    corrupt = str(inputs / "corrupt.landmarks.jsonl")
    failure = [line for line in r.stdout.splitlines() if line.startswith("  " + corrupt + ": ")]
    assert len(failure) == 1 and "corrupt.landmarks.jsonl:3" in failure[0], r.stdout
    assert sorted(os.listdir(out)) == ["take0.vrma", "take1.vrma", "take2.vrma"]
    for i in range(3):
        assert read(out / ("take%d.vrma" % i)) == reference(
            inputs / ("take%d.landmarks.jsonl" % i), tmp_path / ("ref%d.vrma" % i))
    # Resumed: finished outputs are skipped, a removed one is redone.
    os.remove(out / "take1.vrma")
    before = os.stat(out / "take0.vrma").st_mtime_ns
    os.remove(inputs / "corrupt.landmarks.jsonl")
    r = run_batch([str(inputs), "-o", str(out), "--to", "vrma", "--workers", "1"])
    assert r.returncode == 0, r.stdout + r.stderr
    assert "1 converted, 2 skipped (already done), 0 failed" in r.stdout
    assert os.stat(out / "take0.vrma").st_mtime_ns == before
    assert read(out / "take1.vrma") == read(tmp_path / "ref1.vrma")


def test_pose_output_and_bvh_of_poses(tmp_path):
    src = tmp_path / "walk.landmarks.jsonl"
    synth(src, 4, 5)
    r = run_batch([str(src), "-o", str(tmp_path / "poses"), "--to", "pose", "--workers", "1"])
    assert r.returncode == 0, r.stdout + r.stderr
    solved = tmp_path / "ref.pose.jsonl"
    subprocess.run([cli(), "solve", str(src), "-o", str(solved)], check=True,
                   capture_output=True)
    assert read(tmp_path / "poses" / "walk.pose.jsonl") == read(solved)
    # A *.pose.jsonl input starts at the last step.
    r = run_batch([str(solved), "-o", str(tmp_path / "bvh"), "--to", "bvh", "--workers", "1"])
    assert r.returncode == 0, r.stdout + r.stderr
    assert read(tmp_path / "bvh" / "ref.bvh") == reference(solved, tmp_path / "ref.bvh")


def test_bad_usage_exits_2(tmp_path):
    r = run_batch([str(tmp_path), "-o", str(tmp_path / "o"), "--to", "glb"])
    assert r.returncode == 2 and "--avatar" in r.stderr
    r = run_batch([str(tmp_path), "-o", str(tmp_path / "o"), "--to", "fbx"])
    assert r.returncode == 2


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def dask_tool(name):
    path = shutil.which(name) or os.path.join(os.path.dirname(sys.executable), name)
    if not os.path.isfile(path):
        pytest.skip("no %s (Debian's python3-distributed)" % name)
    return path


def test_existing_scheduler_two_worker_processes_one_killed_mid_batch(tmp_path):
    inputs = tmp_path / "in"
    inputs.mkdir()
    for i in range(6):
        synth(inputs / ("long%d.landmarks.jsonl" % i), 40, 30 + i)
    port = free_port()
    address = "tcp://127.0.0.1:%d" % port
    procs = []
    try:
        procs.append(subprocess.Popen(
            [dask_tool("dask-scheduler"), "--host", "127.0.0.1", "--port", str(port),
             "--dashboard-address", ":0"], env=env(), stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL))
        workers = []
        for _ in range(2):
            w = subprocess.Popen([dask_tool("dask-worker"), address, "--nthreads", "1",
                                  "--no-nanny", "--no-dashboard"], env=env(),
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            procs.append(w)
            workers.append(w)
        out = tmp_path / "out"
        driver = subprocess.Popen(
            [sys.executable, "-m", "avatarmap.batch", "--no-progress", str(inputs), "-o",
             str(out), "--to", "vrma", "--scheduler", address], env=env(),
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        # Kill one worker while tasks are being written (a task's work folder exists and not
        # every output is there yet).
        work = out / batch.WORK_FOLDER
        deadline = time.time() + 120
        killed = False
        while time.time() < deadline and driver.poll() is None:
            busy = work.is_dir() and len(os.listdir(work)) >= 2
            done = len([n for n in os.listdir(out) if n.endswith(".vrma")]) if out.is_dir() \
                else 0
            if busy and done < 4:
                workers[0].send_signal(signal.SIGKILL)
                killed = True
                break
            time.sleep(0.01)
        stdout, stderr = driver.communicate(timeout=300)
        assert killed, "the batch ended before a worker could be killed:\n" + stdout
        assert workers[0].wait(timeout=10) == -signal.SIGKILL
        assert driver.returncode == 0, stdout + stderr
        assert "6 converted, 0 skipped (already done), 0 failed" in stdout
        # Only finished outputs: no partial file, no work folder.
        assert sorted(os.listdir(out)) == ["long%d.vrma" % i for i in range(6)]
        for i in (0, 5):
            assert read(out / ("long%d.vrma" % i)) == reference(
                inputs / ("long%d.landmarks.jsonl" % i), tmp_path / "ref.vrma")
    finally:
        for p in procs:
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()


def test_glb_with_an_avatar_equals_cli_convert(tmp_path):
    data = os.environ.get("AVATARMAP_TEST_DATA")
    avatar = os.path.join(data or "", "avatars", "vrm1_spec_53bones.vrm")
    if not data or not os.path.isfile(avatar):
        pytest.skip("AVATARMAP_TEST_DATA is not set: no avatar to drive")
    src = tmp_path / "wave.landmarks.jsonl"
    synth(src, 3, 8)
    r = run_batch([str(src), "-o", str(tmp_path / "out"), "--to", "glb", "--avatar", avatar,
                   "--rig", "auto", "--workers", "1"])
    assert r.returncode == 0, r.stdout + r.stderr
    ref = tmp_path / "ref.glb"
    subprocess.run([cli(), "convert", str(src), "-o", str(ref), "--avatar", avatar, "--quiet"],
                   check=True)
    assert read(tmp_path / "out" / "wave.glb") == read(ref)
