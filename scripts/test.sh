#!/usr/bin/env bash
# Installs what is missing, builds, runs every test (ctest), then a short libFuzzer run of the
# file readers. Tests on real data read $AVATARMAP_TEST_DATA (default: ../shared/data beside
# the checkout, when it exists) and skip with a message without it.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
if [ -z "${AVATARMAP_TEST_DATA:-}" ] && [ -d "$root/../shared/data" ]; then
  export AVATARMAP_TEST_DATA="$(cd "$root/../shared/data" && pwd)"
fi
"$root/scripts/build.sh"
build="${AVATARMAP_BUILD_DIR:-$root/build}"
if [ "${AVATARMAP_SKIP_FUZZ:-0}" != 1 ]; then
  "$root/tools/fuzz/run.sh" "${AVATARMAP_FUZZ_SECONDS:-15}"
fi
cd "$build"
ctest --output-on-failure -j "${AVATARMAP_JOBS:-$(nproc)}"
