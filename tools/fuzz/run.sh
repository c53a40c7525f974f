#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan, docs/fuzzing.md) and either fuzzes
# each for SECONDS (default 15) or replays every corpus once.
#   tools/fuzz/run.sh [SECONDS] [TARGET...]   fuzz (all targets by default), one after another
#   tools/fuzz/run.sh --replay [TARGET...]    run every seed, regression and shared-data input
#                                            once (scripts/sanitize.sh does this)
# Corpora: the checked-in seeds (tools/fuzz/corpus/<name>), the inputs of fixed crashes
# (tools/fuzz/regressions/<name>) and, when $AVATARMAP_TEST_DATA is set, the shared real files
# (avatars, .vrma, CMU BVH clips, tfjs-models recordings), copied at run time, never committed.
# What a fuzz run finds is added to build-fuzz/corpus_<target> and kept between runs.
# Environment: AVATARMAP_FUZZ_BUILD_DIR (default build-fuzz), AVATARMAP_FUZZ_JOBS (build jobs,
# default 2). Exits non-zero when a target crashes or breaks an invariant; the input is left in
# build-fuzz/artifacts/<target>/ (minimise it with -minimize_crash=1, keep it under
# tools/fuzz/regressions/<target>/ once fixed).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${AVATARMAP_FUZZ_BUILD_DIR:-$root/build-fuzz}
jobs=${AVATARMAP_FUZZ_JOBS:-2}
fuzz_dir=$root/tools/fuzz

mode=run
seconds=15
if [ "${1:-}" = --replay ]; then
  mode=replay
  shift
elif [[ "${1:-}" =~ ^[0-9]+$ ]]; then
  seconds=$1
  shift
fi

# name | seed folder | dictionary | -max_len while fuzzing
targets=(
  "fuzz_landmark_reader|landmarks|jsonl.dict|65536"
  "fuzz_pose_reader|pose|jsonl.dict|65536"
  "fuzz_formula|formula|formula.dict|512"
  "fuzz_mapping|mapping|mapping.dict|16384"
  "fuzz_avatar|avatar|gltf.dict|1048576"
  "fuzz_vrma|vrma|gltf.dict|1048576"
  "fuzz_bvh|bvh|bvh.dict|65536"
  "fuzz_tfjs|tfjs|tfjs.dict|65536"
  "fuzz_resample|resample||512"
)
selected=("$@")
wanted() {
  [ ${#selected[@]} -eq 0 ] && return 0
  local s
  for s in "${selected[@]}"; do [ "$s" = "$1" ] && return 0; done
  return 1
}

launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "${launcher[@]}" -DAVATARMAP_BUILD_FUZZ=ON -DAVATARMAP_BUILD_TESTS=OFF \
  -DAVATARMAP_BUILD_BENCH=OFF -DAVATARMAP_BUILD_CLI=OFF -DAVATARMAP_BUILD_C_API=OFF \
  -DAVATARMAP_BUILD_EXAMPLES=OFF -DAVATARMAP_INSTALL=OFF >/dev/null
cmake --build "$build" -j"$jobs" --target avatarmap_fuzz_targets

# shared_inputs NAME DIR: copies the real files that seed target NAME into DIR: the shipped
# mapping tables, and the shared test data when $AVATARMAP_TEST_DATA is set.
shared_inputs() {
  if [ "$1" = fuzz_mapping ]; then
    cp "$root"/mappings/*.json "$2"/
    return 0
  fi
  local data=${AVATARMAP_TEST_DATA:-}
  [ -n "$data" ] && [ -d "$data" ] || return 0
  case $1 in
    fuzz_avatar) cp "$data"/avatars/*.vrm "$data"/avatars/*.glb "$data"/avatars/*.vrma "$2"/ ;;
    fuzz_vrma) cp "$data"/avatars/*.vrma "$2"/ ;;
    fuzz_bvh) cp "$data"/motion/cmu-bvh/*.bvh "$2"/ ;;
    fuzz_tfjs)
      # The first three frames of the BlazePose recording (the whole pair is 270 kB): image
      # points, the separator, world points.
      local tfjs=$data/motion/tfjs-models
      if command -v python3 >/dev/null && [ -e "$tfjs/pose_squats.full.json" ]; then
        python3 - "$tfjs/pose_squats.full.json" "$tfjs/pose_squats_3d.full.json" \
          >"$2/pose_squats_3_frames.txt" <<'EOF'
import json, sys
image, world = (json.load(open(p))[:3] for p in sys.argv[1:3])
sys.stdout.write(json.dumps(image) + "\n===\n" + json.dumps(world))
EOF
      fi
      ;;
  esac
}

export UBSAN_OPTIONS="print_stacktrace=1:suppressions=$fuzz_dir/ubsan.supp:${UBSAN_OPTIONS:-}"
failed=()
for entry in "${targets[@]}"; do
  IFS='|' read -r name seeds dict max_len <<<"$entry"
  wanted "$name" || continue
  exe="$build/tools/fuzz/$name"
  shared="$build/shared_$name"
  rm -rf "$shared"
  mkdir -p "$shared"
  shared_inputs "$name" "$shared"
  if [ "$mode" = replay ]; then
    # Every input once, each file by name (libFuzzer then never writes into these folders).
    inputs=()
    for d in "$fuzz_dir/corpus/$seeds" "$fuzz_dir/regressions/$seeds" "$shared"; do
      [ -d "$d" ] || continue
      for f in "$d"/*; do [ -f "$f" ] && inputs+=("$f"); done
    done
    echo "== $name: replaying ${#inputs[@]} inputs"
    if ! "$exe" -rss_limit_mb=2048 -timeout=60 "${inputs[@]}" >"$build/replay_$name.log" 2>&1; then
      tail -n 60 "$build/replay_$name.log"
      failed+=("$name")
    fi
    continue
  fi
  corpus="$build/corpus_$name"
  artifacts="$build/artifacts/$name"
  mkdir -p "$corpus" "$artifacts"
  cp -n "$fuzz_dir/corpus/$seeds"/* "$corpus"/ 2>/dev/null || true
  extra=("$shared")
  [ -d "$fuzz_dir/regressions/$seeds" ] && extra+=("$fuzz_dir/regressions/$seeds")
  echo "== $name for ${seconds}s"
  if ! nice -n 10 "$exe" -max_total_time="$seconds" -max_len="$max_len" -timeout=10 \
      -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$artifacts/" \
      ${dict:+-dict="$fuzz_dir/$dict"} "$corpus" "${extra[@]}"; then
    echo "$name: crash or broken invariant; input in $artifacts/" >&2
    failed+=("$name")
  fi
done

if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz $mode: failed: ${failed[*]}" >&2
  exit 1
fi
echo "fuzz $mode: all targets passed"
