"""The viewer's controls (docs/viewer.md) in Debian's headless Chromium.

    controls_test.py AVATARMAP WORKDIR

A 10 s recording (`synth` + `solve`: the right arm waves from 4.6 to 7.4 s) as a pose file, a
.vrma and an avatar .glb, and a CMU .bvh, played by `avatarmap view` pages driven through their
controls (the play button, Space, the timeline, the speed list, the loop box, the Open button's
file input). Checked against references read here, not through the page: a bone's rotation after
seeking to t is the .vrma's key at t (read from the file's glTF) or the pose file's pose at t;
time stands still while paused and runs while playing; 2x runs about twice as fast as 1x (a
ratio, generous tolerance); without loop the clip stops at its end; a .glb and a .pose.jsonl
opened through the file input play; an unknown file gets a message; `view x.glb` and `view
x.bvh` play (the .bvh's poses are `avatarmap convert x.bvh -o y.pose.jsonl`'s); `view x.txt`
exits 2 naming what it accepts; --video shows a <video> whose time follows the timeline; the
built-in avatar is labelled as such and served on every page load; the gaze of a .vrma we write
(its lookAt) turns the avatar's eyes as three-vrm's lookAt maps it. Exit 77 (skipped) without
chromium, the test data or the viewer's modules."""

import json
import os
import struct
import subprocess
import sys
import time
import urllib.request

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import cdp  # noqa: E402


from view_process import Checks, skip  # noqa: E402
import view_process  # noqa: E402

if len(sys.argv) != 3:
    sys.exit(__doc__)
EXE, WORK = sys.argv[1], sys.argv[2]
DATA = os.environ.get("AVATARMAP_TEST_DATA", "")
ROBOT = os.path.join(DATA, "avatars", "vrm1_debug_robot.vrm")
BVH = os.path.join(DATA, "motion", "cmu-bvh", "131_01.bvh")
VIDEO = os.path.join(DATA, "motion", "tfjs-models", "pose_squats.mp4")
if not DATA or not os.path.exists(ROBOT):
    skip("AVATARMAP_TEST_DATA is unset or lacks avatars/vrm1_debug_robot.vrm")
if not cdp.find_chromium():
    skip("chromium is missing (Debian: chromium; scripts/setup.sh installs it)")
os.makedirs(WORK, exist_ok=True)

check = Checks()
failures = check.failures


