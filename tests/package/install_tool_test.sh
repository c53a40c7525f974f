#!/usr/bin/env bash
# The tool as a user installs it: scripts/install.sh --skip-build into a fresh prefix, then the
# installed avatarmap run from another folder with a clean environment (no AVATARMAP_*
# variables, a PATH without the prefix): --version, backends (every folder found in the
# prefix, none in the source tree), synth + solve, convert to .glb on the built-in avatar, the
# demo's closing command (the binary's path while it is not on the PATH, `avatarmap` once it
# is), install.sh's PATH advice, a second install (nothing copied again) and, when the models
# and $AVATARMAP_TEST_DATA are there, a capture of a short real video. The libraries are
# checked to come from the prefix (ldd).
#   install_tool_test.sh SOURCE_DIR BUILD_DIR WORK_DIR
# Exit 77 (CTest: skipped) when only the capture part was left out for want of models or data.
set -u
src=$1
build=$2
work=$3
# The sanitizer build (scripts/sanitize.sh) needs its ASan runtime and options in the
# environment, which a clean environment drops: the installed tool is tested on the normal
# build.
if ldd "$build/avatarmap" 2>/dev/null | grep -q 'libclang_rt.asan'; then
  echo "skipped: a sanitizer build (the install is tested on the normal build)"
  exit 77
fi
rm -rf "$work"
mkdir -p "$work/prefix" "$work/elsewhere"
prefix="$work/prefix"
failures=0
fail() {
  echo "FAIL: $*" >&2
  failures=$((failures + 1))
}
models="${AVATARMAP_MODELS:-$src/.cache/avatarmap/models}"
data="${AVATARMAP_TEST_DATA:-}"

# install.sh with PATH lacking the prefix: it installs and says how to add it.
AVATARMAP_BUILD_DIR="$build" AVATARMAP_MODELS="$models" \
  "$src/scripts/install.sh" --skip-build "$prefix" >"$work/install1.out" 2>&1 ||
  { fail "install.sh failed: $(tail -n 20 "$work/install1.out")"; exit 1; }
grep -qF "export PATH=\"$prefix/bin:\$PATH\"" "$work/install1.out" ||
  fail "install.sh did not print the line that puts $prefix/bin on the PATH:" \
    "$(cat "$work/install1.out")"
exe="$prefix/bin/avatarmap"
[ -x "$exe" ] || { fail "no $exe"; exit 1; }
for f in mappings viewer; do
  [ -d "$prefix/share/avatarmap/$f" ] || fail "no $prefix/share/avatarmap/$f"
done

# A clean environment: no AVATARMAP_* variable, no LD_LIBRARY_PATH, a PATH without the prefix.
clean() { env -i HOME="$work" PATH=/usr/local/bin:/usr/bin:/bin TMPDIR="$work" "$@"; }
cd "$work/elsewhere" || exit 1

# The libraries the tool loads: ONNX Runtime (when this build has it) from the prefix.
if ldd "$exe" | grep -q 'not found'; then fail "unresolved libraries: $(ldd "$exe")"; fi
if ldd "$build/avatarmap" | grep -q libonnxruntime; then
  ort=$(ldd "$exe" | awk '/libonnxruntime/ {print $3}')
  [ -n "$ort" ] && [ "$(realpath "$ort")" = "$(realpath "$prefix/lib/libonnxruntime.so.1")" ] ||
    fail "libonnxruntime does not come from $prefix/lib: $(ldd "$exe" | grep onnx)"
fi

out=$(clean "$exe" --version) || fail "--version failed"
[ "$out" = "$("$build/avatarmap" --version)" ] || fail "--version printed '$out'"

clean "$exe" backends >backends.txt 2>&1 || fail "backends failed: $(cat backends.txt)"
for what in "mappings        $prefix/share/avatarmap/mappings (installed)" \
  "viewer page     $prefix/share/avatarmap/viewer (installed)"; do
  grep -qxF "$what" backends.txt ||
    fail "the installed tool does not use its installed folder '$what': $(cat backends.txt)"
done

clean "$exe" synth -o take.landmarks.jsonl --seconds 2 --no-face >synth.out 2>&1 ||
  fail "synth failed: $(cat synth.out)"
