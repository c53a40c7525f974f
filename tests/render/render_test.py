#!/usr/bin/env python3
"""`avatarmap render` end to end (docs/render.md): a short pose file of the built-in avatar
(the synthetic recording's true poses) rendered to an MP4, decoded back by ffmpeg and checked:
frame count, size and rate; frames that differ as the pose moves; the still PNG equal to its
frame; that frame equal (within the encoder's loss) to the viewer's own rendering of the same
pose with the same camera, taken by tests/viewer/cdp.py from `avatarmap view`'s page; a .vrma
and an animated .glb rendered; the source video beside the avatar. Hostile inputs fail with a
clear message, a non-zero status and no output, and no browser or profile is left behind.

Usage: render_test.py AVATARMAP_EXE WORKDIR. Exits 77 (skipped) without chromium, ffmpeg,
Pillow or the viewer's modules."""

import json
import os
import re
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tests", "viewer"))
import cdp  # noqa: E402

W, H, FPS = 320, 180, 10


def skip(why):
    print(f"SKIP: {why}")
    sys.exit(77)


def run(exe, args, env=None, **kw):
    return subprocess.run([exe] + args, text=True, capture_output=True, env=env, cwd=ROOT, **kw)


def frames_of(path, w, h):
    """Every frame of a video as RGB bytes (ffmpeg), and ffprobe's rate and count."""
    probe = subprocess.run(["ffprobe", "-v", "error", "-select_streams", "v:0", "-count_frames",
                            "-show_entries", "stream=width,height,r_frame_rate,nb_read_frames",
                            "-of", "json", path], text=True, capture_output=True, check=True)
    stream = json.loads(probe.stdout)["streams"][0]
    raw = subprocess.run(["ffmpeg", "-v", "error", "-i", path, "-f", "rawvideo", "-pix_fmt",
                          "rgb24", "-"], capture_output=True, check=True).stdout
    size = w * h * 3
    return stream, [raw[i:i + size] for i in range(0, len(raw), size)]


def mean_abs(a, b):
    assert len(a) == len(b), (len(a), len(b))
    return sum(abs(x - y) for x, y in zip(a, b)) / len(a)


def fraction_over(a, b, limit):
    return sum(1 for x, y in zip(a, b) if abs(x - y) > limit) / len(a)


def check(cond, what):
    if not cond:
        print(f"FAIL: {what}")
        sys.exit(1)
    print(f"ok: {what}")


