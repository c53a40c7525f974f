#!/usr/bin/env python3
"""The rendered benchmark (docs/world-benchmark-rendered.md): a known motion played on an avatar
with a face, rendered by the browser viewer's render mode with a known camera, encoded as an
.mp4, captured and solved by `avatarmap animate` with its defaults (no field of view given),
then scored by the project's scorers.

    render_benchmark.py --truth MOTION --out DIR [--avatar AVATAR.vrm] [--cameras c0,c2 | FILE.json]
                        [--seconds 8] [--size 640x360] [--exe avatarmap] [--eval-exe avatarmap]
                        [--compare 4] [--skip-capture]

MOTION: a *.pose.jsonl, a .vrma or a .bvh (the last two converted to poses by `avatarmap
convert`; a .bvh needs a build that reads BVH motion). The truth is resampled to 30 fps
(`convert --fps 30`) and frame i of the video shows truth frame i. Per camera DIR/CAMERA/ holds:
video.mp4, camera.json (the truth camera, in the avatar's world and in the performer's metres),
truth.pose.jsonl (the frames shown, as rendered), truth_camera.pose.jsonl (the same turned by
-azimuth about +Y: the heading the solver reports in; what the scorers get), landmarks.jsonl and
solved.pose.jsonl (`animate`'s),
eval-world.txt / eval-pose.txt (the scorers' raw outputs) and, with --compare N, N PNGs
compare_*.png: the truth (left) and the solved poses (right) rendered with the same camera.
Prints a table (camera, seconds to render, to capture and solve, the scorers' headline figures)
and writes DIR/summary.json. Needs chromium, ffmpeg, Pillow (for --compare) and the viewer's
modules.
"""

import argparse
import base64
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "viewer"))
import cdp  # noqa: E402

FPS = 30

# The fixed cameras (documented in docs/world-benchmark-rendered.md): height of the camera above
# the floor (m), pitch (degrees, + looks up), horizontal distance to the motion's centre (m),
# horizontal field of view (degrees), azimuth around the centre (degrees; 0 = on the +Z side,
# in front of an avatar that faces +Z; + toward +X), roll (degrees, + turns the camera
# counterclockwise). Each keeps a standing person of 1.6-1.9 m whole in a 16:9 frame.
CAMERAS = {
    "c0": dict(height=1.0, pitch=-5, distance=3.5, hfov=60, azimuth=0, roll=0),
    "c1": dict(height=1.6, pitch=-15, distance=3.0, hfov=70, azimuth=20, roll=0),
    "c2": dict(height=0.8, pitch=5, distance=4.5, hfov=55, azimuth=-30, roll=0),
    "c3": dict(height=1.8, pitch=-20, distance=2.5, hfov=80, azimuth=0, roll=0),
    "c4": dict(height=0.7, pitch=10, distance=3.5, hfov=80, azimuth=45, roll=0),
    "c5": dict(height=1.2, pitch=-3, distance=4.5, hfov=48, azimuth=-10, roll=3),
    "c6": dict(height=1.4, pitch=-10, distance=4.0, hfov=65, azimuth=90, roll=0),
    "c7": dict(height=0.9, pitch=0, distance=4.5, hfov=50, azimuth=-100, roll=-2),
}


def log(*args):
    print(*args, file=sys.stderr, flush=True)


def run(args, **kw):
    return subprocess.run(args, text=True, capture_output=True, **kw)


# ---- poses ------------------------------------------------------------------------------------
def read_poses(path):
    header, poses = None, []
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line:
                continue
            obj = json.loads(line)
            if "format" in obj and "t" not in obj:
                header = obj
            else:
                poses.append(obj)
    return header, poses


def percentile90(values):
    values = sorted(values)
    return values[min(len(values) - 1, int(math.ceil(0.9 * len(values))) - 1)] if values else 0.0


def standing_hips(poses):
    """The performer's standing hips height as retarget_clip_job takes it: the 90th percentile
    of the clip's hips heights."""
    return percentile90([p["hips_position"][1] for p in poses if "hips_position" in p])


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz]


