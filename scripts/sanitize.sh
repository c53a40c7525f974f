#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer run (docs/fuzzing.md): builds the library, the
# CLI, the C API and the tests with clang, -fsanitize=address,undefined (every UB report fatal),
# into build-asan/ (or $AVATARMAP_ASAN_BUILD_DIR), runs the test suite there, then replays every
# fuzz corpus (the checked-in seeds, the regressions and the shared test data) once through the
# libFuzzer targets, which carry the same sanitizers (tools/fuzz/run.sh --replay).
#   scripts/sanitize.sh
# Environment: AVATARMAP_JOBS (parallel jobs, default nproc), AVATARMAP_TEST_DATA (real data;
# the tests that need it skip without it), AVATARMAP_SKIP_SANITIZE_FUZZ=1 (no corpus replay).
# Exits non-zero on any failing test or sanitizer report.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${AVATARMAP_ASAN_BUILD_DIR:-$root/build-asan}"
jobs="${AVATARMAP_JOBS:-$(nproc)}"
start=$(date +%s)

sanitizers="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
# The shared ASan runtime (with UBSan's handlers, C++ ones included): Python must preload it to
# load our instrumented C library, and a process may hold only one ASan runtime, so the
# programs those Python tests start (the CLI) must use the same shared one.
asan_runtime=$(clang -print-file-name=libclang_rt.asan-x86_64.so)
if [ ! -e "$asan_runtime" ]; then
  echo "sanitize: clang's ASan runtime ($asan_runtime) is missing: install libclang-rt-14-dev" >&2
  exit 1
fi
link="-fsanitize=address,undefined -shared-libasan -Wl,-rpath,$(dirname "$asan_runtime")"
# A test that replaces operator new and delete (tests/solve/allocation_test.cpp) must replace
# them for every library, as it does with a static runtime: the shared runtime's sized delete
# would otherwise free what the test's new allocated (FFmpeg's libhwy does). Clang declares
# the sized delete, with default visibility, only under -fsized-deallocation (GCC's default),
# and --export-dynamic exports it to the libraries loaded indirectly.
cxx_only="-fsized-deallocation"
link_exe="$link -Wl,--export-dynamic"
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
# Debug keeps the assertions (programmer errors) on; -O1 keeps the run affordable. ONNX capture
# stays off: ONNX Runtime is a prebuilt, uninstrumented library, and its tests are the slowest.
# Benchmarks and examples are not tests.
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja "${launcher[@]}" \
  -DCMAKE_BUILD_TYPE=Debug -DCMAKE_C_FLAGS_DEBUG="-O1 -g" -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" \
  -DCMAKE_C_FLAGS="$sanitizers" -DCMAKE_CXX_FLAGS="$sanitizers $cxx_only" \
  -DCMAKE_EXE_LINKER_FLAGS="$link_exe" -DCMAKE_SHARED_LINKER_FLAGS="$link" \
  -DAVATARMAP_WITH_ONNX=OFF -DAVATARMAP_BUILD_BENCH=OFF -DAVATARMAP_BUILD_EXAMPLES=OFF \
  -DAVATARMAP_BUILD_TESTS=ON -DAVATARMAP_BUILD_CLI=ON -DAVATARMAP_BUILD_C_API=ON >/dev/null
# Keep going past a target that does not build (-k 0): the tests of the others still run, and
# the run fails at the end.
failed=()
cmake --build "$build" -j "$jobs" -- -k 0 || failed+=(build)
built=$(date +%s)

# Every report is fatal and names its stack; third-party reports we cannot fix are listed,
# with the reason, in tools/fuzz/ubsan.supp.
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:detect_leaks=1:strict_init_order=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$root/tools/fuzz/ubsan.supp:${UBSAN_OPTIONS:-}"

# Tests left out of the sanitized run, each with its reason:
#  - package_*: they configure and build a separate consumer project with the plain compiler
#    flags (an uninstrumented program cannot link the instrumented library) and rebuild the
#    core; they test packaging, not memory safety, and the normal run covers them.
#  - convert.tflite2onnx_selftest: Python and numpy only, no avatarmap code.
#  - python.install_*: they install the Python package with pip and cmake --install (packaging,
#    as package_*); the package's own tests (python.test_*) run below against this build.
# Run apart, below: the tests that load the C library into CPython ($python_tests).
python_tests='^(c_api_python_.*|cli\.hostile_time_test|python\.test_.*)$'
excluded='^(package_.*|convert\.tflite2onnx_selftest|python\.install_.*)$'
cd "$build"
ctest --output-on-failure -j "$jobs" -E "$excluded|$python_tests" || failed+=(tests)

# CPython cannot load an instrumented library unless the ASan runtime is preloaded; CPython's
# own allocations are not ours to check for leaks.
LD_PRELOAD="$asan_runtime" ASAN_OPTIONS="$ASAN_OPTIONS:detect_leaks=0" \
  ctest --output-on-failure -j "$jobs" -R "$python_tests" || failed+=("Python tests")
tested=$(date +%s)

if [ "${AVATARMAP_SKIP_SANITIZE_FUZZ:-0}" != 1 ]; then
  "$root/tools/fuzz/run.sh" --replay || failed+=("fuzz corpus replay")
fi
end=$(date +%s)
echo "sanitize: build $((built - start)) s, tests $((tested - built)) s," \
  "fuzz corpus replay $((end - tested)) s, total $((end - start)) s"
if [ ${#failed[@]} -gt 0 ]; then
  echo "sanitize: failed: ${failed[*]}" >&2
  exit 1
fi
