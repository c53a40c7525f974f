#!/usr/bin/env bash
# Jitter on real video against Google's reference landmarks through the same solve
# (docs/smoothing.md, "Jitter on real video"; issue 9's real-video figure).
#
# Usage: tools/eval/real_jitter.sh [SOLVE OPTIONS...]
# Environment: AVATARMAP (default build/avatarmap), AVATARMAP_TEST_DATA (the shared data
#   folder, default ../shared/data), AVATARMAP_MODELS (capture's models), KEEP (a folder to
#   keep the files in; default a temporary one, removed).
# For pose_squats.mp4 (5 fps) and asl_hand.25fps.mp4 it captures our landmarks
# (`capture --hands --face`, default models), imports tfjs-models' reference landmarks of the
# same video (body for the squats, the right hand for asl_hand), solves both with the same
# options (the defaults unless given) and prints `eval-pose --jitter` per group (deg/s^2,
# smaller is steadier). Each video is compared over the parts the reference has, the same for
# both: the squats over the body (`--parts body,root`; the reference has no hands or face, which
# in ours drive the wrists, neck and head -- the all-parts row is printed too), asl_hand over
# the hand alone (`--parts hands`; the reference has no body, and the video shows no legs).
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
exe=${AVATARMAP:-$here/build/avatarmap}
data=${AVATARMAP_TEST_DATA:-$here/../shared/data}
tf=$data/motion/tfjs-models
[ -x "$exe" ] || { echo "real_jitter.sh: no avatarmap at $exe (set AVATARMAP)" >&2; exit 2; }
[ -d "$tf" ] || { echo "real_jitter.sh: no $tf (set AVATARMAP_TEST_DATA)" >&2; exit 2; }
command -v python3 >/dev/null || { echo "real_jitter.sh: needs python3" >&2; exit 2; }
if [ -n "${KEEP:-}" ]; then
  work=$KEEP
  mkdir -p "$work"
else
  work=$(mktemp -d "${TMPDIR:-/tmp}/avatarmap-jitter-XXXXXX")
  trap 'rm -rf "$work"' EXIT
fi

jitter() {  # NAME LANDMARKS [SOLVE OPTIONS]
  local name=$1 in=$2
  shift 2
  "$exe" solve "$in" -o "$work/$name.pose.jsonl" --quiet "$@" 2>/dev/null
  "$exe" eval-pose --jitter "$work/$name.pose.jsonl" --json | python3 -c '
import json, sys
d = json.load(sys.stdin)
print("%-28s %9.0f %9.0f %9.0f %9.0f" % (sys.argv[1], d["torso"], d["arms"], d["legs"], d["fingers"]))
' "$name"
}

if [ ! -s "$work/squats.landmarks.jsonl" ]; then
  "$exe" capture "$tf/pose_squats.mp4" --hands --face -o "$work/squats.landmarks.jsonl" \
    >/dev/null 2>&1
fi
if [ ! -s "$work/asl.landmarks.jsonl" ]; then
  "$exe" capture "$tf/asl_hand.25fps.mp4" --hands --face -o "$work/asl.landmarks.jsonl" \
    >/dev/null 2>&1
fi
"$exe" import-tfjs "$tf/pose_squats.full.json" "$tf/pose_squats_3d.full.json" --size 720x1280 \
  --fps 5 -o "$work/squats_ref.landmarks.jsonl" 2>/dev/null
size=$(head -1 "$work/asl.landmarks.jsonl" | python3 -c '
import json, sys
w, h = json.load(sys.stdin)["image_size"]; print("%dx%d" % (w, h))')
"$exe" import-tfjs "$tf/asl_hand.full.json" "$tf/asl_hand_3d.full.json" --size "$size" \
  --fps 25 --hand right -o "$work/asl_ref.landmarks.jsonl" 2>/dev/null

printf '%-28s %9s %9s %9s %9s\n' recording torso arms legs fingers
jitter "squats, ours, all parts" "$work/squats.landmarks.jsonl" "$@"
jitter "squats body, ours" "$work/squats.landmarks.jsonl" --parts body,root "$@"
jitter "squats body, Google's" "$work/squats_ref.landmarks.jsonl" --parts body,root "$@"
jitter "asl_hand hand, ours" "$work/asl.landmarks.jsonl" --parts hands "$@"
jitter "asl_hand hand, Google's" "$work/asl_ref.landmarks.jsonl" --parts hands "$@"
