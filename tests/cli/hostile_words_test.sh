#!/usr/bin/env bash
# Messages in our words (issue 8): broken JSON in a mapping table (--rig FILE.json) or in the
# tfjs recordings (import-tfjs) is reported as "FILE: invalid JSON at line L, column C: what is
# wrong", never with a library's text ("[json.exception.out_of_range.406] ..."); deep nesting
# is refused before the parser recurses; a rig no table fits points at --rig and --bind.
# Exit status 1 or 2, never a signal, nothing written. The avatar cases need
# $AVATARMAP_TEST_DATA (skipped with a message when unset).
# Usage: hostile_words_test.sh AVATARMAP_EXE WORK_DIR. Prints "N passed, N failed".
source "$(dirname "$0")/hostile_lib.sh" "$@"

# ours FILE: no library text in FILE.
ours() {
  if grep -qE 'json\.exception|\[json|parse_error|out_of_range|basic_string|vector::' "$1"; then
    fail "$1 quotes a library: $(head -c 400 "$1")"
  else ok; fi
}

# --- import-tfjs: broken JSON ------------------------------------------------------------
printf '[[[1e400,0,0]]]' >big_number.json
run 1 import-tfjs big_number.json big_number.json --size 640x480 --fps 30 -o a.landmarks.jsonl
expect_in err.txt "big_number.json: invalid JSON at line 1, column 4: the number 1e400 is too large"
ours err.txt
absent a.landmarks.jsonl
printf '[[[1,2,3]],\n [[4,5,6]' >cut.json
run 1 import-tfjs cut.json cut.json --size 640x480 --fps 30 -o b.landmarks.jsonl
expect_in err.txt "cut.json: invalid JSON at line 2"
expect_in err.txt "ends too early"
ours err.txt
head -c 200000 /dev/zero | tr '\0' '[' >deep.json
run 1 import-tfjs deep.json deep.json --size 640x480 --fps 30 -o c.landmarks.jsonl
expect_in err.txt "deep.json: JSON nests deeper than 128 levels"
ours err.txt
printf '{"frames": []}' >object.json
run 1 import-tfjs object.json object.json --size 640x480 --fps 30 -o d.landmarks.jsonl
expect_in err.txt "expected a JSON array of frames (tfjs-models test format), got an object"
printf '[[[1,2,3]]]' >one_point.json
run 1 import-tfjs one_point.json one_point.json --size 640x480 --fps 30 -o e.landmarks.jsonl
expect_in err.txt "frame 0: expected an array of 33 points, got an array of 1"

# --- mapping tables and rigs (need an avatar) ---------------------------------------------
if [ -n "${AVATARMAP_TEST_DATA:-}" ] && [ -d "$AVATARMAP_TEST_DATA/avatars" ]; then
  avatars=$AVATARMAP_TEST_DATA/avatars
  "$exe" synth -o in.landmarks.jsonl --seconds 0.2 --no-face >/dev/null 2>&1 ||
    fail "synth failed"
  printf '{"format_version": 1,\n "units_scale": 1e400, "name": "t", "bones": {}}' >big.json
  run 1 convert in.landmarks.jsonl -o big.glb --avatar "$avatars/gltf_cesium_man.glb" --rig big.json
  expect_in err.txt "big.json: invalid JSON at line 2, column 17: the number 1e400 is too large"
  ours err.txt
  absent big.glb
  printf '{"format_version": 1, "name": "t", "bones": {"hips": {"rig": "H", "f": [1, "y", "z"]}}}' \
    >typed.json
  run 1 convert in.landmarks.jsonl -o typed.glb --avatar "$avatars/gltf_cesium_man.glb" --rig typed.json
  expect_in err.txt "typed.json: bones.hips.f[0]: expected a string, got a number"
  ours err.txt
  { printf '{"format_version": 1, "name": "t", "bones": {}, "x": '
    head -c 100000 /dev/zero | tr '\0' '['; } >nested.json
  run 1 convert in.landmarks.jsonl -o nested.glb --avatar "$avatars/gltf_cesium_man.glb" --rig nested.json
  expect_in err.txt "nested.json: JSON nests deeper than 128 levels"
  absent nested.glb
  run 1 convert in.landmarks.jsonl -o man.glb --avatar "$avatars/gltf_cesium_man.glb"
  expect_in err.txt "no mapping table fits"
  expect_in err.txt "--rig NAME"
  expect_in err.txt "--bind BONE=JOINT"
  expect_in err.txt "avatarmap inspect $avatars/gltf_cesium_man.glb"
  absent man.glb
else
  skip_part "AVATARMAP_TEST_DATA is not set: the mapping-table and rig cases"
fi

finish
