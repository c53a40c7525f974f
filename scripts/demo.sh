#!/usr/bin/env bash
# The main job on a built-in default: installs what is missing, builds, synthesises a
# 10-second recording of a scripted motion, solves it and prints the summary.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
AVATARMAP_SKIP_FUZZ=1 "$root/scripts/setup.sh"
"$root/scripts/build.sh" >/dev/null
exec "${AVATARMAP_BUILD_DIR:-$root/build}/avatarmap" demo "$@"
