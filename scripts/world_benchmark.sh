#!/usr/bin/env bash
# The world benchmark (docs/world-benchmark.md): for each CMU clip x camera, landmarks from the
# motion capture (`synth --mocap`, scenario blazepose) -> `solve` with its defaults (no --fov)
# -> `eval-world`; then, when `convert --avatar` reads a BVH rig, the motion put on the
# performer's own skeleton and on copies with legs 20 % shorter / longer (foot figures).
# Prints one table (and OUT/results.jsonl). Split: TUNE = 131_01 with cameras 0-1; REPORT =
# 131_02 and 131_03 with cameras 2-3; the other rows are printed as "other".
#
# Usage: scripts/world_benchmark.sh BUILD OUT [--data DIR] [--quick]
#   BUILD   the build folder holding `avatarmap`
#   OUT     a folder for the files (created)
#   --data  the clips' folder (default $AVATARMAP_TEST_DATA/motion/cmu-bvh, else
#           ../shared/data/motion/cmu-bvh next to the repository)
#   --quick landmark level only (no rig outputs, no stage ablations)
# Exit 77 when the clips are missing (as a skipped test).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:?usage: world_benchmark.sh BUILD OUT [--data DIR] [--quick]}"
out="${2:?usage: world_benchmark.sh BUILD OUT [--data DIR] [--quick]}"
shift 2
data="${AVATARMAP_TEST_DATA:+$AVATARMAP_TEST_DATA/motion/cmu-bvh}"
[ -n "$data" ] || data="$root/../shared/data/motion/cmu-bvh"
quick=0
while [ $# -gt 0 ]; do
  case "$1" in
    --data) data="$2"; shift 2 ;;
    --quick) quick=1; shift ;;
    *) echo "world_benchmark.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
avm="$build/avatarmap"
[ -x "$avm" ] || { echo "world_benchmark.sh: no $avm (build first)" >&2; exit 2; }
if [ ! -f "$data/131_01.bvh" ]; then
  echo "world_benchmark.sh: no CMU clips in $data (set AVATARMAP_TEST_DATA): skipped" >&2
  exit 77
fi
mkdir -p "$out"
results="$out/results.jsonl"
: > "$results"

clips=(131_01 131_02 131_03)
# The fixed cameras: height above the floor (m), horizontal distance to the mean hips (m),
# lateral offset (m, + the performer's left), pitch (deg, + up), roll (deg), horizontal fov.
cameras=(
  "1.0 3.5 0.0 -2 0 60"
  "1.6 4.0 0.8 -12 3 50"
  "0.6 3.0 -0.6 5 -4 75"
  "1.9 4.5 0.3 -20 2 85"
)

split_of() {  # clip camera -> tune|report|other
  if [ "$1" = 131_01 ] && [ "$2" -le 1 ]; then echo tune
  elif [ "$1" != 131_01 ] && [ "$2" -ge 2 ]; then echo report
  else echo other; fi
}

# Stage switches the solver offers (found in `solve --help`, never assumed): each adds a run.
ablations=()
if [ "$quick" = 0 ]; then
  while read -r flag; do
    [ -n "$flag" ] && ablations+=("$flag")
  done < <("$avm" solve --help | grep -oE -- '--no-[a-z-]+' | grep -v -- '--no-hand-fit' | sort -u)
fi
# A rig from a BVH (another helper's work): `convert --help` names .bvh as an avatar.
bvh_rig=0
if [ "$quick" = 0 ] && "$avm" convert --help | grep -qiE -- '--avatar[^\n]*\.bvh|avatar.*\.bvh'; then
  bvh_rig=1
fi

foot_lock_switch=0
if [ "$bvh_rig" = 1 ] && "$avm" convert --help | grep -q -- '--no-foot-lock'; then
  foot_lock_switch=1
fi

# Leg-scaled copy of a CMU BVH: OFFSETs of the leg joints (hips' children down to the toes)
# multiplied by $3.
scale_legs() {
  awk -v k="$3" '
    { sub(/\r$/, "") }
    /JOINT|ROOT/ { name = $2 }
    /OFFSET/ && name ~ /^(LeftHip|RightHip|LeftKnee|RightKnee|LeftAnkle|RightAnkle)$/ {
      printf "%s OFFSET %.5f %.5f %.5f\n", substr($0, 1, index($0, "OFFSET") - 1), $2 * k, $3 * k, $4 * k
      next
    }
    { print }' "$1" > "$2"
}

row() {  # label split file.json
  python3 - "$@" <<'EOF'
import json, sys
label, split, path = sys.argv[1:4]
d = json.load(open(path))
f = lambda k, w=7, p=1: (("%" + str(w) + "." + str(p) + "f") % d[k]) if k in d else " " * (w - 1) + "-"
print("%-30s %-6s %6d %s %s %s %s %s %s %s %s %s" % (label, split, d["frames"], f("mpjpe_mm"),
      f("pa_mpjpe_mm"), f("lean_deg", 6, 2), f("accel_mm", 6, 2), f("root_cm", 6, 1),
      f("skate_cm_s", 6, 2), f("truth_skate_cm_s", 6, 2), f("penetration_cm", 6, 2),
      f("lowest_toe_cm", 6, 1)))
EOF
}

printf '%-30s %-6s %6s %7s %7s %6s %6s %6s %6s %6s %6s %6s\n' run split frames MPJPE PA-MPJ \
  lean accel root skate tskate pen lowtoe
