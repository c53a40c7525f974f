#!/usr/bin/env bash
# Hostile avatars through the CLI: hostile_avatar_test.sh AVATARMAP_EXE WORK_DIR.
# `avatarmap inspect` and `convert --avatar` (to .glb and .bvh) on avatars built to crash the
# loader (20,000 levels of JSON in extras or VRMC_vrm, text and GLB; broken GLB chunk
# lengths), to leak a file (buffer or image URIs ../secret.txt, absolute, file:, a symbolic
# link out of the folder) or to pass a wrong rig (hips node 2^40, a zero scale): exit status 1
# with a message naming the file and the fault, never a signal, no output created or
# replaced, the secret in no output. A legitimate avatar with a buffer in a subfolder and an
# external texture converts, and the texture's bytes are in the .glb.
# Registered with CTest as cli.hostile_avatar_test by tests/cli/CMakeLists.txt.
source "$(dirname "$0")/hostile_lib.sh" "$@"

# repeat TEXT N: TEXT N times.
repeat() { printf "%${2}s" '' | sed "s/ /$1/g"; }

# u32 N: N as 4 little-endian bytes.
u32() { printf "$(printf '\\x%02x\\x%02x\\x%02x\\x%02x' $(($1 & 255)) $((($1 >> 8) & 255)) \
  $((($1 >> 16) & 255)) $((($1 >> 24) & 255)))"; }

# glb JSON_FILE OUT [TOTAL_DELTA [BIN_FILE]]: packs a JSON file (and a BIN chunk of a length
# that is a multiple of 4) into a GLB; the header's total length is off by TOTAL_DELTA.
glb() {
  local json=$1 out=$2 delta=${3:-0} bin=${4:-}
  cp "$json" glb_json.tmp
  while [ $(($(wc -c <glb_json.tmp) % 4)) -ne 0 ]; do printf ' ' >>glb_json.tmp; done
  local n b=0
  n=$(wc -c <glb_json.tmp)
  [ -n "$bin" ] && b=$((8 + $(wc -c <"$bin")))
  {
    printf 'glTF'; u32 2; u32 $((20 + n + b + delta)); u32 "$n"; printf 'JSON'; cat glb_json.tmp
    if [ -n "$bin" ]; then u32 $((b - 8)); printf 'BIN\0'; cat "$bin"; fi
  } >"$out"
  rm -f glb_json.tmp
}

# avatar_json [EXTRA_TOP_LEVEL] [HIPS_NODE] [HIPS_EXTRA]: a VRM 1.0 avatar of three nodes.
avatar_json() {
  local extra=${1:-} hips=${2:-1} hips_extra=${3:-}
  printf '{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],'
  printf '"nodes":[{"name":"root","children":[1]},'
  printf '{"name":"hips","children":[2],"translation":[0,1,0]%s},' "$hips_extra"
  printf '{"name":"spine","translation":[0,0.1,0]}],'
  printf '"extensionsUsed":["VRMC_vrm"],"extensions":{"VRMC_vrm":{"specVersion":"1.0",'
  printf '"humanoid":{"humanBones":{"hips":{"node":%s},"spine":{"node":2}}}}}%s}' "$hips" "$extra"
}

# ---- inputs ---------------------------------------------------------------------------------
"$exe" synth -o m.landmarks.jsonl --seconds 1 --no-face >/dev/null 2>synth.err ||
  { echo "FAIL: synth failed: $(cat synth.err)" >&2; exit 1; }
secret=TOP-SECRET-7f3a9c
printf '%s' "$secret" >secret.txt
mkdir -p av/sub av/tex
echo "the user's old output" >keep.glb
cp keep.glb keep.orig

# convert_fails AVATAR WORDS: inspect and convert (.glb, .bvh) all fail with WORDS, naming
# the avatar; no output created; the existing output untouched.
convert_fails() {
  local avatar=$1 words=$2
  run error inspect "$avatar"
  expect_in err.txt "$avatar"
  expect_in err.txt "$words"
  run error convert m.landmarks.jsonl --avatar "$avatar" -o new.glb --quiet
  expect_in err.txt "$words"
  absent new.glb
  run error convert m.landmarks.jsonl --avatar "$avatar" -o new.bvh --quiet
  absent new.bvh
  run error convert m.landmarks.jsonl --avatar "$avatar" -o keep.glb --quiet
  if cmp -s keep.glb keep.orig; then pass; else fail "keep.glb was replaced by a failed run"; fi
}

# ---- the control: a clean avatar converts ---------------------------------------------------
avatar_json >av/clean.gltf
run ok inspect av/clean.gltf
run ok convert m.landmarks.jsonl --avatar av/clean.gltf -o clean.glb --quiet
run ok convert m.landmarks.jsonl --avatar av/clean.gltf -o clean.bvh --quiet

