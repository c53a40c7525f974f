"""Several people in the browser viewer (docs/viewer.md, "Several people") in Debian's headless
Chromium.

    people_test.py AVATARMAP WORKDIR

A small WebSocket server written here (the pose socket's protocol, RFC 6455 by hand) stands in
for `avatarmap live --serve` with several people: `avatarmap view --avatar ROBOT --connect PORT`
points its page at it, and the server sends it pose lines whose "person" and "slot" keys say
whose they are. Read back through the page's test hooks (state(), people(), boneRotation(name,
slot)) and checked against the poses sent: lines without "slot" drive the one avatar, as
before, which stays shown when they stop; two slots get two avatars, each with its own person's
arm rotation; without a root translation they stand 1 m apart by slot, with one they stand
where their hips say (slot 1 left of slot 0 when its hips are); a slot whose poses stop is
hidden after 1.5 s and shown again when they resume, slot 0's (the page's own avatar) too; a
"gone" notice hides a slot's avatar at once. Exit 77 (skipped) without chromium, the
test data or the viewer's modules."""

import base64
import hashlib
import json
import math
import os
import socket
import sys
import threading
import time

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
if not DATA or not os.path.exists(ROBOT):
    skip("AVATARMAP_TEST_DATA is unset or lacks avatars/vrm1_debug_robot.vrm")
if not cdp.find_chromium():
    skip("chromium is missing (Debian: chromium; scripts/setup.sh installs it)")
os.makedirs(WORK, exist_ok=True)

check = Checks()
WS_GUID = "258EAFA5-E914-47DA-95CA-C5AB0DC85B11"  # RFC 6455, section 1.3


class PoseSource:
    """A WebSocket server on 127.0.0.1 speaking the pose socket's protocol: every page that
    connects is sent the current lines (set_lines) every 40 ms, one text message each."""

    def __init__(self):
        self.server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.server.bind(("127.0.0.1", 0))
        self.server.listen(4)
        self.port = self.server.getsockname()[1]
        self.lock = threading.Lock()
        self.lines = []
        self.stopping = False
        threading.Thread(target=self._accept, daemon=True).start()

    def set_lines(self, lines):
        with self.lock:
            self.lines = list(lines)

    def stop(self):
        self.stopping = True
        self.server.close()

    def _accept(self):
        while not self.stopping:
            try:
                conn, _ = self.server.accept()
            except OSError:
                return
            threading.Thread(target=self._serve, args=(conn,), daemon=True).start()

    def _serve(self, conn):
        try:
            request = b""
            while b"\r\n\r\n" not in request:
                chunk = conn.recv(4096)
                if not chunk:
                    return
                request += chunk
            headers = {}
            for line in request.decode("latin-1").split("\r\n")[1:]:
                if ":" in line:
                    name, value = line.split(":", 1)
                    headers[name.strip().lower()] = value.strip()
            accept = base64.b64encode(
                hashlib.sha1((headers["sec-websocket-key"] + WS_GUID).encode()).digest()).decode()
            conn.sendall(("HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\n"
                          "Connection: Upgrade\r\nSec-WebSocket-Accept: " + accept + "\r\n"
                          "Sec-WebSocket-Protocol: avatarmap.pose\r\n\r\n").encode())
            while not self.stopping:
                with self.lock:
                    lines = self.lines
                for text in lines:
                    data = text.encode()
                    if len(data) < 126:
                        header = bytes([0x81, len(data)])
                    elif len(data) < 65536:
                        header = bytes([0x81, 126]) + len(data).to_bytes(2, "big")
                    else:
                        header = bytes([0x81, 127]) + len(data).to_bytes(8, "big")
                    conn.sendall(header + data)
                time.sleep(0.04)
        except OSError:
            pass
        finally:
            conn.close()


def arm(angle):
    """leftUpperArm turned by `angle` radians about Z, [x, y, z, w]."""
    return [0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)]


def line(t, arm_angle, hips_x=0.0, person=None, slot=None):
    """One *.pose.jsonl line, with the person's keys last as the pose server writes them."""
    pose = {"t": t, "hips_position": [hips_x, 0.9, 0.0], "foot_contact": [0, 0],
            "bones": {"leftUpperArm": arm(arm_angle)}, "expressions": {}}
    if slot is not None:
        pose["person"] = person
        pose["slot"] = slot
    return json.dumps(pose, separators=(",", ":"))


def same_rotation(got, want, tol=1e-5):
    """Quaternions equal up to sign."""
    if not got:
        return False
    dot = abs(sum(a * b for a, b in zip(got, want)))
    return abs(dot - 1) < tol


def people(browser):
    return {p["slot"]: p for p in browser.evaluate("window.avatarmapViewer.people()")}


def rotation(browser, slot):
    return browser.evaluate(f"window.avatarmapViewer.boneRotation('leftUpperArm', {slot})")


