#!/usr/bin/env bash
# Dim, washed-out and half-shadowed pictures against Google's MediaPipe Pose (docs/capture.md
# "Low light").
#
#   tools/eval/lowlight.sh [OUTDIR] [--no-google-variants]     (default out/lowlight, git-ignored)
#
# From the shared photos with one person (portrait.png, pose.jpg, squats_upper.png, frame 0 of
# pose_squats.mp4, the right man of three_people.jpg) it makes, with ffmpeg, darker (every value
# times k), flatter (grey + k x the contrast), noisy dark, and half-shadowed (one side times k
# with a soft edge) versions, then runs
#   - Google's MediaPipe Pose web solution (tools/eval/mediapipe_web/reference.py, static-image
#     mode, validated bit-exact against the shared goldens) on the originals: the truth, and on
#     every version (whether Google finds the person; skipped with --no-google-variants);
#   - ours, `avatarmap capture IMAGE` with the default options and with --no-low-light.
# Per version: found or not, and the mean distance of the points (Google's on the version, ours
# with and without the lift) from Google's on the original over the points Google sees there (visibility > 0.5, inside the image), in % of the image
# diagonal; then a summary per family. A run takes about 10 minutes (3 without Google's runs on
# the versions), nearly all of it Google's.
#
# Environment: AVATARMAP_TEST_DATA (default: ../shared/data beside the checkout),
# AVATARMAP_EXE (default build/avatarmap), AVATARMAP_MODELS as for capture. Needs ffmpeg,
# chromium and python3 (standard library). Exit 77 when one is missing or there is no data.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
out="$root/out/lowlight"
google_variants=1
for a in "$@"; do
  case "$a" in
    --no-google-variants) google_variants=0 ;;
    -h | --help) sed -n '2,22p' "$0"; exit 0 ;;
    -*) echo "lowlight: unknown option $a" >&2; exit 2 ;;
    *) out="$a" ;;
  esac
done
data="${AVATARMAP_TEST_DATA:-}"
if [ -z "$data" ] && [ -d "$root/../shared/data" ]; then data="$root/../shared/data"; fi
exe="${AVATARMAP_EXE:-$root/build/avatarmap}"
mp="$root/tools/eval/mediapipe_web"
tf="$data/motion/tfjs-models"
if [ -z "$data" ] || [ ! -f "$tf/pose.jpg" ]; then echo "lowlight: no shared data" >&2; exit 77; fi
for tool in ffmpeg python3 chromium; do
  command -v "$tool" >/dev/null || { echo "lowlight: $tool is needed" >&2; exit 77; }
done
[ -x "$exe" ] || { echo "lowlight: no $exe (build it, or set AVATARMAP_EXE)" >&2; exit 1; }
"$root/scripts/fetch_mediapipe_web.sh" >&2

rm -rf "$out"
mkdir -p "$out/src" "$out/var" "$out/google_src" "$out/google" "$out/ours" "$out/plain"
ff() { ffmpeg -v error -nostdin -y "$@"; }

ff -i "$data/motion/upper_body/portrait.png" "$out/src/portrait.png"
ff -i "$tf/pose.jpg" "$out/src/pose.png"
ff -i "$data/motion/upper_body/squats_upper.png" "$out/src/squats_upper.png"
ff -i "$tf/pose_squats.mp4" -frames:v 1 "$out/src/squats0.png"
ff -i "$tf/three_people.jpg" -vf "crop=359:861:690:0" "$out/src/tp_right.png"

