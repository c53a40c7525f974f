"""The viewer's render mode (docs/world-benchmark-rendered.md) in Debian's headless Chromium.

    render_mode_test.py AVATARMAP WORKDIR

Pins the camera convention: the built-in avatar in its T-pose, rendered with known cameras
(position + yaw/pitch/roll, position + look-at + roll; horizontal and vertical fields of view;
two canvas sizes) with a magenta marker at a bone; the marker's pixel must be where the bone's
rest position, read from the avatar file itself (the glTF nodes' translations), projects by hand
through a pinhole with those numbers — within 2 pixels. Also: the background and floor colours,
renderAt(t) on a .vrma clip is deterministic (the same t twice gives the same picture, another t
another one), an emotion preset (`happy`) of a .vrma we write is played by three-vrm (the face of
an avatar whose happy moves its texture changes, and only when happy does), a pose's ARKit
blendshapes move the built-in avatar's face and win over the expressions bound to the same
morph target, and no exception in the page. Exit 77 (skipped) without chromium, Pillow or the
viewer's modules."""

import io
import json
import math
import os
import signal
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
SKIP = 77


def skip(why):
    print(f"SKIPPED: {why}")
    sys.exit(SKIP)


try:
    from PIL import Image
except ImportError:
    skip("Pillow is missing (Debian: python3-pil; scripts/setup.sh installs it)")
import cdp  # noqa: E402

if len(sys.argv) != 3:
    sys.exit(__doc__)
EXE, WORK = sys.argv[1], sys.argv[2]
if not cdp.find_chromium():
    skip("chromium is missing (Debian: chromium; scripts/setup.sh installs it)")
os.makedirs(WORK, exist_ok=True)
failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


# ---- the avatar's rest positions, from its glTF nodes ------------------------------------------
def rest_positions(vrm_path):
    """World rest position of each VRM humanoid bone: the sum of the node translations from the
    root (the built-in avatar's nodes carry no rest rotation or scale: checked)."""
    data = open(vrm_path, "rb").read()
    length, kind = struct.unpack_from("<II", data, 12)
    assert kind == 0x4E4F534A, "the first GLB chunk is JSON"
    gltf = json.loads(data[20:20 + length])
    nodes = gltf["nodes"]
    parent = {}
    for i, n in enumerate(nodes):
        for c in n.get("children", []):
            parent[c] = i
    for n in nodes:
        assert n.get("rotation", [0, 0, 0, 1]) == [0, 0, 0, 1] and "scale" not in n and \
            "matrix" not in n, "a node with a rest rotation or scale"
    positions = {}
    for name, bone in gltf["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"].items():
        i, p = bone["node"], [0.0, 0.0, 0.0]
        while i is not None:
            t = nodes[i].get("translation", [0, 0, 0])
            p = [p[k] + t[k] for k in range(3)]
            i = parent.get(i)
        positions[name] = p
    return positions


# ---- the pinhole, written out with matrices ----------------------------------------------------
def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return [[1, 0, 0], [0, c, -s], [0, s, c]]


def rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return [[c, 0, s], [0, 1, 0], [-s, 0, c]]


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def axes(cam):
    """(right, up, back) of the camera in world axes."""
    if "look" in cam:
        forward = unit([cam["look"][i] - cam["pos"][i] for i in range(3)])
        right = unit(cross(forward, [0, 1, 0]))
        up = cross(right, forward)
        back = [-f for f in forward]
    else:
        r = matmul(matmul(rot_y(math.radians(cam["yaw"])), rot_x(math.radians(cam["pitch"]))),
                   [[1, 0, 0], [0, 1, 0], [0, 0, 1]])
        right, up, back = [r[i][0] for i in range(3)], [r[i][1] for i in range(3)], \
            [r[i][2] for i in range(3)]
    roll = math.radians(cam.get("roll", 0))  # counterclockwise as the camera looks
    right, up = ([math.cos(roll) * right[i] + math.sin(roll) * up[i] for i in range(3)],
                 [math.cos(roll) * up[i] - math.sin(roll) * right[i] for i in range(3)])
    return right, up, back


def project(cam, p):
    w, h = cam["size"]
    if "hfov" in cam:
        f = w / 2 / math.tan(math.radians(cam["hfov"]) / 2)
    else:
        f = h / 2 / math.tan(math.radians(cam["vfov"]) / 2)
    right, up, back = axes(cam)
    d = [p[i] - cam["pos"][i] for i in range(3)]
    x = sum(d[i] * right[i] for i in range(3))
    y = sum(d[i] * up[i] for i in range(3))
    z = -sum(d[i] * back[i] for i in range(3))  # depth in front of the camera
    return w / 2 + f * x / z, h / 2 - f * y / z


