#!/usr/bin/env bash
# Prepares what the ONNX capture backend needs, idempotently: ONNX Runtime from npm
# (scripts/fetch_onnxruntime.sh), MediaPipe's .tflite models (scripts/fetch_models.sh), and
# their ONNX conversions by the project's own converter (tools/convert/tflite2onnx.py) into
# <models>/onnx. A model is converted again when its .tflite is newer than its .onnx or the
# conversion options changed (kept in <model>.onnx.args).
# Needs npm and Debian's python3 with python3-onnx and python3-numpy (scripts/setup.sh).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
models="${AVATARMAP_MODELS:-$root/.cache/avatarmap/models}"
"$root/scripts/fetch_onnxruntime.sh"
"$root/scripts/fetch_models.sh"
mkdir -p "$models/onnx"
# name [outputs to drop]: pose_landmark's 256x256 segmentation output is not used and costs
# much of its time (REFERENCE §4); its heatmap is kept: the pipeline refines the landmarks from
# it as MediaPipe does (max error on pose.jpg 9.1 px with it, 15.2 px without).
while read -r name drop; do
  src="$models/$name.tflite"
  dst="$models/onnx/$name.onnx"
  if [ -f "$dst" ] && [ "$dst" -nt "$src" ] && [ "$(cat "$dst.args" 2>/dev/null)" = "$drop" ]; then
    continue
  fi
  echo "prepare_capture: converting $name"
  args=()
  [ -n "$drop" ] && args=(--drop-outputs "$drop")
  /usr/bin/python3 "$root/tools/convert/tflite2onnx.py" "${args[@]}" "$src" "$dst.tmp"
  mv "$dst.tmp" "$dst"
  printf '%s' "$drop" >"$dst.args"
done <<'LIST'
pose_detection
pose_landmark_lite Identity_2
pose_landmark_full Identity_2
pose_landmark_heavy Identity_2
palm_detection_lite
palm_detection_full
hand_landmark_lite
hand_landmark_full
face_detection_short_range
face_landmark
LIST
# FLOPs per inference of each model, for bench/bench_models.cpp's share of the CPU's peak
# (-maxdepth 1: not the optimised copies in onnx/ort-optimized/, docs/capture.md "Start-up").
if [ ! -f "$models/onnx/flops.json" ] || [ -n "$(find "$models/onnx" -maxdepth 1 -name '*.onnx' -newer "$models/onnx/flops.json")" ]; then
  /usr/bin/python3 "$root/tools/models/count_flops.py" "$models/onnx"/*.onnx \
    --json "$models/onnx/flops.json" >/dev/null
fi
echo "prepare_capture: ONNX Runtime and $(ls "$models/onnx"/*.onnx | wc -l) ONNX models ready in $models/onnx"
