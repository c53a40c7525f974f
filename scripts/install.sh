#!/usr/bin/env bash
# Installs avatarmap as a tool into a prefix the user owns (default ~/.local), idempotently:
#   scripts/install.sh [--skip-build] [PREFIX]
# 1. installs what is missing (scripts/setup.sh) and prepares ONNX Runtime and the capture
#    models (scripts/prepare_capture.sh), then builds (scripts/build.sh) — all skipped with
#    --skip-build, which installs what the build folder already holds;
# 2. `cmake --install BUILD --prefix PREFIX`: PREFIX/bin/avatarmap, the libraries (with ONNX
#    Runtime's, found through the programs' RPATH), the headers and package config, and
#    PREFIX/share/avatarmap/{mappings,viewer};
# 3. copies the converted models to PREFIX/share/avatarmap/models/onnx and the viewer's modules
#    to PREFIX/share/avatarmap/viewer-modules (only the files that changed);
# 4. checks that PREFIX/bin/avatarmap runs and says whether PREFIX/bin is on the PATH (and the
#    line to add when it is not).
# The installed tool finds its tables, models and viewer from where it lies (docs/cli.md,
# "Installing"): no environment variable is needed, and the checkout may then be removed.
# Environment: AVATARMAP_BUILD_DIR (default build/), AVATARMAP_MODELS (the models cache,
# default .cache/avatarmap/models), AVATARMAP_VIEWER_MODULES (default .cache/avatarmap/viewer).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_first=1
prefix=""
for arg in "$@"; do
  case "$arg" in
    --skip-build) build_first=0 ;;
    -h | --help)
      sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'
      exit 0
      ;;
    -*)
      echo "install: unknown option '$arg' (usage: scripts/install.sh [--skip-build] [PREFIX])" >&2
      exit 2
      ;;
    *)
      if [ -n "$prefix" ]; then
        echo "install: give one PREFIX (got '$prefix' and '$arg')" >&2
        exit 2
      fi
      prefix=$arg
      ;;
  esac
done
prefix="${prefix:-$HOME/.local}"
mkdir -p "$prefix"
prefix="$(cd "$prefix" && pwd)"
build="${AVATARMAP_BUILD_DIR:-$root/build}"
models="${AVATARMAP_MODELS:-$root/.cache/avatarmap/models}"
modules="${AVATARMAP_VIEWER_MODULES:-$root/.cache/avatarmap/viewer}"

if [ "$build_first" = 1 ]; then
  AVATARMAP_SKIP_FUZZ=1 AVATARMAP_SKIP_SANITIZE=1 "$root/scripts/setup.sh"
  "$root/scripts/prepare_capture.sh" ||
    echo "install: warning: ONNX Runtime or the models could not be prepared: the installed" \
      "tool will not capture (run scripts/prepare_capture.sh, then this script again)" >&2
  echo "install: building in $build"
  "$root/scripts/build.sh" >/dev/null
fi
if [ ! -x "$build/avatarmap" ]; then
  echo "install: $build/avatarmap is missing: build first (scripts/install.sh without" \
    "--skip-build, or scripts/build.sh)" >&2
  exit 1
fi

cmake --install "$build" --prefix "$prefix" >/dev/null
share="$prefix/share/avatarmap"

# copy_tree FROM TO: the files of FROM that TO lacks or holds different, each written to a
# temporary name and renamed (a run cut short leaves no half-written file).
copy_tree() {
  local from=$1 to=$2 rel n=0
  while IFS= read -r -d '' rel; do
    rel=${rel#./}
    if [ ! -f "$to/$rel" ] || ! cmp -s "$from/$rel" "$to/$rel"; then
      mkdir -p "$(dirname "$to/$rel")"
      cp "$from/$rel" "$to/$rel.install-tmp"
      mv -f "$to/$rel.install-tmp" "$to/$rel"
      n=$((n + 1))
    fi
  done < <(cd "$from" && find . -type f ! -name '*.tmp' -print0)
  echo "$n"
}

if [ -f "$models/onnx/pose_detection.onnx" ]; then
  n=$(copy_tree "$models/onnx" "$share/models/onnx")
  echo "install: models: $share/models/onnx ($n files updated)"
else
  echo "install: warning: no converted models in $models/onnx: the installed tool will not" \
    "capture (run $root/scripts/prepare_capture.sh, then this script again)" >&2
fi
if [ -f "$modules/VERSION" ]; then
  n=$(copy_tree "$modules" "$share/viewer-modules")
  echo "install: viewer modules: $share/viewer-modules ($n files updated)"
else
  echo "install: warning: no viewer modules in $modules: \`avatarmap view\` will say what is" \
    "missing (run $root/scripts/fetch_viewer_modules.sh, then this script again)" >&2
fi

version=$(env -u AVATARMAP_MODELS -u AVATARMAP_MAPPINGS -u AVATARMAP_VIEWER_PAGE \
  -u AVATARMAP_VIEWER_MODULES "$prefix/bin/avatarmap" --version) || {
  echo "install: $prefix/bin/avatarmap does not run" >&2
  exit 1
}
echo "install: $version in $prefix/bin/avatarmap"

# Whether PREFIX/bin is on the PATH, and which avatarmap a shell runs.
on_path=0
IFS=: read -r -a path_dirs <<<"${PATH:-}"
for d in "${path_dirs[@]}"; do
  if [ -n "$d" ] && [ -d "$d" ] && [ "$d/" -ef "$prefix/bin/" ]; then
    on_path=1
    break
  fi
done
if [ "$on_path" = 1 ]; then
  found=$(command -v avatarmap || true)
  if [ -n "$found" ] && [ "$found" -ef "$prefix/bin/avatarmap" ]; then
    echo "install: $prefix/bin is on your PATH: run \`avatarmap --help\`"
  else
    echo "install: $prefix/bin is on your PATH, but \`avatarmap\` runs $found (earlier on the" \
      "PATH): put $prefix/bin before it, or run $prefix/bin/avatarmap"
  fi
else
  echo "install: $prefix/bin is not on your PATH; add it (e.g. to ~/.bashrc) with:"
  echo "  export PATH=\"$prefix/bin:\$PATH\""
  echo "install: until then run $prefix/bin/avatarmap"
fi
