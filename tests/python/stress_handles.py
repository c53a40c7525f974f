"""Stress of the Python handles' thread rules (run by hand, not by pytest): for N seconds,
rounds of one handle used by three threads at once — one pushing, one sampling, one closing
it after a random delay — each round in a child process, so that a crash (a signal) is
counted instead of ending the run.

    PYTHONPATH=bindings/python /usr/bin/python3 tests/python/stress_handles.py --seconds 60
    ... --handle solver      # Solver only (no models needed); default: live and solver,
                             # each half of the time
    ... --package DIR        # another copy of the package (e.g. the previous commit's)

Prints one line per handle: rounds, child processes, crashes (by signal), calls, calls that
raised the handle's "closed" error (expected: the handle was closed under them), and any
other exception (unexpected; its first text is shown). Exit status 0 when nothing crashed and
nothing unexpected was raised, 1 otherwise.
"""

import argparse
import collections
import json
import os
import random
import signal
import subprocess
import sys
import threading
import time


def _image():
    import numpy as np
    rng = np.random.default_rng(1)
    return rng.integers(0, 255, (720, 1280, 3), dtype=np.uint8)


def _frame(t):
    import numpy as np
    world = np.zeros((33, 5), dtype=np.float32)
    world[:, 3:] = 0.9
    world[11, :3], world[12, :3] = (0.18, -0.5, 0), (-0.18, -0.5, 0)
    world[23, :3], world[24, :3] = (0.10, 0, 0), (-0.10, 0, 0)
    image = world.copy()
    image[:, :3] = 0.5 + 0.4 * world[:, :3]
    return {"t": t, "pose": image, "pose_world": world}


def _round(am, kind, counts, errors):
    """One handle, three threads: push, sample, close."""
    if kind == "live":
        handle = am.Live(static_images=True, hands=False, face=False, threads=1)
        image = _image()

        def push(i):
            handle.push(image, i / 30.0)

        def sample(i):
            handle.sample(i / 30.0)
            handle.stats()
    else:
        handle = am.Solver()

        def push(i):
            handle.push(_frame(i / 30.0))

        def sample(i):
            handle.sample(i / 30.0)

    stop = threading.Event()

    def loop(call):
        i = 0
        while not stop.is_set():
            try:
                call(i)
                counts["calls"] += 1
            except am.AvatarmapError as e:
                if "closed" in str(e):
                    counts["closed_errors"] += 1
                    return
                counts["other_errors"] += 1
                errors.append("%s: %s" % (type(e).__name__, e))
                return
            except Exception as e:  # noqa: BLE001 - counted and shown
                counts["other_errors"] += 1
                errors.append("%s: %s" % (type(e).__name__, e))
                return
            i += 1

    threads = [threading.Thread(target=loop, args=(push,)),
               threading.Thread(target=loop, args=(sample,))]
    for t in threads:
        t.start()
    time.sleep(random.uniform(0.0, 0.02))
    handle.close()
    time.sleep(0.002)
    stop.set()
    for t in threads:
        t.join()
    counts["rounds"] += 1


def child(kind, rounds):
    import avatarmap as am
    counts = collections.Counter()
    errors = []
    for _ in range(rounds):
        _round(am, kind, counts, errors)
        # After every round: a crash in the next one still leaves these counts.
        print(json.dumps({"counts": counts, "errors": errors[:3]}), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=10.0,
                    help="total running time, shared between the handles (default 10)")
    ap.add_argument("--handle", choices=("live", "solver", "all"), default="all")
    ap.add_argument("--package", help="folder holding the avatarmap package to test")
    ap.add_argument("--rounds", type=int, default=20, help="rounds per child process")
    ap.add_argument("--child", choices=("live", "solver"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.package:
        sys.path.insert(0, a.package)
    if a.child:
        child(a.child, a.rounds)
        return 0
    env = dict(os.environ)
    if a.package:
        env["PYTHONPATH"] = a.package + os.pathsep + env.get("PYTHONPATH", "")
    kinds = ("live", "solver") if a.handle == "all" else (a.handle,)
    bad = False
    for kind in kinds:
        total = collections.Counter()
        crashes = collections.Counter()
        errors = []
        end = time.monotonic() + a.seconds / len(kinds)
        while time.monotonic() < end:
            done = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", kind,
                                   "--rounds", str(a.rounds)],
                                  capture_output=True, text=True, env=env)
            total["children"] += 1
            if done.returncode < 0:
                crashes[signal.Signals(-done.returncode).name] += 1
            elif done.returncode != 0:
                crashes["exit %d" % done.returncode] += 1
                errors.append(done.stderr.strip().splitlines()[-1:] or ["?"])
            reports = [line for line in done.stdout.splitlines() if line.startswith("{")]
            if reports:
                report = json.loads(reports[-1])  # cumulative
                total.update(report["counts"])
                errors.extend(report["errors"])
            if done.returncode < 0:
                total["rounds"] += 1  # the round that crashed
        print("%s: %d rounds in %d processes, crashed rounds %s, %d calls, %d 'closed' errors, "
              "%d other errors%s" % (
                  kind, total["rounds"], total["children"],
                  dict(crashes) if crashes else 0, total["calls"], total["closed_errors"],
                  total["other_errors"], (" (e.g. %s)" % errors[0]) if errors else ""))
        bad = bad or bool(crashes) or total["other_errors"] > 0
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
