#!/usr/bin/env bash
# The main job on a built-in default: installs what is missing, builds, synthesises a
# 10-second recording of a scripted motion, solves it and prints the summary, then writes the
# motion onto the built-in avatar (avatarmap-demo/demo.glb, .vrma, avatar.vrm) and says how to
# watch it.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
AVATARMAP_SKIP_FUZZ=1 "$root/scripts/setup.sh"
"$root/scripts/build.sh" >/dev/null
exec "${AVATARMAP_BUILD_DIR:-$root/build}/avatarmap" demo "$@"