def run(*args):
    subprocess.run([EXE, *args], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def View(*args):
    return view_process.View(EXE, WORK, *args)


# ---- references read here -------------------------------------------------------------------
def read_poses(path):
    """The pose lines of a *.pose.jsonl (header left out)."""
    poses = []
    for line in open(path):
        value = json.loads(line) if line.strip() else {}
        if "t" in value:
            poses.append(value)
    return poses


def pose_at(poses, t):
    """The pose shown at t seconds from the first pose: the last whose time is <= t."""
    t0 = poses[0]["t"]
    best = poses[0]
    for p in poses:
        if p["t"] - t0 <= t + 1e-9:
            best = p
    return best


def vrma_keys(path, bone):
    """(times, [x, y, z, w] rotations) of `bone`'s rotation channel in a .vrma (GLB)."""
    blob = open(path, "rb").read()
    magic, _, length = struct.unpack_from("<4sII", blob, 0)
    assert magic == b"glTF", path
    offset, doc, binary = 12, None, None
    while offset < length:
        size, kind = struct.unpack_from("<II", blob, offset)
        chunk = blob[offset + 8:offset + 8 + size]
        if kind == 0x4E4F534A:
            doc = json.loads(chunk)
        elif kind == 0x004E4942:
            binary = chunk
        offset += 8 + size
    node = doc["extensions"]["VRMC_vrm_animation"]["humanoid"]["humanBones"][bone]["node"]

    def floats(accessor_index, width):
        accessor = doc["accessors"][accessor_index]
        view = doc["bufferViews"][accessor["bufferView"]]
        start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
        stride = view.get("byteStride", 4 * width)
        return [list(struct.unpack_from(f"<{width}f", binary, start + i * stride))
                for i in range(accessor["count"])]

    for animation in doc["animations"]:
        for channel in animation["channels"]:
            target = channel["target"]
            if target.get("node") == node and target["path"] == "rotation":
                sampler = animation["samplers"][channel["sampler"]]
                times = [v[0] for v in floats(sampler["input"], 1)]
                return times, floats(sampler["output"], 4)
    raise KeyError(f"{path}: no rotation channel for {bone}")


def same_rotation(a, b, tolerance=1e-4):
    if not a or not b:
        return False
    dot = abs(sum(x * y for x, y in zip(a, b)))
    return dot > 1 - tolerance


def angle_between(a, b):
    import math
    dot = min(1.0, abs(sum(x * y for x, y in zip(a, b))))
    return math.degrees(2 * math.acos(dot))


# ---- page helpers ---------------------------------------------------------------------------
def js(browser, expression):
    return browser.evaluate(expression)


def seek(browser, t):
    before = (browser.state() or {}).get("frames", 0)
    js(browser, f"(() => {{ const s = document.getElementById('timeline'); s.value = '{t}';"
                "s.dispatchEvent(new Event('input', {bubbles: true})); })()")
    time.sleep(0.15)
    # Two frames drawn after the seek, however slow the machine (a loaded CI machine once read
    # the eyes before the page had drawn the new time).
    browser.wait_for(lambda st: st.get("frames", 0) >= before + 2, 10, f"two frames after seek {t}")


def click(browser, element_id):
    js(browser, f"document.getElementById('{element_id}').click()")


def set_select(browser, element_id, value):
    js(browser, f"(() => {{ const e = document.getElementById('{element_id}'); e.value = '{value}';"
                "e.dispatchEvent(new Event('change', {bubbles: true})); })()")


def set_checkbox(browser, element_id, checked):
    js(browser, f"(() => {{ const e = document.getElementById('{element_id}');"
                f"e.checked = {'true' if checked else 'false'};"
                "e.dispatchEvent(new Event('change', {bubbles: true})); })()")


def press_space(browser):
    for kind in ("keyDown", "keyUp"):
        browser.call("Input.dispatchKeyEvent", type=kind, key=" ", code="Space",
                     windowsVirtualKeyCode=32, nativeVirtualKeyCode=32, text=" " if kind == "keyDown" else "")


def open_file(browser, path):
    """Gives `path` to the Open button's file input (DevTools DOM.setFileInputFiles)."""
    root = browser.call("DOM.getDocument")["root"]["nodeId"]
    node = browser.call("DOM.querySelector", nodeId=root, selector="#open-file")["nodeId"]
    browser.call("DOM.setFileInputFiles", files=[path], nodeId=node)


def clock(browser):
    """(clip time, page milliseconds) read together."""
    v = js(browser, "(() => { const s = window.avatarmapViewer.state();"
                    "return [s.clipTime, performance.now()]; })()")
    return v[0], v[1] / 1000.0


def rate(browser, seconds=1.5):
    """Clip seconds per page second over `seconds` of playing."""
    t0, w0 = clock(browser)
    time.sleep(seconds)
    t1, w1 = clock(browser)
    return (t1 - t0) / (w1 - w0)


def loaded(browser, url, kind, timeout=40):
    browser.navigate(url)
    return browser.wait_for(lambda s: s["avatar"] == "ready" and s["clipKind"] == kind
                            and s["frames"] > 5, timeout, f"a {kind} animation playing")


# ---- the cases --------------------------------------------------------------------------------
def check_controls(browser, url, clip_file, pose_file):
    """Play/pause, seeking, speed and loop on the page of `view wave.vrma`."""
    state = loaded(browser, url, "vrma")
    duration = state["clipDuration"]
    check(state["playing"] and abs(duration - 10) < 0.5,
          f"vrma: plays on its own, duration {duration:.2f} s")
    # Pause (button): time stands still.
    click(browser, "play")
    time.sleep(0.2)
    a = browser.state()
    time.sleep(0.6)
    b = browser.state()
    check(not a["playing"] and a["clipTime"] == b["clipTime"],
          f"paused (button): the time stays at {a['clipTime']:.3f} -> {b['clipTime']:.3f} s")
    # Play (Space): time runs.
    press_space(browser)
    time.sleep(0.6)
    c = browser.state()
    check(c["playing"] and c["clipTime"] != b["clipTime"],
          f"Space plays: {b['clipTime']:.3f} -> {c['clipTime']:.3f} s")
    press_space(browser)
    time.sleep(0.2)
    d = browser.state()
    time.sleep(0.5)
    check(not d["playing"] and browser.state()["clipTime"] == d["clipTime"],
          "Space pauses again: the time stays")
    # Seek to a key of the clip: the bone is the file's key there (paused, then also while
    # the seek is followed by more frames).
    times, rotations = vrma_keys(clip_file, "rightUpperArm")
    for want in (6.0, 2.0, 9.0):
        i = min(range(len(times)), key=lambda k: abs(times[k] - want))
        seek(browser, f"{times[i]:.6f}")
        page = js(browser, "window.avatarmapViewer.boneRotation('rightUpperArm')")
        shown = browser.state()["clipTime"]
        check(same_rotation(page, rotations[i]),
              f"vrma seek to {times[i]:.3f} s (page time {shown:.3f}): rightUpperArm {fmt(page)} "
              f"= the file's key {fmt(rotations[i])} ({angle_between(page, rotations[i]):.3f} deg)")
    # The same times of the pose file the clip was made of: the same arm within a degree.
    poses = read_poses(pose_file)
    seek(browser, "6.0")
    page = js(browser, "window.avatarmapViewer.boneRotation('rightUpperArm')")
    ref = pose_at(poses, 6.0)["bones"]["rightUpperArm"]
    check(angle_between(page, ref) < 1.0,
          f"vrma at 6.0 s: rightUpperArm within a degree of the pose file's "
          f"({angle_between(page, ref):.3f} deg)")
    # Speed: 2x against 1x, measured as a ratio.
    seek(browser, "0.5")
    press_space(browser)
    one = rate(browser)
    set_select(browser, "speed", "2")
    seek(browser, "0.5")
    two = rate(browser)
    check(browser.state()["speed"] == 2, "the speed list sets 2x")
    check(1.4 < two / one < 2.8,
          f"2x runs about twice as fast as 1x: {one:.2f} and {two:.2f} clip s per s "
          f"(ratio {two / one:.2f})")
    set_select(browser, "speed", "1")
    # Loop off: the clip stops at its end.
    set_checkbox(browser, "loop", False)
    seek(browser, f"{duration - 0.3:.3f}")
    end = browser.wait_for(lambda s: not s["playing"], 10, "the clip to stop at its end")
    time.sleep(0.3)
    check(abs(end["clipTime"] - duration) < 1e-6 and not browser.state()["playing"]
          and not end["loop"], f"loop off: stopped at {end['clipTime']:.3f} of {duration:.3f} s")
    press_space(browser)  # play again from the start
    time.sleep(0.3)
    again = browser.state()
    check(again["playing"] and again["clipTime"] < 1.0,
          f"play after the end starts again ({again['clipTime']:.2f} s)")


def fmt(q):
    return "[" + ", ".join(f"{v:.4f}" for v in q) + "]" if q else str(q)


def check_pose_seek(browser, poses, what, times=(6.0, 2.5, 8.9)):
    for t in times:
        seek(browser, t)
        page = js(browser, "window.avatarmapViewer.boneRotation('rightUpperArm')")
        ref = pose_at(poses, t)
        want = ref["bones"].get("rightUpperArm", [0, 0, 0, 1])
        check(same_rotation(page, want, 1e-6),
              f"{what} seek to {t} s: rightUpperArm {fmt(page)} = the file's pose at "
              f"t {ref['t']:.3f} {fmt(want)}")


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz]


