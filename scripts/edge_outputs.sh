#!/usr/bin/env bash
# Runs a fixed set of avatarmap commands (CLI and Python) on real data and fixed-seed synth
# recordings and prints "sha256  name" for every file written, sorted by name, so that a
# refactor can be shown to leave every output byte-identical:
#   scripts/edge_outputs.sh BUILD_A OUT_A; scripts/edge_outputs.sh BUILD_B OUT_B
#   diff OUT_A/SHA256SUMS OUT_B/SHA256SUMS
# BUILD_DIR holds avatarmap and bindings/c/libavatarmap_c.so; OUT_DIR must be new or empty.
# Inputs: $AVATARMAP_TEST_DATA (default <repo>/../shared/data), $AVATARMAP_MODELS (default
# <repo>/.cache/avatarmap/models), $PYTHON (default: the first python3 with NumPy).
# Besides the outputs, the list holds NAME.refused (exit status and message of a command
# expected to fail, or of a Python call that refuses what the CLI takes), NAME.warnings
# (the "warning" lines a command printed) and NAME.FAILED (a command that should have
# worked; the script then exits 1). Lines ending in "(timing-dependent)" (live) differ
# from run to run by design: compare them by hand. Logs are in OUT_DIR/logs (not listed).
set -euo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 BUILD_DIR OUT_DIR" >&2
  exit 2
fi
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$(cd "$1" && pwd)
out=$2
data=${AVATARMAP_TEST_DATA:-$here/../shared/data}
export AVATARMAP_MODELS=${AVATARMAP_MODELS:-$here/.cache/avatarmap/models}
pydir=${AVATARMAP_PYTHON_DIR:-$here/bindings/python}
A=$build/avatarmap
clib=$build/bindings/c/libavatarmap_c.so
tfjs=$data/motion/tfjs-models
robot=$data/avatars/vrm1_debug_robot.vrm

[[ -x $A ]] || { echo "$0: no $A" >&2; exit 2; }
[[ -d $data/avatars && -d $tfjs ]] || { echo "$0: no test data in $data" >&2; exit 2; }
mkdir -p "$out"
if [[ -n $(ls -A "$out") ]]; then
  echo "$0: $out is not empty (stale files would enter the list); give a new folder" >&2
  exit 2
fi
out=$(cd "$out" && pwd)
cd "$out"   # every generated file is named relative to OUT_DIR (paths can enter messages)
mkdir logs
failed=0
start=$SECONDS

# Paths that differ between runs or machines, masked in recorded messages.
mask() { sed -e "s|$out|OUT|g" -e "s|$data|DATA|g" -e "s|$build|BUILD|g" -e "s|$here|REPO|g"; }

# run NAME CMD...: runs CMD (echoed), log in logs/NAME.log; its warning lines go to
# NAME.warnings; a failure is recorded as NAME.FAILED and the run goes on.
run() {
  local name=$1; shift
  echo "+ $*" >&2
  local rc=0
  "$@" >"logs/$name.log" 2>&1 || rc=$?
  if [[ $rc -ne 0 ]]; then
    { echo "exit $rc"; mask <"logs/$name.log"; } >"$name.FAILED"
    echo "FAILED ($rc): $name; see $out/logs/$name.log" >&2
    failed=1
  elif grep -qi warning "logs/$name.log"; then
    grep -i warning "logs/$name.log" | mask >"$name.warnings"
  fi
}

# refuse NAME CMD...: CMD is expected to fail; its exit status and message go to NAME.refused.
refuse() {
  local name=$1; shift
  echo "+ $* (expected to fail)" >&2
  local rc=0
  "$@" >"logs/$name.log" 2>&1 || rc=$?
  if [[ $rc -ne 0 ]]; then
    { echo "exit $rc"; mask <"logs/$name.log"; } >"$name.refused"
  else
    echo "note: $name: expected a refusal, the command succeeded" >&2
  fi
}

# ---- 1. inputs: fixed-seed synth recordings, real reference landmarks, the built-in avatar
run synth_noisy   "$A" synth -o synth.landmarks.jsonl --scenario noisy --seconds 3 --seed 7 \
                       --truth synth.truth.pose.jsonl
run synth_demo    "$A" synth -o demo.landmarks.jsonl --seconds 2 --seed 1
run builtin_vrm   "$A" avatar -o builtin.vrm
run import_squats "$A" import-tfjs "$tfjs/pose_squats.full.json" "$tfjs/pose_squats_3d.full.json" \
                       --size 720x1280 --fps 5 -o squats.landmarks.jsonl