def query(cam, marker):
    w, h = cam["size"]
    q = f"?render=1&w={w}&h={h}&cam={','.join(str(v) for v in cam['pos'])}&marker={marker}"
    if "look" in cam:
        q += f"&look={','.join(str(v) for v in cam['look'])}"
    else:
        q += f"&yaw={cam['yaw']}&pitch={cam['pitch']}"
    q += f"&roll={cam.get('roll', 0)}"
    q += f"&hfov={cam['hfov']}" if "hfov" in cam else f"&vfov={cam['vfov']}"
    return q


# ---- the page ---------------------------------------------------------------------------------
class View:
    def __init__(self, *args):
        self.log = open(os.path.join(WORK, f"view{len(os.listdir(WORK))}.log"), "w")
        self.process = subprocess.Popen([EXE, "view", *args, "--port", "0", "--quiet"],
                                        stdout=subprocess.PIPE, stderr=self.log, text=True)
        self.url = self.process.stdout.readline().strip()
        if not self.url:
            self.process.wait()
            self.log.close()
            text = open(self.log.name).read()
            if "fetch_viewer_modules" in text:
                skip("the viewer's modules are missing: " + text.strip())
            raise RuntimeError(f"avatarmap view did not start: {text}")

    def stop(self):
        self.process.send_signal(signal.SIGINT)
        code = self.process.wait(20)
        self.log.close()
        return code


def open_page(browser, url, size):
    browser.call("Emulation.setDeviceMetricsOverride", width=size[0], height=size[1],
                 deviceScaleFactor=1, mobile=False)
    browser.navigate(url)
    deadline = time.monotonic() + 30
    while not browser.evaluate("!!(window.avatarmapViewer && window.avatarmapViewer.ready)"):
        if time.monotonic() > deadline:
            raise TimeoutError(f"no render-mode page: {browser.exceptions[-3:]}")
        time.sleep(0.05)
    return call(browser, "window.avatarmapViewer.ready()")


def call(browser, expression):
    r = browser.call("Runtime.evaluate", expression=expression, awaitPromise=True,
                     returnByValue=True)
    if "exceptionDetails" in r:
        raise RuntimeError(f"{expression}: {json.dumps(r['exceptionDetails'])[:400]}")
    return r["result"].get("value")


def shot(browser, size):
    import base64
    data = browser.call("Page.captureScreenshot", format="png",
                        clip=dict(x=0, y=0, width=size[0], height=size[1], scale=1))["data"]
    return Image.open(io.BytesIO(base64.b64decode(data))).convert("RGB")


