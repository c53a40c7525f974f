# Shared by the hostile-input suites (tests/cli/hostile_*_test.sh EXE WORK_DIR): sourced with
# the script's arguments, it sets $exe, makes a fresh WORK_DIR and enters it, and defines the
# checks below. Each check counts a pass or a failure; `finish` prints the closing line
# "N passed, N failed" and exits 1 when anything failed, 77 (CTest: skipped) when a part was
# left out for want of the shared data, the models or a tool (`skip_part`), else 0.
# shellcheck shell=bash
set -u

exe=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
cd "$work" || exit 1

passed=0
failed=0
pass() { passed=$((passed + 1)); }
ok() { pass; }
fail() {
  echo "FAIL: $*" >&2
  failed=$((failed + 1))
}

# run WANT ARGS...: runs the tool (at most 120 s; stdout out.txt, stderr err.txt). WANT is
# "ok" (status 0), "error" (status 1 or 2) or an exact status. A signal or a time-out (status
# 124 and above) always fails: hostile input must never kill the tool.
run() {
  local want=$1
  shift
  timeout 120 "$exe" "$@" >out.txt 2>err.txt
  local got=$?
  local good=0
  case "$want" in
    ok) [ "$got" -eq 0 ] && good=1 ;;
    error) { [ "$got" -eq 1 ] || [ "$got" -eq 2 ]; } && good=1 ;;
    *) [ "$got" -eq "$want" ] && [ "$got" -lt 124 ] && good=1 ;;
  esac
  if [ "$good" -eq 1 ]; then
    pass
  else
    fail "avatarmap $* exited $got, expected $want"
    echo "--- stderr:" >&2
    head -c 2000 err.txt >&2
  fi
}

# expect_in FILE TEXT / expect_not_in FILE TEXT: FILE contains (does not contain) TEXT.
expect_in() {
  if LC_ALL=C grep -qF -- "$2" "$1"; then pass; else
    fail "$1 does not contain '$2': $(head -c 1000 "$1")"
  fi
}
expect_not_in() {
  if LC_ALL=C grep -qF -- "$2" "$1"; then fail "$1 contains '$2'"; else pass; fi
}

# absent PATH: nothing was written there. kept PATH TEXT: PATH still holds exactly TEXT.
absent() { if [ ! -e "$1" ]; then pass; else fail "$1 was written"; fi; }
kept() { if [ "$(cat "$1")" = "$2" ]; then pass; else fail "$1 was replaced"; fi; }

# same_file A B: identical content.
same_file() { if cmp -s "$1" "$2"; then pass; else fail "$1 differs from $2"; fi; }

# no_temp [DIR]: no temporary file of the writers (hidden .NAME.tmp.XXXXXX, or NAME.tmp.*) is
# left in DIR (default: the working folder). Names *.tmp.keep* are the tests' own.
no_temp() {
  local dir=${1:-.} left
  left=$(find "$dir" -maxdepth 1 -name '*.tmp.*' ! -name '*.tmp.keep*' | head -5)
  if [ -z "$left" ]; then pass; else fail "temporary files left in $dir: $left"; fi
}

# short_lines FILE: no line of FILE is longer than 600 characters (no 300-digit numbers).
short_lines() {
  local longest
  longest=$(awk '{ if (length($0) > m) m = length($0) } END { print m + 0 }' "$1")
  if [ "$longest" -le 600 ]; then pass; else fail "$1 has a line of $longest characters"; fi
}

# skip_part WHY: a part of the suite was left out (data, models or a tool missing); the suite
# then ends as skipped (exit 77, CTest: skipped) when nothing failed, never as passed.
skipped=""
skip_part() {
  echo "skipped part: $1"
  skipped="${skipped:+$skipped; }$1"
}

# finish: the closing line; the exit status says whether everything passed (77: passed, but
# a part was skipped).
finish() {
  echo "$passed passed, $failed failed"
  [ "$failed" -eq 0 ] || return 1
  if [ -n "$skipped" ]; then
    echo "skipped: $skipped"
    return 77
  fi
  return 0
}
