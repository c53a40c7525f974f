"""Batch conversion of many recordings on Dask distributed.

    python3 -m avatarmap.batch INPUTS... -o OUTDIR --to vrma|glb|bvh|pose [--avatar A]
                               [--scheduler tcp://HOST:8786 | --dashboard [HOST:]PORT] [options]

Each input file is one task: a video or image is captured (landmarks), landmarks are solved
(proxy poses, offline smoothing) and the poses are written in the asked format; a
``*.landmarks.jsonl`` starts at the solve and a ``*.pose.jsonl`` or ``.vrma`` at the last step
(each by the library's rule and job, as ``avatarmap convert`` reads and writes it). Without
``--scheduler`` a ``LocalCluster`` runs one worker process per core, one task (and, for
capture, one inference thread) at a time each; with ``--scheduler`` the same tasks go to the
workers of an existing cluster, which must see the inputs and OUTDIR at the same paths and
have this package installed.

The local cluster listens on 127.0.0.1 only: its scheduler, its workers and their HTTP
endpoints (``--host`` changes the scheduler's and workers' address); the dashboard is off
unless ``--dashboard [HOST:]PORT`` asks for it (on 127.0.0.1 unless HOST says otherwise). An
address beyond loopback, asked for with these options or as a remote ``--scheduler``, is
named in a warning: Dask's connections are neither authenticated nor encrypted without TLS,
and whoever reaches a scheduler runs code on its workers.

Outputs are ``OUTDIR/STEM.EXT``. A task writes in a folder of its own under
``OUTDIR/.avatarmap-batch/`` and renames the finished file into place, so OUTDIR never holds
a partial output, even when a worker dies (Dask then runs the task again elsewhere). A run
skips the outputs that already exist (``--force`` redoes them), so a stopped batch is resumed
by running the same command again. A file that fails is reported with its reason and the
others go on. The closing table lists every file, its frames and speed, and the failures;
the exit status is 0 when nothing failed, 1 when a file failed (or the scheduler could not
be reached), 2 on bad usage (options, OUTDIR a file or not creatable, an address Dask cannot
use). Messages name every address with its password masked (``user:***@``).
See docs/python.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import ipaddress
import logging
import os
import re
import shutil
import socket
import stat
import sys
import time
import uuid
from typing import Callable, Dict, List, Optional, Sequence, Tuple

from . import _lib
from ._data import _motion_input

VIDEO_SUFFIXES = (".mp4", ".mkv", ".avi", ".mov", ".webm", ".m4v", ".mpg", ".mpeg", ".ts",
                  ".flv", ".wmv", ".y4m")
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp")
OUTPUT_SUFFIXES = {"vrma": ".vrma", "glb": ".glb", "bvh": ".bvh", "pose": ".pose.jsonl"}
WORK_FOLDER = ".avatarmap-batch"
LOOPBACK = "127.0.0.1"
PROG = "avatarmap.batch"


class UsageError(Exception):
    """Bad usage: the message is printed as "avatarmap.batch: error: ..." and the exit status
    is 2."""


# ---- messages -----------------------------------------------------------------------------

_CREDENTIALS = re.compile(r"(?P<scheme>\b[A-Za-z][A-Za-z0-9+.-]*:/+)(?P<user>[^\s/@:]*):"
                          r"(?P<password>[^\s/@]*)@")


def redact(text: str) -> str:
    """`text` with the password of every URL in it masked: scheme://user:***@host."""
    return _CREDENTIALS.sub(lambda m: "%s%s:***@" % (m.group("scheme"), m.group("user")),
                            str(text))


def warn(message: str) -> None:
    print("%s: warning: %s" % (PROG, redact(message)), file=sys.stderr, flush=True)


class _RedactLogs(logging.Filter):
    """Masks passwords in log records (Dask's own messages may quote an address)."""

    def filter(self, record: logging.LogRecord) -> bool:
        try:
            message = record.getMessage()
        except Exception:  # noqa: BLE001 - a bad record is logging's to report
            return True
        masked = redact(message)
        if masked != message:
            record.msg, record.args = masked, None
        return True


def _redact_logs() -> None:
    """Installs _RedactLogs on the handlers of the root and Dask's loggers (filters on a
    logger do not apply to its children's records; handlers see them all)."""
    for name in (None, "distributed", "dask"):
        for handler in logging.getLogger(name).handlers:
            if not any(isinstance(f, _RedactLogs) for f in handler.filters):
                handler.addFilter(_RedactLogs())


