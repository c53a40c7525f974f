#!/usr/bin/env bash
# Every .vrma and .glb avatarmap writes, and the built-in avatar, pass the Khronos glTF validator
# with 0 errors.
#   check_gltf_validator.sh AVATARMAP_EXE WORK_DIR
# The validator comes from the npm registry (package gltf-validator), installed once into
# $AVATARMAP_NPM_CACHE (default: WORK_DIR/npm). Exit 77 (skipped) without node/npm or when
# the package cannot be installed. The avatar cases need AVATARMAP_TEST_DATA.
set -u
here=$(cd "$(dirname "$0")" && pwd)
exe=$1
work=$2
mkdir -p "$work"
cd "$work" || exit 1
command -v node >/dev/null && command -v npm >/dev/null || { echo "node/npm not found: skipped"; exit 77; }
npm_dir=${AVATARMAP_NPM_CACHE:-$work/npm}
if [ ! -d "$npm_dir/node_modules/gltf-validator" ]; then
  mkdir -p "$npm_dir"
  (cd "$npm_dir" && npm install --silent --no-audit --no-fund gltf-validator@2.0.0-dev.3.10 >/dev/null 2>&1) ||
    { echo "could not install gltf-validator from the npm registry: skipped"; exit 77; }
fi
"$exe" synth -o motion.landmarks.jsonl --seconds 2 --noise 2 >/dev/null 2>&1 || { echo "synth failed"; exit 1; }
"$exe" convert motion.landmarks.jsonl -o motion.vrma --quiet || exit 1
files=(motion.vrma)
# The built-in avatar, and the motion on it (no test data needed).
"$exe" avatar -o builtin.vrm 2>/dev/null || exit 1
"$exe" convert motion.landmarks.jsonl -o builtin_moving.glb --quiet --avatar builtin.vrm || exit 1
files+=(builtin.vrm builtin_moving.glb)
if [ -n "${AVATARMAP_TEST_DATA:-}" ]; then
  for avatar in vrm1_debug_robot.vrm vrm1_spec_53bones.vrm vrm1_spec_expressions.vrm; do
    "$exe" convert motion.landmarks.jsonl -o "${avatar%.vrm}.glb" --quiet \
      --avatar "$AVATARMAP_TEST_DATA/avatars/$avatar" || exit 1
    files+=("${avatar%.vrm}.glb")
  done
fi
NODE_PATH="$npm_dir/node_modules" node "$here/validate_gltf.js" "${files[@]}"
