#!/usr/bin/env bash
# Lag against jitter of the live filter (`solve --filter live`, `live`, avm_solver_push): the
# table of docs/smoothing.md, "Live: lag against jitter". One row per setting of the rotation
# filter, from live_filter_eval (tools/eval/live_filter.cpp; the columns are explained there).
#
# Usage: tools/eval/live_filter.sh [SETTING...]
#   SETTING: live_filter_eval's options in one word with commas for spaces, e.g.
#   "--min-cutoff,1,--beta,2" (default: the settings of the documented table).
# Environment: BUILD (the build folder; default build/ beside this checkout; needs the
#   avatarmap and live_filter_eval targets), AVATARMAP_TEST_DATA (the test data; its
#   motion/tfjs-models/asl_hand.25fps.mp4 and pose_squats.mp4 are captured with
#   `avatarmap capture --hands --face`, which needs the models: AVATARMAP_MODELS; without them
#   the video columns are left out), SEEDS (synthetic seeds for the error columns; default
#   "1 2 3": tuning seeds only, never the held-out 101-105), FPS (default 30),
#   KEEP (a folder to keep the files in; default: a temporary folder, removed).
set -euo pipefail

here=$(cd "$(dirname "$0")/../.." && pwd)
build=${BUILD:-$here/build}
exe=$build/avatarmap
eval_exe=$build/tools/eval/live_filter_eval
fps=${FPS:-30}
read -r -a seeds <<<"${SEEDS:-1 2 3}"
for x in "$exe" "$eval_exe"; do
  [ -x "$x" ] || { echo "live_filter.sh: no $x; build the avatarmap and live_filter_eval targets or set BUILD" >&2; exit 2; }
done
for s in "${seeds[@]}"; do
  [[ $s =~ ^[0-9]+$ ]] || { echo "live_filter.sh: seeds are integers, got '$s'" >&2; exit 2; }
  if [ "$s" -ge 101 ] && [ "$s" -le 105 ]; then
    echo "live_filter.sh: seeds 101-105 are held out for the report (docs/accuracy.md); tune on 1-5" >&2
    exit 2
  fi
done
if [ -n "${KEEP:-}" ]; then
  work=$KEEP
  mkdir -p "$work"
else
  work=$(mktemp -d "${TMPDIR:-/tmp}/avatarmap-live-filter-XXXXXX")
  trap 'rm -rf "$work"' EXIT
fi

# Synthetic recordings with their truth (as tools/eval/accuracy.sh makes them).
inputs=()
for scene in clean noisy; do
  for seed in "${seeds[@]}"; do
    base=$work/$scene-$seed
    [ -s "$base.landmarks.jsonl" ] ||
      "$exe" synth --scenario "$scene" --seed "$seed" --seconds 20 --fps 30 --size 1280x720 \
        -o "$base.landmarks.jsonl" --truth "$base.truth.pose.jsonl" 2>/dev/null
    inputs+=("--$scene" "$base.landmarks.jsonl" "$base.truth.pose.jsonl")
  done
done

# Real video, captured once.
videos=${AVATARMAP_TEST_DATA:-}/motion/tfjs-models
for v in asl_hand.25fps:asl pose_squats:squats; do
  file=$videos/${v%%:*}.mp4
  name=${v##*:}
  out=$work/$name.landmarks.jsonl
  if [ ! -s "$out" ]; then
    if [ -z "${AVATARMAP_TEST_DATA:-}" ] || [ ! -f "$file" ] ||
      ! "$exe" capture "$file" --hands --face -o "$out" --quiet 2>"$work/capture.err"; then
      echo "live_filter.sh: no $name column (set AVATARMAP_TEST_DATA and AVATARMAP_MODELS to capture $file)" >&2
      rm -f "$out"
      continue
    fi
  fi
  inputs+=(--video "$name" "$out")
done

settings=("$@")
if [ ${#settings[@]} -eq 0 ]; then
  # shellcheck disable=SC2054  # commas separate each setting's options, not the elements
  settings=(
    --none
    --legacy
    # One Euro, speed from the output (as before), no extrapolation: min cutoff, beta, d_cutoff
    --min-cutoff,0.7,--beta,0.3,--predict,0
    --min-cutoff,1.5,--beta,1,--predict,0
    --min-cutoff,1.5,--beta,2,--predict,0
    --min-cutoff,3,--beta,0.5,--predict,0
    --min-cutoff,0.5,--beta,2,--predict,0
    --min-cutoff,1.5,--beta,0.5,--d-cutoff,0.5,--predict,0
    --min-cutoff,1.5,--beta,0.5,--d-cutoff,2,--predict,0
    # the input's velocity as the speed (the reference implementations' derivative)
    --speed,input,--min-cutoff,1,--beta,2,--predict,0
    --speed,input,--min-cutoff,1.5,--beta,2,--predict,0
    --speed,input,--min-cutoff,1,--beta,2,--d-cutoff,0.3,--predict,0
    # extrapolation along the input's velocity
    --predict-from,input,--d-cutoff,0.5
    --speed,input,--min-cutoff,1,--beta,1,--d-cutoff,0.3,--predict,0.5,--predict-from,input
    # extrapolation along the filtered velocity: the defaults (no options), and around them
    ""
    --predict,1
    --predict,0.75,--max-predict,0.1
    --min-cutoff,0.5,--beta,0.5,--d-cutoff,0.5,--predict,0.5
    --min-cutoff,1.5,--beta,0.5,--predict,1
  )
fi

printf '%-72s ' setting
"$eval_exe" --header --fps "$fps" "${inputs[@]}"
for s in "${settings[@]}"; do
  IFS=, read -r -a args <<<"$s"
  printf '%-72s ' "${s:-(defaults)}"
  "$eval_exe" --fps "$fps" ${args[@]+"${args[@]}"} "${inputs[@]}"
done
