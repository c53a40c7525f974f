#!/usr/bin/env bash
# Hostile output paths: hostile_output_test.sh AVATARMAP_EXE WORK_DIR.
# Every output goes through one atomic writer (src/common/atomic_file.hpp). Checks, through the
# CLI: a missing folder, a folder as the output, a read-only folder and a file-size limit give
# exit status 1 or 2 with the reason (errno text); a failed run never replaces an existing
# output and never leaves a temporary file; a user's files at guessable temporary names are
# untouched and a symlink placed there is never followed; a replaced file keeps its mode; a
# FIFO output stays a FIFO; SIGTERM, SIGINT and SIGHUP during a long write leave no temporary
# file. Registered with CTest as cli.hostile_output_test by tests/cli/CMakeLists.txt.
source "$(dirname "$0")/hostile_lib.sh" "$@"

# mode_is FILE OCTAL
mode_is() {
  local m
  m=$(stat -c '%a' "$1")
  if [ "$m" = "$2" ]; then pass; else fail "$1 has mode $m, expected $2"; fi
}

# ---- inputs ---------------------------------------------------------------------------------
"$exe" synth -o in.landmarks.jsonl --seconds 2 --no-face >/dev/null 2>synth.err ||
  { echo "FAIL: synth failed: $(cat synth.err)" >&2; exit 1; }
"$exe" solve in.landmarks.jsonl -o in.pose.jsonl >/dev/null 2>solve.err ||
  { echo "FAIL: solve failed: $(cat solve.err)" >&2; exit 1; }
echo "garbage" >bad.landmarks.jsonl
# Good frames, then a broken line: the output is being written when the run fails.
head -n 20 in.landmarks.jsonl >late_bad.landmarks.jsonl
echo '{"t": 9, "pose": [[0.5, 0.5, ' >>late_bad.landmarks.jsonl

# ---- a missing folder ---------------------------------------------------------------------
run error synth -o nope/x.landmarks.jsonl --seconds 1
expect_in err.txt "folder 'nope' does not exist"
run error solve in.landmarks.jsonl -o nope/x.pose.jsonl
expect_in err.txt "nope/x.pose.jsonl: cannot write: folder 'nope' does not exist"
for out in nope/x.vrma nope/x.bvh nope/x.pose.jsonl; do
  run error convert in.pose.jsonl -o "$out"
  expect_in err.txt "$out: cannot write: folder 'nope' does not exist"
done
if [ -e nope ]; then fail "a missing folder was created"; else pass; fi

# A "folder" that is a file.
echo "a file" >plain
run error convert in.pose.jsonl -o plain/x.vrma
expect_in err.txt "is not a folder (Not a directory)"
expect_in plain "a file"

# ---- the output is a folder ---------------------------------------------------------------
for out in d.vrma d.bvh d.pose.jsonl d.landmarks.jsonl; do
  mkdir -p "$out"
  echo inside >"$out/inside.txt"
done
run error synth -o d.landmarks.jsonl --seconds 1
expect_in err.txt "d.landmarks.jsonl: cannot write: it is a folder"
run error solve in.landmarks.jsonl -o d.pose.jsonl
expect_in err.txt "it is a folder"
run error convert in.pose.jsonl -o d.vrma
expect_in err.txt "it is a folder"
run error convert in.pose.jsonl -o d.bvh
expect_in err.txt "it is a folder"
for out in d.vrma d.bvh d.pose.jsonl d.landmarks.jsonl; do
  if [ -d "$out" ] && [ "$(cat "$out/inside.txt")" = inside ]; then pass; else
    fail "folder $out was changed"; fi
done

# ---- a read-only folder -------------------------------------------------------------------
if [ "$(id -u)" -ne 0 ]; then
  mkdir ro && chmod 555 ro
  run error solve in.landmarks.jsonl -o ro/x.pose.jsonl
  expect_in err.txt "folder 'ro' is not writable (Permission denied)"
  chmod 755 ro
elif [ -d /sys ]; then
  # Permissions do not stop root; sysfs refuses new files to everyone.
  run error solve in.landmarks.jsonl -o /sys/x.pose.jsonl
  expect_in err.txt "folder '/sys' is not writable ("
else
  echo "note: running as root without /sys: read-only folder case skipped" >&2
fi

