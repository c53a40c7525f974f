#!/usr/bin/env bash
# Hostile frame times through the tool (issue 8): `solve --fps` and `convert` on captures whose
# last frame is stamped before the first, whose frames lie 10^6 s or 1.7e308 s apart, a .vrma
# whose last key is at 10^9 s, and a header "fps" so small that index / fps overflows. Each
# must end with exit status 0 (a documented result: frames out of order skipped or sorted,
# with a warning), 1 or 2 and a short message naming the file and the limit; never a signal,
# never a run that writes without bound, never an existing output replaced by a failed run.
# Usage: hostile_time_test.sh AVATARMAP_EXE WORK_DIR. Prints "N passed, N failed".
here=$(cd "$(dirname "$0")" && pwd)
source "$(dirname "$0")/hostile_lib.sh" "$@"

# lines FILE: number of lines.
lines() { wc -l <"$1" | tr -d ' '; }

printf '{"t":5}\n{"t":5.1}\n{"t":1}\n' >backwards.landmarks.jsonl
printf '{"t":0}\n{"t":1000000}\n' >gap.landmarks.jsonl
printf '{"t":0}\n{"t":1.7e308}\n' >far.landmarks.jsonl
printf '{"t":-1.7e308}\n{"t":1.7e308}\n' >inf_span.landmarks.jsonl
printf '{"format":"avatarmap.landmarks","fps":1e-310}\n{}\n{}\n' >tiny_fps.landmarks.jsonl

# --- solve --fps: a frame earlier than the one before it is skipped with a warning --------
run 0 solve backwards.landmarks.jsonl -o backwards.pose.jsonl --fps 60
expect_in err.txt "warning: frame 2 (t = 1.000 s) is earlier than the frame before it"
expect_in err.txt "skipped 1 frames earlier than the frame before them"
# 5.0 .. 5.1 s at 60 fps: 7 poses (t = 5 + k/60, k = 0..6) after the header line.
if [ "$(lines backwards.pose.jsonl)" -eq 8 ]; then ok; else
  fail "backwards.pose.jsonl has $(lines backwards.pose.jsonl) lines, expected 8"
fi

# --- solve --fps: a 10^6 s gap or a 1.7e308 s one fails at once, writing nothing ---------
echo precious >gap.pose.jsonl
run 1 solve gap.landmarks.jsonl -o gap.pose.jsonl --fps 60
expect_in err.txt "gap.landmarks.jsonl: frame 1 (t = 1000000.000 s) is 1000000.00 s after the first frame"
expect_in err.txt "at most 86400 s"
kept gap.pose.jsonl precious
for f in far inf_span; do
  run 1 solve $f.landmarks.jsonl -o $f.pose.jsonl --fps 1000
  expect_in err.txt "after the first frame"
  short_lines err.txt
  absent $f.pose.jsonl
done
# 41943.04 s at 100 fps: within 24 h but more than 4194304 poses, refused before writing them.
printf '{"t":0}\n{"t":41943.04}\n' >many.landmarks.jsonl
run 1 solve many.landmarks.jsonl -o many.pose.jsonl --fps 100
expect_in err.txt "would write more than 4194304 poses"
absent many.pose.jsonl

# --- solve without --fps: times pass through; the summary stays short -----------------------
run 0 solve far.landmarks.jsonl -o far_own.pose.jsonl
expect_in err.txt "1.7e+308"
short_lines err.txt
run 0 solve backwards.landmarks.jsonl -o backwards_own.pose.jsonl
if [ "$(lines backwards_own.pose.jsonl)" -eq 4 ]; then ok; else fail "backwards_own: not 3 poses"; fi

# --- a header fps so small that index / fps overflows: a line error, not an infinite time ---
run 1 solve tiny_fps.landmarks.jsonl -o tiny.pose.jsonl --fps 30
expect_in err.txt "tiny_fps.landmarks.jsonl:3:"
expect_in err.txt "\"fps\" is too small"
absent tiny.pose.jsonl

# --- convert: out of order is sorted (warning); huge spans are refused, nothing written ----
run 0 convert backwards.landmarks.jsonl -o backwards.vrma
expect_in err.txt "1 frame(s) of backwards.landmarks.jsonl were out of time order; sorted"
expect_in err.txt "(4.10 s) into 124 frames at 30 fps"
for out in gap.vrma gap.bvh gap_resampled.pose.jsonl; do
  extra=()
  [ "$out" = gap_resampled.pose.jsonl ] && extra=(--fps 60)
  run 1 convert gap.landmarks.jsonl -o $out "${extra[@]}"
  expect_in err.txt "gap.landmarks.jsonl: the frame times span 1000000.00 s"
  expect_in err.txt "more than a clip may span (86400 s = 24 h)"
  absent $out