clean "$exe" solve take.landmarks.jsonl -o take.pose.jsonl >solve.out 2>&1 ||
  fail "solve failed: $(cat solve.out)"
[ "$(wc -l <take.pose.jsonl)" -ge 50 ] || fail "solve wrote $(wc -l <take.pose.jsonl) lines"
clean "$exe" convert take.pose.jsonl -o take.glb >convert.out 2>&1 ||
  fail "convert to .glb without --avatar failed: $(cat convert.out)"
[ -s take.glb ] || fail "no take.glb"

# The demo's closing command runs as printed: the binary's path off the PATH, `avatarmap` on
# it. The printed `view` command is run (for a second) in the same clean environment.
clean "$exe" demo --synthetic --seconds 1 --out demo >demo.out 2>&1 ||
  fail "demo failed: $(tail -n 5 demo.out)"
view_cmd=$(grep -oE "^ *[^ ]*avatarmap view [^ ]+" demo.out | head -n 1 | sed -E 's/^ +//')
[ "${view_cmd%% *}" = "$exe" ] ||
  fail "the demo does not print the installed binary's path: $(grep -F ' view ' demo.out)"
# (Without the viewer's modules, which install.sh copies when setup fetched them, the viewer
# cannot serve: that part is left out.)
if [ -d "$prefix/share/avatarmap/viewer-modules" ]; then
  # shellcheck disable=SC2086  # the command as printed, split by the shell as a user's would
  clean $view_cmd --port 0 --seconds 1 >view.out 2>&1 ||
    fail "the printed command '$view_cmd' does not run: $(tail -n 5 view.out)"
fi
env -i HOME="$work" PATH="$prefix/bin:/usr/bin:/bin" TMPDIR="$work" avatarmap demo --synthetic \
  --seconds 1 --out demo >demo2.out 2>&1 || fail "demo from the PATH failed"
grep -qE "^ *avatarmap view demo/" demo2.out ||
  fail "the demo run from the PATH does not print \`avatarmap view\`: $(grep -F ' view ' demo2.out)"

# A second install with the prefix on the PATH: nothing copied again, and it says so.
PATH="$prefix/bin:$PATH" AVATARMAP_BUILD_DIR="$build" AVATARMAP_MODELS="$models" \
  "$src/scripts/install.sh" --skip-build "$prefix" >"$work/install2.out" 2>&1 ||
  fail "the second install failed: $(tail -n 20 "$work/install2.out")"
grep -qF "$prefix/bin is on your PATH" "$work/install2.out" ||
  fail "install.sh does not see $prefix/bin on the PATH: $(cat "$work/install2.out")"
if grep -q "models: .*([1-9][0-9]* files updated)" "$work/install2.out"; then
  fail "the second install copied the models again: $(cat "$work/install2.out")"
fi

skipped=""
video="$data/motion/tfjs-models/pose_squats.mp4"
if [ ! -f "$models/onnx/pose_detection.onnx" ]; then
  skipped="no models in $models/onnx (scripts/prepare_capture.sh)"
elif ! "$build/avatarmap" backends 2>/dev/null | grep -q '^ *onnx'; then
  skipped="this build has no onnx backend"
elif [ -z "$data" ] || [ ! -f "$video" ]; then
  skipped="AVATARMAP_TEST_DATA is not set to the shared real data"
else
  installed_models="models          $prefix/share/avatarmap/models/onnx (installed)"
  clean "$exe" backends | grep -qxF "$installed_models" ||
    fail "the installed tool does not use its installed models: $(clean "$exe" backends)"
  clean "$exe" capture "$video" -o squats.landmarks.jsonl >capture.out 2>&1 ||
    fail "capture with the installed models failed: $(tail -n 5 capture.out)"
  [ "$(wc -l <squats.landmarks.jsonl 2>/dev/null || echo 0)" -ge 60 ] ||
    fail "capture wrote too few frames: $(tail -n 5 capture.out)"
fi

if [ "$failures" -gt 0 ]; then
  echo "$failures failure(s); files in $work" >&2
  exit 1
fi
rm -rf "$prefix"  # the models are large
if [ -n "$skipped" ]; then
  echo "skipped the capture part: $skipped"
  exit 77
fi
echo "ok"