# ---- a failed run keeps the existing output -------------------------------------------------
echo "previous poses" >kept.pose.jsonl
cp kept.pose.jsonl kept.expected
run error solve bad.landmarks.jsonl -o kept.pose.jsonl
same_file kept.pose.jsonl kept.expected
run error solve late_bad.landmarks.jsonl -o kept.pose.jsonl
expect_in err.txt "late_bad.landmarks.jsonl:21"
same_file kept.pose.jsonl kept.expected
for out in kept.vrma kept.bvh; do
  echo "previous $out" >"$out"
  cp "$out" "$out.expected"
  run error convert bad.landmarks.jsonl -o "$out"
  same_file "$out" "$out.expected"
done
no_temp .

# ---- a file-size limit (EFBIG, as on a full disk) ------------------------------------------
# ulimit -f counts 1024-byte blocks; every output here is larger than 8 KiB.
for out in big.landmarks.jsonl big.pose.jsonl big.vrma big.bvh; do
  echo "previous $out" >"$out"
  cp "$out" "$out.expected"
done
(
  ulimit -f 8
  "$exe" synth -o big.landmarks.jsonl --seconds 10 >out.txt 2>err.txt
  echo $? >status.txt
)
got=$(cat status.txt)
if [ "$got" -eq 1 ] || [ "$got" -eq 2 ]; then pass; else fail "synth over ulimit -f exited $got"; fi
expect_in err.txt "File too large"
same_file big.landmarks.jsonl big.landmarks.jsonl.expected
for args in "solve in.landmarks.jsonl -o big.pose.jsonl" "convert in.pose.jsonl -o big.vrma" \
  "convert in.pose.jsonl -o big.bvh"; do
  (
    ulimit -f 8
    # shellcheck disable=SC2086
    "$exe" $args >out.txt 2>err.txt
    echo $? >status.txt
  )
  got=$(cat status.txt)
  if [ "$got" -eq 1 ] || [ "$got" -eq 2 ]; then pass; else fail "$args over ulimit -f exited $got"; fi
  expect_in err.txt "File too large"
  expect_in err.txt "the previous file is unchanged"
done
for out in big.pose.jsonl big.vrma big.bvh; do same_file "$out" "$out.expected"; done
no_temp .

# ---- .glb (needs an avatar from the shared test data) ---------------------------------------
avatar="${AVATARMAP_TEST_DATA:-}/avatars/vrm1_debug_robot.vrm"
if [ -n "${AVATARMAP_TEST_DATA:-}" ] && [ -f "$avatar" ]; then
  echo "previous glb" >old.glb
  cp old.glb old.glb.expected
  chmod 640 old.glb
  mkdir -p elsewhere
  echo "precious" >elsewhere/glb_victim.txt
  cp elsewhere/glb_victim.txt glb_victim.expected
  echo "user's own tmp" >old.glb.tmp
  ln -s "$PWD/elsewhere/glb_victim.txt" .old.glb.tmp.XXXXXX
  (
    ulimit -f 8
    "$exe" convert in.pose.jsonl --avatar "$avatar" -o old.glb >out.txt 2>err.txt
    echo $? >status.txt
  )
  got=$(cat status.txt)
  if [ "$got" -eq 1 ] || [ "$got" -eq 2 ]; then pass; else fail ".glb over ulimit -f exited $got"; fi
  expect_in err.txt "File too large"
  same_file old.glb old.glb.expected
  run error convert bad.landmarks.jsonl --avatar "$avatar" -o old.glb
  same_file old.glb old.glb.expected
  run ok convert in.pose.jsonl --avatar "$avatar" -o old.glb
  if [ "$(head -c 4 old.glb)" = glTF ]; then pass; else fail "old.glb is not a GLB now"; fi
  mode_is old.glb 640
  expect_in old.glb.tmp "user's own tmp"
  same_file elsewhere/glb_victim.txt glb_victim.expected
  run error convert in.pose.jsonl --avatar "$avatar" -o nope/x.glb
  expect_in err.txt "nope/x.glb: cannot write: folder 'nope' does not exist"
  if [ -L .old.glb.tmp.XXXXXX ]; then pass; else fail "the planted symlink was removed"; fi
  rm -f .old.glb.tmp.XXXXXX  # ours, planted above: not a leftover
  no_temp .
else
  skip_part "AVATARMAP_TEST_DATA is not set: the .glb cases"
fi