run import_hand   "$A" import-tfjs "$tfjs/asl_hand.full.json" "$tfjs/asl_hand_3d.full.json" \
                       --size 620x1080 --fps 25 --hand right -o asl_hand.landmarks.jsonl

# ---- 2. solve: landmarks -> poses
run solve_synth    "$A" solve synth.landmarks.jsonl -o synth.pose.jsonl
run solve_synth_t1 "$A" solve synth.landmarks.jsonl -o synth.t1.pose.jsonl --threads 1
run solve_synth_live "$A" solve synth.landmarks.jsonl -o synth.live.pose.jsonl --filter live --confidence
run solve_demo     "$A" solve demo.landmarks.jsonl -o demo.pose.jsonl --fps 60
run solve_squats   "$A" solve squats.landmarks.jsonl -o squats.pose.jsonl
run solve_hand     "$A" solve asl_hand.landmarks.jsonl -o asl_hand.pose.jsonl

# A pose file with two frames out of time order (frames 2 and 3 swapped; line 1 is the header).
awk 'NR==4 { held = $0; next } NR==5 { print; print held; next } { print }' \
  synth.pose.jsonl >ooo.pose.jsonl

# ---- 3. convert: every output format, without an avatar, with a data-dir VRM and with the
# built-in avatar (.glb without one is refused)
for ext in vrma glb bvh pose.jsonl; do
  if [[ $ext == glb ]]; then
    refuse "convert_synth_none.$ext" "$A" convert synth.pose.jsonl -o "c.synth.none.$ext"
  else
    run "convert_synth_none.$ext" "$A" convert synth.pose.jsonl -o "c.synth.none.$ext"
  fi
  run "convert_synth_robot.$ext"   "$A" convert synth.pose.jsonl -o "c.synth.robot.$ext" --avatar "$robot"
  run "convert_synth_builtin.$ext" "$A" convert synth.pose.jsonl -o "c.synth.builtin.$ext" --avatar builtin.vrm
done
run convert_synth_fps60   "$A" convert synth.pose.jsonl -o c.synth.fps60.vrma --fps 60
run convert_synth_vrm0    "$A" convert synth.pose.jsonl -o c.synth.vrm0.glb --avatar "$data/avatars/vrm0_sphere.vrm"
run convert_landmarks     "$A" convert synth.landmarks.jsonl -o c.synthlm.none.vrma
run convert_squats_vrma   "$A" convert squats.pose.jsonl -o c.squats.none.vrma
run convert_squats_glb    "$A" convert squats.pose.jsonl -o c.squats.robot.glb --avatar "$robot"
# .vrma in: one convert wrote, and a real one from the data dir
for ext in vrma bvh pose.jsonl; do
  run "convert_vrma_none.$ext" "$A" convert c.synth.none.vrma -o "c.fromvrma.none.$ext"
done
run convert_vrma_builtin "$A" convert c.synth.none.vrma -o c.fromvrma.builtin.glb --avatar builtin.vrm
run convert_cliptest     "$A" convert "$data/avatars/clip_test.vrma" -o c.cliptest.none.pose.jsonl
# out-of-order pose file (converted with a warning)
for ext in vrma bvh pose.jsonl; do
  run "convert_ooo_none.$ext" "$A" convert ooo.pose.jsonl -o "c.ooo.none.$ext"
done
run convert_ooo_builtin "$A" convert ooo.pose.jsonl -o c.ooo.builtin.glb --avatar builtin.vrm

# ---- 4-6. capture, animate, live: need the ONNX backend and the converted models
skip_capture=""
if ! "$A" backends 2>/dev/null | grep -q '^onnx'; then
  skip_capture="this build has no onnx backend ($A backends)"
elif [[ ! -f $AVATARMAP_MODELS/onnx/pose_detection.onnx ]]; then
  skip_capture="no models in $AVATARMAP_MODELS/onnx (scripts/prepare_capture.sh)"
fi
if [[ -n $skip_capture ]]; then
  echo "skipped capture: $skip_capture" >&2
  echo "skipped animate: $skip_capture" >&2
  echo "skipped live: $skip_capture" >&2
