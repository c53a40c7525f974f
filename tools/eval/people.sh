#!/usr/bin/env bash
# The several-people measuring stick (issue 25; docs/capture.md): videos of two people made
# from the shared single-person clip with ffmpeg, captured with `capture --people 2`, and
# checked against each person's single-person capture of the clip it came from.
#
# Usage: tools/eval/people.sh [WORK_DIR]
# Environment: AVATARMAP (default build/avatarmap beside this checkout), AVATARMAP_TEST_DATA
#   (the shared data; pose_squats.mp4 is read from it), PEOPLE_ARGS (more capture options).
# Needs ffmpeg and python3 with NumPy. The scenes (pose_squats.mp4 is 720x1280, 65 frames at
# 5 frames/s, one person):
#   side:  the clip beside its mirror image started 1.6 s later (looped): two people of the
#          same size, apart;
#   cross: the clip on the left of a 1440x1280 canvas, and a 0.75-scaled copy started 6.4 s
#          later (looped) sliding in front of it from the right edge (at 4 s) to beyond the
#          left one (at 7 s): a crossing that hides the first person for about a second (the
#          copy is an opaque rectangle), the second person visible from 4 to 7 s; made at 25
#          frames/s (the copy moves 26 px a frame; the people's own frames change at 5).
# Truth: the single-person capture of pose_squats.mp4, mapped into each scene by the known
# scale, offset, mirror and delay. Per scene and truth person: frames where it is visible
# (less than half of its box covered), frames where an output person matches it (its visible
# body points' mean distance within 10 % of the person's box diagonal), the matched ids and
# their switches, the mean distance in % of the diagonal, and skeletons spanning two people
# (over 30 % of a skeleton's points nearer the other person).
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
exe=${AVATARMAP:-$here/build/avatarmap}
data=${AVATARMAP_TEST_DATA:?set AVATARMAP_TEST_DATA to the shared data}
clip=$data/motion/tfjs-models/pose_squats.mp4
work=${1:-$(mktemp -d "${TMPDIR:-/tmp}/avatarmap-people-XXXXXX")}
mkdir -p "$work"
command -v ffmpeg >/dev/null || { echo "people.sh: needs ffmpeg" >&2; exit 2; }
py=""
for p in python3 /usr/bin/python3; do
  if "$p" -c 'import numpy' 2>/dev/null; then py=$p; break; fi
done
[ -n "$py" ] || { echo "people.sh: needs python3 with NumPy" >&2; exit 2; }
[ -x "$exe" ] || { echo "people.sh: no avatarmap at $exe" >&2; exit 2; }

ff() { ffmpeg -hide_banner -loglevel error -y "$@"; }
# 13 s at 5 frames/s: the clip's own rate and length.
ff -stream_loop 2 -i "$clip" -stream_loop 2 -i "$clip" -filter_complex \
  "[1:v]trim=start=1.6,setpts=PTS-STARTPTS,hflip[b];[0:v][b]hstack=inputs=2,trim=duration=13,fps=5" \
  -c:v libx264 -crf 16 -pix_fmt yuv420p "$work/side.mp4"
ff -stream_loop 2 -i "$clip" -stream_loop 2 -i "$clip" -filter_complex \
  "color=black:s=1440x1280:r=25:d=13[bg];[1:v]trim=start=6.4,setpts=PTS-STARTPTS,scale=540:960,fps=25[b];\
[0:v]fps=25[a0];[bg][a0]overlay=0:0:shortest=1[a];[a][b]overlay=x='1440-(1440+540)*(t-4)/3':y=320:shortest=1,trim=duration=13" \
  -c:v libx264 -crf 16 -pix_fmt yuv420p "$work/cross.mp4"

"$exe" capture "$clip" -o "$work/truth.landmarks.jsonl" --quiet
for scene in side cross; do
  /usr/bin/time -f "%e" -o "$work/$scene.time" "$exe" capture "$work/$scene.mp4" --people 2 \
    -o "$work/$scene.landmarks.jsonl" --quiet ${PEOPLE_ARGS:-}
done

"$py" - "$work" <<'PY'
import json, sys
import numpy as np
work = sys.argv[1]
def load(path):
    rows = [json.loads(l) for l in open(path) if l.strip()]
    return rows[0], [r for r in rows[1:] if "pose" in r]