def axis_quat(axis, degrees):
    import math
    h = math.radians(degrees) / 2
    return [math.sin(h) * c for c in axis] + [math.cos(h)]


def gaze_pose_file(path, yaw, pitch, switch=2.0):
    """A 4 s pose file: a still T-pose; from `switch` s both eyes turned by yaw (about +Y,
    toward the avatar's left) then pitch (about +X, down) and happy = 1, before that straight
    ahead and happy = 0. Returns the eye rotation [x, y, z, w]."""
    eye = quat_mul(axis_quat((0, 1, 0), yaw), axis_quat((1, 0, 0), pitch))
    with open(path, "w") as f:
        f.write('{"format":"avatarmap.pose","version":1,"fps":30}\n')
        for i in range(121):
            t = i / 30
            on = t >= switch - 1e-9
            frame = {"t": t, "expressions": {"happy": 1 if on else 0}}
            if on:
                frame["bones"] = {"leftEye": eye, "rightEye": eye}
            f.write(json.dumps(frame) + "\n")
    return eye


def avatar_look_at(path):
    """The VRMC_vrm.lookAt object of a .vrm (GLB), read here."""
    blob = open(path, "rb").read()
    size = struct.unpack_from("<I", blob, 12)[0]
    return json.loads(blob[20:20 + size])["extensions"]["VRMC_vrm"]["lookAt"]


