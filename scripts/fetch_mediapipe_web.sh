#!/usr/bin/env bash
# Fetches Google's MediaPipe Pose web solution (npm @mediapipe/pose: pose.js, its wasm graph
# and the .tflite models, Apache-2.0) from a pinned npm package into a folder that
# tools/eval/mediapipe_web/reference.py serves to headless Chromium (docs/closeups.md):
#
#   <dir>/pose/{pose.js,pose_solution_*.{js,wasm,data},*.tflite,pose_web.binarypb,package.json}
#   <dir>/VERSION                                       what was fetched
#
# The version is the one the shared data's golden/upper_body_* and pose_jpg_full.json were
# made with (data/README.md). Folder: $AVATARMAP_MEDIAPIPE_WEB, default
# .cache/avatarmap/mediapipe_web in the repository (git-ignored; never committed). Idempotent:
# when VERSION names the pinned package it exits at once. The tarball is checked against the
# registry integrity pinned below before it is unpacked.
set -euo pipefail

# name@version  directory  sha512 integrity (npm view NAME@VERSION dist.integrity)
packages=(
  "@mediapipe/pose@0.5.1675469404 pose sha512-DFZsNWTsSphRIZppnUCuunzBiHP2FdJXR9ehc7mMi4KG+oPaOH0Em3d6kr7Py+TSyTXC1doH88KcF28k2sBxsQ=="
)

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=npm_pack_checked.sh
. "$root/scripts/npm_pack_checked.sh"
dest="${AVATARMAP_MEDIAPIPE_WEB:-$root/.cache/avatarmap/mediapipe_web}"
want="$(for p in "${packages[@]}"; do echo "${p%% *}"; done)"

if [ -f "$dest/VERSION" ] && [ "$(cat "$dest/VERSION")" = "$want" ] &&
   [ -f "$dest/pose/pose.js" ] && [ -f "$dest/pose/pose_landmark_full.tflite" ]; then
  echo "fetch_mediapipe_web: $(echo "$want" | tr '\n' ' ')in $dest"
  exit 0
fi
for tool in npm tar openssl base64; do
  command -v "$tool" >/dev/null || { echo "fetch_mediapipe_web: $tool is needed" >&2; exit 1; }
done

mkdir -p "$dest"
work="$(mktemp -d "$dest/.fetch.XXXXXX")"
trap 'rm -rf "$work"' EXIT
for p in "${packages[@]}"; do
  read -r spec dir integrity <<<"$p"
  tgz="$(npm_pack_checked fetch_mediapipe_web "$spec" "$integrity" "$work")"
  mkdir -p "$work/$dir"
  tar -xzf "$work/$tgz" -C "$work/$dir" --strip-components=1
  rm -f "$work/$tgz"
  rm -rf "${dest:?}/$dir"
  mv "$work/$dir" "$dest/$dir"
done
printf '%s\n' "$want" >"$dest/VERSION"
echo "fetch_mediapipe_web: $(echo "$want" | tr '\n' ' ')in $dest"