def turned(pose, yaw_deg, offset, scale):
    """The pose turned by yaw about +Y, its hips moved by offset after scaling by scale."""
    p = dict(pose)
    a = math.radians(yaw_deg)
    q = [0.0, math.sin(a / 2), 0.0, math.cos(a / 2)]
    bones = dict(p.get("bones", {}))
    bones["hips"] = quat_mul(q, bones.get("hips", [0, 0, 0, 1]))
    p["bones"] = bones
    x, y, z = p["hips_position"]
    c, s = math.cos(a), math.sin(a)
    x, z = c * x + s * z, -s * x + c * z
    p["hips_position"] = [x * scale + offset[0], y * scale, z * scale + offset[2]]
    return p


# ---- cameras ----------------------------------------------------------------------------------
def place_camera(spec, centre, width, height):
    """The camera of spec around centre (x, z in the avatar's world): position, yaw, pitch,
    roll, fovs and the focal length in pixels (square pixels)."""
    az = math.radians(spec["azimuth"])
    pos = [centre[0] + spec["distance"] * math.sin(az), spec["height"],
           centre[1] + spec["distance"] * math.cos(az)]
    hfov = spec["hfov"]
    vfov = math.degrees(2 * math.atan(math.tan(math.radians(hfov) / 2) * height / width))
    focal = width / 2 / math.tan(math.radians(hfov) / 2)
    return dict(position=pos, yaw=spec["azimuth"], pitch=spec["pitch"], roll=spec.get("roll", 0),
                hfov=hfov, vfov=vfov, focal_pixels=focal, width=width, height=height)


def project(cam, point):
    """Pixel (u right, v down) of a world point, or None behind the camera: the camera of the
    viewer's render mode (rotation Y(yaw) X(pitch) Z(roll), looking along its -Z)."""
    yaw, pitch, roll = (math.radians(cam[k]) for k in ("yaw", "pitch", "roll"))
    d = [point[i] - cam["position"][i] for i in range(3)]
    # world -> camera: undo yaw (about Y), then pitch (about X), then roll (about Z)
    c, s = math.cos(yaw), math.sin(yaw)
    x, y, z = c * d[0] - s * d[2], d[1], s * d[0] + c * d[2]
    c, s = math.cos(pitch), math.sin(pitch)
    x, y, z = x, c * y + s * z, -s * y + c * z
    c, s = math.cos(roll), math.sin(roll)
    x, y = c * x + s * y, -s * x + c * y
    if z >= -1e-6:
        return None
    f = cam["focal_pixels"]
    return (cam["width"] / 2 + f * x / -z, cam["height"] / 2 - f * y / -z)


def in_frame_fraction(cam, poses, scale, standing):
    """Fraction of frames whose hips, head top (hips + 0.95 x standing hips height) and feet
    (the floor below the hips) all project inside the image."""
    inside = 0
    for p in poses:
        x, y, z = (v * scale for v in p["hips_position"])
        points = [(x, y, z), (x, y + 0.95 * standing * scale, z), (x, 0.0, z)]
        uv = [project(cam, q) for q in points]
        if all(q and 0 <= q[0] < cam["width"] and 0 <= q[1] < cam["height"] for q in uv):
            inside += 1
    return inside / max(1, len(poses))


# ---- the viewer -------------------------------------------------------------------------------
class Viewer:
    def __init__(self, exe, avatar, workdir):
        args = [exe, "view", "--port", "0", "--quiet"] + (["--avatar", avatar] if avatar else [])
        self.log = open(os.path.join(workdir, "view.log"), "w")
        self.process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=self.log, text=True,
                                        cwd=ROOT)
        self.url = self.process.stdout.readline().strip()
        if not self.url:
            self.process.wait()
            raise RuntimeError("avatarmap view did not start: " +
                               open(os.path.join(workdir, "view.log")).read())

    def stop(self):
        self.process.send_signal(signal.SIGINT)
        try:
            self.process.wait(20)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self.log.close()