else
  # pose_squats.mp4: 720x1280, 5 fps, 13 s (65 frames); asl_hand.25fps.mp4: 620x1080, 25 fps
  run capture_squats "$A" capture "$tfjs/pose_squats.mp4" -o cap.squats.landmarks.jsonl \
                          --seconds 3 --hands --face --overlay cap.squats.overlay.png --quiet
  run capture_hand   "$A" capture "$tfjs/asl_hand.25fps.mp4" -o cap.hand.landmarks.jsonl \
                          --seconds 2 --hands --quiet
  run solve_cap_squats "$A" solve cap.squats.landmarks.jsonl -o cap.squats.pose.jsonl
  # animate has no --seconds: the whole squats clip (65 frames)
  run animate_glb  "$A" animate "$tfjs/pose_squats.mp4" -o anim.squats.builtin.glb --avatar builtin.vrm \
                        --keep-landmarks anim.squats.landmarks.jsonl --quiet
  run animate_vrma "$A" animate "$tfjs/pose_squats.mp4" -o anim.squats.none.vrma --quiet
  # live paces the file as a camera and drops frames by wall clock: timing-dependent
  run live_squats  "$A" live "$tfjs/pose_squats.mp4" -o live.squats.pose.jsonl --seconds 3 \
                        --fps 30 --threads 1 --quiet
fi

# ---- 7. Python: avatarmap.convert_file on the same inputs, through BUILD_DIR's C library
py=${PYTHON:-}
if [[ -z $py ]]; then
  for cand in python3 /usr/bin/python3; do
    if command -v "$cand" >/dev/null && "$cand" -c 'import numpy' 2>/dev/null; then py=$cand; break; fi
  done
fi
if [[ -z $py ]]; then
  echo "skipped python: no python3 with NumPy (set PYTHON)" >&2
else
  # name|input|output|fps|avatar   (fps "" = convert_file's default, 0: the frames' own times)
  pyjobs=(
    "py_synth_default.vrma|synth.pose.jsonl|py.synth.default.vrma||"
    "py_synth_none.vrma|synth.pose.jsonl|py.synth.none.vrma|30|"
    "py_synth_builtin.glb|synth.pose.jsonl|py.synth.builtin.glb||builtin.vrm"
    "py_synth_robot.glb|synth.pose.jsonl|py.synth.robot.glb||$robot"
    "py_synth_none.bvh|synth.pose.jsonl|py.synth.none.bvh|30|"
    "py_landmarks_none.vrma|synth.landmarks.jsonl|py.synthlm.none.vrma|30|"
    "py_fromvrma_none.pose.jsonl|c.synth.none.vrma|py.fromvrma.none.pose.jsonl||"
    "py_ooo_none.vrma|ooo.pose.jsonl|py.ooo.none.vrma|30|"
    "py_ooo_builtin.glb|ooo.pose.jsonl|py.ooo.builtin.glb||builtin.vrm"
  )
  for job in "${pyjobs[@]}"; do
    IFS='|' read -r name src dst fps avatar <<<"$job"
    echo "+ $py -c avatarmap.convert_file('$src', '$dst', fps=${fps:-default}, avatar=${avatar:-None})" >&2
    rc=0
    PYTHONPATH=$pydir AVATARMAP_C_LIBRARY=$clib PYTHONDONTWRITEBYTECODE=1 "$py" -c '
import sys, avatarmap
src, dst, fps, avatar = sys.argv[1:5]
kw = {}
if fps: kw["fps"] = float(fps)
if avatar: kw["avatar"] = avatar
try:
    avatarmap.convert_file(src, dst, **kw)
except avatarmap.AvatarmapError as e:
    print("%s: %s" % (type(e).__name__, e))
    sys.exit(3)
' "$src" "$dst" "$fps" "$avatar" >"logs/$name.log" 2>&1 || rc=$?
    if [[ $rc -eq 3 ]]; then
      mask <"logs/$name.log" >"$name.refused"
      echo "python-refused $src -> $dst: $(mask <"logs/$name.log")" >&2
    elif [[ $rc -ne 0 ]]; then
      { echo "exit $rc"; mask <"logs/$name.log"; } >"$name.FAILED"
      echo "FAILED ($rc): $name; see $out/logs/$name.log" >&2
      failed=1
    fi
  done
fi

# ---- checksums: every file but the logs, sorted by name
find . -type f ! -path './logs/*' ! -name SHA256SUMS -printf '%P\n' | LC_ALL=C sort |
  while IFS= read -r f; do
    sum=$(sha256sum -- "$f" | cut -d' ' -f1)
    case $f in
      live*) echo "$sum  $f  (timing-dependent)" ;;
      *) echo "$sum  $f" ;;
    esac
  done >SHA256SUMS
cat SHA256SUMS
echo "edge_outputs: $(wc -l <SHA256SUMS) files in $out, $((SECONDS - start)) s" >&2
exit "$failed"
