"""Batch conversion of many recordings on Dask distributed.

    python3 -m avatarmap.batch INPUTS... -o OUTDIR --to vrma|glb|bvh|pose [--avatar A]
                               [--scheduler tcp://HOST:8786] [options]

Each input file is one task: a video or image is captured (landmarks), landmarks are solved
(proxy poses, offline smoothing) and the poses are written in the asked format; a
``*.landmarks.jsonl`` starts at the solve and a ``*.pose.jsonl`` at the last step. Without
``--scheduler`` a ``LocalCluster`` runs one worker process per core, one task (and, for
capture, one inference thread) at a time each; with ``--scheduler`` the same tasks go to the
workers of an existing cluster, which must see the inputs and OUTDIR at the same paths and
have this package installed.

Outputs are ``OUTDIR/STEM.EXT``. A task writes in a folder of its own under
``OUTDIR/.avatarmap-batch/`` and renames the finished file into place, so OUTDIR never holds
a partial output, even when a worker dies (Dask then runs the task again elsewhere). A run
skips the outputs that already exist (``--force`` redoes them), so a stopped batch is resumed
by running the same command again. A file that fails is reported with its reason and the
others go on. The closing table lists every file, its frames and speed, and the failures;
the exit status is 0 when nothing failed, 1 when a file failed, 2 on bad usage.
See docs/python.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import os
import shutil
import sys
import time
import uuid
from typing import Dict, List, Optional, Sequence, Tuple

VIDEO_SUFFIXES = (".mp4", ".mkv", ".avi", ".mov", ".webm", ".m4v", ".mpg", ".mpeg", ".ts",
                  ".flv", ".wmv", ".y4m")
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp")
LANDMARKS_SUFFIX = ".landmarks.jsonl"
POSE_SUFFIX = ".pose.jsonl"
OUTPUT_SUFFIXES = {"vrma": ".vrma", "glb": ".glb", "bvh": ".bvh", "pose": POSE_SUFFIX}
WORK_FOLDER = ".avatarmap-batch"


@dataclasses.dataclass
class Task:
    """One input file and what it becomes."""
    input: str   # absolute path
    kind: str    # "media" (video or image), "landmarks" or "poses"
    output: str  # absolute path of the finished output


@dataclasses.dataclass
class Result:
    """What became of one input."""
    input: str
    output: str = ""
    status: str = "ok"  # "ok", "skipped" (output already there) or "failed"
    frames: int = 0
    seconds: float = 0.0  # wall-clock time of the task on its worker
    reason: str = ""      # why it failed
    worker: str = ""      # host:pid that finished it


def input_kind(path: str) -> Optional[Tuple[str, str]]:
    """(kind, stem) of an input path by its name, or None when it is no input we read."""
    name = os.path.basename(path)
    low = name.lower()
    if low.endswith(LANDMARKS_SUFFIX):
        return "landmarks", name[:-len(LANDMARKS_SUFFIX)]
    if low.endswith(POSE_SUFFIX):
        return "poses", name[:-len(POSE_SUFFIX)]
    stem, ext = os.path.splitext(name)
    if ext.lower() in VIDEO_SUFFIXES or ext.lower() in IMAGE_SUFFIXES:
        return "media", stem
    return None


def plan(inputs: Sequence[str], outdir: str, to: str) -> Tuple[List[Task], List[Result]]:
    """Tasks for the inputs (folders give the files in them that we read, sorted), and the
    inputs that cannot be tasks (missing, unknown type, two inputs onto one output) as failed
    results; a *.pose.jsonl that is its own output (OUTDIR read as input with --to pose) is
    skipped."""
    tasks: List[Task] = []
    bad: List[Result] = []
    by_output: Dict[str, Task] = {}
    suffix = OUTPUT_SUFFIXES[to]
    for given in inputs:
        if os.path.isdir(given):
            names = sorted(n for n in os.listdir(given)
                           if input_kind(n) and os.path.isfile(os.path.join(given, n)))
            if not names:
                bad.append(Result(given, status="failed",
                                  reason="a folder with no video, image, *.landmarks.jsonl or "
                                         "*.pose.jsonl in it"))
            paths = [os.path.join(given, n) for n in names]
        else:
            paths = [given]
        for p in paths:
            path = os.path.abspath(p)
            kind = input_kind(path)
            if not os.path.isfile(path):
                bad.append(Result(path, status="failed", reason="no such file"))
                continue
            if kind is None:
                bad.append(Result(path, status="failed",
                                  reason="not a video, image, *.landmarks.jsonl or *.pose.jsonl "
                                         "(by its name)"))
                continue
            out = os.path.join(outdir, kind[1] + suffix)
            if os.path.abspath(out) == path:  # a *.pose.jsonl in OUTDIR itself, --to pose
                bad.append(Result(path, out, status="skipped"))
                continue
            if out in by_output:
                if by_output[out].input != path:
                    bad.append(Result(path, status="failed",
                                      reason="its output %s is also %s's; rename one" %
                                             (out, by_output[out].input)))
                continue
            task = Task(path, kind[0], out)
            by_output[out] = task
            tasks.append(task)
    return tasks, bad


def _count_poses(path: str) -> int:
    """Frames in a *.pose.jsonl (its lines after the header)."""
    n = 0
    with open(path, "rb") as f:
        for line in f:
            if line.startswith(b'{"t"'):
                n += 1
    return n


def convert_one(task: Task, options: dict) -> Result:
    """Runs on a worker: capture -> solve -> write, in a folder of its own, the finished file
    renamed into place. Failures of the input come back as a failed Result (not an exception:
    Dask would run it again for nothing); a dying worker leaves only its work folder, which
    the next run or the driver removes."""
    import avatarmap  # on the worker

    t0 = time.perf_counter()
    worker = "%s:%d" % (os.uname().nodename, os.getpid())
    stem = os.path.basename(task.output)
    work = os.path.join(os.path.dirname(task.output), WORK_FOLDER,
                        "%s.%s" % (stem, uuid.uuid4().hex[:12]))
    result = Result(task.input, task.output, worker=worker)
    try:
        os.makedirs(work)
        src, kind, frames = task.input, task.kind, 0
        if kind == "media":
            landmarks = os.path.join(work, "capture" + LANDMARKS_SUFFIX)
            summary = avatarmap.capture_file(src, landmarks, models=options.get("models"),
                                             hands=options.get("hands", True),
                                             face=options.get("face", True),
                                             threads=options.get("threads", 1))
            frames = int(summary.frames)
            src, kind = landmarks, "landmarks"
        finished = os.path.join(work, "out" + OUTPUT_SUFFIXES[options["to"]])
        # One thread a task (file_threads=1): the workers are one per core; the CLI parses a
        # file ahead on a second thread.
        if kind == "landmarks" and options["to"] == "pose":
            avatarmap.solve_file(src, finished, file_threads=1)
            frames = frames or _count_poses(finished)
        elif kind == "landmarks":  # solved in memory, as `avatarmap convert IN.landmarks.jsonl`
            n = avatarmap.convert_file(src, finished, fps=options.get("fps", 0.0),
                                       avatar=options.get("avatar"),
                                       mapping=options.get("mapping"), file_threads=1)
            frames = frames or n
        else:
            frames = avatarmap.convert_file(src, finished, fps=options.get("fps", 0.0),
                                            avatar=options.get("avatar"),
                                            mapping=options.get("mapping"))
        os.replace(finished, task.output)
        result.frames = frames
    except (avatarmap.AvatarmapError, OSError, ValueError) as e:
        result.status = "failed"
        result.reason = str(e) or type(e).__name__
    finally:
        shutil.rmtree(work, ignore_errors=True)
    result.seconds = time.perf_counter() - t0
    return result


def _remove_work_folder(outdir: str) -> None:
    """Removes OUTDIR/.avatarmap-batch when no task of this run can still be writing there
    (left-overs of workers that died)."""
    shutil.rmtree(os.path.join(outdir, WORK_FOLDER), ignore_errors=True)


def _format_table(results: List[Result], wall: float, startup: float = 0.0,
                  out=sys.stdout) -> None:
    """The closing table. `wall`: from the first task handed to Dask to the last result;
    `startup`: connecting to (or starting) the cluster before that."""
    done = [r for r in results if r.status == "ok"]
    skipped = [r for r in results if r.status == "skipped"]
    failed = [r for r in results if r.status == "failed"]
    frames = sum(r.frames for r in done)
    width = max([len(os.path.basename(r.input)) for r in results] + [4])
    print("", file=out)
    print("%-*s  %8s  %8s  %9s  %s" % (width, "file", "frames", "seconds", "frames/s", "result"),
          file=out)
    for r in results:
        rate = "%9.1f" % (r.frames / r.seconds) if r.status == "ok" and r.seconds > 0 else \
            "%9s" % "-"
        what = {"ok": "-> " + r.output, "skipped": "skipped: %s exists" % r.output,
                "failed": "FAILED"}[r.status]
        print("%-*s  %8s  %8s  %s  %s" % (width, os.path.basename(r.input),
                                           r.frames if r.status == "ok" else "-",
                                           "%.2f" % r.seconds if r.status == "ok" else "-",
                                           rate, what), file=out)
    print("", file=out)
    print("batch: %d files: %d converted, %d skipped (already done), %d failed; %d frames in "
          "%.2f s: %.1f frames/s (cluster start-up %.2f s before)"
          % (len(results), len(done), len(skipped), len(failed), frames, wall,
             frames / wall if wall > 0 else 0.0, startup), file=out)
    if failed:
        print("failures:", file=out)
        for r in failed:
            print("  %s: %s" % (r.input, r.reason), file=out)


def _parse(argv: Optional[Sequence[str]]) -> argparse.Namespace:
    ap = argparse.ArgumentParser(
        prog="python3 -m avatarmap.batch",
        description="Convert many recordings (videos, images, *.landmarks.jsonl, *.pose.jsonl) "
                    "to animation files on Dask distributed: one task per file, a local "
                    "cluster unless --scheduler is given. Finished outputs are skipped, so "
                    "running the same command again resumes a stopped batch.")
    ap.add_argument("inputs", nargs="+", metavar="INPUT",
                    help="files, or folders (the files in them that are inputs)")
    ap.add_argument("-o", "--output", required=True, metavar="OUTDIR",
                    help="folder of the outputs, OUTDIR/STEM.EXT (made when missing)")
    ap.add_argument("--to", required=True, choices=sorted(OUTPUT_SUFFIXES),
                    help="vrma: VRM Animation; glb: the avatar with the motion (needs "
                         "--avatar); bvh: the proxy skeleton, or the avatar's rig with "
                         "--avatar; pose: *.pose.jsonl")
    ap.add_argument("--avatar", help="the avatar (.vrm, .glb, .gltf) for --to glb or bvh")
    ap.add_argument("--rig", "--mapping", dest="mapping", metavar="auto|NAME|FILE.json",
                    help="how the avatar's joints map to the proxy, as `avatarmap convert "
                         "--rig`: auto (default), a shipped table's name or FILE.json")
    ap.add_argument("--fps", type=float, default=None,
                    help="output frame rate (default 30 as `avatarmap convert`; --to pose: "
                         "the frames' own times)")
    ap.add_argument("--scheduler", metavar="ADDRESS",
                    help="an existing Dask scheduler (tcp://HOST:8786); default: a local "
                         "cluster")
    ap.add_argument("--workers", type=int, default=0,
                    help="local cluster: worker processes (default: one per core)")
    ap.add_argument("--threads", type=int, default=1,
                    help="inference threads per capture task (default 1; 2 runs the body "
                         "beside the hands and face)")
    ap.add_argument("--models", help="the converted models (default: the package's)")
    ap.add_argument("--no-hands", action="store_true", help="capture: body and face only")
    ap.add_argument("--no-face", action="store_true", help="capture: body and hands only")
    ap.add_argument("--force", action="store_true", help="redo outputs that already exist")
    ap.add_argument("--no-progress", action="store_true",
                    help="no progress bar (default: one on a terminal)")
    a = ap.parse_args(argv)
    if a.to == "glb" and not a.avatar:
        ap.error("--to glb needs --avatar")
    if a.avatar and a.to not in ("glb", "bvh"):
        ap.error("--avatar is for --to glb or bvh")
    if a.workers < 0 or a.workers > 256:
        ap.error("--workers is 1 .. 256 (0: one per core)")
    if a.threads < 1 or a.threads > 64:
        ap.error("--threads is 1 .. 64")
    if a.fps is None:
        a.fps = 0.0 if a.to == "pose" else 30.0
    if not (a.fps >= 0 and a.fps <= 1000):
        ap.error("--fps is 0 .. 1000 (0: the frames' own times)")
    if a.avatar and not os.path.isfile(a.avatar):
        ap.error("--avatar %s: no such file" % a.avatar)
    return a


def run(args: argparse.Namespace, out=sys.stdout) -> int:
    """The batch for parsed arguments; returns the exit status."""
    outdir = os.path.abspath(args.output)
    os.makedirs(outdir, exist_ok=True)
    tasks, results = plan(args.inputs, outdir, args.to)
    todo = []
    for t in tasks:
        if os.path.exists(t.output) and not args.force:
            results.append(Result(t.input, t.output, status="skipped"))
        else:
            todo.append(t)
    options = {"to": args.to, "avatar": os.path.abspath(args.avatar) if args.avatar else None,
               "mapping": args.mapping, "fps": args.fps, "threads": args.threads,
               "models": os.path.abspath(args.models) if args.models else None,
               "hands": not args.no_hands, "face": not args.no_face}
    timing = {"startup": 0.0, "wall": 0.0}
    if todo:
        results.extend(_run_on_dask(todo, options, args, timing))
        _remove_work_folder(outdir)  # what workers that died left
    order = {os.path.abspath(p): i for i, p in enumerate(args.inputs)}
    results.sort(key=lambda r: (order.get(r.input, len(order)), r.input))
    _format_table(results, timing["wall"], timing["startup"], out)
    return 1 if any(r.status == "failed" for r in results) else 0


def _run_on_dask(todo: List[Task], options: dict, args: argparse.Namespace,
                 timing: dict) -> List[Result]:
    from distributed import Client, LocalCluster, progress

    t0 = time.perf_counter()
    cluster = None
    if args.scheduler:
        try:
            client = Client(args.scheduler, timeout=15)
        except (OSError, TimeoutError) as e:
            raise SystemExit("batch: cannot reach the scheduler at %s: %s" % (args.scheduler, e))
    else:
        workers = args.workers or os.cpu_count() or 1
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR)
        client = Client(cluster)
    try:
        t1 = time.perf_counter()
        timing["startup"] = t1 - t0
        names = ["avatarmap-batch %s %s" % (os.path.basename(t.input), uuid.uuid4().hex[:8])
                 for t in todo]
        futures = client.map(convert_one, todo, options=options, key=names, pure=False)
        if not args.no_progress and sys.stdout.isatty():
            progress(futures)  # Dask's text bar, on standard output as the closing table
            print("")
        results = []
        for task, f in zip(todo, futures):
            try:
                results.append(f.result())
            except Exception as e:  # KilledWorker (every worker it ran on died), lost scheduler
                reason = "%s: %s" % (type(e).__name__, e)
                if type(e).__name__ == "KilledWorker":
                    import dask
                    reason = ("the workers running it died %s times (Dask's "
                              "distributed.scheduler.allowed-failures); the file may make its "
                              "worker run out of memory" %
                              dask.config.get("distributed.scheduler.allowed-failures"))
                results.append(Result(task.input, task.output, status="failed", reason=reason))
        timing["wall"] = time.perf_counter() - t1
        return results
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def main(argv: Optional[Sequence[str]] = None) -> int:
    args = _parse(argv)
    try:
        return run(args)
    except KeyboardInterrupt:
        print("batch: interrupted; finished outputs are kept, run the same command to go on",
              file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