# ---- addresses ----------------------------------------------------------------------------


def _is_loopback(host: str) -> bool:
    """Whether every address `host` names is a loopback one (a name is resolved; a name that
    does not resolve counts as not loopback)."""
    host = host.strip("[]")
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        pass
    try:
        infos = socket.getaddrinfo(host, None)
    except (OSError, UnicodeError):
        return False
    return bool(infos) and all(ipaddress.ip_address(i[4][0].split("%")[0]).is_loopback
                               for i in infos)


def _check_host(host: str, option: str) -> str:
    """A host for the local cluster to listen on: an IPv4 address or a name (Dask's
    dashboard addresses take no IPv6 literal)."""
    if not host or ":" in host or "/" in host or any(c.isspace() for c in host):
        raise UsageError("%s %r: expected an IPv4 address or a host name (e.g. 127.0.0.1)"
                         % (option, host))
    return host


def parse_dashboard(value: str) -> Tuple[str, int]:
    """--dashboard [HOST:]PORT -> (host, port); HOST defaults to 127.0.0.1 (also for
    ":PORT", which Dask itself reads as every interface)."""
    host, sep, port = value.rpartition(":")
    if not sep:
        host = ""
    try:
        number = int(port)
    except ValueError:
        number = -1
    if not 0 <= number <= 65535:
        raise UsageError("--dashboard %r: expected [HOST:]PORT with PORT 0 .. 65535 (0: any "
                         "free port)" % value)
    return (_check_host(host, "--dashboard") if host else LOOPBACK), number


def check_scheduler(address: str) -> str:
    """The scheme of a --scheduler address Dask can connect to; UsageError otherwise."""
    from distributed.comm import parse_address
    from distributed.comm.addressing import parse_host_port
    from distributed.comm.registry import get_backend
    shown = redact(address)
    try:
        scheme, location = parse_address(address)
        get_backend(scheme)
        if scheme in ("tcp", "tls", "ws", "wss"):
            if "@" in location:
                raise ValueError("a Dask address holds no user or password")
            parse_host_port(location)
    except ValueError as e:
        raise UsageError("--scheduler %s: %s (expected tcp://HOST:PORT, tls://HOST:PORT, ...)"
                         % (shown, redact(str(e)))) from None
    return scheme


def _warn_exposure(args: argparse.Namespace) -> None:
    """A warning for each address beyond loopback the options ask for."""
    if args.scheduler:
        from distributed.comm.addressing import get_address_host
        scheme = check_scheduler(args.scheduler)
        try:
            host = get_address_host(args.scheduler)
        except ValueError:
            host = ""
        if scheme != "inproc" and not _is_loopback(host):
            warn("the scheduler %s is not on this machine: the tasks (file paths, options) and "
                 "their results cross the network%s, and whoever can reach that scheduler runs "
                 "code on its workers" % (args.scheduler, "" if scheme in ("tls", "wss") else
                                          " unencrypted and unauthenticated (%s://; tls:// "
                                          "or an SSH tunnel protects them)" % scheme))
        return
    if not _is_loopback(args.host):
        warn("--host %s: the local cluster's scheduler and workers listen on %s, reachable "
             "from other machines; whoever reaches them runs code as you (Dask has no "
             "authentication without TLS)" % (args.host, "every interface"
                                                if args.host == "0.0.0.0" else args.host))
    if args.dashboard is not None and not _is_loopback(args.dashboard[0]):
        warn("--dashboard %s:%d: Dask's dashboard (task and file names, the workers' state) "
             "is served to %s without authentication"
             % (args.dashboard[0], args.dashboard[1], "every interface"
                if args.dashboard[0] == "0.0.0.0" else "other machines"))


@dataclasses.dataclass
class Task:
    """One input file and what it becomes."""
    input: str   # absolute path
    kind: str    # "media" (video or image), or input_kind's "landmarks", "poses" or "vrma"
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
    """(kind, stem) of an input, or None when it is no input we read: "media" (a video or an
    image, by its suffix: captured first), else the motion file the library reads it as
    (avatarmap.motion_input_kind, the rule of ``avatarmap convert``: "landmarks", "poses" or
    "vrma"). The stem is the file's name without the suffix that decided."""
    name = os.path.basename(path)
    stem, ext = os.path.splitext(name)
    if ext.lower() in VIDEO_SUFFIXES or ext.lower() in IMAGE_SUFFIXES:
        return "media", stem
    kind, without = _motion_input(path)
    if kind is None:
        return None
    return kind, os.path.basename(without)