class Page:
    """One render-mode page in headless Chromium, its viewport exactly the canvas."""

    def __init__(self, browser, url, cam, performer_hips, extra=""):
        self.b = browser
        self.w, self.h = cam["width"], cam["height"]
        self.b.call("Emulation.setDeviceMetricsOverride", width=self.w, height=self.h,
                    deviceScaleFactor=1, mobile=False)
        position = ",".join("%.6f" % v for v in cam["position"])
        query = (f"?render=1&w={self.w}&h={self.h}&cam={position}"
                 f"&yaw={cam['yaw']}&pitch={cam['pitch']}&roll={cam['roll']}&hfov={cam['hfov']}"
                 f"&performerHips={performer_hips:.6f}{extra}")
        self.b.navigate(url + query)
        deadline = time.monotonic() + 30
        while not self.b.evaluate("!!(window.avatarmapViewer && window.avatarmapViewer.ready)"):
            if time.monotonic() > deadline:
                raise TimeoutError(f"the render-mode page did not start: {self.b.exceptions[-3:]}")
            time.sleep(0.05)
        self.state = self.eval_async("window.avatarmapViewer.ready()")

    def eval_async(self, expression):
        r = self.b.call("Runtime.evaluate", expression=expression, awaitPromise=True,
                        returnByValue=True)
        if "exceptionDetails" in r:
            raise RuntimeError(f"{expression[:60]}: {json.dumps(r['exceptionDetails'])[:400]}")
        return r["result"].get("value")

    def pose(self, pose):
        return self.eval_async(f"window.avatarmapViewer.renderPose({json.dumps(pose)})")

    def png(self):
        data = self.b.call("Page.captureScreenshot", format="png",
                           clip=dict(x=0, y=0, width=self.w, height=self.h, scale=1))["data"]
        return base64.b64decode(data)


# ---- one camera -------------------------------------------------------------------------------
def render_video(page, poses, path):
    ffmpeg = subprocess.Popen(["ffmpeg", "-loglevel", "error", "-y", "-f", "image2pipe",
                               "-framerate", str(FPS), "-c:v", "png", "-i", "-", "-c:v", "libx264",
                               "-preset", "veryfast", "-crf", "18", "-pix_fmt", "yuv420p", path],
                              stdin=subprocess.PIPE)
    for p in poses:
        page.pose(p)
        ffmpeg.stdin.write(page.png())
    ffmpeg.stdin.close()
    if ffmpeg.wait() != 0:
        raise RuntimeError("ffmpeg failed")


def headline(name, text):
    """The headline numbers a scorer printed as JSON: eval-pose's means over all bones by part
    (degrees); eval-world's numbers up to two levels deep. None when it printed no JSON."""
    try:
        obj = json.loads(text)
    except ValueError:
        return None
    flat = {}

    def walk(prefix, v, depth):
        if isinstance(v, dict) and depth < 2:
            for k, w in v.items():
                walk(f"{prefix}.{k}" if prefix else k, w, depth + 1)
        elif isinstance(v, (int, float)) and not isinstance(v, bool):
            flat[prefix] = v
    if name == "eval-pose":
        flat = {k: v["mean"] for k, v in obj.get("all", {}).items() if "mean" in v}
    else:
        walk("", obj, 0)
    return flat


