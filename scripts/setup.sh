#!/usr/bin/env bash
# Installs what avatarmap needs from Debian's packages, only when something is missing
# (idempotent; a no-op on a prepared machine). Used by scripts/demo.sh and scripts/test.sh.
set -euo pipefail

packages=(build-essential cmake ninja-build pkg-config
          libglm-dev libeigen3-dev nlohmann-json3-dev libtinygltf-dev
          libgtest-dev libgmock-dev libbenchmark-dev libstb-dev python3
          libavformat-dev libavcodec-dev libavutil-dev libswscale-dev
          libavdevice-dev ffmpeg  # devices (v4l2:, lavfi:); the ffmpeg tool streams in tests
          python3-onnx python3-numpy  # python3-onnx: the tflite -> ONNX converter (tools/convert)
          liblo-tools  # oscdump, oscsend: the independent OSC receiver of the VMC tests
          # The Python package (docs/python.md): its tests, a venv to pip-install it into,
          # and Dask for `python3 -m avatarmap.batch`.
          python3-pytest python3-venv python3-pip python3-wheel python3-distributed)
# The browser viewer (docs/viewer.md): its server library, and headless Chromium for its tests.
packages+=(libwebsockets-dev chromium python3-pil)
# The fuzz run and the sanitizer run (scripts/test.sh, scripts/sanitize.sh) need clang with its
# sanitizer runtime.
if [ "${AVATARMAP_SKIP_FUZZ:-0}" != 1 ] || [ "${AVATARMAP_SKIP_SANITIZE:-0}" != 1 ]; then
  packages+=(clang libclang-rt-14-dev)
fi
# Optional: Blender, for the add-on's test (docs/blender.md; CTest label `blender`) and
# interop.blender. Large (about 480 MB with what it pulls in), so only when asked:
# AVATARMAP_WITH_BLENDER=1.
if [ "${AVATARMAP_WITH_BLENDER:-0}" = 1 ]; then
  packages+=(blender)
fi

missing=()
for p in "${packages[@]}"; do
  [ -n "$p" ] || continue
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=""
  if [ "$(id -u)" != 0 ]; then sudo_cmd="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo_cmd apt-get update -qq
  $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The viewer's JavaScript modules (three.js, three-vrm) from npm into the cache; without the
# registry the viewer's tests skip and `avatarmap view` says what to run.
"$(dirname "${BASH_SOURCE[0]}")/fetch_viewer_modules.sh" ||
  echo "setup: warning: the viewer's modules could not be fetched (scripts/fetch_viewer_modules.sh)" >&2
# Khronos's glTF validator from npm, for the tests that validate the files we write; without
# it those checks skip.
"$(dirname "${BASH_SOURCE[0]}")/fetch_gltf_validator.sh" ||
  echo "setup: warning: the glTF validator could not be fetched (scripts/fetch_gltf_validator.sh)" >&2
