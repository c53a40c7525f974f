#!/usr/bin/env bash
# The built-in avatar and a motion on it, as three.js + @pixiv/three-vrm (what the viewer uses)
# see them, in Node (tools/interop/three_vrm_check.mjs): VRM 1.0 with 55 humanoid bones and the
# expressions, blink closing both eyes, and the animated .glb's joints where avatarmap's own
# forward kinematics puts them (1 mm).
#   check_three_vrm.sh AVATARMAP_EXE WORK_DIR
# The packages come from the npm registry, installed once into $AVATARMAP_NPM_CACHE (default:
# WORK_DIR/npm). Exit 77 (skipped) without node/npm or when they cannot be installed.
set -u
here=$(cd "$(dirname "$0")" && pwd)
exe=$1
work=$2
mkdir -p "$work"
cd "$work" || exit 1
command -v node >/dev/null && command -v npm >/dev/null || { echo "node/npm not found: skipped"; exit 77; }
npm_dir=${AVATARMAP_NPM_CACHE:-$work/npm}
if [ ! -d "$npm_dir/node_modules/@pixiv/three-vrm" ] || [ ! -d "$npm_dir/node_modules/three" ]; then
  mkdir -p "$npm_dir"
  (cd "$npm_dir" && npm install --silent --no-audit --no-fund three@0.160.0 @pixiv/three-vrm@2.1.0 >/dev/null 2>&1) ||
    { echo "could not install three and @pixiv/three-vrm from the npm registry: skipped"; exit 77; }
fi
"$exe" avatar -o builtin.vrm 2>/dev/null || { echo "avatar failed"; exit 1; }
"$exe" synth -o motion.landmarks.jsonl --seconds 2 >/dev/null 2>&1 || { echo "synth failed"; exit 1; }
"$exe" convert motion.landmarks.jsonl -o moving.glb --avatar builtin.vrm --fps 30 \
  --dump-positions moving.ours.json --quiet || exit 1
# Node resolves ES module imports from the script's folder upward, not NODE_PATH: run a copy
# beside the packages.
cp "$here/three_vrm_check.mjs" "$npm_dir/three_vrm_check.mjs" || exit 1
node "$npm_dir/three_vrm_check.mjs" builtin.vrm moving.glb moving.ours.json