def check_gaze(browser):
    """The gaze of a .vrma we write is played by three-vrm: the clip's eye rotations become the
    file's lookAt, and the avatar's eye bones turn by the yaw and pitch of the gaze mapped through
    the avatar's own lookAt range maps (read here from the .vrm: three-vrm's VRMLookAtBoneApplier
    turns each eye by Euler YXZ (pitch', yaw'), yaw' = outputScale * min(yaw / inputMaxValue, 1),
    the left eye's yaw toward its outer side by rangeMapHorizontalOuter, the right eye's by
    rangeMapHorizontalInner, a positive pitch by rangeMapVerticalUp)."""
    yaw, pitch = 20.0, 10.0
    poses = os.path.join(WORK, "gaze.pose.jsonl")
    clip = os.path.join(WORK, "gaze.vrma")
    gaze_pose_file(poses, yaw, pitch)
    run("convert", poses, "-o", clip)
    look = avatar_look_at(ROBOT)
    check(look.get("type", "bone") == "bone", f"{ROBOT}: a bone-type lookAt")

    def mapped(name, value):
        m = look[name]
        return m["outputScale"] * min(max(value / m["inputMaxValue"], 0.0), 1.0)

    def eye_rotation(horizontal):
        return quat_mul(axis_quat((0, 1, 0), mapped(horizontal, yaw)),
                        axis_quat((1, 0, 0), mapped("rangeMapVerticalUp", pitch)))

    view = View(clip, "--avatar", ROBOT, "--quiet")
    try:
        state = loaded(browser, view.url, "vrma")
        check(abs(state["clipDuration"] - 4.0) < 0.05,
              f"gaze.vrma (with lookAt and happy) loads: {state['clipDuration']:.2f} s")
        click(browser, "play")  # pause
        seek(browser, "1.0")
        for eye in ("leftEye", "rightEye"):
            page = js(browser, f"window.avatarmapViewer.boneRotation('{eye}')")
            check(same_rotation(page, [0, 0, 0, 1], 1e-6),
                  f"gaze.vrma at 1 s: {eye} straight ahead {fmt(page)}")
        seek(browser, "3.0")
        for eye, horizontal in (("leftEye", "rangeMapHorizontalOuter"),
                                ("rightEye", "rangeMapHorizontalInner")):
            page = js(browser, f"window.avatarmapViewer.boneRotation('{eye}')")
            want = eye_rotation(horizontal)
            check(page is not None and angle_between(page, want) < 0.05,
                  f"gaze.vrma at 3 s: {eye} {fmt(page)} = the gaze ({yaw:.0f} deg left, "
                  f"{pitch:.0f} deg down) through the avatar's range maps {fmt(want)} "
                  f"({angle_between(page, want) if page else float('nan'):.3f} deg)")
    finally:
        view.stop()


def check_pose_file(browser, url, pose_file):
    loaded(browser, url, "poses")
    click(browser, "play")  # pause
    check_pose_seek(browser, read_poses(pose_file), "pose file")


