#!/usr/bin/env bash
# Accuracy of `avatarmap solve` on the synthetic generator's recordings (docs/accuracy.md).
#
# Usage: tools/eval/accuracy.sh [SEEDS...]      (default: the held-out seeds 101-105)
#   Seeds 1-5 are for tuning, 101-105 for the report: never tune on the report seeds.
# Environment: AVATARMAP (the tool; default build/avatarmap beside this checkout),
#   SECONDS_PER_RUN (default 20), FPS (default 30), SIZE (default 1280x720),
#   FILTERS (default "default none": solve's defaults, and --filter none for comparison),
#   KEEP (a folder to keep the files in; default: a temporary folder, removed),
#   SOLVE_ARGS (more options for every solve, e.g. "--smoothing 1.5").
# For each seed and scenario (clean, noisy) it synthesises a recording with its truth, solves
# it with each filter setting and prints one row of mean errors in degrees ("-" where a
# recording has no low-visibility burst). A last row per scenario and filter gives the mean
# over the seeds. Columns: bone-direction error overall and per group, head orientation,
# "body" (torso, arms and legs together), "lv-frame" (every bone on the frames with a
# low-visibility burst), "lv-bone" (the bones of the limbs in a burst only), and the face:
# "blink" (mean absolute error of each eye's closure), "jaw" (jawOpen, from the files'
# blendshapes), "visemes" (the mean of aa, ih, ou, ee, oh's errors) and "gaze" (degrees,
# the eyes relative to the head). Needs python3 (to read eval-pose --json).
set -euo pipefail

here=$(cd "$(dirname "$0")/../.." && pwd)
exe=${AVATARMAP:-$here/build/avatarmap}
seconds=${SECONDS_PER_RUN:-20}
fps=${FPS:-30}
size=${SIZE:-1280x720}
filters=${FILTERS:-default none}
if [ ! -x "$exe" ]; then
  echo "accuracy.sh: no avatarmap at $exe; build it or set AVATARMAP=path/to/avatarmap" >&2
  exit 2
fi
command -v python3 >/dev/null || { echo "accuracy.sh: needs python3" >&2; exit 2; }
seeds=("$@")
[ ${#seeds[@]} -gt 0 ] || seeds=(101 102 103 104 105)
for s in "${seeds[@]}"; do
  [[ $s =~ ^[0-9]+$ ]] || { echo "accuracy.sh: seeds are integers, got '$s'" >&2; exit 2; }
done

if [ -n "${KEEP:-}" ]; then
  work=$KEEP
  mkdir -p "$work"
else
  work=$(mktemp -d "${TMPDIR:-/tmp}/avatarmap-accuracy-XXXXXX")
  trap 'rm -rf "$work"' EXIT
fi

printf '%-6s %-6s %-8s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s\n' seed scene filter \
  overall torso arms legs fingers head body lv-frame lv-bone blink jaw visemes gaze
declare -A sums counts
for scene in clean noisy; do
  for seed in "${seeds[@]}"; do
    base=$work/$scene-$seed
    "$exe" synth --scenario "$scene" --seed "$seed" --seconds "$seconds" --fps "$fps" \
      --size "$size" -o "$base.landmarks.jsonl" --truth "$base.truth.pose.jsonl" 2>/dev/null
    for filter in $filters; do
      args=()
      [ "$filter" = default ] || args=(--filter "$filter")
      "$exe" solve "$base.landmarks.jsonl" -o "$base.$filter.pose.jsonl" --quiet \
        ${args[@]+"${args[@]}"} ${SOLVE_ARGS:-} 2>/dev/null
      json=$("$exe" eval-pose "$base.truth.pose.jsonl" "$base.$filter.pose.jsonl" --json)
      row=$(python3 -c '
import json, sys
d = json.loads(sys.stdin.read()); a = d["all"]; m = d["marked"]; lv = d["low_visibility"]
v = [a[k]["mean"] for k in ("overall", "torso", "arms", "legs", "fingers", "head")]
n = sum(a[k]["count"] for k in ("torso", "arms", "legs"))
v.append(sum(a[k]["mean"] * a[k]["count"] for k in ("torso", "arms", "legs")) / max(n, 1))
f = lambda s, ok: "%.4f" % s if ok else "-"
fa = d["face"]
face = [fa["blink"]["mean"], fa["jawOpen"]["mean"],
        sum(fa[k]["mean"] for k in ("aa", "ih", "ou", "ee", "oh")) / 5, fa["gaze"]["mean"]]
print(" ".join("%.4f" % x for x in v), f(lv["overall"]["mean"], lv["overall"]["count"] > 0),
      f(m["mean"], m["count"] > 0), " ".join("%.4f" % x for x in face))
' <<<"$json")
      read -r o t a l f h body lf m fb fj fv fg <<<"$row"
      fmt() { [ "$1" = - ] && echo - || printf '%.2f' "$1"; }
      printf '%-6s %-6s %-8s %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8s %8s %8.3f %8.3f %8.3f %8.2f\n' \
        "$seed" "$scene" "$filter" "$o" "$t" "$a" "$l" "$f" "$h" "$body" "$(fmt "$lf")" \
        "$(fmt "$m")" "$fb" "$fj" "$fv" "$fg"
      key="$scene $filter"
      vals=("$o" "$t" "$a" "$l" "$f" "$h" "$body" "$lf" "$m" "$fb" "$fj" "$fv" "$fg")
      for i in "${!vals[@]}"; do
        [ "${vals[$i]}" = - ] && continue
        sums[$key.$i]=$(awk -v x="${sums[$key.$i]:-0}" -v y="${vals[$i]}" 'BEGIN{print x + y}')
        counts[$key.$i]=$((${counts[$key.$i]:-0} + 1))
      done
    done
  done
  for filter in $filters; do
    key="$scene $filter"
    means=()
    for i in 0 1 2 3 4 5 6 7 8 9 10 11 12; do
      if [ -n "${counts[$key.$i]:-}" ]; then
        format=%.2f
        [ "$i" -ge 9 ] && [ "$i" -le 11 ] && format=%.3f
        means+=("$(awk -v x="${sums[$key.$i]}" -v n="${counts[$key.$i]}" -v f="$format" \
          'BEGIN{printf f, x / n}')")
      else
        means+=(-)
      fi
    done
    printf '%-6s %-6s %-8s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s\n' mean "$scene" \
      "$filter" "${means[@]}"
  done
done
