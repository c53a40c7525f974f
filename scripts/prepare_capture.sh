#!/usr/bin/env bash
# Prepares what the ONNX capture backend needs, idempotently: ONNX Runtime from npm
# (scripts/fetch_onnxruntime.sh), MediaPipe's .tflite models (scripts/fetch_models.sh), and
# their ONNX conversions by the project's own converter (tools/convert/tflite2onnx.py) into
# <models>/onnx. A model is converted again only when its .tflite is newer than its .onnx.
# Needs npm and Debian's python3 with python3-onnx and python3-numpy (scripts/setup.sh).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
models="${AVATARMAP_MODELS:-$root/.cache/avatarmap/models}"
"$root/scripts/fetch_onnxruntime.sh"
"$root/scripts/fetch_models.sh"
mkdir -p "$models/onnx"
# name [outputs to drop]: pose_landmark's 256x256 segmentation and heatmap outputs are not
# used by the pipeline and cost about half its time (REFERENCE §4).
while read -r name drop; do
  src="$models/$name.tflite"
  dst="$models/onnx/$name.onnx"
  [ -f "$dst" ] && [ "$dst" -nt "$src" ] && continue
  echo "prepare_capture: converting $name"
  args=()
  [ -n "$drop" ] && args=(--drop-outputs "$drop")
  /usr/bin/python3 "$root/tools/convert/tflite2onnx.py" "${args[@]}" "$src" "$dst.tmp"
  mv "$dst.tmp" "$dst"
done <<'LIST'
pose_detection
pose_landmark_lite Identity_2,Identity_3
pose_landmark_full Identity_2,Identity_3
pose_landmark_heavy Identity_2,Identity_3
palm_detection_lite
palm_detection_full
hand_landmark_lite
hand_landmark_full
face_detection_short_range
face_landmark
LIST
echo "prepare_capture: ONNX Runtime and $(ls "$models/onnx" | wc -l) ONNX models ready in $models"