_URL = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]*://")


def _not_a_file(path: str) -> str:
    """Why `path` is no regular file we can read ("" when it is one)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        if os.path.islink(path):
            return "a dangling symbolic link (to %s, which does not exist)" % os.readlink(path)
        return "no such file"
    except OSError as e:
        return "cannot be read (%s)" % (e.strerror or e)
    if stat.S_ISREG(st.st_mode):
        return ""
    kinds = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISSOCK, "a socket"),
             (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"))
    return "not a regular file (%s)" % next((name for test, name in kinds
                                             if test(st.st_mode)), "special")


def plan(inputs: Sequence[str], outdir: str, to: str,
         warn: Callable[[str], None] = warn) -> Tuple[List[Task], List[Result]]:
    """Tasks for the inputs (folders give the files in them that we read, sorted), and the
    inputs that cannot be tasks (missing, a dangling link, not a regular file, a URL, unknown
    type, two inputs onto one output) as failed results; a *.pose.jsonl that is its own output
    (OUTDIR read as input with --to pose) is skipped. Entries of a folder named as inputs
    that are no regular file (a dangling symbolic link, a FIFO, ...) are skipped with a
    warning each, through `warn`."""
    tasks: List[Task] = []
    bad: List[Result] = []
    by_output: Dict[str, Task] = {}
    suffix = OUTPUT_SUFFIXES[to]
    for given in inputs:
        if _URL.match(given):
            bad.append(Result(given, status="failed",
                              reason="a URL: the batch reads files (capture it to a file first)"))
            continue
        if os.path.isdir(given):
            names = []
            for n in sorted(os.listdir(given)):
                if not input_kind(n):
                    continue
                why = _not_a_file(os.path.join(given, n))
                if why:
                    warn("%s: skipped: %s" % (os.path.join(given, n), why))
                else:
                    names.append(n)
            if not names:
                bad.append(Result(given, status="failed",
                                  reason="a folder with no video, image, *.landmarks.jsonl, "
                                         "*.pose.jsonl or *.vrma in it"))
            paths = [os.path.join(given, n) for n in names]
        else:
            paths = [given]
        for p in paths:
            path = os.path.abspath(p)
            kind = input_kind(path)
            why = _not_a_file(path)
            if why:
                bad.append(Result(path, status="failed", reason=why))
                continue
            if kind is None:
                bad.append(Result(path, status="failed",
                                  reason="not a video, image, *.landmarks.jsonl, *.pose.jsonl or "
                                         "*.vrma"))
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
            landmarks = os.path.join(work, "capture.landmarks.jsonl")
            summary = avatarmap.capture_file(src, landmarks, models=options.get("models"),
                                             hands=options.get("hands", True),
                                             face=options.get("face", True),
                                             threads=options.get("threads", 1))
            frames = int(summary.frames)
            src, kind = landmarks, "landmarks"
        finished = os.path.join(work, "out" + OUTPUT_SUFFIXES[options["to"]])
        # The library's convert (`avatarmap convert`): landmarks solved in memory, the frames
        # in time order, the format by the output's name. One thread a task (file_threads=1):
        # the workers are one per core; the CLI parses a file ahead on a second thread.
        solve = {"file_threads": 1} if kind == "landmarks" else {}
        n = avatarmap.convert_file(src, finished, fps=options.get("fps", 0.0),
                                   avatar=options.get("avatar"), mapping=options.get("mapping"),
                                   **solve)
        frames = frames or n
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
    `startup`: connecting to (or starting) the cluster before that. Passwords in paths and
    reasons are masked."""
    def line(text: str = "") -> None:
        out.write(redact(text) + "\n")

    done = [r for r in results if r.status == "ok"]
    skipped = [r for r in results if r.status == "skipped"]
    failed = [r for r in results if r.status == "failed"]
    frames = sum(r.frames for r in done)
    width = max([len(os.path.basename(r.input)) for r in results] + [4])
    line()
    line("%-*s  %8s  %8s  %9s  %s" % (width, "file", "frames", "seconds", "frames/s", "result"))
    for r in results:
        rate = "%9.1f" % (r.frames / r.seconds) if r.status == "ok" and r.seconds > 0 else \
            "%9s" % "-"
        what = {"ok": "-> " + r.output, "skipped": "skipped: %s exists" % r.output,
                "failed": "FAILED"}[r.status]
        line("%-*s  %8s  %8s  %s  %s" % (width, os.path.basename(r.input),
                                          r.frames if r.status == "ok" else "-",
                                          "%.2f" % r.seconds if r.status == "ok" else "-",
                                          rate, what))
    line()
    line("batch: %d files: %d converted, %d skipped (already done), %d failed; %d frames in "
         "%.2f s: %.1f frames/s (cluster start-up %.2f s before)"
         % (len(results), len(done), len(skipped), len(failed), frames, wall,
            frames / wall if wall > 0 else 0.0, startup))
    if failed:
        line("failures:")
        for r in failed:
            line("  %s: %s" % (r.input, r.reason))


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # type: ignore[override]
        self.print_usage(sys.stderr)
        raise UsageError(message)


