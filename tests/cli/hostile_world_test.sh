#!/usr/bin/env bash
# `avatarmap synth --mocap` and `avatarmap eval-world` (docs/world-benchmark.md): bad usage and
# bad files give a clear error (exit 1 or 2, never a signal) without writing outputs; with the
# shared data, a round trip synth -> solve -> eval-world on a CMU clip, and the truth against
# itself scores 0.
# Usage: hostile_world_test.sh EXE WORK_DIR
# shellcheck source=hostile_lib.sh
source "$(dirname "$0")/hostile_lib.sh"

# A tiny BVH with both arms but no legs, and one with a non-finite value.
legless() {
  cat <<'EOF'
HIERARCHY
ROOT Hips
{
OFFSET 0 0 0
CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
JOINT Neck
{
OFFSET 0 0.5 0
CHANNELS 3 Zrotation Xrotation Yrotation
End Site
{
OFFSET 0 0.2 0
}
}
}
MOTION
Frames: 2
Frame Time: 0.0333333
EOF
  echo "0 1 0 0 0 0 0 0 0"
  echo "0 1 0 0 0 0 ${1:-0} 0 0"
}
legless >legless.bvh
legless nan >nan.bvh

run 2 synth --mocap legless.bvh
expect_in err.txt "-o OUT.landmarks.jsonl"
run 1 synth --mocap missing.bvh -o a.landmarks.jsonl
expect_in err.txt "missing.bvh"
absent a.landmarks.jsonl
run 1 synth --mocap legless.bvh -o a.landmarks.jsonl
expect_in err.txt "no left hip"
absent a.landmarks.jsonl
absent a.camera.json
run 1 synth --mocap nan.bvh -o a.landmarks.jsonl
absent a.landmarks.jsonl
run 2 synth --mocap legless.bvh -o a.landmarks.jsonl --fov 500
expect_in err.txt "field of view"
run 2 synth --mocap legless.bvh -o a.landmarks.jsonl --scenario noisy
expect_in err.txt "blazepose or clean"
run 2 synth --mocap legless.bvh -o a.landmarks.jsonl --fps -3
run 2 eval-world legless.bvh
expect_in err.txt "TRUTH.bvh and SOLVED"
run 2 eval-world a.bvh b.pose.jsonl --units 0
run 1 eval-world missing.bvh b.pose.jsonl
expect_in err.txt "missing.bvh"
run 1 eval-world legless.bvh b.pose.jsonl
expect_in err.txt "no left hip"
run ok eval-world --help
expect_in out.txt "MPJPE"

clip="${AVATARMAP_TEST_DATA:-}/motion/cmu-bvh/131_03.bvh"
if [ -z "${AVATARMAP_TEST_DATA:-}" ] || [ ! -f "$clip" ]; then
  skip_part "AVATARMAP_TEST_DATA is not set: the CMU round trip"
else
  # A pose file that is not one, and a BVH as its own solved take (metres per unit as given).
  echo '{"t":0,"bones":{}}' >bad.pose.jsonl
  run 1 eval-world "$clip" bad.pose.jsonl
  run ok eval-world "$clip" "$clip" --solved-units 0.056444 --json
  expect_in out.txt '"mpjpe_mm":0.000'
  expect_in out.txt '"root_cm":0.000'
  # Skate equals the truth's own speed on its planted frames (the floor of the figure).
  skate=$(grep -o '"skate_cm_s":[0-9.]*' out.txt | cut -d: -f2)
  expect_in out.txt "\"truth_skate_cm_s\":$skate,"
  # The round trip with a fixed camera: the camera sidecar, then scores that are finite.
  run ok synth --mocap "$clip" -o rec.landmarks.jsonl --camera-height 1.2 --distance 3.5 \
    --lateral 0 --pitch -5 --roll 0 --fov 60 --seed 2
  expect_in rec.camera.json '"horizontal_fov_degrees":60.0000'
  expect_in rec.camera.json '"pitch_degrees":-5.0000'
  expect_in err.txt "inside the image"
  frames=$(($(wc -l <rec.landmarks.jsonl) - 1))
  [ "$frames" -gt 250 ] && pass || fail "rec.landmarks.jsonl has $frames frames"
  run ok solve rec.landmarks.jsonl -o solved.pose.jsonl --quiet
  run ok eval-world "$clip" solved.pose.jsonl --json
  expect_in out.txt "\"frames\":$frames,"
  expect_not_in out.txt "nan"
  run ok eval-world "$clip" solved.pose.jsonl
  for word in MPJPE PA-MPJPE 'torso lean' 'root error' 'foot skate' penetration; do
    expect_in out.txt "$word"
  done
  # A truth too short for the solved take's times: refused, not scored.
  run 1 eval-world legless.bvh solved.pose.jsonl
fi
finish
