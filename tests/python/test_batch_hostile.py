"""`python3 -m avatarmap.batch` under hostile use (issue 20): what its local cluster listens
on, and its messages for a bad OUTDIR, a bad scheduler address, dangling links, URLs with
credentials. Exit statuses and standard error as a user sees them."""

import os
import subprocess
import sys
import time

import pytest

pytest.importorskip("distributed")

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
try:  # the package on PYTHONPATH (CTest's: bindings/python), else the source tree's
    from avatarmap import batch
except ImportError:
    sys.path.insert(0, os.path.join(ROOT, "bindings", "python"))
    from avatarmap import batch
from listeners import exposed, listening, process_tree  # noqa: E402


def env():
    e = dict(os.environ)
    e["PYTHONPATH"] = os.path.dirname(os.path.dirname(os.path.abspath(batch.__file__))) + \
        os.pathsep + e.get("PYTHONPATH", "")
    return e


def cli():
    path = os.environ.get("AVATARMAP_CLI") or os.path.join(ROOT, "build", "avatarmap")
    if not os.path.isfile(path):
        pytest.skip("no avatarmap CLI at %s (set AVATARMAP_CLI)" % path)
    return path


def synth(path, seconds, seed=1):
    subprocess.run([cli(), "synth", "-o", str(path), "--seconds", str(seconds), "--seed",
                    str(seed)], check=True, capture_output=True)


def run_batch(args, timeout=300):
    return subprocess.run([sys.executable, "-m", "avatarmap.batch", "--no-progress"] + args,
                          capture_output=True, text=True, env=env(), timeout=timeout)


def _no_traceback(r):
    assert "Traceback" not in r.stderr + r.stdout, r.stderr


# ---- listeners (finding 1) ----------------------------------------------------------------


def _cluster_listeners(**kwargs):
    """The listening sockets of this process and its children while the batch's local
    cluster (batch.local_cluster, as the batch builds it) runs with one worker."""
    from distributed import Client
    before = {(ip, port) for ip, port, _ in listening(process_tree(os.getpid()))}
    cluster = batch.local_cluster(1, **kwargs)
    try:
        with Client(cluster) as client:
            client.wait_for_workers(1, timeout=60)
            found = [e for e in listening(process_tree(os.getpid()))
                     if (e[0], e[1]) not in before]
    finally:
        cluster.close()
    return found


def test_local_cluster_listens_on_loopback_only():
    """Dask's defaults served the scheduler's HTTP on 0.0.0.0:8787 and [::]:8787 and each
    worker's on every interface."""
    found = _cluster_listeners()
    # The scheduler and its HTTP endpoint, the nanny, the worker and its HTTP endpoint.
    assert len(found) >= 4, found
    assert exposed(found) == [], "listening beyond loopback: %s" % exposed(found)
    assert all(port != 8787 for _, port, _ in found)


def test_dashboard_on_request_on_loopback():
    plain = _cluster_listeners()
    with_dashboard = _cluster_listeners(dashboard=("127.0.0.1", 0))
    assert exposed(with_dashboard) == []
    assert len(with_dashboard) == len(plain)  # the HTTP server, now with the dashboard