def _parse(argv: Optional[Sequence[str]]) -> argparse.Namespace:
    ap = _Parser(
        prog="python3 -m avatarmap.batch",
        description="Convert many recordings (videos, images, *.landmarks.jsonl, *.pose.jsonl) "
                    "to animation files on Dask distributed: one task per file, a local "
                    "cluster unless --scheduler is given. Finished outputs are skipped, so "
                    "running the same command again resumes a stopped batch.",
        epilog="The local cluster listens on 127.0.0.1 only (scheduler, workers, their HTTP "
               "endpoints) and has no dashboard unless --dashboard asks for one; any address "
               "beyond loopback (--host, --dashboard, a remote --scheduler) is named in a "
               "warning. Exit status: 0 all converted, 1 a file failed or the scheduler could "
               "not be reached, 2 bad usage.")
    ap.add_argument("inputs", nargs="+", metavar="INPUT",
                    help="files, or folders (the files in them that are inputs; entries that "
                         "are no regular file, such as dangling symbolic links, are skipped "
                         "with a warning)")
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
                    help="an existing Dask scheduler (tcp://HOST:8786, tls://HOST:8786); "
                         "default: a local cluster. A scheduler on another machine gets a "
                         "warning: without tls:// the tasks cross the network unencrypted")
    ap.add_argument("--host", default=LOOPBACK, metavar="HOST",
                    help="local cluster: the address its scheduler and workers listen on "
                         "(default 127.0.0.1; another one, e.g. 0.0.0.0, gets a warning)")
    ap.add_argument("--dashboard", metavar="[HOST:]PORT",
                    help="local cluster: serve Dask's dashboard on HOST:PORT (HOST default "
                         "127.0.0.1; PORT 0: any free port; needs python3-bokeh). Default: "
                         "no dashboard")
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
    if not (a.fps >= 0 and a.fps <= _lib.MAX_FPS):
        ap.error("--fps is 0 .. %g (0: the frames' own times)" % _lib.MAX_FPS)
    if a.avatar and not os.path.isfile(a.avatar):
        ap.error("--avatar %s: no such file" % a.avatar)
    if a.scheduler and (a.dashboard is not None or a.host != LOOPBACK):
        ap.error("--host and --dashboard are for the local cluster (the scheduler at %s is "
                 "configured where it runs)" % a.scheduler)
    a.host = _check_host(a.host, "--host")
    a.dashboard = parse_dashboard(a.dashboard) if a.dashboard is not None else None
    return a


def _outdir(path: str) -> str:
    """OUTDIR, made when missing; UsageError when it is a file or cannot be made."""
    outdir = os.path.abspath(path)
    if os.path.exists(outdir) and not os.path.isdir(outdir):
        raise UsageError("OUTDIR %s is a file; give a folder (made when missing)" % path)
    try:
        os.makedirs(outdir, exist_ok=True)
    except OSError as e:
        raise UsageError("OUTDIR %s cannot be created: %s" % (path, e.strerror or e)) from None
    if not os.access(outdir, os.W_OK | os.X_OK):
        raise UsageError("OUTDIR %s is not writable" % path)
    return outdir


