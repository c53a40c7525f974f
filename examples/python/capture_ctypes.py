#!/usr/bin/env python3
"""Capture a video through the avatarmap C API from Python with ctypes only.

Usage:
    capture_ctypes.py VIDEO [--library PATH] [--models DIR] [--max-frames N]
                      [--no-hands] [--no-face] [--live]

Frames are decoded by the ffmpeg command line (ffprobe for the size and rate; `ffmpeg -f rawvideo
-pix_fmt rgb24` piped), handed to an avm_estimator (landmarks -> solved, live-filtered proxy
pose) one by one, and one line per frame is printed: its time, the parts seen and the left
upper arm's rotation {x, y, z, w} with its confidence. With --live the frames are pushed into
an avm_live handle as a camera thread would (at their own times) while this thread samples the
pose, and the handle's counters and latency are printed at the end. The models come from
--models, else $AVATARMAP_MODELS/onnx; the library from --library, else $AVATARMAP_C_LIBRARY,
else the system search path. Every failure is one "error: ..." line and exit status 1 (2 on bad
usage); never a traceback.
"""

import argparse
import ctypes
import json
import os
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from solve_ctypes import (AVM_OK, AvmError, AvmFrame, AvmPose,  # noqa: E402
                          AvmSolverOptions, load_library, set_field, text)

AVM_ERROR_END_OF_FILE = 4
AVM_ERROR_UNSUPPORTED = 5
AVM_PIXEL_RGB8 = 0
AVM_BONE_LEFT_UPPER_ARM = None  # looked up by name


class AvmImage(ctypes.Structure):
    _fields_ = [("data", ctypes.c_void_p), ("width", ctypes.c_int32), ("height", ctypes.c_int32),
                ("stride_bytes", ctypes.c_int32), ("format", ctypes.c_int32)]


class AvmEstimatorOptions(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32), ("models_dir", ctypes.c_char_p),
                ("model_complexity", ctypes.c_int32), ("hands", ctypes.c_int32),
                ("face", ctypes.c_int32), ("hand_model_complexity", ctypes.c_int32),
                ("threads", ctypes.c_int32), ("mirrored", ctypes.c_int32),
                ("static_images", ctypes.c_int32), ("max_people", ctypes.c_int32)]


class AvmLiveStats(ctypes.Structure):
    _fields_ = [("pushed", ctypes.c_int64), ("processed", ctypes.c_int64),
                ("dropped", ctypes.c_int64), ("failed", ctypes.c_int64),
                ("latency_p50_ms", ctypes.c_double), ("latency_p95_ms", ctypes.c_double),
                ("latency_max_ms", ctypes.c_double), ("newest_t", ctypes.c_double)]


def declare_capture(lib):
    p = ctypes.c_void_p
    sigs = {
        "avm_estimator_options_init_sized": (ctypes.c_int, [ctypes.POINTER(AvmEstimatorOptions),
                                                            ctypes.c_size_t]),
        "avm_estimator_create": (ctypes.c_int, [ctypes.POINTER(AvmEstimatorOptions),
                                                ctypes.POINTER(AvmSolverOptions),
                                                ctypes.POINTER(p)]),
        "avm_estimator_destroy": (None, [p]),
        "avm_estimator_process": (ctypes.c_int, [p, ctypes.POINTER(AvmImage), ctypes.c_double,
                                                 ctypes.POINTER(AvmFrame),
                                                 ctypes.POINTER(AvmPose)]),
        "avm_estimator_last_error": (ctypes.c_char_p, [p]),
        "avm_live_create": (ctypes.c_int, [ctypes.POINTER(AvmEstimatorOptions),
                                           ctypes.POINTER(AvmSolverOptions), ctypes.POINTER(p)]),
        "avm_live_destroy": (None, [p]),
        "avm_live_push": (ctypes.c_int, [p, ctypes.POINTER(AvmImage), ctypes.c_double]),
        "avm_live_sample": (ctypes.c_int, [p, ctypes.c_double, ctypes.POINTER(AvmPose)]),
        "avm_live_get_stats": (ctypes.c_int, [p, ctypes.POINTER(AvmLiveStats)]),
        "avm_live_last_error": (ctypes.c_char_p, [p, ctypes.c_char_p, ctypes.c_size_t]),
    }
    for name, (restype, argtypes) in sigs.items():
        fn = getattr(lib, name)
        fn.restype = restype
        fn.argtypes = argtypes