def marker_centre(img):
    """Centroid of the magenta marker's pixels (None when there are none)."""
    w, h = img.size
    data = img.tobytes()
    xs, ys = [], []
    for i in range(w * h):
        r, g, b = data[3 * i], data[3 * i + 1], data[3 * i + 2]
        if r > 180 and b > 180 and g < 90:
            xs.append(i % w)
            ys.append(i // w)
    if not xs:
        return None
    return sum(xs) / len(xs) + 0.5, sum(ys) / len(ys) + 0.5, len(xs)


CAMERAS = [
    ("front, pitched down 5 deg, hfov 60", dict(pos=[0, 1.2, 3.0], yaw=0, pitch=-5, hfov=60,
                                              size=(640, 360)), ["hips"]),
    ("right of the avatar, yaw 30, pitch +10, hfov 75",
     dict(pos=[1.5, 0.6, 2.6], yaw=30, pitch=10, hfov=75, size=(640, 360)), ["hips"]),
    ("high, yaw -20, pitch -20, roll 8, vfov 40 at 960x540",
     dict(pos=[-1.0, 1.8, 2.5], yaw=-20, pitch=-20, roll=8, vfov=40, size=(960, 540)),
     ["hips", "head", "leftHand"]),
    ("look-at the hips from the left, roll -6, hfov 50",
     dict(pos=[-2.0, 1.7, 2.8], look=[0, 0.9, 0], roll=-6, hfov=50, size=(640, 360)),
     ["hips", "head", "rightFoot"]),
]


def still_face_clip(name, happy_from):
    """A .vrma made by `avatarmap convert` from a pose file whose body stands still in the T-pose
    for 4 s and whose `happy` weight is 0 before `happy_from` seconds and 1 from there (None:
    never)."""
    poses = os.path.join(WORK, name + ".pose.jsonl")
    with open(poses, "w") as f:
        f.write('{"format":"avatarmap.pose","version":1,"fps":30}\n')
        for i in range(121):
            t = i / 30
            happy = 1 if happy_from is not None and t >= happy_from - 1e-9 else 0
            f.write(json.dumps({"t": t, "expressions": {"happy": happy}}) + "\n")
    clip = os.path.join(WORK, name + ".vrma")
    subprocess.run([EXE, "convert", poses, "-o", clip, "--quiet"], check=True, capture_output=True)
    return clip


def check_emotion():
    """three-vrm plays an emotion preset of our .vrma: with an avatar whose `happy` moves its
    face texture (the VRM spec sample vrm1_spec_expressions.vrm), a still body renders the same
    picture at two times while happy is 0, another one once happy is 1; the same clip without
    happy renders the same picture at all three times."""
    data = os.environ.get("AVATARMAP_TEST_DATA", "")
    avatar = os.path.join(data, "avatars", "vrm1_spec_expressions.vrm")
    if not data or not os.path.exists(avatar):
        print("skip  the emotion check: AVATARMAP_TEST_DATA lacks avatars/vrm1_spec_expressions.vrm")
        return
    cam = CAMERAS[0][1]
    for name, happy_from in (("happy", 2.0), ("no_happy", None)):
        clip = still_face_clip(name, happy_from)
        view = View(clip, "--avatar", avatar)
        browser = cdp.Browser(640, 360)
        try:
            open_page(browser, view.url + query(cam, "none"), cam["size"])
            pictures = []
            for t in (0.5, 1.5, 3.0):
                call(browser, f"window.avatarmapViewer.renderAt({t})")
                pictures.append(shot(browser, cam["size"]).tobytes())
            check(pictures[0] == pictures[1], f"{name}.vrma: a still body, the same picture at 0.5 "
                                              "and 1.5 s")
            if happy_from is None:
                check(pictures[0] == pictures[2], f"{name}.vrma: without happy, the same at 3 s")
            else:
                changed = sum(1 for a, b in zip(pictures[0], pictures[2]) if a != b) // 3
                check(changed > 0, f"{name}.vrma: happy = 1 at 3 s changes the face "
                                   f"(~{changed} pixel components differ)")
            check(not browser.exceptions, f"{name}.vrma: no exception in the page "
                                          f"{browser.exceptions[:2]}")
        finally:
            browser.quit()
            view.stop()


def check_arkit(avatar):
    """A pose's ARKit blendshapes move the built-in avatar's face (its 52 ARKit morph targets,
    set directly), and win over the expressions bound to the same target: aa (bound to
    jawOpen x 0.75) with jawOpen 0.75 draws what jawOpen 0.75 alone draws, not a mouth open
    1.5 times; aa alone draws the same (three-vrm applies 0.75 to the same target); a pose
    without blendshapes afterwards draws the neutral face again."""
    cam = dict(pos=[0, 1.6, 0.7], look=[0, 1.6, 0], hfov=30, size=(320, 320))
    view = View("--avatar", avatar)
    browser = cdp.Browser(320, 320)
    try:
        state = open_page(browser, view.url + query(cam, "none"), cam["size"])
        # Its custom expressions browDownLeft/Right are ARKit names too: they claim those two
        # shapes (bound to the targets of the same names, weight 1); the 50 others are targets.
        check(state.get("arkitTargets") == 50 and state.get("arkitExpressions") == 2,
              f"the built-in avatar: 50 ARKit targets and 2 ARKit-named expressions "
              f"({state.get('arkitTargets')}, {state.get('arkitExpressions')})")
        poses = {
            "neutral": {},
            "jawOpen 1": {"blendshapes": {"jawOpen": 1}},
            "aa": {"expressions": {"aa": 1}},
            "jawOpen 0.75": {"blendshapes": {"jawOpen": 0.75}},
            "aa + jawOpen 0.75": {"expressions": {"aa": 1}, "blendshapes": {"jawOpen": 0.75}},
            "tongueOut": {"blendshapes": {"tongueOut": 1}},
            "browDownLeft": {"blendshapes": {"browDownLeft": 1}},
            "neutral again": {"expressions": {"aa": 0}},
        }
        pictures = {}
        for name, pose in poses.items():
            call(browser, f"window.avatarmapViewer.renderPose({json.dumps(pose)})")
            pictures[name] = shot(browser, cam["size"]).tobytes()

        def differ(a, b):
            return sum(1 for x, y in zip(pictures[a], pictures[b]) if x != y) // 3

        for name in ("jawOpen 1", "aa", "tongueOut", "browDownLeft"):
            check(differ("neutral", name) > 50,
                  f"{name} changes the face ({differ('neutral', name)} pixel components)")
        check(differ("aa", "jawOpen 0.75") == 0,
              f"aa = jawOpen x 0.75 on the built-in avatar ({differ('aa', 'jawOpen 0.75')})")
        check(differ("aa + jawOpen 0.75", "jawOpen 0.75") == 0,
              "aa with jawOpen 0.75: the blendshape alone drives jawOpen "
              f"({differ('aa + jawOpen 0.75', 'jawOpen 0.75')})")
        check(differ("neutral again", "neutral") == 0,
              f"a pose without blendshapes: the neutral face again "
              f"({differ('neutral again', 'neutral')})")
        check(not browser.exceptions, f"ARKit poses: no exception in the page "
                                      f"{browser.exceptions[:2]}")
    finally:
        browser.quit()
        view.stop()


def main():
    avatar = os.path.join(WORK, "builtin.vrm")
    subprocess.run([EXE, "avatar", "-o", avatar], check=True, capture_output=True)
    rest = rest_positions(avatar)
    hips_height = json.loads(subprocess.run([EXE, "inspect", avatar, "--json"], check=True,
                                            capture_output=True, text=True).stdout)["hips_height"]
    check(abs(rest["hips"][1] - hips_height) < 1e-4,
          f"the glTF nodes put the hips at the height inspect reports ({rest['hips'][1]:.4f} m, "
          f"{hips_height:.4f} m)")
    view = View("--avatar", avatar)
    browser = cdp.Browser(640, 360)
    try:
        for what, cam, bones in CAMERAS:
            for bone in bones:
                state = open_page(browser, view.url + query(cam, bone), cam["size"])
                state = call(browser, "window.avatarmapViewer.renderPose({})")  # the T-pose
                img = shot(browser, cam["size"])
                check(img.size == tuple(cam["size"]), f"{what}: canvas {img.size}")
                found = marker_centre(img)
                expected = project(cam, rest[bone])
                if found is None:
                    check(False, f"{what}: the {bone} marker is drawn")
                    continue
                err = math.hypot(found[0] - expected[0], found[1] - expected[1])
                check(err < 2.0, f"{what}: {bone} at ({found[0]:.1f}, {found[1]:.1f}) px, by hand "
                                 f"({expected[0]:.1f}, {expected[1]:.1f}): {err:.2f} px apart "
                                 f"({found[2]} marker pixels)")
                if bone == "hips" and "hfov" in cam:
                    check(abs(state["camera"]["hfov"] - cam["hfov"]) < 1e-6,
                          f"{what}: the page reports hfov {state['camera']['hfov']:.4f}")
        # Background above the horizon and floor below the feet (the first camera).
        cam = CAMERAS[0][1]
        open_page(browser, view.url + query(cam, "none"), cam["size"])
        call(browser, "window.avatarmapViewer.renderPose({})")
        img = shot(browser, cam["size"])
        corner = img.getpixel((5, 5))
        check(corner == (0xB4, 0xB8, 0xBD), f"background colour {corner}")
        floor = img.getpixel((5, 355))
        check(floor != (0xB4, 0xB8, 0xBD) and sum(floor) < sum((0xB4, 0xB8, 0xBD)),
              f"the floor is drawn below the horizon {floor}")
        # A malformed parameter: ready() rejects, naming it.
        try:
            open_page(browser, view.url + "?render=1&cam=1,2&hfov=wide", (640, 360))
            check(False, "a malformed camera is refused")
        except RuntimeError as e:
            check("cam=1,2" in str(e) and "hfov=wide" in str(e),
                  f"a malformed camera is refused, naming the parameters: {str(e)[:160]}")
        browser.exceptions.clear()
    finally:
        browser.quit()
        check(view.stop() == 0, "view exits 0 on SIGINT")

    # renderAt(t) on a clip: deterministic.
    landmarks = os.path.join(WORK, "demo.landmarks.jsonl")
    truth = os.path.join(WORK, "demo.truth.pose.jsonl")
    clip = os.path.join(WORK, "demo.vrma")
    subprocess.run([EXE, "synth", "-o", landmarks, "--truth", truth, "--seconds", "4"], check=True,
                   capture_output=True)
    subprocess.run([EXE, "convert", truth, "-o", clip, "--quiet"], check=True, capture_output=True)
    view = View(clip, "--avatar", avatar)
    browser = cdp.Browser(640, 360)
    try:
        cam = CAMERAS[0][1]
        open_page(browser, view.url + query(cam, "none"), cam["size"])
        pictures = []
        for t in (1.0, 2.5, 1.0):
            state = call(browser, f"window.avatarmapViewer.renderAt({t})")
            pictures.append(shot(browser, cam["size"]).tobytes())
            check(abs(state["clipTime"] - t) < 1e-6,
                  f"renderAt({t}): clip time {state['clipTime']}")
        check(pictures[0] == pictures[2], "renderAt: the same time twice gives the same picture")
        check(pictures[0] != pictures[1], "renderAt: another time gives another picture")
        check(not browser.exceptions, f"no exception in the page {browser.exceptions[:2]}")
    finally:
        browser.quit()
        view.stop()
    check_emotion()
    check_arkit(avatar)
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)
    print("all checks passed")


main()