# The versions: name and filter. lut: every value v -> expression; shadow: one side times k,
# ramping to 1 over the middle 10 % of the width.
lut() { echo "lutrgb=r=$1:g=$1:b=$1"; }
shadow() { # side k [expression of v before the shadow]
  local side=$1 k=$2 v=${3:-}
  local f
  if [ "$side" = L ]; then
    f="if(lt(X,W*0.45),$k,if(gt(X,W*0.55),1,$k+(1-$k)*(X-W*0.45)/(W*0.1)))"
  else
    f="if(gt(X,W*0.55),$k,if(lt(X,W*0.45),1,$k+(1-$k)*(W*0.55-X)/(W*0.1)))"
  fi
  local r="r(X,Y)" g="g(X,Y)" b="b(X,Y)"
  if [ -n "$v" ]; then r="${v//v/r(X,Y)}"; g="${v//v/g(X,Y)}"; b="${v//v/b(X,Y)}"; fi
  echo "format=rgb24,geq=r='($r)*$f':g='($g)*$f':b='($b)*$f'"
}
versions="dim0.35|$(lut 'val*0.35')
dim0.2|$(lut 'val*0.2')
dim0.12|$(lut 'val*0.12')
dim0.06|$(lut 'val*0.06')
dim0.04|$(lut 'val*0.04')
flat0.3|$(lut '128+(val-128)*0.3')
flat0.15|$(lut '128+(val-128)*0.15')
flat0.08|$(lut '128+(val-128)*0.08')
flat0.05|$(lut '128+(val-128)*0.05')
dimnoise|$(lut 'val*0.12'),noise=alls=12:allf=u
shadowL0.3|$(shadow L 0.3)
shadowL0.15|$(shadow L 0.15)
shadowL0.06|$(shadow L 0.06)
shadowR0.3|$(shadow R 0.3)
shadowR0.15|$(shadow R 0.15)
shadowR0.06|$(shadow R 0.06)
shadowLflat|$(shadow L 0.15 '64+(v-128)*0.5')"
for s in "$out"/src/*.png; do
  n=$(basename "$s" .png)
  while IFS='|' read -r v filter; do
    ff -i "$s" -vf "$filter" "$out/var/${n}__$v.png"
  done <<<"$versions"
done

echo "lowlight: Google's reference on the originals" >&2
python3 "$mp/reference.py" --reuse -o "$out/google_src" "$out"/src/*.png >&2
if [ "$google_variants" = 1 ]; then
  echo "lowlight: Google's reference on $(find "$out/var" -name '*.png' | wc -l) versions" >&2
  python3 "$mp/reference.py" --reuse -o "$out/google" "$out"/var/*.png >&2
fi
echo "lowlight: ours ($exe), with and without --no-low-light" >&2
for f in "$out"/var/*.png; do
  n=$(basename "$f" .png)
  "$exe" capture "$f" -o "$out/ours/$n.landmarks.jsonl" --quiet 2>/dev/null || true
  "$exe" capture "$f" -o "$out/plain/$n.landmarks.jsonl" --quiet --no-low-light 2>/dev/null || true
done
python3 - "$out" "$google_variants" <<'PY' | tee "$out/table.md"
import json, math, os, sys
from collections import defaultdict
out, with_google = sys.argv[1], sys.argv[2] == "1"
def ours(folder, n):
    p = f"{out}/{folder}/{n}.landmarks.jsonl"
    if not os.path.exists(p):
        return None
    rows = [json.loads(l) for l in open(p) if l.strip()]
    return rows[1]["pose"] if len(rows) > 1 and "pose" in rows[1] else None
def error(g, pose):
    w, h = g["w"], g["h"]
    d = [math.hypot(p[0] - q[0] * w, p[1] - q[1] * h) for p, q in zip(g["landmarks_px"], pose)
         if p[3] > 0.5 and 0 <= p[0] < w and 0 <= p[1] < h]
    return 100 * sum(d) / len(d) / math.hypot(w, h)
names = sorted(f[:-4] for f in os.listdir(f"{out}/var"))
print("| version | Google: found, % diag | --no-low-light, % diag | default, % diag |")
print("|---|---|---|---|")
fam = defaultdict(lambda: {"n": 0, "g": 0, "ge": [], "plain": [], "ours": [], "pm": 0, "om": 0})
for n in names:
    src, v = n.split("__")
    truth = json.load(open(f"{out}/google_src/{src}_pose.json"))
    family = v.rstrip("0123456789.")
    f = fam[family]
    f["n"] += 1
    gtext = "-"
    if with_google:
        g = json.load(open(f"{out}/google/{n}_pose.json"))
        gtext = "missed"
        if g["landmarks_px"]:
            f["g"] += 1
            e = error(truth, [[p[0] / g["w"], p[1] / g["h"]] for p in g["landmarks_px"]])
            f["ge"].append(e)
            gtext = f"{e:.2f}"
    cells = []
    for key, folder in (("plain", "plain"), ("ours", "ours")):
        pose = ours(folder, n)
        if pose is None:
            f[key[0] + "m"] += 1
            cells.append("missed")
        else:
            e = error(truth, pose)
            f[key].append(e)
            cells.append(f"{e:.2f}")
    print(f"| {n} | {gtext} | {cells[0]} | {cells[1]} |")
print()
def mean(x):
    return f"{sum(x) / len(x):.2f} %" if x else "-"
for family, f in fam.items():
    g = f"Google finds {f['g']}, mean {mean(f['ge'])}; " if with_google else ""
    print(f"{family}: {f['n']} versions; {g}--no-low-light finds {f['n'] - f['pm']}, mean "
          f"{mean(f['plain'])}; default finds {f['n'] - f['om']}, mean {mean(f['ours'])}")
PY