def probe(video):
    """(width, height, fps) of the video's first stream, by ffprobe."""
    try:
        out = subprocess.run(
            ["ffprobe", "-v", "error", "-select_streams", "v:0", "-show_entries",
             "stream=width,height,r_frame_rate", "-of", "json", video],
            check=True, capture_output=True, text=True).stdout
    except FileNotFoundError:
        raise AvmError("the ffprobe command is missing (Debian package ffmpeg)")
    except subprocess.CalledProcessError as e:
        raise AvmError("ffprobe could not read %s: %s" % (video, e.stderr.strip()))
    streams = json.loads(out).get("streams") or []
    if not streams:
        raise AvmError("%s has no video stream" % video)
    s = streams[0]
    num, _, den = s.get("r_frame_rate", "30/1").partition("/")
    fps = float(num) / float(den or 1) if float(den or 1) else 30.0
    return int(s["width"]), int(s["height"]), fps or 30.0


def frames(video, width, height, limit):
    """Yields packed RGB frames (bytes) decoded by ffmpeg."""
    size = width * height * 3
    # ffmpeg's own messages are dropped: it complains of the pipe closing when we stop early;
    # a video it cannot decode shows as no frames.
    proc = subprocess.Popen(["ffmpeg", "-v", "error", "-i", video, "-f", "rawvideo",
                             "-pix_fmt", "rgb24", "-"], stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL)
    try:
        n = 0
        while limit <= 0 or n < limit:
            buf = proc.stdout.read(size)
            if len(buf) < size:
                break
            yield buf
            n += 1
    finally:
        proc.stdout.close()
        proc.kill()
        proc.wait()


def image_of(buf, width, height):
    img = AvmImage()
    img.data = ctypes.cast(ctypes.c_char_p(buf), ctypes.c_void_p)
    # Checked: a width from a hostile file's header must not wrap in the int32_t fields.
    set_field(img, "width", width, "image width")
    set_field(img, "height", height, "image height")
    set_field(img, "stride_bytes", width * 3, "image row stride (width x 3 bytes)")
    img.format = AVM_PIXEL_RGB8
    return img


