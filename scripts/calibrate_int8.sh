#!/usr/bin/env bash
# Recomputes the activation ranges of the int8 models (tools/models/int8_ranges/*.json, committed)
# from real frames of the shared test data; scripts/prepare_capture.sh then builds the int8
# models from them. Needed only when the float conversions or the calibration set change.
# Calibration set (docs/convert.md "int8 models"): frames 0-31 of pose_squats.mp4, frames 0-161
# of asl_hand.25fps.mp4 and three_people.jpg; the other frames and pose.jpg, hands.jpg and
# portrait.jpg (the goldens) are held out for the agreement figures.
# Usage: scripts/calibrate_int8.sh BUILD_DIR DATA_DIR [MODEL ...]
#   BUILD_DIR: a build with AVATARMAP_WITH_ONNX=ON (tools/convert: capture_crops, ort_calib)
#   DATA_DIR:  the shared test data folder (motion/tfjs-models/)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:?usage: calibrate_int8.sh BUILD_DIR DATA_DIR [MODEL ...]}"
data="${2:?usage: calibrate_int8.sh BUILD_DIR DATA_DIR [MODEL ...]}"
shift 2
models="${AVATARMAP_MODELS:-$root/.cache/avatarmap/models}/onnx"
out="$root/tools/models/int8_ranges"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
d="$data/motion/tfjs-models"
"$build/tools/convert/capture_crops" --models "$models" --out "$work" \
  "$d/pose_squats.mp4@0-31" "$d/asl_hand.25fps.mp4@0-161" "$d/three_people.jpg"
mkdir -p "$out"
# model name -> the crops it is fed
crops_of() {
  case "$1" in
    pose_landmark_*) echo pose_landmark ;;
    palm_detection_*) echo palm_detection ;;
    hand_landmark_*) echo hand_landmark ;;
    *) echo "$1" ;;
  esac
}
list=("$@")
[ ${#list[@]} -eq 0 ] && list=(pose_detection pose_landmark_lite pose_landmark_full
  palm_detection_lite palm_detection_full hand_landmark_lite hand_landmark_full
  face_detection_short_range face_landmark)
for name in "${list[@]}"; do
  crops="$(crops_of "$name")"
  /usr/bin/python3 "$root/tools/convert/quantize.py" instrument "$models/$name.onnx" "$work/$name.onnx"
  "$build/tools/convert/ort_calib" "$work/$name.onnx" "$work/$crops.f32" "$work/$name.json"
  /usr/bin/python3 - "$work/$name.json" "$work/$crops.txt" "$out/$name.json" "$name" <<'PY'
import json, sys
ranges = json.load(open(sys.argv[1]))
sources = {}
for line in open(sys.argv[2]):
    f = line.split()
    sources.setdefault(f[0], set()).add(int(f[1]))
doc = {"model": sys.argv[4] + ".onnx",
       "calibrated_on": {k: f"frames {min(v)}-{max(v)} ({len(v)} frames)" for k, v in sorted(sources.items())},
       "samples": ranges["samples"],
       "tensors": {k: ranges["tensors"][k] for k in sorted(ranges["tensors"])}}
tmp = sys.argv[3] + ".tmp"
with open(tmp, "w") as f:
    json.dump(doc, f, indent=0, sort_keys=False)
    f.write("\n")
import os
os.replace(tmp, sys.argv[3])
PY
  echo "calibrate_int8: $name ($(cat "$work/$crops.txt" | wc -l) crops) -> $out/$name.json"
done
