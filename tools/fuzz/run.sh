#!/usr/bin/env bash
# Builds the libFuzzer targets with clang and runs each for SECONDS (default 20) on a copy
# of the checked-in seed corpus. Exits non-zero when a target finds a crash; the input is
# left as crash-* in the build folder.
#   tools/fuzz/run.sh [SECONDS] [BUILD_DIR]
set -euo pipefail
seconds=${1:-20}
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${2:-$root/build-fuzz}
jobs=${AVATARMAP_FUZZ_JOBS:-2}

CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DAVATARMAP_BUILD_FUZZ=ON -DAVATARMAP_BUILD_TESTS=OFF -DAVATARMAP_BUILD_BENCH=OFF \
  -DAVATARMAP_BUILD_CLI=OFF -DAVATARMAP_BUILD_C_API=OFF -DAVATARMAP_BUILD_EXAMPLES=OFF \
  -DAVATARMAP_INSTALL=OFF >/dev/null
cmake --build "$build" -j"$jobs" --target fuzz_landmark_reader fuzz_pose_reader fuzz_formula \
  fuzz_mapping

# fuzz TARGET CORPUS DICT MAX_LEN: runs one target on a copy of its checked-in seed corpus.
fuzz() {
  local corpus="$build/corpus_$1"
  mkdir -p "$corpus"
  cp -n "$root/tools/fuzz/corpus/$2"/* "$corpus/" 2>/dev/null || true
  echo "== $1 for ${seconds}s"
  (cd "$build" && "./tools/fuzz/$1" -max_total_time="$seconds" -max_len="$4" -timeout=10 \
     -rss_limit_mb=2048 -print_final_stats=1 -dict="$root/tools/fuzz/$3" "$corpus")
}

fuzz fuzz_landmark_reader landmarks jsonl.dict 65536
fuzz fuzz_pose_reader pose jsonl.dict 65536
fuzz fuzz_formula formula formula.dict 512
fuzz fuzz_mapping mapping mapping.dict 8192