def parts(frame):
    names = ("pose", "left_hand", "right_hand", "face")
    return ",".join(n for n in names if getattr(frame, n)) or "-"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("video")
    ap.add_argument("--library")
    ap.add_argument("--models")
    ap.add_argument("--max-frames", type=int, default=0)
    ap.add_argument("--no-hands", action="store_true")
    ap.add_argument("--no-face", action="store_true")
    ap.add_argument("--live", action="store_true")
    ap.add_argument("--skip-if-unavailable", action="store_true",
                    help="exit 77 (a test's 'skipped') without ffmpeg, models or the video")
    args = ap.parse_args()
    args.video = os.path.expandvars(args.video)  # "$AVATARMAP_TEST_DATA/..." from the tests
    if args.skip_if_unavailable:
        import shutil
        missing = [n for n in ("ffmpeg", "ffprobe") if shutil.which(n) is None]
        if not (args.models or os.environ.get("AVATARMAP_MODELS")):
            missing.append("models (--models or AVATARMAP_MODELS)")
        if not os.path.exists(args.video):
            missing.append(args.video)
        if missing:
            print("skipped: missing " + ", ".join(missing))
            return 77
    lib = load_library(args.library)
    declare_capture(lib)
    arm = lib.avm_bone_from_name(b"leftUpperArm")
    opts = AvmEstimatorOptions()
    lib.avm_estimator_options_init_sized(ctypes.byref(opts), ctypes.sizeof(opts))
    models = args.models.encode() if args.models else None
    opts.models_dir = models
    set_field(opts, "hands", 0 if args.no_hands else 1)
    set_field(opts, "face", 0 if args.no_face else 1)
    width, height, fps = probe(args.video)
    handle = ctypes.c_void_p()
    create = lib.avm_live_create if args.live else lib.avm_estimator_create
    st = create(ctypes.byref(opts), None, ctypes.byref(handle))
    if st == AVM_ERROR_UNSUPPORTED and args.skip_if_unavailable:
        print("skipped: %s" % text(lib.avm_last_create_error()))  # a build without ONNX Runtime
        return 77
    if st != AVM_OK:
        raise AvmError("%s: %s: %s" % ("avm_live_create" if args.live else "avm_estimator_create",
                                       text(lib.avm_status_string(st)),
                                       text(lib.avm_last_create_error())))
    pose = AvmPose()
    frame = AvmFrame()
    count = 0
    try:
        if not args.live:
            for i, buf in enumerate(frames(args.video, width, height, args.max_frames)):
                t = i / fps
                img = image_of(buf, width, height)
                st = lib.avm_estimator_process(handle, ctypes.byref(img), t, ctypes.byref(frame),
                                               ctypes.byref(pose))
                if st != AVM_OK:
                    raise AvmError("frame %d: %s" % (i, text(lib.avm_estimator_last_error(handle))))
                q = pose.rotations[arm]
                print("t %.3f parts %s leftUpperArm {%.3f, %.3f, %.3f, %.3f} confidence %.2f" % (
                    t, parts(frame), q[0], q[1], q[2], q[3], pose.confidence[arm]))
                count += 1
            if count == 0:
                raise AvmError("no frame could be decoded from %s" % args.video)
            print("captured %d frames of %s (%dx%d, %.2f fps)" % (count, args.video, width,
                                                                   height, fps))
        else:
            done = threading.Event()
            sampled = [0]

            def render():  # the render thread: samples 60 times a second
                start = time.monotonic()
                while not done.is_set():
                    out = AvmPose()
                    t = time.monotonic() - start
                    if lib.avm_live_sample(handle, t, ctypes.byref(out)) == AVM_OK:
                        sampled[0] += 1
                    time.sleep(1 / 60)

            thread = threading.Thread(target=render)
            thread.start()
            start = time.monotonic()
            try:
                for i, buf in enumerate(frames(args.video, width, height, args.max_frames)):
                    t = i / fps
                    delay = start + t - time.monotonic()
                    if delay > 0:
                        time.sleep(delay)  # a camera delivers frames at their own times
                    img = image_of(buf, width, height)
                    if lib.avm_live_push(handle, ctypes.byref(img), t) != AVM_OK:
                        err = ctypes.create_string_buffer(512)
                        raise AvmError("push: %s" % text(lib.avm_live_last_error(handle, err, 512)))
                    count += 1
                time.sleep(0.5)  # let the worker finish the newest frame
            finally:
                done.set()
                thread.join()
            stats = AvmLiveStats()
            lib.avm_live_get_stats(handle, ctypes.byref(stats))
            print("live: %d pushed, %d processed, %d dropped, %d failed; latency p50 %.1f ms, "
                  "p95 %.1f ms; %d poses sampled" % (
                      stats.pushed, stats.processed, stats.dropped, stats.failed,
                      stats.latency_p50_ms, stats.latency_p95_ms, sampled[0]))
    finally:
        (lib.avm_live_destroy if args.live else lib.avm_estimator_destroy)(handle)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except AvmError as e:
        print("error: %s" % e, file=sys.stderr)
        sys.exit(1)
    except OSError as e:
        print("error: %s" % e, file=sys.stderr)
        sys.exit(1)
