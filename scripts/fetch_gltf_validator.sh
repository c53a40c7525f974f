#!/usr/bin/env bash
# Fetches Khronos's glTF validator (npm's gltf-validator, Apache-2.0; JavaScript compiled from
# Dart, no dependencies) for the tests that validate the .glb and .vrma files we write
# (tests/convert/face_glb_test.py finds it through NODE_PATH, which ctest sets):
#
#   <dir>/gltf-validator/{index.js,module.mjs,package.json,...}
#
# Folder: $AVATARMAP_NODE_MODULES, default .cache/avatarmap/node_modules in the repository
# (git-ignored; never committed). Idempotent: when the pinned version is there it exits at
# once. The tarball is checked against the registry integrity pinned below before it is
# unpacked.
set -euo pipefail
spec="gltf-validator@2.0.0-dev.3.10"
integrity="sha512-odJ4k0tRkGXiDGn78yDBg+fBbAIvBnXxh3RwAta0emSxGtyagFE8B4xELB1oYe3S5RD8Ci3uZAsZaascH2LAEQ=="
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=npm_pack_checked.sh
. "$root/scripts/npm_pack_checked.sh"
dest="${AVATARMAP_NODE_MODULES:-$root/.cache/avatarmap/node_modules}"
version="${spec##*@}"
if [ -f "$dest/gltf-validator/package.json" ] &&
   grep -q "\"version\": *\"$version\"" "$dest/gltf-validator/package.json"; then
  echo "fetch_gltf_validator: $spec in $dest"
  exit 0
fi
for tool in npm tar openssl base64; do
  command -v "$tool" >/dev/null || { echo "fetch_gltf_validator: $tool is needed" >&2; exit 1; }
done
mkdir -p "$dest"
work="$(mktemp -d "$dest/.fetch.XXXXXX")"
trap 'rm -rf "$work"' EXIT
tgz="$(npm_pack_checked fetch_gltf_validator "$spec" "$integrity" "$work")"
tar -xzf "$work/$tgz" -C "$work"
rm -rf "${dest:?}/gltf-validator"
mv "$work/package" "$dest/gltf-validator"
echo "fetch_gltf_validator: $spec in $dest"
