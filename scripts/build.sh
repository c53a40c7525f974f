#!/usr/bin/env bash
# Configures and builds avatarmap (Release) into build/ (or $AVATARMAP_BUILD_DIR).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${AVATARMAP_BUILD_DIR:-$root/build}"
jobs="${AVATARMAP_JOBS:-$(nproc)}"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" -j "$jobs"
