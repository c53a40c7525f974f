#!/usr/bin/env bash
# How `python3 -m avatarmap.batch` scales with workers (docs/python.md, "Batch on Dask";
# issue 12's figures). Whole-command wall times, configurations alternated, medians and ratios.
#
# Usage: tools/eval/batch_scaling.sh [landmarks|videos|all] [RUNS]
# Environment: AVATARMAP (default build/avatarmap), AVATARMAP_TEST_DATA (the shared data
#   folder, default ../shared/data; videos only), AVATARMAP_MODELS (capture's models),
#   PYTHON (default /usr/bin/python3), KEEP (a folder to keep the inputs in).
#  landmarks: 20 synthetic landmark files (`avatarmap synth --scenario noisy`, 300 s each at
#    30 fps with hands and the 478-point face) -> .vrma, on a local cluster of 1 and of 2
#    workers.
#  videos: 4 copies of asl_hand.25fps.mp4 and 4 of pose_squats.mp4 -> .vrma with hands and
#    face, on two single-thread workers (--workers 2 --threads 1) against one two-thread
#    worker (--workers 1 --threads 2).
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
exe=${AVATARMAP:-$here/build/avatarmap}
py=${PYTHON:-/usr/bin/python3}
what=${1:-all}
runs=${2:-3}
[ -x "$exe" ] || { echo "batch_scaling.sh: no avatarmap at $exe (set AVATARMAP)" >&2; exit 2; }
if [ -n "${KEEP:-}" ]; then
  work=$KEEP
  mkdir -p "$work"
else
  work=$(mktemp -d "${TMPDIR:-/tmp}/avatarmap-batch-XXXXXX")
  trap 'rm -rf "$work"' EXIT
fi
export PYTHONPATH="$here/bindings/python${PYTHONPATH:+:$PYTHONPATH}"

# time_batch NAME OUT ARGS...: one run's wall seconds into $work/NAME.times
time_batch() {
  local name=$1 out=$2
  shift 2
  rm -rf "$out"
  local t0 t1
  t0=$(date +%s.%N)
  "$py" -m avatarmap.batch --no-progress -o "$out" "$@" >"$work/$name.log" 2>&1 ||
    { echo "batch_scaling.sh: $name failed:" >&2; cat "$work/$name.log" >&2; exit 1; }
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" 'BEGIN {print b - a}' >>"$work/$name.times"
}

median() { sort -n "$1" | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

report() {  # report A B FRAMES: medians, frames/s and the ratio A/B
  local a b
  a=$(median "$work/$1.times")
  b=$(median "$work/$2.times")
  printf '%-28s median %7.2f s (%s)  %8.1f frames/s\n' "$1" "$a" \
    "$(sort -n "$work/$1.times" | tr '\n' ' ')" "$(awk -v f="$3" -v t="$a" 'BEGIN {print f / t}')"
  printf '%-28s median %7.2f s (%s)  %8.1f frames/s\n' "$2" "$b" \
    "$(sort -n "$work/$2.times" | tr '\n' ' ')" "$(awk -v f="$3" -v t="$b" 'BEGIN {print f / t}')"
  printf '%s / %s: %.2fx\n' "$1" "$2" "$(awk -v x="$a" -v y="$b" 'BEGIN {print x / y}')"
}

if [ "$what" = landmarks ] || [ "$what" = all ]; then
  mkdir -p "$work/lm"
  for i in $(seq 1 20); do
    f=$work/lm/take$i.landmarks.jsonl
    [ -s "$f" ] || "$exe" synth --scenario noisy --seconds 300 --seed $((100 + i)) -o "$f" >/dev/null 2>&1
  done
  frames=$((20 * 9000))
  rm -f "$work"/lm_*.times
  for r in $(seq 1 "$runs"); do
    time_batch lm_one_worker "$work/out1" "$work/lm" --to vrma --workers 1
    time_batch lm_two_workers "$work/out2" "$work/lm" --to vrma --workers 2
  done
  echo "20 landmark files (300 s each, $frames frames, $(du -sh "$work/lm" | cut -f1)) -> vrma, whole command:"
  report lm_one_worker lm_two_workers "$frames"
  tail -1 "$work/lm_two_workers.log"
fi

if [ "$what" = videos ] || [ "$what" = all ]; then
  data=${AVATARMAP_TEST_DATA:-$here/../shared/data}
  [ -d "$data/motion/tfjs-models" ] || { echo "batch_scaling.sh: no $data/motion/tfjs-models (set AVATARMAP_TEST_DATA)" >&2; exit 2; }
  mkdir -p "$work/vid"
  for i in 1 2 3 4; do
    ln -sf "$data/motion/tfjs-models/asl_hand.25fps.mp4" "$work/vid/asl$i.mp4"
    ln -sf "$data/motion/tfjs-models/pose_squats.mp4" "$work/vid/squats$i.mp4"
  done
  rm -f "$work"/vid_*.times
  for r in $(seq 1 "$runs"); do
    time_batch vid_two_workers_1_thread "$work/vo2" "$work/vid" --to vrma --workers 2 --threads 1
    time_batch vid_one_worker_2_threads "$work/vo1" "$work/vid" --to vrma --workers 1 --threads 2
  done
  frames=$(grep -o '[0-9]* frames in' "$work/vid_two_workers_1_thread.log" | tail -1 | cut -d' ' -f1)
  echo "8 videos (4x asl_hand, 4x pose_squats; $frames frames) -> vrma with hands and face:"
  report vid_one_worker_2_threads vid_two_workers_1_thread "$frames"
fi