def check_open(browser, url, glb_file, pose_file):
    """The Open button's file input: a .glb, a .pose.jsonl, an unknown file."""
    browser.navigate(url)
    browser.wait_for(lambda s: s["avatar"] == "ready", 40, "the avatar")
    open_file(browser, glb_file)
    s = browser.wait_for(lambda s: s["clipKind"] == "glb" and s["avatar"] == "ready", 40,
                         "the .glb opened")
    time.sleep(0.8)
    s2 = browser.state()
    check(s2["playing"] and s2["clipTime"] != s["clipTime"] and abs(s2["clipDuration"] - 10) < 0.5,
          f"open .glb: plays ({s['clipTime']:.2f} -> {s2['clipTime']:.2f} s of "
          f"{s2['clipDuration']:.2f})")
    click(browser, "play")
    seek(browser, 6.0)
    up = js(browser, "window.avatarmapViewer.rawBoneRotation('rightUpperArm')")
    seek(browser, 2.0)
    down = js(browser, "window.avatarmapViewer.rawBoneRotation('rightUpperArm')")
    check(angle_between(up, down) > 20,
          f"open .glb: the right upper arm turns {angle_between(up, down):.1f} deg between "
          "2 s and 6 s (the wave)")
    open_file(browser, pose_file)
    browser.wait_for(lambda s: s["clipKind"] == "poses", 20, "the .pose.jsonl opened")
    a = browser.state()
    time.sleep(0.6)
    b = browser.state()
    check(b["playing"] and b["clipTime"] != a["clipTime"],
          f"open .pose.jsonl: plays ({a['clipTime']:.2f} -> {b['clipTime']:.2f} s)")
    click(browser, "play")
    check_pose_seek(browser, read_poses(pose_file), "opened pose file", times=(6.0,))
    junk = os.path.join(WORK, "notes.txt")
    open(junk, "w").write("not motion\n")
    open_file(browser, junk)
    s = browser.wait_for(lambda s: "cannot open notes.txt" in s["message"], 10,
                         "a message about notes.txt")
    shown = js(browser, "getComputedStyle(document.getElementById('message')).display")
    check(shown == "block" and ".pose.jsonl" in s["message"],
          f"an unknown file gets a visible message: {s['message']!r}")


def check_video(browser, pose_file, video):
    view = View(pose_file, "--avatar", ROBOT, "--video", video)
    try:
        browser.navigate(view.url)
        s = browser.wait_for(lambda s: s["video"] in ("ready", "failed") and s["clipKind"], 40,
                             "the video")
        if s["video"] == "failed":
            return s["message"]
        check(js(browser, "getComputedStyle(document.querySelector('video')).display") == "block",
              "--video: a <video> is shown beside the avatar")
        offset = read_poses(pose_file)[0]["t"]
        click(browser, "play")  # pause
        for t in (3.0, 1.25, 7.5):
            seek(browser, t)
            try:
                s = browser.wait_for(lambda s, t=t: s["videoTime"] is not None
                                     and abs(s["videoTime"] - (t + offset)) < 0.05,
                                     10, f"the video at {t + offset:.3f} s")
            except TimeoutError:
                s = browser.state()
            check(s["videoTime"] is not None and abs(s["videoTime"] - (t + offset)) < 0.05,
                  f"--video: timeline {t} s -> video {s['videoTime']} s (want {t + offset:.3f})")
        press_space(browser)
        time.sleep(1.0)
        s = browser.state()
        check(s["playing"] and abs(s["videoTime"] - (s["clipTime"] + offset)) < 0.3,
              f"--video playing: video {s['videoTime']:.2f} s, animation {s['clipTime']:.2f} s")
    finally:
        view.stop()
    return None


def check_builtin(browser):
    view = View()
    try:
        config = json.load(urllib.request.urlopen(view.url + "config.json"))
        check(config["avatar_name"] == "built-in avatar" and "avatarmap-viewer" not in
              json.dumps(config), f"built-in avatar: config names it {config['avatar_name']!r}")
        for load in range(2):
            browser.navigate(view.url)
            browser.wait_for(lambda s: s["avatar"] == "ready" and s["frames"] > 12, 40,
                             "the built-in avatar")
            hud = js(browser, "document.getElementById('hud').textContent")
            check(hud.startswith("built-in avatar (ready)"),
                  f"page load {load + 1}: the page says {hud.splitlines()[0]!r}")
        blob = urllib.request.urlopen(view.url + "avatar.vrm").read()
        check(blob[:4] == b"glTF", f"/avatar.vrm still served ({len(blob)} bytes)")
    finally:
        view.stop()


