#!/usr/bin/env bash
# Output names and the clips behind them through the tool (issue 9, one writer table): every
# command that writes a clip chooses the format from the output's extension in any case
# (.VRMA is a .vrma), refuses an unknown one before any work with one message that lists the
# formats, writes .glb without an avatar on the built-in one, and refuses to scale root motion by a standing hips
# height that is not above the floor; a refused run writes nothing and keeps an existing file.
# Usage: hostile_output_names_test.sh AVATARMAP_EXE WORK_DIR. Prints "N passed, N failed".
source "$(dirname "$0")/hostile_lib.sh" "$@"

run 0 synth -o clip.landmarks.jsonl --seconds 1

# --- extensions in any case -------------------------------------------------------------------
run 0 convert clip.landmarks.jsonl -o UPPER.VRMA --quiet
if [ "$(head -c 4 UPPER.VRMA)" = "glTF" ]; then ok; else fail "UPPER.VRMA is not a GLB"; fi
run 0 convert clip.landmarks.jsonl -o Mixed.Bvh --quiet
if head -n 1 Mixed.Bvh | grep -q '^HIERARCHY'; then ok; else fail "Mixed.Bvh is not a BVH"; fi
run 0 convert clip.landmarks.jsonl -o Poses.POSE.JSONL --quiet
expect_in Poses.POSE.JSONL '"format":"avatarmap.pose"'
# Inputs too: a .VRMA reads as VRM Animation.
run 0 convert UPPER.VRMA -o again.pose.jsonl --fps 30
expect_in err.txt "converted 30 input frames (0.97 s) into 30 frames at 30 fps"

# --- an unknown extension: one message listing the formats, nothing written ----------------------
echo precious >keep.fbx
run 2 convert clip.landmarks.jsonl -o keep.fbx
expect_in err.txt "keep.fbx: unknown output format; the name must end in .vrma, .glb, .bvh or .pose.jsonl (any case)"
kept keep.fbx precious
run 2 animate no-such-video.mp4 -o out.fbx
expect_in err.txt "out.fbx: unknown output format; the name must end in .vrma, .glb, .bvh or .pose.jsonl"
absent out.fbx
# --- .glb in any case without --avatar: the built-in avatar ------------------------------------
run 0 convert clip.landmarks.jsonl -o out.GLB
expect_in err.txt "avatar (built-in):"
expect_in out.GLB "VRMC_vrm"
run 1 animate no-such-video.mp4 -o out.Glb
expect_in err.txt "no-such-video.mp4"
absent out.Glb

# --- root motion needs hips above the floor -------------------------------------------------------
data=${AVATARMAP_TEST_DATA:-}
avatar=$data/avatars/vrm1_spec_53bones.vrm
if [ -n "$data" ] && [ -f "$avatar" ]; then
  # Poses whose hips sit at y = 0 in every frame: no standing height to scale root motion by.
  printf '{"format":"avatarmap.pose"}\n{"t":0,"hips_position":[0,0,0]}\n{"t":0.1,"hips_position":[0.1,0,0]}\n' >flat.pose.jsonl
  echo precious >flat.bvh
  run 1 convert flat.pose.jsonl -o flat.bvh --avatar "$avatar"
  expect_in err.txt "flat.pose.jsonl: the performer's standing hips height"
  expect_in err.txt "turn root motion off"
  kept flat.bvh precious
  run 0 convert flat.pose.jsonl -o flat_still.bvh --avatar "$avatar" --no-root-motion --quiet
  if head -n 1 flat_still.bvh | grep -q '^HIERARCHY'; then ok; else fail "flat_still.bvh is not a BVH"; fi
  run 0 convert clip.landmarks.jsonl -o Avatar.GLB --avatar "$avatar" --quiet
  if [ "$(head -c 4 Avatar.GLB)" = "glTF" ]; then ok; else fail "Avatar.GLB is not a GLB"; fi
else
  skip_part "AVATARMAP_TEST_DATA is not set: the avatar cases"
fi
no_temp

finish
