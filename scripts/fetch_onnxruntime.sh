#!/usr/bin/env bash
# Fetches the official ONNX Runtime CPU build for Linux x64 (MIT) from a pinned npm package
# into a prefix that CMake's AVATARMAP_ONNXRUNTIME_DIR points at (see docs/models.md):
#
#   <dir>/include/onnxruntime_c_api.h ...     official C/C++ headers (ORT_API_VERSION 29)
#   <dir>/lib/libonnxruntime.so.1.29.0        official CPU library (soname libonnxruntime.so.1)
#   <dir>/lib/libonnxruntime.so.1 -> libonnxruntime.so.1.29.0
#   <dir>/lib/libonnxruntime.so   -> libonnxruntime.so.1
#   <dir>/LICENSE, ThirdPartyNotices.txt, VERSION
#
#   scripts/fetch_onnxruntime.sh            fetch when missing, verify
#   scripts/fetch_onnxruntime.sh --check    verify only, never touch the network
#   scripts/fetch_onnxruntime.sh --force    re-fetch and replace files that differ
#   scripts/fetch_onnxruntime.sh --update-manifest
#                                           re-fetch and rewrite the checksums (after changing
#                                           the pinned version below)
#
# Folder: $AVATARMAP_ONNXRUNTIME_DIR, default .cache/avatarmap/onnxruntime in the repository
# (git-ignored). Idempotent: with everything present and matching it exits at once. The
# files are checked against tools/onnxruntime/onnxruntime-linux-x64.sha256 and never
# committed. The npm package is the asus4/onnxruntime-unity plugin, which repackages
# Microsoft's release binaries; only its Linux x64 library and the headers are used.
set -euo pipefail

package=com.github.asus4.onnxruntime@0.4.9  # latest on the npm registry; carries ORT 1.29.0
ort_version=1.29.0
headers_in_package="package/Plugins/iOS~/onnxruntime.xcframework/ios-arm64/onnxruntime.framework/Headers"
library_in_package="package/Plugins/Linux/x64/libonnxruntime.so"

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dest="${AVATARMAP_ONNXRUNTIME_DIR:-$root/.cache/avatarmap/onnxruntime}"
manifest="$root/tools/onnxruntime/onnxruntime-linux-x64.sha256"
library="libonnxruntime.so.$ort_version"

mode=fetch
case "${1:-}" in
  "") ;;
  --check) mode=check ;;
  --force) mode=force ;;
  --update-manifest) mode=update ;;
  *) echo "usage: $0 [--check|--force|--update-manifest]" >&2; exit 2 ;;
esac

if [ "$(uname -s)/$(uname -m)" != Linux/x86_64 ]; then
  echo "fetch_onnxruntime: only Linux x86_64 is provided; on $(uname -s)/$(uname -m) install" \
       "ONNX Runtime yourself and point CMake at it (docs/models.md)" >&2
  exit 1
fi

# Prints one line per missing or differing file; returns 0 when all is present and matches.
cache_state() {
  local bad=0 sum name
  [ -f "$manifest" ] || { echo "missing manifest $manifest"; return 1; }
  while read -r sum name; do
    [ -n "$sum" ] || continue
    if [ ! -f "$dest/$name" ]; then
      echo "missing  $name"; bad=1
    elif [ "$(sha256sum "$dest/$name" | cut -d' ' -f1)" != "$sum" ]; then
      echo "DIFFERS  $name"; bad=1
    fi
  done <"$manifest"
  if [ "$(readlink "$dest/lib/libonnxruntime.so.1" 2>/dev/null)" != "$library" ] ||
     [ "$(readlink "$dest/lib/libonnxruntime.so" 2>/dev/null)" != libonnxruntime.so.1 ]; then
    echo "missing  lib/libonnxruntime.so.1 or lib/libonnxruntime.so link"; bad=1
  fi
  return $bad
}