def main():
    pose_file = os.path.join(WORK, "wave.pose.jsonl")
    clip_file = os.path.join(WORK, "wave.vrma")
    glb_file = os.path.join(WORK, "wave.glb")
    landmarks = os.path.join(WORK, "wave.landmarks.jsonl")
    run("synth", "-o", landmarks, "--seconds", "10")
    run("solve", landmarks, "-o", pose_file)
    run("convert", pose_file, "-o", clip_file)
    run("convert", pose_file, "--avatar", ROBOT, "-o", glb_file)

    # The command line: unknown kinds refused, naming what is accepted.
    junk = os.path.join(WORK, "x.txt")
    open(junk, "w").write("x\n")
    r = subprocess.run([EXE, "view", junk, "--port", "0"], capture_output=True, text=True,
                       timeout=20)
    check(r.returncode == 2 and all(e in r.stderr for e in (".pose.jsonl", ".vrma", ".glb", ".bvh")),
          f"view x.txt exits {r.returncode}: {r.stderr.strip()}")

    browser = cdp.Browser(width=1000, height=640)
    try:
        view = View(clip_file, "--avatar", ROBOT, "--quiet")
        check_controls(browser, view.url, clip_file, pose_file)
        view.stop()

        view = View(pose_file, "--avatar", ROBOT, "--quiet")
        check_pose_file(browser, view.url, pose_file)
        view.stop()

        view = View("--avatar", ROBOT, "--quiet")
        check_open(browser, view.url, glb_file, pose_file)
        view.stop()

        view = View(glb_file, "--quiet")
        s = loaded(browser, view.url, "glb")
        check(s["avatarName"] == "wave.glb" and abs(s["clipDuration"] - 10) < 0.5,
              f"view x.glb: the avatar {s['avatarName']} plays its {s['clipDuration']:.2f} s")
        view.stop()

        if os.path.exists(BVH):
            bvh_poses = os.path.join(WORK, "bvh.pose.jsonl")
            run("convert", BVH, "-o", bvh_poses)
            poses = read_poses(bvh_poses)
            view = View(BVH, "--avatar", ROBOT, "--quiet")
            s = loaded(browser, view.url, "poses")
            span = poses[-1]["t"] - poses[0]["t"]
            check(abs(s["clipDuration"] - span) < 1e-3,
                  f"view x.bvh: plays {s['clipDuration']:.3f} s (convert: {span:.3f} s)")
            click(browser, "play")
            check_pose_seek(browser, poses, "view x.bvh", times=(span * 0.3, span * 0.7))
            view.stop()
        else:
            print(f"note: {BVH} is missing: view x.bvh not tried")

        if os.path.exists(VIDEO):
            problem = check_video(browser, pose_file, VIDEO)
            if problem:  # this Chromium cannot decode H.264: a VP8 WebM of our own instead
                print(f"note: {VIDEO}: {problem}; trying a WebM")
                webm = os.path.join(WORK, "source.webm")
                subprocess.run(["ffmpeg", "-y", "-loglevel", "error", "-f", "lavfi", "-i",
                                "testsrc=duration=11:size=320x240:rate=25", "-c:v", "libvpx",
                                "-g", "5", webm], check=True)
                problem = check_video(browser, pose_file, webm)
                check(problem is None, f"--video: {problem}")
        else:
            print(f"note: {VIDEO} is missing: --video not tried")

        check_builtin(browser)
        check_gaze(browser)
        check(not browser.exceptions, f"no page exceptions: {browser.exceptions[:2]}")
    finally:
        browser.quit()

    if failures:
        print(f"{len(failures)} FAILED")
        sys.exit(1)
    print("all passed")


main()