def score(args, truth_path, solved_path, camdir):
    results = {}
    # eval-world reads a BVH truth and samples it at the solved times, which start at 0: the
    # BVH itself only when the video starts at its first frame.
    eval_truth = truth_path
    if args.truth.lower().endswith(".bvh"):
        eval_truth = args.truth
        if args.start != 0:
            log("warning: --start is not 0: eval-world samples the BVH from its first frame")
    for name, exe, cmd in (("eval-world", args.eval_exe, [eval_truth, solved_path, "--json"]),
                           ("eval-pose", args.exe, [truth_path, solved_path, "--json"])):
        r = run([exe, name, *cmd])
        text = (r.stdout + r.stderr).strip()
        with open(os.path.join(camdir, f"{name}.txt"), "w") as f:
            f.write(f"$ {exe} {name} {' '.join(cmd)}\n(exit {r.returncode})\n{text}\n")
        results[name] = dict(exit=r.returncode, output=text[-4000:],
                             figures=headline(name, r.stdout) if r.returncode == 0 else None)
    return results


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--truth", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--avatar", default="", help="a .vrm (default: the built-in avatar)")
    ap.add_argument("--cameras", default="c0,c1,c2,c3",
                    help="names from the fixed list (" + ",".join(CAMERAS) + ") or a .json list")
    ap.add_argument("--seconds", type=float, default=8.0)
    ap.add_argument("--start", type=float, default=0.0, help="first truth second shown")
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--exe", default=os.environ.get("AVATARMAP_EXE", "avatarmap"))
    ap.add_argument("--eval-exe", default=None,
                    help="the avatarmap with eval-world (default --exe)")
    ap.add_argument("--compare", type=int, default=0, help="side-by-side PNGs per camera")
    ap.add_argument("--skip-capture", action="store_true", help="render only")
    args = ap.parse_args()
    args.eval_exe = args.eval_exe or args.exe
    width, height = (int(v) for v in args.size.lower().split("x"))
    os.makedirs(args.out, exist_ok=True)
    for tool in ("ffmpeg",):
        if not shutil.which(tool):
            sys.exit(f"{tool} is missing")
    if not cdp.find_chromium():
        sys.exit("chromium is missing")
    if args.compare > 0:
        try:
            import PIL  # noqa: F401
        except ImportError:
            sys.exit("--compare needs Pillow (Debian: python3-pil; run this with /usr/bin/python3)")

    if args.cameras.endswith(".json"):
        cameras = json.load(open(args.cameras))
    else:
        unknown = [k for k in args.cameras.split(",") if k not in CAMERAS]
        if unknown:
            sys.exit(f"unknown camera {unknown[0]}: the fixed ones are {', '.join(CAMERAS)}")
        cameras = {k: CAMERAS[k] for k in args.cameras.split(",")}

    # The truth at 30 fps, the span shown.
    truth30 = os.path.join(args.out, "truth30.pose.jsonl")
    r = run([args.exe, "convert", args.truth, "-o", truth30, "--fps", str(FPS), "--quiet"])
    if r.returncode != 0:
        sys.exit(f"could not read the truth {args.truth}: {r.stderr.strip()}")
    header, poses = read_poses(truth30)
    first = int(round(args.start * FPS))
    shown = poses[first:first + int(round(args.seconds * FPS))]
    if not shown:
        sys.exit("the truth has no frames in the span asked for")
    t0 = shown[0]["t"]
    standing = standing_hips(poses)
    viewer = Viewer(args.exe, args.avatar, args.out)
    browser = cdp.Browser(width, height)
    summary = []
    try:
        for name, spec in cameras.items():
            camdir = os.path.join(args.out, name)
            os.makedirs(camdir, exist_ok=True)
            # The truth in the frames shown, its clock starting at 0 (the video's): as rendered
            # (truth.pose.jsonl) and turned by -azimuth about +Y (truth_camera.pose.jsonl), the
            # heading the solver reports in (the performer seen from the front faces +Z).
            truth_path = os.path.join(camdir, "truth.pose.jsonl")
            truth_camera_path = os.path.join(camdir, "truth_camera.pose.jsonl")
            for path, yaw in ((truth_path, 0), (truth_camera_path, -spec["azimuth"])):
                with open(path, "w") as f:
                    f.write(json.dumps(header or {"format": "avatarmap.pose", "version": 1,
                                                  "fps": FPS}, separators=(",", ":")) + "\n")
                    for p in shown:
                        q = turned(p, yaw, (0, 0, 0), 1.0) if yaw else dict(p)
                        q["t"] = round(p["t"] - t0, 6)
                        f.write(json.dumps(q, separators=(",", ":")) + "\n")
            row = dict(camera=name, spec=spec, frames=len(shown))
            started = time.monotonic()
            probe = Page(browser, viewer.url, place_camera(spec, (0, 0), width, height), standing)
            # hipsScale (the avatar's rest hips height over standing) is set by the first pose
            first_state = probe.pose(shown[0])
            scale = first_state["hipsScale"]
            xs = [p["hips_position"][0] * scale for p in shown]
            zs = [p["hips_position"][2] * scale for p in shown]
            centre = ((min(xs) + max(xs)) / 2, (min(zs) + max(zs)) / 2)
            cam = place_camera(spec, centre, width, height)
            page = Page(browser, viewer.url, cam, standing)
            render_video(page, shown, os.path.join(camdir, "video.mp4"))
            row["render_s"] = round(time.monotonic() - started, 1)
            row["in_frame"] = round(in_frame_fraction(cam, shown, scale, standing), 3)
            sidecar = dict(
                truth=os.path.abspath(args.truth), truth_start_s=t0, fps=FPS, frames=len(shown),
                avatar=args.avatar or "built-in",
                avatar_rest_hips_m=first_state["hipsScale"] * standing,
                performer_standing_hips_m=standing, avatar_per_performer_metre=scale,
                camera_avatar_world=cam,
                camera_performer_metres=dict(cam, position=[v / scale for v in cam["position"]]),
                convention=("Y up, floor Y = 0, the avatar faces +Z; the camera looks along -Z, "
                            "rotation Y(yaw) X(pitch) Z(roll); yaw 0 looks along -Z; pitch + up; "
                            "hfov horizontal; pixels u right, v down, square"),
                page_camera=page.state["camera"])
            with open(os.path.join(camdir, "camera.json"), "w") as f:
                json.dump(sidecar, f, indent=1)
            log(f"{name}: rendered {len(shown)} frames in {row['render_s']} s "
                f"(in frame {row['in_frame']:.0%})")
            if not args.skip_capture:
                started = time.monotonic()
                solved_path = os.path.join(camdir, "solved.pose.jsonl")
                r = run([args.exe, "animate", os.path.join(camdir, "video.mp4"), "-o", solved_path,
                         "--keep-landmarks", os.path.join(camdir, "landmarks.jsonl"), "--quiet"])
                row["capture_s"] = round(time.monotonic() - started, 1)
                if r.returncode != 0:
                    row["error"] = r.stderr.strip()[-500:]
                    log(f"{name}: animate failed: {row['error']}")
                else:
                    row["scores"] = score(args, truth_camera_path, solved_path, camdir)
                    log(f"{name}: captured and solved in {row['capture_s']} s")
                    if args.compare > 0:
                        _, solved = read_poses(solved_path)
                        k = standing / max(1e-6, standing_hips(solved))
                        s0 = turned(solved[0], spec["azimuth"], (0, 0, 0), k)["hips_position"]
                        h0 = shown[0]["hips_position"]
                        off = (h0[0] - s0[0], 0, h0[2] - s0[2])
                        placed = [turned(p, spec["azimuth"], off, k) for p in solved]
                        row["compare"] = compare_frames(browser, viewer.url, cam, standing, shown,
                                                        placed, args.compare, camdir)
            summary.append(row)
    finally:
        browser.quit()
        viewer.stop()
    with open(os.path.join(args.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
    print_table(summary)


def compare_frames(browser, url, cam, standing, truth, placed, count, camdir):
    from PIL import Image
    import io
    n = min(len(truth), len(placed))
    picks = [int((k + 0.5) * n / count) for k in range(count)]
    shots = {}
    for label, poses in (("truth", truth), ("solved", placed)):
        page = Page(browser, url, cam, standing)
        for i in picks:
            page.pose(poses[max(0, i - 1)])  # a frame before, so spring bones settle alike
            page.pose(poses[i])
            shots[(label, i)] = Image.open(io.BytesIO(page.png())).convert("RGB")
    paths = []
    for i in picks:
        a, b = shots[("truth", i)], shots[("solved", i)]
        both = Image.new("RGB", (a.width * 2 + 4, a.height), (255, 255, 255))
        both.paste(a, (0, 0))
        both.paste(b, (a.width + 4, 0))
        path = os.path.join(camdir, f"compare_{i:04d}.png")
        both.save(path)
        paths.append(path)
    return paths


def print_table(summary):
    keys = []
    for row in summary:
        for name in ("eval-world", "eval-pose"):
            figs = (row.get("scores", {}).get(name) or {}).get("figures") or {}
            keys += [f"{name}:{k}" for k in figs if f"{name}:{k}" not in keys]
    print("| camera | h m | pitch | dist m | hfov | az | frames | in frame | render s "
          "| capture+solve s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for row in summary:
        s = row["spec"]
        print(f"| {row['camera']} | {s['height']} | {s['pitch']} | {s['distance']} | {s['hfov']} | "
              f"{s['azimuth']} | {row['frames']} | {row['in_frame']:.0%} | {row['render_s']} | "
              f"{row.get('capture_s', '-')} |")
    for row in summary:
        for name in ("eval-world", "eval-pose"):
            sc = row.get("scores", {}).get(name)
            if sc is None:
                continue
            figs = sc.get("figures")
            if figs:
                text = ", ".join(f"{k} {v:.4g}" for k, v in figs.items())
            else:
                first_line = sc["output"].splitlines()[0][:160] if sc["output"] else ""
                text = f"exit {sc['exit']}: {first_line}"
            print(f"{row['camera']} {name}: {text}")
        if "error" in row:
            print(f"{row['camera']} animate failed: {row['error']}")


if __name__ == "__main__":
    main()