def test_a_real_batch_listens_on_loopback_only(tmp_path):
    """Polled from outside while `python3 -m avatarmap.batch` runs on two workers."""
    inputs = tmp_path / "in"
    inputs.mkdir()
    for i in range(4):
        synth(inputs / ("take%d.landmarks.jsonl" % i), 20, i + 1)
    driver = subprocess.Popen([sys.executable, "-m", "avatarmap.batch", "--no-progress",
                               str(inputs), "-o", str(tmp_path / "out"), "--to", "vrma",
                               "--workers", "2"], env=env(), stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    seen = {}
    while driver.poll() is None:
        for ip, port, pid in listening(process_tree(driver.pid)):
            seen[(ip, port)] = pid
        time.sleep(0.01)
    stdout, stderr = driver.communicate()
    assert driver.returncode == 0, stdout + stderr
    assert len(seen) >= 4, "the poll saw no cluster: %s" % seen
    assert [k for k in seen if not k[0].is_loopback] == []
    assert stderr == ""  # no warning: nothing asked for an address beyond loopback


def test_addresses_beyond_loopback_are_named_in_warnings(tmp_path):
    src = tmp_path / "a.landmarks.jsonl"
    synth(src, 1)
    r = run_batch([str(src), "-o", str(tmp_path / "out"), "--to", "pose", "--workers", "1",
                   "--host", "0.0.0.0", "--dashboard", "0.0.0.0:0"])
    assert r.returncode == 0, r.stderr
    assert "warning: --host 0.0.0.0: the local cluster's scheduler and workers listen on " \
           "every interface" in r.stderr
    assert "warning: --dashboard 0.0.0.0:0" in r.stderr and "every interface" in r.stderr
    r = run_batch([str(src), "-o", str(tmp_path / "out2"), "--to", "pose",
                   "--scheduler", "tcp://192.0.2.1:1"], timeout=120)
    assert r.returncode == 1  # TEST-NET-1: never reached
    assert "warning: the scheduler tcp://192.0.2.1:1 is not on this machine" in r.stderr
    assert "unencrypted" in r.stderr
    assert "error: cannot reach the scheduler at tcp://192.0.2.1:1" in r.stderr
    _no_traceback(r)


def test_dashboard_and_host_option_values():
    assert batch.parse_dashboard("8787") == ("127.0.0.1", 8787)
    assert batch.parse_dashboard(":0") == ("127.0.0.1", 0)
    assert batch.parse_dashboard("localhost:9000") == ("localhost", 9000)
    for bad in ("", "x", "70000", "::1:80", "a b:1", "-1"):
        with pytest.raises(batch.UsageError):
            batch.parse_dashboard(bad)
    assert batch._is_loopback("127.0.0.2") and batch._is_loopback("::1")
    assert batch._is_loopback("localhost") and not batch._is_loopback("0.0.0.0")
    assert not batch._is_loopback("192.0.2.1")


# ---- messages (finding 6) -----------------------------------------------------------------


def test_outdir_a_file_or_not_creatable_is_bad_usage(tmp_path):
    src = tmp_path / "a.landmarks.jsonl"
    src.write_text('{"t":0}\n')
    a_file = tmp_path / "afile"
    a_file.write_text("x")
    r = run_batch([str(src), "-o", str(a_file), "--to", "vrma"])
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip() == "avatarmap.batch: error: OUTDIR %s is a file; give a folder " \
                               "(made when missing)" % a_file
    r = run_batch([str(src), "-o", str(a_file / "sub"), "--to", "vrma"])
    assert r.returncode == 2
    assert r.stderr.strip() == "avatarmap.batch: error: OUTDIR %s cannot be created: Not a " \
                               "directory" % (a_file / "sub")
    assert a_file.read_text() == "x"


def test_bad_scheduler_addresses_are_bad_usage(tmp_path):
    src = tmp_path / "a.landmarks.jsonl"
    src.write_text('{"t":0}\n')
    for address, words in [("foo://head:8786", "unknown address scheme 'foo'"),
                           ("tcp://head", "head"),
                           ("tcp://user:s3cret@head:8786", "holds no user or password")]:
        r = run_batch([str(src), "-o", str(tmp_path / "out"), "--to", "vrma",
                       "--scheduler", address], timeout=60)
        assert r.returncode == 2, (address, r.stderr)
        assert r.stderr.startswith("avatarmap.batch: error: --scheduler "), r.stderr
        assert words in r.stderr
        assert "s3cret" not in r.stderr + r.stdout
        _no_traceback(r)
    assert not (tmp_path / "out").exists() or not os.listdir(tmp_path / "out")
    r = run_batch([str(src), "-o", str(tmp_path / "out"), "--to", "vrma",
                   "--scheduler", "tcp://127.0.0.1:1", "--dashboard", "8787"])
    assert r.returncode == 2 and "for the local cluster" in r.stderr


def test_dangling_links_in_a_folder_are_named(tmp_path):
    inputs = tmp_path / "in"
    inputs.mkdir()
    synth(inputs / "good.landmarks.jsonl", 1)
    os.symlink(tmp_path / "gone.landmarks.jsonl", inputs / "dangling.landmarks.jsonl")
    os.mkfifo(inputs / "pipe.landmarks.jsonl")
    os.symlink(tmp_path / "nothing.txt", inputs / "notes.txt")  # not an input: not named
    r = run_batch([str(inputs), "-o", str(tmp_path / "out"), "--to", "pose", "--workers", "1"])
    assert r.returncode == 0, r.stdout + r.stderr
    assert "avatarmap.batch: warning: %s: skipped: a dangling symbolic link (to %s, which " \
           "does not exist)" % (inputs / "dangling.landmarks.jsonl",
                                tmp_path / "gone.landmarks.jsonl") in r.stderr
    assert "avatarmap.batch: warning: %s: skipped: not a regular file (a FIFO)" % (
        inputs / "pipe.landmarks.jsonl") in r.stderr
    assert "notes.txt" not in r.stderr
    assert "1 converted, 0 skipped (already done), 0 failed" in r.stdout
    # Named on the command line: a failure with the same reason.
    r = run_batch([str(inputs / "dangling.landmarks.jsonl"), "-o", str(tmp_path / "out"),
                   "--to", "pose", "--workers", "1"])
    assert r.returncode == 1
    assert "dangling.landmarks.jsonl: a dangling symbolic link" in r.stdout


def test_credentials_in_urls_are_masked(tmp_path):
    r = run_batch(["http://user:s3cret@example.com/take.mp4", "https://me:pw%40x@host/b.mp4",
                   "-o", str(tmp_path / "out"), "--to", "vrma"])
    assert r.returncode == 1
    assert "http://user:***@example.com/take.mp4: a URL: the batch reads files" in r.stdout
    assert "https://me:***@host/b.mp4" in r.stdout
    assert "s3cret" not in r.stdout + r.stderr and "pw%40x" not in r.stdout + r.stderr
    _no_traceback(r)


def test_redact():
    assert batch.redact("tcp://u:p@h:1 and http://a:b@c/d?x=1") == \
        "tcp://u:***@h:1 and http://a:***@c/d?x=1"
    assert batch.redact("http://u@h/x, /tmp/a:b@c, mailto:x@y") == \
        "http://u@h/x, /tmp/a:b@c, mailto:x@y"
