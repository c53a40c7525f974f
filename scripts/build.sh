#!/usr/bin/env bash
# Configures and builds avatarmap (Release) into build/ (or $AVATARMAP_BUILD_DIR).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${AVATARMAP_BUILD_DIR:-$root/build}"
jobs="${AVATARMAP_JOBS:-$(nproc)}"
# The ONNX capture backend is built when ONNX Runtime has been fetched
# (scripts/prepare_capture.sh); $AVATARMAP_WITH_ONNX=0/1 forces it off/on.
onnx=OFF
ort="${AVATARMAP_ONNXRUNTIME_DIR:-$root/.cache/avatarmap/onnxruntime}"
[ -e "$ort/lib/libonnxruntime.so.1" ] && onnx=ON
case "${AVATARMAP_WITH_ONNX:-}" in 0) onnx=OFF ;; 1) onnx=ON ;; esac
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DAVATARMAP_WITH_ONNX="$onnx" >/dev/null
cmake --build "$build" -j "$jobs"
