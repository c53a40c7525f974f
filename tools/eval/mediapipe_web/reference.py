#!/usr/bin/env python3
"""Google's reference body landmarks for still images (docs/closeups.md).

Runs Google's own MediaPipe Pose web solution (npm @mediapipe/pose, its wasm graph and
.tflite models, fetched and integrity-checked by scripts/fetch_mediapipe_web.sh into
.cache/avatarmap/mediapipe_web) in Debian's headless Chromium (WebGL on SwiftShader), in
static-image mode: each image is sent once to a graph that has seen no earlier frame,
smoothing and selfie mode off. The files are served from a loopback HTTP server (the wasm
and its data cannot load from file://); the page posts each result back to it.

    reference.py IMAGE... -o OUTDIR [--model-complexity 1] [--relative-to DIR] [--reuse]

writes OUTDIR/<image stem>_pose.json in the layout of the shared goldens
(golden/upper_body_portrait_pose.json): solution, image, w, h, modelComplexity, options,
landmarks_px (33 x [x px, y px, z px (z times the width), visibility]) and world
(33 x [x, y, z m, visibility]); both lists are empty when MediaPipe finds no person.
Needs only Python's standard library and chromium. Exit 77 without chromium or the fetched
package (like the project's skipped tests), 1 on any failure."""

import argparse
import http.server
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
TYPES = {".js": "text/javascript", ".wasm": "application/wasm", ".html": "text/html",
         ".json": "application/json", ".png": "image/png", ".jpg": "image/jpeg",
         ".jpeg": "image/jpeg"}


def find_chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


class State:
    def __init__(self, job, images, mp_dir):
        self.job = job
        self.images = images
        self.mp_dir = mp_dir
        self.results = {}
        self.errors = []
        self.done = threading.Event()