printf '%-30s %-6s %6s %7s %7s %6s %6s %6s %6s %6s %6s %6s\n' "" "" "" mm mm deg mm/f2 cm cm/s cm/s cm cm
start=$(date +%s)
for clip in "${clips[@]}"; do
  bvh="$data/$clip.bvh"
  for c in 0 1 2 3; do
    read -r h d l p r f <<< "${cameras[$c]}"
    name="${clip}_cam$c"
    split=$(split_of "$clip" "$c")
    "$avm" synth --mocap "$bvh" -o "$out/$name.landmarks.jsonl" --seed $((c + 1)) \
      --camera-height "$h" --distance "$d" --lateral "$l" --pitch "$p" --roll "$r" --fov "$f" \
      2> "$out/$name.synth.txt"
    "$avm" solve "$out/$name.landmarks.jsonl" -o "$out/$name.pose.jsonl" --quiet 2> "$out/$name.solve.txt"
    "$avm" eval-world "$bvh" "$out/$name.pose.jsonl" --json > "$out/$name.json"
    row "$name" "$split" "$out/$name.json"
    echo "{\"run\":\"$name\",\"split\":\"$split\",\"scores\":$(cat "$out/$name.json")}" >> "$results"
    for flag in ${ablations[@]+"${ablations[@]}"}; do
      tag="${flag#--}"
      "$avm" solve "$out/$name.landmarks.jsonl" -o "$out/$name.$tag.pose.jsonl" --quiet "$flag" \
        2> /dev/null || continue
      "$avm" eval-world "$bvh" "$out/$name.$tag.pose.jsonl" --json > "$out/$name.$tag.json"
      row "$name $flag" "$split" "$out/$name.$tag.json"
      echo "{\"run\":\"$name $flag\",\"split\":\"$split\",\"scores\":$(cat "$out/$name.$tag.json")}" >> "$results"
    done
    if [ "$bvh_rig" = 1 ]; then
      for legs in 1.0 0.8 1.2; do
        rig="$out/$clip.legs$legs.bvh"
        [ -f "$rig" ] || scale_legs "$bvh" "$rig" "$legs"
        o="$out/$name.rig$legs.bvh"
        "$avm" convert "$out/$name.pose.jsonl" --avatar "$rig" -o "$o" 2> "$out/$name.convert$legs.txt" || {
          echo "  (convert onto $rig failed: see $out/$name.convert$legs.txt)"; continue; }
        extra=(); [ "$legs" = 1.0 ] || extra=(--feet-only)
        "$avm" eval-world "$bvh" "$o" --json ${extra[@]+"${extra[@]}"} > "$out/$name.rig$legs.json"
        row "$name rig legs x$legs" "$split" "$out/$name.rig$legs.json"
        echo "{\"run\":\"$name rig legs x$legs\",\"split\":\"$split\",\"scores\":$(cat "$out/$name.rig$legs.json")}" >> "$results"
        # The same without the rig's foot locking, when convert has the switch.
        if [ "$foot_lock_switch" = 1 ]; then
          "$avm" convert "$out/$name.pose.jsonl" --avatar "$rig" -o "$out/$name.rig$legs.nolock.bvh" \
            --no-foot-lock 2> /dev/null || continue
          "$avm" eval-world "$bvh" "$out/$name.rig$legs.nolock.bvh" --json ${extra[@]+"${extra[@]}"} \
            > "$out/$name.rig$legs.nolock.json"
          row "$name rig x$legs --no-foot-lock" "$split" "$out/$name.rig$legs.nolock.json"
          echo "{\"run\":\"$name rig legs x$legs --no-foot-lock\",\"split\":\"$split\",\"scores\":$(cat "$out/$name.rig$legs.nolock.json")}" >> "$results"
        fi
      done
    fi
  done
done
# Means per split and variant (the variant: the run's name without its clip and camera).
echo
echo "means per split (TUNE = 131_01 cameras 0-1, REPORT = 131_02/131_03 cameras 2-3):"
python3 - "$results" <<'EOF'
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
keys = ["mpjpe_mm", "pa_mpjpe_mm", "lean_deg", "accel_mm", "root_cm", "skate_cm_s",
        "truth_skate_cm_s", "penetration_cm", "lowest_toe_cm"]
groups = {}
for r in rows:
    variant = r["run"].split(" ", 1)[1] if " " in r["run"] else "solve (defaults)"
    groups.setdefault((r["split"], variant), []).append(r["scores"])
print("%-6s %-26s %7s %7s %6s %6s %6s %6s %6s %6s %6s" % ("split", "variant", "MPJPE", "PA-MPJ",
      "lean", "accel", "root", "skate", "tskate", "pen", "lowtoe"))
for (split, variant), v in sorted(groups.items()):
    if split == "other":
        continue
    def m(k, w, p):
        xs = [x[k] for x in v if k in x]
        return ("%" + str(w) + "." + str(p) + "f") % (sum(xs) / len(xs)) if xs else " " * (w - 1) + "-"
    print("%-6s %-26s %s %s %s %s %s %s %s %s %s" % (split, variant, m("mpjpe_mm", 7, 1),
          m("pa_mpjpe_mm", 7, 1), m("lean_deg", 6, 2), m("accel_mm", 6, 2), m("root_cm", 6, 1),
          m("skate_cm_s", 6, 2), m("truth_skate_cm_s", 6, 2), m("penetration_cm", 6, 2),
          m("lowest_toe_cm", 6, 1)))
EOF
echo "($(( $(date +%s) - start )) s; files in $out; rig outputs: $([ "$bvh_rig" = 1 ] && echo yes || echo "no: convert --avatar does not take a .bvh yet"); ablations: ${ablations[*]:-none})"
