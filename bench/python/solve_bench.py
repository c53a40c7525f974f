#!/usr/bin/env python3
"""Timing of the Python package's whole-file solving (run by hand; not a test).

(a) Per-frame overhead of avatarmap.solve() over the C API's avm_solve_frames on the same
    frames: the same block and options handed to avm_solve_frames straight through ctypes,
    against solve(Landmarks) (argument checks, options, the output record array, Poses).
(b) A long landmark file: Python (read_landmarks + solve + write_animation to .pose.jsonl;
    and solve_file) against `avatarmap solve FILE -o OUT` on the same file.

Usage (Debian's python3; the package from the source tree or installed):
  build/avatarmap synth -o /tmp/ten.landmarks.jsonl --seconds 600 --fps 30
  PYTHONPATH=bindings/python /usr/bin/python3 bench/python/solve_bench.py \\
      /tmp/ten.landmarks.jsonl --cli build/avatarmap [--repeat 3]
Each figure is the best of --repeat runs (wall clock).
"""

import argparse
import ctypes
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import avatarmap as am
from avatarmap import _data, _lib


def best(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def head(lm, n):
    return am.Landmarks(t=np.ascontiguousarray(lm.t[:n]), image_width=lm.image_width,
                        image_height=lm.image_height,
                        **{p: np.ascontiguousarray(getattr(lm, p)[:n]) for p, _ in _data.PARTS})


def overhead(lm, sizes, repeat):
    print("(a) solve() over avm_solve_frames, offline filter (best of %d)" % repeat)
    print("%8s %12s %12s %14s" % ("frames", "C call ms", "solve() ms", "overhead us/frame"))
    solve_frames = _lib.fn("avm_solve_frames")
    for n in sizes:
        part = head(lm, n)
        options = _data.solver_options({"image_width": part.image_width,
                                        "image_height": part.image_height})
        block, keep = _data.frame_block(part)
        out = np.empty(n, dtype=am.POSE_DTYPE)
        err = ctypes.create_string_buffer(256)

        def c_call():
            assert solve_frames(ctypes.byref(block), options, out.ctypes.data, err, 256) == 0

        def py_call():
            am.solve(part)

        c_call(), py_call()  # warm
        # Interleaved so that both see the same machine state.
        tc, tp = [], []
        for _ in range(repeat):
            tc.append(best(c_call, 1))
            tp.append(best(py_call, 1))
        c, p = min(tc), min(tp)
        print("%8d %12.3f %12.3f %14.3f" % (n, c * 1e3, p * 1e3, (p - c) / n * 1e6))


def whole_file(path, cli, repeat):
    tmp = tempfile.mkdtemp(prefix="avm_bench_")
    out_cli = os.path.join(tmp, "cli.pose.jsonl")
    out_py = os.path.join(tmp, "py.pose.jsonl")
    out_file = os.path.join(tmp, "file.pose.jsonl")
    parts = {}

    def python_path():
        t0 = time.perf_counter()
        lm = am.read_landmarks(path)
        t1 = time.perf_counter()
        poses = am.solve(lm)
        t2 = time.perf_counter()
        am.write_animation(poses, out_py)
        t3 = time.perf_counter()
        parts.setdefault("read", []).append(t1 - t0)
        parts.setdefault("solve", []).append(t2 - t1)
        parts.setdefault("write", []).append(t3 - t2)
        parts["frames"] = len(lm)

    rows = [("avatarmap solve (CLI, --threads 2)",
             lambda: subprocess.run([cli, "solve", path, "-o", out_cli, "--quiet"], check=True,
                                          stderr=subprocess.DEVNULL)),
            ("avatarmap solve (CLI, --threads 1)",
             lambda: subprocess.run([cli, "solve", path, "-o", out_cli, "--quiet", "--threads",
                                     "1"], check=True, stderr=subprocess.DEVNULL)),
            ("Python read_landmarks + solve + write_animation", python_path),
            ("Python solve_file", lambda: am.solve_file(path, out_file)),
            ("Python solve_file to arrays (Poses, no file)", lambda: am.solve_file(path))]
    runs = [[] for _ in rows]
    for name, fn in rows:
        fn()  # warm the page cache
    for _ in range(repeat):  # alternated, one run of each in turn
        for i, (name, fn) in enumerate(rows):
            runs[i].append(best(fn, 1))
    results = [float(np.median(r)) for r in runs]
    print("(b) %s: %d frames (median of %d, alternated)" % (path, parts["frames"], repeat))
    base = results[0]
    for (name, _), t in zip(rows, results):
        print("  %-50s %7.3f s  %.2fx" % (name, t, t / base))
    print("  Python path parts (medians): read %.3f s, solve %.3f s, write %.3f s"
          % tuple(float(np.median(parts[k])) for k in ("read", "solve", "write")))
    same = open(out_cli, "rb").read() == open(out_file, "rb").read()
    print("  solve_file's output identical to the CLI's: %s" % same)
    a, b = am.read_poses(out_py), am.read_poses(out_cli)
    print("  Python path's poses vs the CLI's: largest rotation difference %.3g (float "
          "precision: avm_clip_add normalises again)" % np.abs(a.rotations - b.rotations).max())
    for f in (out_cli, out_py, out_file):
        os.unlink(f)
    os.rmdir(tmp)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("landmarks")
    ap.add_argument("--cli", help="the avatarmap tool, for (b)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--sizes", default="1,30,1800,18000")
    args = ap.parse_args()
    print("library %s (%s)" % (am.library_path(), am.version()))
    lm = am.read_landmarks(args.landmarks)
    sizes = [min(int(s), len(lm)) for s in args.sizes.split(",")]
    overhead(lm, sizes, args.repeat)
    if args.cli:
        whole_file(args.landmarks, args.cli, args.repeat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
