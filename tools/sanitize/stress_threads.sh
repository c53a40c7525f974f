#!/usr/bin/env bash
# Thread-misuse stress of the live handle under a sanitizer: builds tests/c/c_live_threads_test
# with clang and -fsanitize=thread (or address,undefined) and ONNX Runtime in build-thread/
# (build-address/), then runs its three scenarios (destroy during push and sample, two pushers,
# push/sample/destroy from three threads) for SECONDS each. Needs the models
# (scripts/prepare_capture.sh) and clang with its sanitizer runtimes (scripts/setup.sh).
# Usage: tools/sanitize/stress_threads.sh thread|address [SECONDS]   (default 60)
# Prints the test's counts and the number of sanitizer reports; exits non-zero on any.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
kind=${1:?give thread or address}
seconds=${2:-60}
# A C executable linked by the C driver needs the C++ part of UBSan's runtime too (vptr checks).
case "$kind" in
  thread) san="-fsanitize=thread" link="$san" ;;
  address)
    san="-fsanitize=address,undefined -fno-sanitize-recover=undefined"
    link="$san -fsanitize-link-c++-runtime -lstdc++"
    ;;
  *) echo "stress_threads: give thread or address" >&2; exit 2 ;;
esac
build="$root/build-$kind"
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_C_FLAGS_DEBUG="-O1 -g" -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" \
  -DCMAKE_C_FLAGS="$san -fno-omit-frame-pointer" -DCMAKE_CXX_FLAGS="$san -fno-omit-frame-pointer" \
  -DCMAKE_EXE_LINKER_FLAGS="$link" -DCMAKE_SHARED_LINKER_FLAGS="$san" -DAVATARMAP_WITH_ONNX=ON \
  -DAVATARMAP_BUILD_BENCH=OFF -DAVATARMAP_BUILD_EXAMPLES=OFF -DAVATARMAP_BUILD_TESTS=ON >/dev/null
cmake --build "$build" --target c_live_threads_test
export AVATARMAP_MODELS="${AVATARMAP_MODELS:-$root/.cache/avatarmap/models}"
export AVATARMAP_STRESS_SECONDS="$seconds"
export TSAN_OPTIONS="suppressions=$root/tools/sanitize/tsan.supp:${TSAN_OPTIONS:-}"
# ORT keeps its allocations until exit; leaks are not what this run looks for.
export ASAN_OPTIONS="detect_leaks=0:${ASAN_OPTIONS:-}"
log="$build/c_live_threads_test.log"
status=0
"$build/tests/c/c_live_threads_test" >"$log" 2>&1 || status=$?
grep -E "cycles|passed" "$log" || true
reports=$(grep -cE "WARNING: ThreadSanitizer|ERROR: AddressSanitizer|runtime error:" "$log" || true)
echo "stress_threads ($kind, $seconds s a scenario): $reports sanitizer reports (log: $log)"
[ "$status" -eq 0 ] && [ "$reports" -eq 0 ]