# ---- deep nesting: an error, not a crash ----------------------------------------------------
deep="$(repeat '[' 20000)1$(repeat ']' 20000)"
avatar_json ",\"extras\":$deep" >av/deep_extras.gltf
convert_fails av/deep_extras.gltf "deeper than 128 levels"
avatar_json '' 1 ",\"extras\":{\"a\":$deep}" >av/deep_node.json
glb av/deep_node.json av/deep_node.vrm
convert_fails av/deep_node.vrm "deeper than"
# 20,000 levels inside VRMC_vrm itself.
avatar_json >av/vrmc.json
sed -i "s/\"specVersion\":\"1.0\",/\"specVersion\":\"1.0\",\"meta\":$deep,/" av/vrmc.json
glb av/vrmc.json av/deep_vrmc.vrm
convert_fails av/deep_vrmc.vrm "deeper than"

# A deep .vrma as the motion input.
glb av/deep_node.json deep_motion.vrma
run error convert deep_motion.vrma -o motion.bvh --quiet
expect_in err.txt "deep_motion.vrma"
expect_in err.txt "deeper than"
absent motion.bvh

# ---- broken GLB containers ------------------------------------------------------------------
glb av/clean.gltf av/long.vrm 64
convert_fails av/long.vrm "truncated"
glb av/clean.gltf av/ok.vrm
run ok inspect av/ok.vrm
head -c 100 av/ok.vrm >av/cut.vrm
convert_fails av/cut.vrm "truncated"
{ cat av/ok.vrm; u32 4000; printf 'BIN\0'; printf 'xxxx'; } >av/bin_len.vrm
glb_size=$(wc -c <av/bin_len.vrm)
# Fix the total length so that only the BIN chunk's own length lies.
{ printf 'glTF'; u32 2; u32 "$glb_size"; tail -c +13 av/bin_len.vrm; } >av/bin_len2.vrm
convert_fails av/bin_len2.vrm "BIN chunk declares 4000 bytes"

# ---- URIs: nothing outside the avatar's folder is read --------------------------------------
ln -s "$work/secret.txt" av/link.bin
len=${#secret}
for uri in "../secret.txt" "$work/secret.txt" "file://$work/secret.txt" "link.bin" \
  "%2e%2e/secret.txt"; do
  case $uri in
    ../*|%2e*) words="leaves the avatar's folder" ;;
    file:*) words="scheme (file:)" ;;
    link.bin) words="symbolic link" ;;
    *) words="absolute path" ;;
  esac
  avatar_json ",\"buffers\":[{\"uri\":\"$uri\",\"byteLength\":$len}]" >av/buffer_uri.gltf
  convert_fails av/buffer_uri.gltf "$words"
  expect_in err.txt "buffers[0].uri"
  avatar_json ",\"images\":[{\"uri\":\"$uri\"}]" >av/image_uri.gltf
  convert_fails av/image_uri.gltf "$words"
  expect_in err.txt "images[0].uri"
done
# A GLB whose second buffer names the secret (the first is the BIN chunk).
printf 'abcd' >bin4.tmp
avatar_json ",\"buffers\":[{\"byteLength\":4},{\"uri\":\"../secret.txt\",\"byteLength\":$len}]" \
  >av/two_buffers.json
glb av/two_buffers.json av/two_buffers.vrm 0 bin4.tmp
convert_fails av/two_buffers.vrm "leaves the avatar's folder"
expect_in err.txt "buffers[1].uri"
# The secret is in no file but its own, neither as it is nor in base64 (glTF data: URIs).
secret_b64=$(printf '%s' "$secret" | base64 | head -c 16)
leaks=$(LC_ALL=C grep -rlF -e "$secret" -e "$secret_b64" . | grep -v '^./secret.txt$' |
  grep -v '^./av/link.bin$')
if [ -z "$leaks" ]; then pass; else fail "the secret leaked into: $leaks"; fi

# ---- a legitimate .gltf with a buffer in a subfolder and an external texture ---------------
printf '0123456789abcdef' >av/sub/data.bin
printf '\x89PNG\r\n\x1a\nTEXTURE-MARKER-5d1e-not-decodable' >av/tex/skin.png
avatar_json ',"buffers":[{"uri":"sub/data.bin","byteLength":16}],"images":[{"uri":"tex/skin.png"}]' \
  >av/legit.gltf
run ok inspect av/legit.gltf
run ok convert m.landmarks.jsonl --avatar av/legit.gltf -o legit.glb --quiet
expect_in legit.glb "TEXTURE-MARKER-5d1e-not-decodable"
expect_in legit.glb '"mimeType":"image/png"'
expect_not_in legit.glb '"uri"'

# ---- wrong rigs -----------------------------------------------------------------------------
avatar_json '' 1099511627776 >av/hips40.gltf
convert_fails av/hips40.gltf "1099511627776"
expect_in err.txt "'hips'"
avatar_json '' 1 ',"scale":[0,1,1]' >av/zero_scale.gltf
convert_fails av/zero_scale.gltf "zero"
expect_in err.txt "'hips'"
expect_not_in err.txt "nan"

finish