def main():
    exe, work = sys.argv[1], sys.argv[2]
    if not cdp.find_chromium():
        skip("chromium not found (sudo apt-get install chromium)")
    if not shutil.which("ffmpeg") or not shutil.which("ffprobe"):
        skip("ffmpeg/ffprobe not found")
    try:
        from PIL import Image
    except ImportError:
        skip("Pillow not found (python3-pil)")
    backends = run(exe, ["backends"])
    if re.search(r"viewer modules.*(not found|missing)", backends.stdout + backends.stderr, re.I):
        skip("the viewer's modules are missing (scripts/fetch_viewer_modules.sh)")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    tmp = os.path.join(work, "tmp")  # the browser's profiles go here: must end up empty
    os.makedirs(tmp)
    env = dict(os.environ, TMPDIR=tmp)

    def no_leftovers(what):
        check(os.listdir(tmp) == [], f"{what}: no browser profile left ({os.listdir(tmp)})")
        ps = subprocess.run(["ps", "-eo", "args"], text=True, capture_output=True).stdout
        check(tmp not in ps, f"{what}: no browser process left")

    # A 1-s pose file of the demo motion at 10 fps (squats, waving: the pose moves).
    poses = os.path.join(work, "motion.pose.jsonl")
    r = run(exe, ["synth", "-o", os.path.join(work, "motion.landmarks.jsonl"), "--truth", poses,
                  "--seconds", "1", "--fps", str(FPS)])
    check(r.returncode == 0, f"synth: {r.stderr[-300:]}")
    lines = [json.loads(x) for x in open(poses) if x.strip()]
    body = [x for x in lines if "t" in x]

    out = os.path.join(work, "out.mp4")
    r = run(exe, ["render", poses, "-o", out, "--size", f"{W}x{H}", "--stills", "0.5"], env=env,
            timeout=300)
    print(r.stderr[-800:])
    check(r.returncode == 0, "render a pose file")
    no_leftovers("pose file")
    stream, frames = frames_of(out, W, H)
    check(stream["width"] == W and stream["height"] == H, f"size {stream['width']}x{stream['height']}")
    check(stream["r_frame_rate"] == f"{FPS}/1", f"rate {stream['r_frame_rate']} (the file's own)")
    check(int(stream["nb_read_frames"]) == len(body) == len(frames) == 10,
          f"{len(frames)} frames for {len(body)} poses (0 .. 0.9 s)")
    moved = mean_abs(frames[0], frames[-1])
    check(moved > 1.0, f"frames differ as the pose moves (mean |diff| {moved:.2f})")

    still_path = os.path.join(work, "out_t0.5.png")
    check(os.path.exists(still_path), "the still out_t0.5.png exists")
    still = Image.open(still_path).convert("RGB")
    check(still.size == (W, H), "the still's size")
    d = mean_abs(still.tobytes(), frames[5])
    check(d < 3.0, f"the still is frame 5 (mean |diff| {d:.2f} after H.264)")
    d_other = min(mean_abs(still.tobytes(), f) for k, f in enumerate(frames) if k != 5)
    check(d_other > 1.2 * d, f"and no other frame (the nearest: {d_other:.2f})")

    # The viewer's own rendering of the same pose with the same camera.
    m = re.search(r"render-mode page for this camera: \?(\S+)", r.stderr)
    check(m is not None, "render prints the viewer's render-mode query")
    view = subprocess.Popen([exe, "view", "--port", "0", "--quiet"], stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True, cwd=ROOT)
    browser = None
    try:
        url = view.stdout.readline().strip()
        browser = cdp.Browser(W, H)
        browser.call("Emulation.setDeviceMetricsOverride", width=W, height=H,
                     deviceScaleFactor=1, mobile=False)
        browser.navigate(url + "?" + m.group(1))
        deadline = time.monotonic() + 60
        while not browser.evaluate("!!(window.avatarmapViewer && window.avatarmapViewer.ready)"):
            check(time.monotonic() < deadline, "the viewer's render-mode page starts")
            time.sleep(0.05)
        res = browser.call("Runtime.evaluate", expression="window.avatarmapViewer.ready().then("
                           "() => window.avatarmapViewer.renderPose(" + json.dumps(body[5]) +
                           ")).then(() => 0)", awaitPromise=True, returnByValue=True)
        check("exceptionDetails" not in res, f"renderPose in the viewer {res}")
        import base64
        png = base64.b64decode(browser.call("Page.captureScreenshot", format="png", clip=dict(
            x=0, y=0, width=W, height=H, scale=1))["data"])
        ref_path = os.path.join(work, "viewer_t0.5.png")
        open(ref_path, "wb").write(png)
        ref = Image.open(ref_path).convert("RGB").tobytes()
    finally:
        if browser:
            browser.quit()
        view.terminate()
        view.wait(20)
    d = mean_abs(ref, still.tobytes())
    check(d < 1.0, f"the still matches the viewer's own frame (mean |diff| {d:.3f})")
    check(fraction_over(ref, still.tobytes(), 24) < 0.002, "and nearly every pixel within 24")
    d = mean_abs(ref, frames[5])
    check(d < 3.0, f"the video's frame 5 matches the viewer's (mean |diff| {d:.2f})")

    # A .vrma and an animated .glb of the same motion.
    vrma = os.path.join(work, "motion.vrma")
    check(run(exe, ["convert", poses, "-o", vrma]).returncode == 0, "convert to .vrma")
    out_vrma = os.path.join(work, "vrma.mp4")
    r = run(exe, ["render", vrma, "-o", out_vrma, "--size", f"{W}x{H}", "--quiet"], env=env,
            timeout=300)
    check(r.returncode == 0 and r.stderr == "", f"render a .vrma quietly {r.stderr[-300:]}")
    stream, frames_v = frames_of(out_vrma, W, H)
    span = body[-1]["t"] - body[0]["t"]  # 0.9 s of keys: frames 0 .. 27 at 30 fps
    check(stream["r_frame_rate"] == "30/1" and len(frames_v) == int(span * 30 + 1e-3) + 1,
          f"a clip at 30 fps: {len(frames_v)} frames")
    check(mean_abs(frames_v[0], frames_v[-1]) > 1.0, "the .vrma moves")
    glb = os.path.join(work, "motion.glb")
    r = run(exe, ["convert", poses, "-o", glb])
    check(r.returncode == 0, f"convert to .glb {r.stderr[-300:]}")
    out_glb = os.path.join(work, "glb.mp4")
    r = run(exe, ["render", glb, "-o", out_glb, "--size", f"{W}x{H}", "--quiet"], env=env,
            timeout=300)
    check(r.returncode == 0, f"render an animated .glb {r.stderr[-300:]}")
    _, frames_g = frames_of(out_glb, W, H)
    check(len(frames_g) == len(frames_v), f"the .glb: {len(frames_g)} frames")
    moved = max(mean_abs(frames_g[0], f) for f in frames_g)
    check(moved > 1.0, f"the .glb moves (mean |diff| up to {moved:.2f})")
    # The same motion on the same avatar: the .glb's own animation and the .vrma's poses look
    # alike frame by frame (retargeted joint rotations vs proxy poses; cameras framed alike).
    alike = max(mean_abs(frames_g[k], frames_v[k]) for k in range(len(frames_g)))
    check(alike < 2.0, f"the .glb's frames are the .vrma's (mean |diff| at most {alike:.2f})")
    no_leftovers(".vrma and .glb")

    # Beside a source video (a test pattern with the synthetic landmarks drawn on it).
    src = os.path.join(work, "source.mp4")
    subprocess.run(["ffmpeg", "-v", "error", "-f", "lavfi", "-i",
                    "color=c=0x204060:s=1280x720:r=10:d=1", "-pix_fmt", "yuv420p", src],
                   check=True)
    out_side = os.path.join(work, "side.mp4")
    r = run(exe, ["render", poses, "-o", out_side, "--size", f"{2 * W}x{H}", "--video", src,
                  "--landmarks", os.path.join(work, "motion.landmarks.jsonl"), "--quiet"],
            env=env, timeout=300)
    check(r.returncode == 0, f"render beside a video {r.stderr[-300:]}")
    stream, frames_s = frames_of(out_side, 2 * W, H)
    check(len(frames_s) == 10, "beside a video: 10 frames")
    right = b"".join(frames_s[5][y * 6 * W + 3 * W:(y + 1) * 6 * W] for y in range(H))
    check(mean_abs(right, frames[5]) < 3.0, "the right half is the avatar's frame")
    left = [frames_s[5][y * 6 * W + x * 3:y * 6 * W + x * 3 + 3] for y in range(H)
            for x in range(W)]
    blue = sum(1 for p in left if abs(p[0] - 0x20) < 12 and abs(p[2] - 0x60) < 12)
    check(blue > 0.3 * len(left), f"the left half is the source video ({blue} pixels)")
    drawn = sum(1 for p in left if p[0] > 200 and p[1] > 100)  # orange/white landmark lines
    check(drawn > 20, f"with its landmarks drawn ({drawn} pixels)")

    # Hostile inputs: a clear message, a non-zero status, no output.
    nan_poses = os.path.join(work, "nan.pose.jsonl")
    with open(nan_poses, "w") as f:
        for i, line in enumerate(open(poses)):
            f.write(line.replace('"hips_position":[', '"hips_position":[NaN,', 1)
                    if i == 3 else line)
    txt = os.path.join(work, "motion.txt")
    shutil.copy(poses, txt)
    for name, args, words in [
        ("a missing file", [os.path.join(work, "missing.vrma")], "no such file"),
        ("a .txt", [txt], "not an animation"),
        ("NaN in a pose file", [nan_poses], "nan"),
        ("a bad size", [poses, "--size", "12x9"], "size"),
        ("landmarks without a video", [poses, "--landmarks", poses], "video"),
    ]:
        bad_out = os.path.join(work, "bad.mp4")
        r = run(exe, ["render"] + args + ["-o", bad_out, "--stills", "0"], env=env, timeout=120)
        check(r.returncode != 0 and words in r.stderr.lower(),
              f"{name}: status {r.returncode}, {r.stderr.strip()[-200:]!r}")
        left = [x for x in os.listdir(work) if x.startswith("bad")]
        check(left == [], f"{name}: no output left ({left})")
    r = run(exe, ["render", poses, "-o", os.path.join(work, "bad.mp4")],
            env=dict(env, PATH="/nonexistent"), timeout=60)
    check(r.returncode != 0 and "apt-get install chromium" in r.stderr,
          f"no chromium: {r.stderr.strip()!r}")
    no_leftovers("hostile inputs")
    print("all render checks passed")


if __name__ == "__main__":
    main()
