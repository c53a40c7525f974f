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
# face_landmark_with_attention (the 478-point mesh with irises) holds three MediaPipe custom
# operators that the converter rewrites as standard ONNX (docs/convert.md "Custom operators").
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
face_landmark_with_attention
LIST
# int8 versions (<name>.int8.onnx) from the float ones and the activation ranges calibrated on
# real frames (tools/models/int8_ranges/<name>.json, made by scripts/calibrate_int8.sh; docs/
# convert.md "int8 models"). Rebuilt when the float model, the ranges, the quantizer or the
# options (kept in <name>.int8.onnx.args) change; written to a temporary file and moved into
# place, so an interrupted run leaves no half-written model. What stays float in each model was
# decided by measurement (docs/capture.md "int8 models"): the layers whose quantization costs
# the most agreement (measured one at a time on calibration crops) in pose_landmark_full and
# hand_landmark_full; the palm and face models are kept entirely float (--all-float), since
# their int8 versions were no faster (PReLU has no int8 kernel) or missed the tolerances.
quantizer="$root/tools/convert/quantize.py"
while read -r name qargs; do
  src="$models/onnx/$name.onnx"
  ranges="$root/tools/models/int8_ranges/$name.json"
  dst="$models/onnx/$name.int8.onnx"
  [ -f "$ranges" ] || continue
  if [ -f "$dst" ] && [ "$dst" -nt "$src" ] && [ "$dst" -nt "$ranges" ] && [ "$dst" -nt "$quantizer" ] &&
    [ "$(cat "$dst.args" 2>/dev/null)" = "$qargs" ]; then
    continue
  fi
  echo "prepare_capture: quantizing $name"
  # shellcheck disable=SC2086  # qargs is a list of options
  /usr/bin/python3 "$quantizer" quantize "$src" "$ranges" "$dst.tmp" $qargs >/dev/null
  mv "$dst.tmp" "$dst"
  printf '%s' "$qargs" >"$dst.args"
done <<'LIST'
pose_detection --calibration minmax --float-tail 1
pose_landmark_lite --all-float
pose_landmark_full --calibration minmax --float-tail 1 --float-from n_Conv__403 --float-nodes n_Conv__7,n_Conv__14
palm_detection_lite --all-float
palm_detection_full --all-float
hand_landmark_lite --calibration minmax --float-tail 1 --float-nodes n_Conv__5,n_Conv__12
hand_landmark_full --calibration minmax --float-tail 1 --float-from n_Conv__287 --float-nodes n_Conv__5,n_Conv__12,n_Conv__19,n_Conv__23,n_Conv__30
face_detection_short_range --all-float
face_landmark --all-float
LIST
# FLOPs per inference of each model, for bench/bench_models.cpp's share of the CPU's peak
# (-maxdepth 1: not the optimised copies in onnx/ort-optimized/, docs/capture.md "Start-up").
if [ ! -f "$models/onnx/flops.json" ] || [ -n "$(find "$models/onnx" -maxdepth 1 -name '*.onnx' ! -name '*.int8.onnx' -newer "$models/onnx/flops.json")" ]; then
  /usr/bin/python3 "$root/tools/models/count_flops.py" $(ls "$models/onnx"/*.onnx | grep -v '\.int8\.onnx$') \
    --json "$models/onnx/flops.json" >/dev/null
fi
echo "prepare_capture: ONNX Runtime and $(ls "$models/onnx"/*.onnx | grep -vc '\.int8\.onnx$') ONNX models" \
  "($(ls "$models/onnx"/*.int8.onnx 2>/dev/null | wc -l) int8) ready in $models/onnx"
