#!/usr/bin/env bash
# Fetches the browser viewer's JavaScript modules (docs/viewer.md) from pinned npm packages
# into a folder that `avatarmap view` and `live --serve` serve under /modules/:
#
#   <dir>/three/{build,examples/jsm,LICENSE}            three.js (MIT)
#   <dir>/three-vrm/{lib,LICENSE}                       @pixiv/three-vrm (MIT)
#   <dir>/three-vrm-animation/{lib,LICENSE}             @pixiv/three-vrm-animation (MIT)
#   <dir>/VERSION                                       what was fetched
#
# Folder: $AVATARMAP_VIEWER_MODULES, default .cache/avatarmap/viewer in the repository
# (git-ignored; never committed). Idempotent: when VERSION names the pinned packages it exits
# at once. Each tarball is checked against the registry integrity pinned below before it is
# unpacked; the three-vrm bundles import only "three", so their npm dependencies are not needed.
set -euo pipefail

# name@version  directory  sha512 integrity (npm view NAME@VERSION dist.integrity)
packages=(
  "three@0.187.0 three sha512-Qiu7R+Cmh8CstZsY1uJOSWnVlfo7ZtNLV7mF8Jltk3LB3AtDu9cRZlcnRKkAk8Y4z6KKw35z7Y7Urd7jWY8etA=="
  "@pixiv/three-vrm@3.5.5 three-vrm sha512-RPXy7jYAXs704NIpZlosB0U2ENu21G9DrqGWdQgRe8dShaCo1ugpj+6BVPRCy91nt+MPMA96j5rbsSzEl0HlQA=="
  "@pixiv/three-vrm-animation@3.5.5 three-vrm-animation sha512-Q0kEtmftxfv0iCUHQkJH2jAr1zmT9ywYXnAzhxnLPMYCsx0Kken3J3U2GJF9PdGZmLlKpoK0LFEXVdD/L7ZA4Q=="
)

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# shellcheck source=npm_pack_checked.sh
. "$root/scripts/npm_pack_checked.sh"
dest="${AVATARMAP_VIEWER_MODULES:-$root/.cache/avatarmap/viewer}"
want="$(for p in "${packages[@]}"; do echo "${p%% *}"; done)"

if [ -f "$dest/VERSION" ] && [ "$(cat "$dest/VERSION")" = "$want" ] &&
   [ -f "$dest/three/build/three.module.js" ] && [ -f "$dest/three-vrm/lib/three-vrm.module.js" ] &&
   [ -f "$dest/three-vrm-animation/lib/three-vrm-animation.module.js" ]; then
  echo "fetch_viewer_modules: $(echo "$want" | tr '\n' ' ')in $dest"
  exit 0
fi
for tool in npm tar openssl base64; do
  command -v "$tool" >/dev/null || { echo "fetch_viewer_modules: $tool is needed" >&2; exit 1; }
done

mkdir -p "$dest"
work="$(mktemp -d "$dest/.fetch.XXXXXX")"
trap 'rm -rf "$work"' EXIT
for p in "${packages[@]}"; do
  read -r spec dir integrity <<<"$p"
  tgz="$(npm_pack_checked fetch_viewer_modules "$spec" "$integrity" "$work")"
  mkdir -p "$work/$dir"
  case "$dir" in
    three) tar -xzf "$work/$tgz" -C "$work/$dir" --strip-components=1 \
             package/build package/examples/jsm package/LICENSE package/package.json ;;
    *) tar -xzf "$work/$tgz" -C "$work/$dir" --strip-components=1 \
         package/lib package/LICENSE package/package.json ;;
  esac
  rm -f "$work/$tgz"
  rm -rf "${dest:?}/$dir"
  mv "$work/$dir" "$dest/$dir"
done
printf '%s\n' "$want" >"$dest/VERSION"
echo "fetch_viewer_modules: $(echo "$want" | tr '\n' ' ')in $dest"
