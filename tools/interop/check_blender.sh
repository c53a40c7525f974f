#!/usr/bin/env bash
# Interoperability check against Blender's own importers: files written by `avatarmap convert`
# are imported by Blender (tools/interop/blender_check.py, run headless) and every joint's world
# position at several frames is compared with avatarmap's own forward kinematics of the same
# frames (`convert --dump-positions`, a diagnostic option). Cases:
#   proxy.bvh  the proxy skeleton (no --avatar)
#   rig.bvh    the rig of vrm1_spec_53bones.vrm (--avatar)
#   rig.glb    that avatar with the motion as a glTF animation
# Prints the largest error per file in millimetres and in millimetres per metre of the joints'
# height span, and fails when any exceeds 1 mm/m.
#
# Usage: check_blender.sh AVATARMAP_EXE WORK_DIR [DATA_DIR]
#   DATA_DIR: the shared data folder (default $AVATARMAP_TEST_DATA); without it only the proxy
#   case runs. Environment: BLENDER (default `blender`), PYTHON (default `python3`).
# Exit status: 0 all within tolerance, 1 a file is off (or a step failed), 77 skipped (no
# Blender or no Python).
set -euo pipefail

exe=${1:?usage: check_blender.sh AVATARMAP_EXE WORK_DIR [DATA_DIR]}
work=${2:?usage: check_blender.sh AVATARMAP_EXE WORK_DIR [DATA_DIR]}
data=${3:-${AVATARMAP_TEST_DATA:-}}
blender=${BLENDER:-blender}
python=${PYTHON:-python3}
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

if ! command -v "$blender" >/dev/null 2>&1; then
  echo "SKIP: $blender not found (apt-get install blender)"
  exit 77
fi
if ! command -v "$python" >/dev/null 2>&1; then
  echo "SKIP: $python not found"
  exit 77
fi

mkdir -p "$work"
cd "$work"
frames=0,7,15,29,44,59  # of the 60 written (2 s at 30 fps)

"$exe" synth -o motion.landmarks.jsonl --seconds 2 --fps 30 >/dev/null 2>&1
"$exe" convert motion.landmarks.jsonl -o motion.pose.jsonl --quiet

cases=("proxy.bvh:55")
"$exe" convert motion.pose.jsonl -o proxy.bvh --fps 30 --dump-positions proxy.bvh.ours.json \
  --quiet
avatar=""
if [[ -n "$data" && -f "$data/avatars/vrm1_spec_53bones.vrm" ]]; then
  avatar="$data/avatars/vrm1_spec_53bones.vrm"
  for out in rig.bvh rig.glb; do
    "$exe" convert motion.pose.jsonl -o "$out" --fps 30 --avatar "$avatar" \
      --dump-positions "$out.ours.json" --quiet
  done
  cases+=("rig.bvh:53" "rig.glb:53")
else
  echo "note: no shared data (DATA_DIR / AVATARMAP_TEST_DATA): VRM cases skipped"
fi

status=0
for c in "${cases[@]}"; do
  file=${c%%:*}
  min_joints=${c##*:}
  if ! "$blender" -b --factory-startup -P "$here/blender_check.py" -- --input "$file" \
      --frames "$frames" --fps 30 --bvh-scale 0.01 --out "$file.blender.json" \
      >"$file.blender.log" 2>&1 || [[ ! -s "$file.blender.json" ]]; then
    echo "FAIL $file: Blender did not import it (see $work/$file.blender.log):"
    tail -n 20 "$file.blender.log"
    status=1
    continue
  fi
  "$python" - "$file" "$file.ours.json" "$file.blender.json" "$min_joints" <<'PY' || status=1
import json, math, sys
name, ours_path, theirs_path, min_joints = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
ours = json.load(open(ours_path))["frames"]
theirs = json.load(open(theirs_path))["frames"]
worst, worst_at, height, compared = 0.0, "", 0.0, None
for k, got in theirs.items():
    want = ours[int(k)]
    common = [n for n in want if n in got]
    compared = len(common) if compared is None else min(compared, len(common))
    ys = [want[n][1] for n in common]
    if ys:
        height = max(height, max(ys) - min(ys))
    for n in common:
        e = math.dist(want[n], got[n])
        if e > worst:
            worst, worst_at = e, "%s at frame %s" % (n, k)
mm = worst * 1000.0
per_m = mm / height if height > 0 else float("inf")
ok = compared >= min_joints and per_m <= 1.0
print("%s %s: %d joints x %d frames, max error %.4f mm (%s), %.4f mm/m of a %.3f m joint span"
      % ("ok  " if ok else "FAIL", name, compared or 0, len(theirs), mm, worst_at or "-", per_m,
         height))
if compared < min_joints:
    print("     only %d joints matched by name, expected at least %d" % (compared, min_joints))
sys.exit(0 if ok else 1)
PY
done
exit $status