def wait_people(browser, predicate, timeout, what):
    deadline = time.monotonic() + timeout
    seen = None
    while time.monotonic() < deadline:
        seen = people(browser)
        if predicate(seen):
            return seen
        time.sleep(0.05)
    raise TimeoutError(f"waited {timeout} s for {what}; people {seen}; state {browser.state()}; "
                       f"console {browser.console[-5:]}; exceptions {browser.exceptions[-3:]}")


def main():
    source = PoseSource()
    view = view_process.View(EXE, WORK, "--avatar", ROBOT, "--connect", str(source.port))
    browser = cdp.Browser()
    try:
        # One person, as before several: lines without "slot" drive the page's avatar, which
        # stays shown when they stop.
        source.set_lines([line(1.0, 0.6)])
        browser.navigate(view.url)
        browser.wait_for(lambda s: s["avatar"] == "ready" and s["posesApplied"] > 5, 60,
                         "the avatar posed by one person's lines")
        check(same_rotation(rotation(browser, 0), arm(0.6)), "one person: the pose is applied")
        source.set_lines([])
        time.sleep(2.0)  # longer than the 1.5 s after which a person's avatar is hidden
        seen = people(browser)
        check(list(seen) == [0] and seen[0]["visible"] and browser.state()["people"] == 1,
              f"one person: one avatar, still shown after its poses stop ({seen})")

        # Two people, no root translation (hips X = Z = 0): side by side, 1 m apart by slot.
        source.set_lines([line(2.0, 0.8, person=5, slot=0), line(2.0, -0.5, person=9, slot=1)])
        seen = wait_people(browser, lambda p: 1 in p and p[1]["visible"] and p[0]["visible"]
                           and p[1]["posesApplied"] > 3, 60, "a second avatar for slot 1")
        check(browser.state()["people"] == 2, "two people: two avatars shown")
        check(seen[0]["person"] == 5 and seen[1]["person"] == 9,
              f"each avatar knows its person ({seen[0]['person']}, {seen[1]['person']})")
        r0, r1 = rotation(browser, 0), rotation(browser, 1)
        check(same_rotation(r0, arm(0.8)), f"slot 0's avatar has person 5's arm ({r0})")
        check(same_rotation(r1, arm(-0.5)), f"slot 1's avatar has person 9's arm ({r1})")
        check(not same_rotation(r0, r1, 1e-3), "the two avatars' poses differ")
        gap = seen[1]["x"] - seen[0]["x"]
        check(abs(gap - 1.0) < 1e-3, f"without root translation slot 1 stands 1 m right ({gap})")

        # A root translation: each stands where its hips say (slot 1 now left of slot 0).
        source.set_lines([line(3.0, 0.8, 0.4, person=5, slot=0),
                          line(3.0, -0.5, -0.4, person=9, slot=1)])
        seen = wait_people(browser, lambda p: p[0]["x"] - p[1]["x"] > 0.3, 10,
                           "the avatars placed by their hips")
        gap = seen[0]["x"] - seen[1]["x"]
        check(0.3 < gap < 2.5, f"with root translation slot 1 stands left of slot 0 ({gap} m)")

        # Slot 1's poses stop: its avatar is hidden after 1.5 s; slot 0's stays.
        source.set_lines([line(4.0, 0.8, 0.4, person=5, slot=0)])
        seen = wait_people(browser, lambda p: not p[1]["visible"], 10, "slot 1 hidden")
        check(seen[0]["visible"] and browser.state()["people"] == 1,
              "a person who left is hidden, the other stays")
        source.set_lines([line(5.0, 0.8, 0.4, person=5, slot=0),
                          line(5.0, 0.2, -0.4, person=9, slot=1)])
        wait_people(browser, lambda p: p[1]["visible"], 10, "slot 1 shown again")
        check(same_rotation(rotation(browser, 1), arm(0.2)), "back: slot 1 shows its new pose")
        # Slot 0's person leaves: the page's own avatar is hidden too, slot 1's stays.
        source.set_lines([line(6.0, 0.2, -0.4, person=9, slot=1)])
        seen = wait_people(browser, lambda p: not p[0]["visible"], 10, "slot 0 hidden")
        check(seen[1]["visible"] and browser.state()["people"] == 1,
              "slot 0's person left: its avatar is hidden, slot 1's stays")
        # The server's notice that slot 1's person has gone (pose_server::clear): hidden at
        # once, not after 1.5 s.
        gone = json.dumps({"gone": True, "person": 9, "slot": 1}, separators=(",", ":"))
        source.set_lines([gone])
        t0 = time.time()
        wait_people(browser, lambda p: not p[1]["visible"], 10, "slot 1 hidden by its notice")
        took = time.time() - t0
        check(took < 1.0, f"a gone notice hides the avatar at once ({took:.2f} s, not 1.5 s)")
        check(browser.state()["people"] == 0, "nobody is shown after both left")
        check(not browser.exceptions, f"no page exceptions ({browser.exceptions[-3:]})")
    except TimeoutError as e:
        check(False, str(e))
    finally:
        browser.quit()
        view.stop()
        source.stop()
    if check.failures:
        print(f"{len(check.failures)} check(s) failed")
        sys.exit(1)
    print("all checks passed")


main()