done
echo precious >far.vrma
run 1 convert far.landmarks.jsonl -o far.vrma
expect_in err.txt "span 1.7e+308 s"
short_lines err.txt
kept far.vrma precious
run 1 convert inf_span.landmarks.jsonl -o inf_span.bvh --fps 1000
expect_in err.txt "span inf s"
absent inf_span.bvh
# Poses out of order sorted too, for every output: pose to pose without --fps as well (one
# rule for frame times, convert_file.hpp), with the same warning.
printf '{"format":"avatarmap.pose"}\n{"t":2}\n{"t":1}\n{"t":3}\n' >shuffled.pose.jsonl
run 0 convert shuffled.pose.jsonl -o shuffled.vrma
expect_in err.txt "1 frame(s) of shuffled.pose.jsonl were out of time order"
run 0 convert shuffled.pose.jsonl -o same.pose.jsonl
expect_in err.txt "1 frame(s) of shuffled.pose.jsonl were out of time order; sorted by time before writing"
if [ "$(sed -n 2p same.pose.jsonl | cut -c1-8)$(sed -n 3p same.pose.jsonl | cut -c1-8)" = \
     '{"t":1,"{"t":2,"' ]; then ok; else
  fail "pose to pose did not sort the frames: $(sed -n 2,3p same.pose.jsonl | cut -c1-20)"
fi

# --- a .vrma whose last key is at 10^9 s (our writer's file, its 100 s key patched) ---------
printf '{"t":0}\n{"t":100}\n' >hundred.landmarks.jsonl
run 0 convert hundred.landmarks.jsonl -o hundred.vrma --fps 0.01
if command -v perl >/dev/null; then
  # 100.0f is 00 00 c8 42 (little-endian); 1e9f is 28 6b 6e 4e.
  perl -0777 -pe 's/\x00\x00\xc8\x42/\x28\x6b\x6e\x4e/g' hundred.vrma >key1e9.vrma
  run 1 convert key1e9.vrma -o key1e9.pose.jsonl --fps 30
  expect_in err.txt "key1e9.vrma: the frame times span 1e+09 s"
  absent key1e9.pose.jsonl
  run 1 convert key1e9.vrma -o key1e9.bvh
  expect_in err.txt "more than a clip may span"
  absent key1e9.bvh
else
  echo "perl not found: the .vrma key at 10^9 s case is skipped"
fi
no_temp

# --- the Python ctypes example: C API errors as one clean line, never a traceback -----------
example=$here/../../examples/python/solve_ctypes.py
library=$(dirname "$exe")/bindings/c/libavatarmap_c.so
if command -v python3 >/dev/null && [ -f "$library" ]; then
  # pyrun EXPECTED_STATUS ARGS...: like run, for the example.
  pyrun() {
    local want=$1
    shift
    timeout 60 python3 "$example" --library "$library" "$@" >out.txt 2>err.txt
    local got=$?
    if [ "$got" -eq "$want" ]; then ok; else
      fail "solve_ctypes.py $* exited $got, expected $want"
      head -c 2000 err.txt >&2
    fi
    if grep -q "Traceback" err.txt; then fail "solve_ctypes.py $* printed a traceback"; else ok; fi
  }
  pyrun 1 gap.landmarks.jsonl --output py_gap.vrma --fps 60
  expect_in err.txt "error: write: invalid argument: py_gap.vrma: the frame times span 1000000.00 s"
  absent py_gap.vrma
  pyrun 1 far.landmarks.jsonl --output py_far.pose.jsonl
  expect_in err.txt "span 1.7e+308 s"
  short_lines err.txt
  pyrun 0 backwards.landmarks.jsonl --output py_back.pose.jsonl --fps 60
  expect_in err.txt "skipped 1 frame(s) out of time order"
  expect_in out.txt "wrote py_back.pose.jsonl (2 frames)"
  { printf '{"t":0,"x":'; head -c 100000 /dev/zero | tr '\0' '['; printf '}\n'; } >py_deep.landmarks.jsonl
  pyrun 1 py_deep.landmarks.jsonl
  expect_in err.txt "JSON nested too deeply"
  printf '{"t":NaN}\n' >py_nan.landmarks.jsonl
  pyrun 1 py_nan.landmarks.jsonl
  expect_in err.txt "error: push: invalid argument"
else
  echo "python3 or $library not found: the Python example cases are skipped"
fi

# --- memory running out: an error, never an abort --------------------------------------------
# Two poses 80,000 s apart resampled at 50 fps: 4,000,001 frames (within the limits) of about
# 1 KB each, under a 512 MiB address-space cap. The tool must say so and exit 1, not abort.
printf '{"format":"avatarmap.pose"}\n{"t":0}\n{"t":80000}\n' >oom.pose.jsonl
echo precious >oom.vrma
(
  ulimit -v 524288 2>/dev/null || exit 3
  "$exe" convert oom.pose.jsonl -o oom.vrma --fps 50 >out.txt 2>err.txt
)
got=$?
if grep -qa __asan_init "$exe"; then
  echo "AddressSanitizer build (its shadow memory needs no address-space cap): the out-of-memory case is skipped"
elif [ "$got" -eq 3 ]; then
  echo "ulimit -v is not available here: the out-of-memory case is skipped"
elif [ "$got" -eq 1 ]; then
  ok
  expect_in err.txt "not enough memory"
  kept oom.vrma precious
  no_temp
else
  fail "convert under a 512 MiB cap exited $got, expected 1: $(head -c 300 err.txt)"
fi

finish