_, truth = load(f"{work}/truth.landmarks.jsonl")
tt = np.array([r["t"] for r in truth])
tp = np.array([[p[:2] for p in r["pose"]] for r in truth])  # normalised to 720x1280
tv = np.array([[p[3] for p in r["pose"]] for r in truth])
# MediaPipe's left/right pairs (a mirror image swaps them).
mirror = list(range(33))
for a, b in [(1, 4), (2, 5), (3, 6), (7, 8), (9, 10)] + [(i, i + 1) for i in range(11, 33, 2)]:
    mirror[a], mirror[b] = b, a
def truth_at(t, delay, period=13.0):
    # The source frame shown at t: the last one at or before it (5 frames/s).
    i = min(len(tt) - 1, int(((t + delay) % period) * 5.0 + 1e-6))
    return tp[i], tv[i]
def people(scene, t):
    """Each truth person in the scene at time t: (pixel points, visibility, box diagonal,
    visible?)."""
    out = []
    if scene == "side":
        for k, (delay, x0, flip) in enumerate([(0.0, 0, False), (1.6, 720, True)]):
            p, v = truth_at(t, delay)
            if flip:
                p, v = p[mirror].copy(), v[mirror]
                p[:, 0] = 1.0 - p[:, 0]
            px = np.c_[x0 + p[:, 0] * 720, p[:, 1] * 1280]
            out.append((px, v, np.hypot(720, 1280), True))
    else:
        bx = 1440 - (1440 + 540) * (t - 4.0) / 3.0
        a, av = truth_at(t, 0.0)
        apx = np.c_[a[:, 0] * 720, a[:, 1] * 1280]
        b, bv = truth_at(t, 6.4)
        bpx = np.c_[bx + b[:, 0] * 540, 320 + b[:, 1] * 960]
        # A is hidden where B's rectangle covers its box.
        lo, hi = apx[av > 0.5].min(0), apx[av > 0.5].max(0)
        cover = max(0.0, min(hi[0], bx + 540) - max(lo[0], bx)) / max(1.0, hi[0] - lo[0])
        # B is visible while at least half of its body's box (its visible points) is in the
        # image (its rectangle's black margins do not count).
        blo, bhi = bpx[bv > 0.5, 0].min(), bpx[bv > 0.5, 0].max()
        bvis = (min(bhi, 1440.0) - max(blo, 0.0)) / max(1.0, bhi - blo) >= 0.5
        out.append((apx, av, np.hypot(720, 1280), cover < 0.5))
        out.append((bpx, bv, np.hypot(540, 960), bvis))
    return out
for scene in ("side", "cross"):
    header, rows = load(f"{work}/{scene}.landmarks.jsonl")
    W, H = header.get("image_size", [1440, 1280])
    by_t = {}
    for r in rows:
        by_t.setdefault(round(r["t"], 3), []).append(r)
    times = sorted(by_t)
    stats = [dict(visible=0, found=0, ids=[], err=[]) for _ in range(2)]
    spanning = 0
    for t in times:
        outs = [(r.get("person", 0), np.array([p[:2] for p in r["pose"]]) * [W, H]) for r in by_t[t]]
        truth_now = people(scene, t)
        for k, (px, v, diag, vis) in enumerate(truth_now):
            if not vis:
                continue
            s = stats[k]
            s["visible"] += 1
            m = v > 0.5
            best = None
            for pid, op in outs:
                d = np.linalg.norm(op[m] - px[m], axis=1).mean() / diag
                if best is None or d < best[1]:
                    best = (pid, d)
            if best is not None and best[1] < 0.10:
                s["found"] += 1
                s["ids"].append(best[0])
                s["err"].append(100 * best[1])
        for pid, op in outs:
            if len(truth_now) < 2:
                continue
            d0 = np.linalg.norm(op - truth_now[0][0], axis=1)
            d1 = np.linalg.norm(op - truth_now[1][0], axis=1)
            near0 = (d0 < d1).mean()
            if 0.3 < near0 < 0.7:
                spanning += 1
                print(f"  spanning at t={t}: person {pid}, {near0:.2f} of its points nearer person 0")
    fps_text = open(f"{work}/{scene}.time").read().strip()
    print(f"{scene}: {len(times)} frames, capture {fps_text} s, skeletons spanning two people {spanning}")
    for k, s in enumerate(stats):
        ids = s["ids"]
        switches = sum(1 for a, b in zip(ids, ids[1:]) if a != b)
        found = 100.0 * s["found"] / max(1, s["visible"])
        err = np.mean(s["err"]) if s["err"] else float("nan")
        print(f"  person {k}: visible {s['visible']}, found {s['found']} ({found:.1f} %), "
              f"ids {sorted(set(ids))}, switches {switches}, mean error {err:.2f} % of diagonal")
PY
echo "files in $work"
