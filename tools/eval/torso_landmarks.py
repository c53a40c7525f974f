#!/usr/bin/env python3
"""The torso's direction in landmark files, before any solve (docs/smoothing.md, "Jitter on
real video").

Usage: tools/eval/torso_landmarks.py A.landmarks.jsonl [B.landmarks.jsonl ...]

For each file: the direction from the hips' midpoint to the shoulders' midpoint in the pose's
world points (landmarks 23/24 and 11/12, MediaPipe's axes: x left of the image, y down,
z away from the camera), over the frames that have world points, and

  jitter   the RMS of its second time difference, deg/s^2 (as `eval-pose --jitter` measures
           bones), from the frames' own times;
  x y z    the same per component of the unit direction (1/s^2): which axis the jitter is in;
  slow     the standard deviation of its depth component (z) after a centred 5-frame mean:
           the lean the person really makes over a movement (a squat's cycle is ~12 frames at
           5 fps);
  fast     the standard deviation of what that mean removes: the frame-to-frame part.

Two files of the same video (ours and a reference) compare the estimators: equal "slow" and a
larger "fast" is frame-to-frame noise in the world points, not a different motion.
Needs only Python's standard library.
"""
import json
import math
import sys


def read(path):
    times, dirs = [], []
    with open(path, encoding="utf-8") as f:
        next(f)  # header
        for line in f:
            if not line.strip():
                continue
            d = json.loads(line)
            w = d.get("pose_world")
            if not w or len(w) < 25:
                continue
            mid = lambda a, b: [(w[a][i] + w[b][i]) * 0.5 for i in range(3)]
            s, h = mid(11, 12), mid(23, 24)
            v = [s[i] - h[i] for i in range(3)]
            n = math.sqrt(sum(x * x for x in v))
            if not (n > 0.0) or not all(math.isfinite(x) for x in v):
                continue
            times.append(float(d["t"]))
            dirs.append([x / n for x in v])
    return times, dirs


def std(xs):
    m = sum(xs) / len(xs)
    return math.sqrt(sum((x - m) ** 2 for x in xs) / len(xs))


def main(paths):
    if not paths:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    print("%-40s %7s %9s %7s %7s %7s %7s %7s" % ("file", "frames", "jitter", "x", "y", "z",
                                                 "slow", "fast"))
    for path in paths:
        t, v = read(path)
        if len(v) < 5:
            print(f"{path}: fewer than 5 frames with world points", file=sys.stderr)
            return 1
        sq, comp = 0.0, [0.0, 0.0, 0.0]
        for k in range(1, len(v) - 1):
            dt = 0.5 * (t[k + 1] - t[k - 1])
            if not (dt > 0.0):
                continue
            a = [(v[k + 1][i] - 2.0 * v[k][i] + v[k - 1][i]) / (dt * dt) for i in range(3)]
            sq += sum(x * x for x in a)
            for i in range(3):
                comp[i] += a[i] * a[i]
        m = len(v) - 2
        z = [d[2] for d in v]
        slow = [sum(z[k - 2:k + 3]) / 5.0 for k in range(2, len(z) - 2)]
        fast = [z[k] - slow[k - 2] for k in range(2, len(z) - 2)]
        print("%-40s %7d %9.0f %7.2f %7.2f %7.2f %7.3f %7.3f" % (
            path[-40:], len(v), math.degrees(math.sqrt(sq / m)),
            *(math.sqrt(c / m) for c in comp), std(slow), std(fast)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
