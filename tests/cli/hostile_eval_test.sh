#!/usr/bin/env bash
# `avatarmap synth --scenario/--truth` and `avatarmap eval-pose` (docs/accuracy.md): a round
# trip synth -> solve -> eval-pose, known answers (a truth against itself is 0), and bad usage
# or mismatched files give a clear error (exit 1 or 2, never a signal) without writing outputs.
# Usage: hostile_eval_test.sh EXE WORK_DIR
# shellcheck source=hostile_lib.sh
source "$(dirname "$0")/hostile_lib.sh"

# A short noisy recording with its truth; the truth has the low-visibility marker.
run ok synth --scenario noisy --seed 104 --seconds 6 -o rec.landmarks.jsonl \
  --truth truth.pose.jsonl
expect_in truth.pose.jsonl '"confidence":{'
grep -o '"confidence":{[^}]*}' truth.pose.jsonl | grep -q ':0[,}]' && pass ||
  fail "no bone marked low-visibility in truth.pose.jsonl"
frames=$(($(wc -l <rec.landmarks.jsonl) - 1))
[ "$frames" -eq 180 ] && pass || fail "rec.landmarks.jsonl has $frames frames, expected 180"
truth_frames=$(($(wc -l <truth.pose.jsonl) - 1))
[ "$truth_frames" -eq 180 ] && pass || fail "truth has $truth_frames frames, expected 180"

# The truth against itself: 0 everywhere.
run ok eval-pose truth.pose.jsonl truth.pose.jsonl --json
expect_in out.txt '"frames":180'
expect_in out.txt '"overall":{"mean":0.0000'
expect_in out.txt '"head":{"mean":0.0000'

# Solved poses: a table with every group, and JSON with low-visibility figures.
run ok solve rec.landmarks.jsonl -o solved.pose.jsonl --quiet
run ok eval-pose truth.pose.jsonl solved.pose.jsonl
for word in overall torso arms legs fingers head 'low-visibility frames' 'marked bones'; do
  expect_in out.txt "$word"
done
run ok eval-pose truth.pose.jsonl solved.pose.jsonl --json
expect_in out.txt '"frames":180,"low_visibility_frames":'
expect_not_in out.txt '"low_visibility_frames":0,'
expect_not_in out.txt '"all":{"overall":{"mean":0.0000'
expect_not_in out.txt '"marked":{"mean":0.0000'

# Scenario presets are seeded: the same seed gives the same file, another seed another.
run ok synth --scenario noisy --seed 104 --seconds 6 -o again.landmarks.jsonl
same_file rec.landmarks.jsonl again.landmarks.jsonl
run ok synth --scenario noisy --seed 105 --seconds 6 -o other.landmarks.jsonl
if cmp -s rec.landmarks.jsonl other.landmarks.jsonl; then fail "seeds 104 and 105 agree"; else
  pass
fi

# Bad usage: exit 2, a message naming the option, nothing written.
run 2 synth --scenario loud -o x.landmarks.jsonl
expect_in err.txt "--scenario is demo, clean or noisy"
absent x.landmarks.jsonl
run 2 synth -o same.jsonl --truth same.jsonl
expect_in err.txt "--truth and -o name the same file"
absent same.jsonl
run 2 synth -o x.landmarks.jsonl --low-vis 2
expect_in err.txt "--low-vis"
run 2 synth -o x.landmarks.jsonl --fov 200
expect_in err.txt "--fov"
run 2 synth -o x.landmarks.jsonl --motion dance
expect_in err.txt "--motion"
run 2 synth -o x.landmarks.jsonl --body-noise -1
expect_in err.txt "--body-noise"
absent x.landmarks.jsonl
run 2 eval-pose truth.pose.jsonl
expect_in err.txt "give TRUTH.pose.jsonl and SOLVED.pose.jsonl"
run 2 eval-pose a b c
run 2 eval-pose truth.pose.jsonl solved.pose.jsonl --tolerance -1
run 2 eval-pose truth.pose.jsonl solved.pose.jsonl --bogus

# Mismatched or bad files: exit 1 with the file named.
run 1 eval-pose truth.pose.jsonl absent.pose.jsonl
expect_in err.txt "absent.pose.jsonl"
head -n 50 solved.pose.jsonl >short.pose.jsonl
run 1 eval-pose truth.pose.jsonl short.pose.jsonl
expect_in err.txt "131 of 180 frames"
expect_in err.txt "short.pose.jsonl"
printf '{"format":"avatarmap.pose","version":1}\n{"t":0,"bones":{"hips":[0,0,0' >broken.pose.jsonl
run 1 eval-pose truth.pose.jsonl broken.pose.jsonl
expect_in err.txt "broken.pose.jsonl"
run 1 eval-pose rec.landmarks.jsonl solved.pose.jsonl
no_temp

finish