if [ "$mode" = fetch ] || [ "$mode" = check ]; then
  if state="$(cache_state)"; then
    echo "fetch_onnxruntime: ONNX Runtime $ort_version in $dest matches $manifest"
    exit 0
  fi
  if grep -q '^DIFFERS' <<<"$state"; then
    echo "$state" | sed 's/^/fetch_onnxruntime: /' >&2
    echo "fetch_onnxruntime: files in $dest differ from" \
         "tools/onnxruntime/onnxruntime-linux-x64.sha256. Run '$0 --force' to fetch and" \
         "replace them, or point AVATARMAP_ONNXRUNTIME_DIR at another folder." >&2
    exit 1
  fi
  if [ "$mode" = check ]; then
    echo "$state" | sed 's/^/fetch_onnxruntime: /' >&2
    echo "fetch_onnxruntime: ONNX Runtime is missing from $dest: run $0" >&2
    exit 1
  fi
fi

for tool in npm tar sha256sum; do
  command -v "$tool" >/dev/null || { echo "fetch_onnxruntime: $tool is needed" >&2; exit 1; }
done

mkdir -p "$dest"
work="$(mktemp -d "$dest/.fetch.XXXXXX")"
trap 'rm -rf "$work"' EXIT
stage="$work/stage"
mkdir -p "$stage/include" "$stage/lib"

start=$SECONDS
echo "fetch_onnxruntime: npm pack $package"
tgz="$(cd "$work" && npm pack --silent "$package" 2>"$work/npm.log" | tail -n 1)" || true
if [ -z "$tgz" ] || [ ! -f "$work/$tgz" ]; then
  cat "$work/npm.log" >&2
  echo "fetch_onnxruntime: npm pack $package failed" >&2
  exit 1
fi
size=$(stat -c %s "$work/$tgz")
tar -xzf "$work/$tgz" -C "$work" "$headers_in_package" "$library_in_package" \
    package/LICENSE package/ThirdPartyNotices.txt
rm -f "$work/$tgz"
install -m 0644 "$work/$headers_in_package"/*.h "$stage/include/"
install -m 0755 "$work/$library_in_package" "$stage/lib/$library"
install -m 0644 "$work/package/LICENSE" "$work/package/ThirdPartyNotices.txt" "$stage/"
echo "fetch_onnxruntime: downloaded $((size / 1048576)) MiB in $((SECONDS - start)) s"

api="$(sed -n 's/^#define ORT_API_VERSION \([0-9]*\).*/\1/p' "$stage/include/onnxruntime_c_api.h")"
soname="$(objdump -p "$stage/lib/$library" 2>/dev/null | awk '/SONAME/ {print $2}')" || true
echo "fetch_onnxruntime: headers ORT_API_VERSION $api, library soname ${soname:-(objdump missing)}"

if [ "$mode" = update ]; then
  mkdir -p "$(dirname "$manifest")"
  (cd "$stage" && find . -type f | sed 's|^\./||' | LC_ALL=C sort | xargs sha256sum) >"$manifest"
  echo "fetch_onnxruntime: wrote $manifest; review and commit it"
elif ! (cd "$stage" && sha256sum --check --strict --quiet "$manifest"); then
  echo "fetch_onnxruntime: $package does not hold the files" \
       "tools/onnxruntime/onnxruntime-linux-x64.sha256 lists. If you changed the pinned" \
       "version on purpose, run '$0 --update-manifest' and commit the new checksums;" \
       "otherwise the registry served something else: stop and find out why." >&2
  exit 1
fi

mkdir -p "$dest/include" "$dest/lib"
while read -r _ name; do
  mv -f "$stage/$name" "$dest/$name"
done <"$manifest"
ln -sfn "$library" "$dest/lib/libonnxruntime.so.1"
ln -sfn libonnxruntime.so.1 "$dest/lib/libonnxruntime.so"
printf '%s\n' "onnxruntime $ort_version (ORT_API_VERSION $api) from npm $package" >"$dest/VERSION"
cache_state >/dev/null || { echo "fetch_onnxruntime: verification after install failed" >&2; exit 1; }
echo "fetch_onnxruntime: ONNX Runtime $ort_version in $dest verified against $manifest"
