#!/usr/bin/env bash
# Close-up head-and-shoulders framings against Google's MediaPipe Pose (docs/closeups.md).
#
#   tools/eval/closeups.sh [OUTDIR]          (default out/closeups, git-ignored)
#
# From the shared photos with a person (portrait.png, pose.jpg, frame 0 of pose_squats.mp4,
# three regions of three_people.jpg, one per person) it cuts square head-and-shoulder crops,
# placed from Google's landmarks on the source, at four depths (the body cut just below the
# shoulders ... at the chest below the elbows) and a fifth with the top of the head cut off
# as well, resizes them to 512x512 with ffmpeg, runs
# Google's MediaPipe Pose web solution on each (tools/eval/mediapipe_web/reference.py,
# static-image mode, modelComplexity 1, validated bit-exact against the shared goldens) and
# ours (`avatarmap capture CROP.png`, default options), and prints per crop the mean error in
# % of the crop's diagonal over the points Google sees (visibility > 0.5, inside the image)
# and the shoulder (11, 12) and elbow (13, 14) errors in px, then a summary.
#
# Environment: AVATARMAP_TEST_DATA (default: ../shared/data beside the checkout),
# AVATARMAP_EXE (default build/avatarmap), AVATARMAP_MODELS as for capture. Needs ffmpeg,
# chromium, python3 and the package scripts/fetch_mediapipe_web.sh fetches (run here when
# missing). Exit 77 when chromium, ffmpeg or the data is missing.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
out="${1:-$root/out/closeups}"
data="${AVATARMAP_TEST_DATA:-}"
if [ -z "$data" ]; then
  for d in "$root/../shared/data"; do [ -d "$d" ] && { data="$d"; break; }; done
fi
exe="${AVATARMAP_EXE:-$root/build/avatarmap}"
mp="$root/tools/eval/mediapipe_web"
tf="$data/motion/tfjs-models"
if [ -z "$data" ] || [ ! -f "$tf/pose.jpg" ]; then echo "closeups: no shared data" >&2; exit 77; fi
for tool in ffmpeg ffprobe python3; do
  command -v "$tool" >/dev/null || { echo "closeups: $tool is needed" >&2; exit 77; }
done
[ -x "$exe" ] || { echo "closeups: no $exe (build it, or set AVATARMAP_EXE)" >&2; exit 1; }
"$root/scripts/fetch_mediapipe_web.sh" >&2

rm -rf "$out"
mkdir -p "$out/src" "$out/crops" "$out/google_src" "$out/google" "$out/ours"
ff() { ffmpeg -v error -nostdin -y "$@"; }

# Sources: name, the image Google's reference is made on, its offset in the full photo, the
# full photo's size. three_people: one region per person (Google's pose finds one person).
ff -i "$data/motion/upper_body/portrait.png" "$out/src/portrait.png"
ff -i "$tf/pose.jpg" "$out/src/pose.png"
ff -i "$tf/pose_squats.mp4" -frames:v 1 "$out/src/squats0.png"
ff -i "$tf/three_people.jpg" "$out/src/three_people.png"
#        name      x   y   w   h
regions="tp_left   0   0   560 861
tp_mid    80  300 620 561
tp_right  690 0   359 861"
while read -r name x y w h; do
  ff -i "$out/src/three_people.png" -vf "crop=$w:$h:$x:$y" "$out/src/$name.png"
done <<<"$regions"

size() { ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=p=0 "$1" | tr , ' '; }
{
  for s in portrait pose squats0; do echo "$s $out/src/$s.png 0 0 $(size "$out/src/$s.png")"; done
  tp="$(size "$out/src/three_people.png")"
  while read -r name x y w h; do echo "$name $out/src/$name.png $x $y $tp"; done <<<"$regions"
} >"$out/sources.tsv"

echo "closeups: Google's reference on the sources" >&2
# shellcheck disable=SC2046
python3 "$mp/reference.py" --reuse -o "$out/google_src" $(awk '{print $2}' "$out/sources.tsv") >&2
python3 "$mp/closeups.py" boxes "$out/sources.tsv" "$out/google_src" >"$out/crops.tsv"

# The crops: square, from the full photo, resized to 512x512 (ffmpeg's default bicubic).
while read -r crop name x y side _; do
  case "$name" in tp_*) photo="$out/src/three_people.png" ;; *) photo="$out/src/$name.png" ;; esac
  ff -i "$photo" -vf "crop=$side:$side:$x:$y,scale=512:512" "$out/crops/$crop.png"
done <"$out/crops.tsv"

echo "closeups: Google's reference on $(wc -l <"$out/crops.tsv") crops" >&2
python3 "$mp/reference.py" --reuse -o "$out/google" "$out"/crops/*.png >&2
echo "closeups: ours ($exe)" >&2
while read -r crop _; do
  "$exe" capture "$out/crops/$crop.png" -o "$out/ours/$crop.landmarks.jsonl" --quiet
done <"$out/crops.tsv"
python3 "$mp/closeups.py" table "$out/crops.tsv" "$out/google" "$out/ours" | tee "$out/table.md"