def run(args: argparse.Namespace, out=sys.stdout) -> int:
    """The batch for parsed arguments; returns the exit status (UsageError: bad usage)."""
    outdir = _outdir(args.output)
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


class SchedulerError(Exception):
    """The scheduler given by --scheduler could not be reached (exit status 1)."""


def local_cluster(workers: int, host: str = LOOPBACK,
                  dashboard: Optional[Tuple[str, int]] = None):  # -> distributed.LocalCluster
    """The batch's local cluster: `workers` single-thread worker processes; the scheduler
    and the workers listen on `host` (127.0.0.1 unless asked otherwise); every HTTP endpoint
    (the scheduler's, each worker's) on 127.0.0.1 at a free port, except the scheduler's
    dashboard when `dashboard` = (host, port) asks for one. Dask's own defaults would serve
    the scheduler's HTTP on every interface at 8787 and each worker's on every interface."""
    from distributed import LocalCluster, Nanny

    class QuietNanny(Nanny):
        """A nanny whose worker has no dashboard (LocalCluster turns a worker's dashboard on
        whenever its HTTP address is given)."""

        def __init__(self, *a, **kw):  # type: ignore[no-untyped-def]
            kw["dashboard"] = False
            super().__init__(*a, **kw)

    http = "%s:%d" % dashboard if dashboard else "%s:0" % LOOPBACK
    return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                        worker_class=QuietNanny, host=host, scheduler_port=0,
                        dashboard_address=http, worker_dashboard_address="%s:0" % LOOPBACK,
                        scheduler_kwargs={"dashboard": dashboard is not None},
                        silence_logs=logging.ERROR)


def _quiet_teardown() -> None:
    """Runs in each worker of the local cluster (and in this process) once every result is
    in: Dask's own log is raised to CRITICAL, so a heartbeat that races the scheduler's close
    does not print a traceback after a batch that succeeded."""
    for name in ["distributed"] + [n for n in list(logging.root.manager.loggerDict)
                                   if n.startswith("distributed.")]:
        logging.getLogger(name).setLevel(logging.CRITICAL)


def _run_on_dask(todo: List[Task], options: dict, args: argparse.Namespace,
                 timing: dict) -> List[Result]:
    from distributed import Client, progress

    t0 = time.perf_counter()
    cluster = None
    if args.scheduler:
        try:
            client = Client(args.scheduler, timeout=15)
        except (OSError, TimeoutError) as e:
            raise SchedulerError("cannot reach the scheduler at %s: %s"
                                 % (args.scheduler, e)) from None
    else:
        cluster = local_cluster(args.workers or os.cpu_count() or 1, args.host, args.dashboard)
        _redact_logs()
        if args.host != LOOPBACK:
            print("%s: scheduler at %s" % (PROG, cluster.scheduler_address), file=sys.stderr)
        if args.dashboard:
            print("%s: dashboard at %s" % (PROG, cluster.dashboard_link), file=sys.stderr)
            try:
                import bokeh  # noqa: F401
            except ImportError:
                warn("--dashboard: Bokeh is not installed (Debian: python3-bokeh); the "
                     "dashboard's page only says so")
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
        if cluster is not None:  # only our own workers: a user's scheduler keeps its log
            try:
                client.run(_quiet_teardown)
            except Exception:  # noqa: BLE001 - a worker already gone has nothing to say
                pass
            _quiet_teardown()
        client.close()
        if cluster is not None:
            cluster.close()


def main(argv: Optional[Sequence[str]] = None) -> int:
    try:
        args = _parse(argv)
        _outdir(args.output)  # before Dask's import: a bad OUTDIR is said at once
        try:
            import distributed  # noqa: F401 - sets up Dask's log handlers, filtered below
        except ImportError as e:
            raise UsageError("Dask distributed is needed (Debian: python3-distributed): %s"
                             % e) from None
        _redact_logs()
        _warn_exposure(args)
        return run(args)
    except UsageError as e:
        print("%s: error: %s" % (PROG, redact(str(e))), file=sys.stderr)
        return 2
    except SchedulerError as e:
        print("%s: error: %s" % (PROG, redact(str(e))), file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("%s: interrupted; finished outputs are kept, run the same command to go on"
              % PROG, file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