# ---- guessable temporary names: a user's files untouched, symlinks not followed ------------
mkdir -p elsewhere
echo "precious" >elsewhere/victim.txt
cp elsewhere/victim.txt victim.expected
echo "user's own tmp" >t.vrma.tmp
ln -s "$PWD/elsewhere/victim.txt" t.bvh.tmp
ln -s "$PWD/elsewhere/victim.txt" .t.pose.jsonl.tmp.XXXXXX
run ok convert in.pose.jsonl -o t.vrma
run ok convert in.pose.jsonl -o t.bvh
run ok convert in.pose.jsonl -o t.pose.jsonl
expect_in t.vrma.tmp "user's own tmp"
same_file elsewhere/victim.txt victim.expected
if [ -L t.bvh.tmp ] && [ -L .t.pose.jsonl.tmp.XXXXXX ]; then pass; else
  fail "a symlink at a temporary-looking name was removed or replaced"; fi
expect_in t.bvh "HIERARCHY"

# A symlink as the output itself is replaced by the new file; its target is never written.
ln -s "$PWD/elsewhere/victim.txt" link.bvh
run ok convert in.pose.jsonl -o link.bvh
if [ -L link.bvh ]; then fail "link.bvh is still a symlink"; else pass; fi
expect_in link.bvh "HIERARCHY"
same_file elsewhere/victim.txt victim.expected

# ---- modes of replaced files are kept ------------------------------------------------------
for m in 600 755 640; do
  echo old >"m$m.pose.jsonl"
  chmod "$m" "m$m.pose.jsonl"
  run ok solve in.landmarks.jsonl -o "m$m.pose.jsonl"
  mode_is "m$m.pose.jsonl" "$m"
  same_file "m$m.pose.jsonl" in.pose.jsonl
done
(
  umask 022
  "$exe" convert in.pose.jsonl -o new.vrma >/dev/null 2>&1
)
mode_is new.vrma 644

# ---- a FIFO output is written in place and stays a FIFO ------------------------------------
mkfifo pipe.pose.jsonl
cat pipe.pose.jsonl >from_pipe.txt &
reader=$!
run ok solve in.landmarks.jsonl -o pipe.pose.jsonl
wait "$reader"
if [ -p pipe.pose.jsonl ]; then pass; else fail "pipe.pose.jsonl is no longer a FIFO"; fi
same_file from_pipe.txt in.pose.jsonl

# ---- signals during a long write ------------------------------------------------------------
# Job control on, so that background jobs keep SIGINT (a non-interactive shell would start
# them with SIGINT ignored, and the tool keeps signals it finds ignored).
set -m
for sig in TERM INT HUP; do
  mkdir -p "sig_$sig"
  echo "previous" >"sig_$sig/kept.landmarks.jsonl"
  "$exe" synth --seconds 3000 -o "sig_$sig/big.landmarks.jsonl" >/dev/null 2>"sig_$sig/err.txt" &
  pid=$!
  "$exe" synth --seconds 3000 -o "sig_$sig/kept.landmarks.jsonl" >/dev/null 2>&1 &
  pid2=$!
  # Wait until both temporary files exist and have data (at most 20 s).
  for _ in $(seq 200); do
    n=$(find "sig_$sig" -maxdepth 1 -name '.*.tmp.*' -size +0 | wc -l)
    [ "$n" -ge 2 ] && break
    sleep 0.1
  done
  if [ "$n" -ge 2 ]; then pass; else fail "SIG$sig: the temporary files never appeared"; fi
  kill -s "$sig" "$pid" "$pid2"
  wait "$pid"
  st=$?
  wait "$pid2"
  st2=$?
  want=$((128 + $(kill -l "$sig")))
  if [ "$st" -eq "$want" ] && [ "$st2" -eq "$want" ]; then pass; else
    fail "SIG$sig: exit statuses $st and $st2, expected $want (killed by the signal)"; fi
  if [ -e "sig_$sig/big.landmarks.jsonl" ]; then fail "SIG$sig: an unfinished output appeared"; else
    pass; fi
  expect_in "sig_$sig/kept.landmarks.jsonl" "previous"
  left=$(find "sig_$sig" -name '*.tmp.*' | head -3)
  if [ -z "$left" ]; then pass; else fail "SIG$sig: temporary files left: $left"; fi
done
set +m

finish