def make_handler(state):
    class Handler(http.server.BaseHTTPRequestHandler):
        def log_message(self, *args):
            pass

        def _send(self, code, body, ctype="application/octet-stream"):
            self.send_response(code)
            self.send_header("Content-Type", ctype)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

        def _file(self, base, rel):
            path = os.path.realpath(os.path.join(base, rel))
            if not path.startswith(os.path.realpath(base) + os.sep) or not os.path.isfile(path):
                return self._send(404, b"not found", "text/plain")
            with open(path, "rb") as f:
                body = f.read()
            self._send(200, body, TYPES.get(os.path.splitext(path)[1].lower(),
                                            "application/octet-stream"))

        def do_GET(self):
            p = self.path.split("?", 1)[0]
            if p == "/job":
                return self._send(200, json.dumps(state.job).encode(), "application/json")
            if p.startswith("/mp/"):
                return self._file(state.mp_dir, p[4:])
            if p.startswith("/page/"):
                return self._file(HERE, p[6:])
            if p.startswith("/img/"):
                try:
                    path = state.images[int(p[5:])]
                except (ValueError, IndexError):
                    return self._send(404, b"not found", "text/plain")
                with open(path, "rb") as f:
                    body = f.read()
                return self._send(200, body, TYPES.get(os.path.splitext(path)[1].lower(),
                                                       "application/octet-stream"))
            return self._send(404, b"not found", "text/plain")

        def do_POST(self):
            n = int(self.headers.get("Content-Length", "0"))
            body = json.loads(self.rfile.read(n) or b"{}")
            if self.path == "/result":
                state.results[body["index"]] = body
            elif self.path == "/error":
                state.errors.append(body.get("message", "?"))
                state.done.set()
            elif self.path == "/done":
                state.done.set()
            self._send(200, b"{}", "application/json")

    return Handler


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("images", nargs="+")
    ap.add_argument("-o", "--out", required=True, help="output folder")
    ap.add_argument("--model-complexity", type=int, default=1, choices=(0, 1, 2))
    ap.add_argument("--min-detection-confidence", type=float, default=0.5)
    ap.add_argument("--min-tracking-confidence", type=float, default=0.5)
    ap.add_argument("--relative-to", default=None,
                    help="write the 'image' field relative to this folder")
    ap.add_argument("--reuse", action="store_true",
                    help="one Pose object, reset() between images, instead of a new one each")
    ap.add_argument("--timeout", type=float, default=None,
                    help="seconds for all images (default 60 + 40 per image)")
    ap.add_argument("--mp-dir", default=os.environ.get(
        "AVATARMAP_MEDIAPIPE_WEB", os.path.join(ROOT, ".cache", "avatarmap", "mediapipe_web")))
    args = ap.parse_args()

    if args.timeout is None:
        args.timeout = 60.0 + 40.0 * len(args.images)
    chromium = find_chromium()
    if not chromium:
        print("reference.py: chromium is missing", file=sys.stderr)
        return 77
    if not os.path.isfile(os.path.join(args.mp_dir, "pose", "pose.js")):
        print(f"reference.py: no @mediapipe/pose in {args.mp_dir}: run "
              "scripts/fetch_mediapipe_web.sh", file=sys.stderr)
        return 77
    images = [os.path.abspath(p) for p in args.images]
    for p in images:
        if not os.path.isfile(p):
            print(f"reference.py: no image {p}", file=sys.stderr)
            return 1
    with open(os.path.join(args.mp_dir, "VERSION")) as f:
        version = f.read().strip()

    job = {"modelComplexity": args.model_complexity, "fresh": not args.reuse,
           "minDetectionConfidence": args.min_detection_confidence,
           "minTrackingConfidence": args.min_tracking_confidence,
           "images": [{"url": f"/img/{i}", "name": os.path.basename(p)}
                      for i, p in enumerate(images)]}
    state = State(job, images, args.mp_dir)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), make_handler(state))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    port = server.server_address[1]

    profile = tempfile.mkdtemp(prefix="avatarmap-mpweb-")
    cmd = [chromium, "--headless", "--no-sandbox", "--use-angle=swiftshader",
           "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist", "--no-first-run",
           "--no-default-browser-check", "--disable-background-timer-throttling",
           "--disable-renderer-backgrounding", "--window-size=800,600",
           "--remote-debugging-port=0", f"--user-data-dir={profile}",
           f"http://127.0.0.1:{port}/page/pose.html"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    t0 = time.monotonic()
    try:
        finished = state.done.wait(args.timeout)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGTERM)
            proc.wait(10)
        except (ProcessLookupError, subprocess.TimeoutExpired):
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            proc.wait()
        server.shutdown()
        shutil.rmtree(profile, ignore_errors=True)
    if state.errors:
        print("reference.py: the page failed: " + " | ".join(state.errors), file=sys.stderr)
        return 1
    if not finished or len(state.results) != len(images):
        print(f"reference.py: {len(state.results)} of {len(images)} images after "
              f"{args.timeout:.0f} s", file=sys.stderr)
        return 1

    os.makedirs(args.out, exist_ok=True)
    for i, path in enumerate(images):
        r = state.results[i]
        w, h = r["w"], r["h"]
        name = os.path.relpath(path, args.relative_to) if args.relative_to else path
        out = {"solution": "pose", "image": name, "w": w, "h": h,
               "modelComplexity": args.model_complexity,
               "options": {"sol": "pose", "mc": str(args.model_complexity), "img": name},
               "landmarks_px": [[x * w, y * h, z * w, v] for x, y, z, v in r["landmarks"]],
               "world": r["world"],
               "generator": {"package": version, "browser": os.path.basename(chromium),
                             "static_image_mode": True, "fresh_graph": not args.reuse}}
        stem = os.path.splitext(os.path.basename(path))[0]
        with open(os.path.join(args.out, f"{stem}_pose.json"), "w") as f:
            json.dump(out, f)
        print(f"{stem}: {len(r['landmarks'])} landmarks ({w}x{h})")
    print(f"reference.py: {len(images)} images in {time.monotonic() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
