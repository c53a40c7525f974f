#!/usr/bin/env bash
# Runs one case of the avatarmap command-line tests: cli_test.sh AVATARMAP_EXE WORK_DIR CASE.
# Each case runs the tool in a fresh folder under WORK_DIR and checks its exit status, its
# messages and the files it writes. Registered with CTest by tests/cli/CMakeLists.txt.
set -u

exe=$1
work=$2
case_name=$3
dir="$work/$case_name"
rm -rf "$dir"
mkdir -p "$dir"
cd "$dir" || exit 1

failures=0
fail() {
  echo "FAIL [$case_name]: $*" >&2
  failures=$((failures + 1))
}

# run EXPECTED_STATUS ARGS...: runs the tool, stdout to out.txt, stderr to err.txt.
run() {
  local want=$1
  shift
  "$exe" "$@" >out.txt 2>err.txt
  local got=$?
  if [ "$got" -ne "$want" ]; then
    fail "avatarmap $* exited $got, expected $want"
    echo "--- stdout:" >&2
    head -c 2000 out.txt >&2
    echo "--- stderr:" >&2
    head -c 2000 err.txt >&2
  fi
}

# needs WHAT...: whether each is there — data: the shared real data ($AVATARMAP_TEST_DATA);
# models: the converted models ($AVATARMAP_MODELS/onnx) and this build's onnx backend (the
# sanitizer build, for one, has none). When one is missing the part is left out and the case
# ends as skipped (exit 77, CTest: skipped), never as passed; what ran before still counts.
skipped=""
needs() {
  local what why=""
  for what in "$@"; do
    case "$what" in
      data)
        [ -n "${AVATARMAP_TEST_DATA:-}" ] && [ -d "$AVATARMAP_TEST_DATA" ] ||
          why="AVATARMAP_TEST_DATA is not set to the shared real data" ;;
      models)
        if [ ! -f "${AVATARMAP_MODELS:-}/onnx/pose_detection.onnx" ]; then
          why="no models in \$AVATARMAP_MODELS/onnx (scripts/prepare_capture.sh)"
        elif ! "$exe" backends 2>/dev/null | grep -q '^ *onnx'; then
          why="this build has no onnx backend"
        fi ;;
    esac
    if [ -n "$why" ]; then
      skipped="${skipped:+$skipped; }$why"
      return 1
    fi
  done
}

# expect_in FILE TEXT: FILE contains TEXT (fixed string).
expect_in() {
  if ! grep -qF -- "$2" "$1"; then
    fail "$1 does not contain '$2'"
    echo "--- $1:" >&2
    head -c 2000 "$1" >&2
  fi
}

# lines FILE: number of lines.
lines() { wc -l <"$1" | tr -d ' '; }

# synth_input PATH SECONDS: writes a synthetic recording (30 fps, no face: faster).
synth_input() {
  "$exe" synth -o "$1" --seconds "$2" --no-face >synth.out 2>synth.err ||
    { fail "synth failed: $(cat synth.err)"; return 1; }
}

case $case_name in
  people)
    # A landmark file of two people (version 2, docs/file-formats.md): two recordings' lines
    # interleaved by time with ids 0 and 5 (written here, apart from the tool's writer).
    "$exe" synth -o a.landmarks.jsonl --seconds 2 --seed 3 >/dev/null 2>&1 || fail "synth a"
    "$exe" synth -o b.landmarks.jsonl --seconds 2 --seed 4 --scenario clean >/dev/null 2>&1 ||
      fail "synth b"
    python3 -c 'import json
a = open("a.landmarks.jsonl").read().splitlines()
b = open("b.landmarks.jsonl").read().splitlines()
h = json.loads(a[0]); h["version"] = 2
out = [json.dumps(h)]
for la, lb in zip(a[1:], b[1:]):
    for pid, line in ((0, la), (5, lb)):
        d = json.loads(line); d["person"] = pid; out.append(json.dumps(d))
open("two.landmarks.jsonl", "w").write("\n".join(out) + "\n")' || fail "could not write the two-person file"
    # Each person to its own output: the poses of solving that person's recording alone, the
    # root measured from where the first person (0) was first seen: person 5's hips X/Z are b's
    # alone moved by one constant, everything else is b's.
    run 0 solve two.landmarks.jsonl -o take.pose.jsonl
    expect_in err.txt "person 0 -> take.p0.pose.jsonl"
    expect_in err.txt "person 5 -> take.p5.pose.jsonl"
    [ -e take.pose.jsonl ] && fail "solve of two people wrote take.pose.jsonl"
    run 0 solve a.landmarks.jsonl -o a.pose.jsonl
    run 0 solve b.landmarks.jsonl -o b.pose.jsonl
    cmp -s a.pose.jsonl take.p0.pose.jsonl || fail "person 0's poses differ from a's alone"
    python3 - b.pose.jsonl take.p5.pose.jsonl <<'PY' || fail "person 5 is not b moved by a constant"
import json, sys
alone, moved = ([json.loads(l) for l in open(p) if l.strip()][1:] for p in sys.argv[1:3])
assert len(alone) == len(moved) > 10
shift = [moved[0]["hips_position"][k] - alone[0]["hips_position"][k] for k in (0, 2)]
assert abs(shift[0]) + abs(shift[1]) > 0.05, shift  # synth's two people stand apart
for a, m in zip(alone, moved):
    for k, d in ((0, shift[0]), (2, shift[1])):
        assert abs(m["hips_position"][k] - a["hips_position"][k] - d) < 1e-4
    assert m["hips_position"][1] == a["hips_position"][1]
    assert m["bones"] == a["bones"] and m["t"] == a["t"]
PY
    # One person asked for: one output under the name given, from the same origin; with its
    # own id as the origin person it is b alone.
    run 0 solve two.landmarks.jsonl -o five.pose.jsonl --person 5
    cmp -s take.p5.pose.jsonl five.pose.jsonl || fail "--person 5 is not take.p5's poses"
    run 0 solve two.landmarks.jsonl -o own.pose.jsonl --person 5 --origin-person 5
    cmp -s b.pose.jsonl own.pose.jsonl || fail "--origin-person 5 is not b's poses alone"
    run 1 solve two.landmarks.jsonl -o x.pose.jsonl --person 5 --origin-person 3
    expect_in err.txt "no origin person 3 (its people: 0, 5)"
    [ -e x.pose.jsonl ] && fail "a refused origin person wrote x.pose.jsonl"
    run 2 solve two.landmarks.jsonl -o x.pose.jsonl --person 3
    expect_in err.txt "no person 3 (its people: 0, 5)"
    run 2 solve two.landmarks.jsonl -o -
    expect_in err.txt "cannot share standard output"
    # A single-person file keeps its name; --person 0 is it, another id is not there.
    run 0 solve a.landmarks.jsonl -o one.pose.jsonl --person 0
    cmp -s a.pose.jsonl one.pose.jsonl || fail "--person 0 of a one-person file changed it"
    run 2 solve a.landmarks.jsonl -o one.pose.jsonl --person 1
    expect_in err.txt "no person 1 (its people: 0)"
    # convert: one .glb per person, the avatars given in turn.
    run 0 convert two.landmarks.jsonl -o take.glb --quiet
    [ -s take.p0.glb ] && [ -s take.p5.glb ] || fail "convert did not write take.p0.glb and take.p5.glb"
    [ -e take.glb ] && fail "convert of two people wrote take.glb"
    run 0 convert two.landmarks.jsonl -o five.pose.jsonl --person 5 --quiet
    cmp -s take.p5.pose.jsonl five.pose.jsonl || fail "convert --person 5 is not solve's"
    # An old reader's view: the header says version 2, so a version-1 reader refuses it.
    expect_in two.landmarks.jsonl '"version": 2'
    # live --people 2: one pose file per person. Two people side by side (pose_squats.mp4 beside
    # its mirror image 1.6 s later), made here with the ffmpeg tool.
    run 2 live in.mp4 --people 2 -o -
    expect_in err.txt "several people cannot share standard output"
    if needs data models && command -v ffmpeg >/dev/null; then
      clip="$AVATARMAP_TEST_DATA/motion/tfjs-models/pose_squats.mp4"
      ffmpeg -v error -y -i "$clip" -i "$clip" -filter_complex \
        "[1:v]trim=start=1.6,setpts=PTS-STARTPTS,hflip[b];[0:v][b]hstack=inputs=2" -t 3 \
        -c:v libx264 -pix_fmt yuv420p side.mp4 || fail "ffmpeg could not make side.mp4"
      models="$AVATARMAP_MODELS/onnx"
      run 0 live side.mp4 --people 2 --models "$models" -o live.pose.jsonl --seconds 3
      [ -e live.pose.jsonl ] && fail "live of two people wrote live.pose.jsonl"
      expect_in err.txt "people 0, 1"
      run 0 live "$clip" --models "$models" -o alone.pose.jsonl --seconds 3
      # Person 0 (the clip itself) is nearer the clip's own live poses than person 1 (the
      # mirror image, later) is: each file holds its own person.
      python3 - live.p0.pose.jsonl live.p1.pose.jsonl alone.pose.jsonl <<'PY' ||
import json, math, sys
def load(path):
    rows = [json.loads(l) for l in open(path) if l.strip()][1:]
    return [(r["t"], r["bones"]) for r in rows]
p0, p1, alone = (load(p) for p in sys.argv[1:4])
assert len(p0) > 60 and len(p1) > 60, (len(p0), len(p1))
def angle(a, b):
    d = abs(sum(x * y for x, y in zip(a, b)))
    return 2 * math.degrees(math.acos(min(1.0, d)))
def distance(poses):
    total = n = 0
    for t, bones in poses:
        _, ref = min(alone, key=lambda r: abs(r[0] - t))
        for name in ("leftUpperArm", "rightUpperArm", "leftUpperLeg", "rightUpperLeg"):
            if name in bones and name in ref:
                total += angle(bones[name], ref[name]); n += 1
    return total / max(1, n)
d0, d1 = distance(p0), distance(p1)
print("person 0 vs alone %.1f deg, person 1 vs alone %.1f deg" % (d0, d1))
assert d0 < 15 and d1 > d0 + 20, (d0, d1)  # measured 7.7 and 62.8
PY
        fail "live.p0/p1.pose.jsonl do not hold their own people"
      # The same video captured to a file and solved: the two people stand apart as in the
      # video, the right one (person 1) about as far right of the left one as live puts it.
      run 0 capture side.mp4 --people 2 --models "$models" -o side.landmarks.jsonl --quiet
      run 0 solve side.landmarks.jsonl -o side.pose.jsonl
      python3 - side.p0.pose.jsonl side.p1.pose.jsonl live.p0.pose.jsonl live.p1.pose.jsonl <<'PY' ||
import json, sys
def mean_x(path):
    rows = [json.loads(l) for l in open(path) if l.strip()][1:]
    return sum(r["hips_position"][0] for r in rows) / len(rows)
f0, f1, l0, l1 = (mean_x(p) for p in sys.argv[1:5])
gap_file, gap_live = f1 - f0, l1 - l0
print("person 1 right of person 0: %.2f m (files), %.2f m (live)" % (gap_file, gap_live))
# Two people 720 px apart at one depth, each about 1100 px tall: 1 to 2.5 m apart.
assert 0.8 < gap_file < 3.0 and abs(gap_file - gap_live) < 0.5, (gap_file, gap_live)
PY
        fail "the solved files do not stand the two people apart as live does"
    fi
    ;;
  glb_builtin)
    # A .glb without --avatar carries the built-in avatar, as `avatarmap avatar` writes it:
    # the same file as with --avatar set to that avatar, loaded by our own loader (inspect) as
    # the VRM 1.0 avatar, and its animation (read here by an independent GLB reader) drives
    # the avatar's humanoid bones and moves over time.
    synth_input in.landmarks.jsonl 2 || exit 1
    run 0 solve in.landmarks.jsonl -o in.pose.jsonl
    run 0 avatar -o builtin.vrm
    run 0 convert in.pose.jsonl -o default.glb
    expect_in err.txt "avatar (built-in):"
    expect_in err.txt "wrote default.glb"
    run 0 convert in.pose.jsonl -o given.glb --avatar builtin.vrm
    cmp -s default.glb given.glb || fail "default.glb differs from the same motion on builtin.vrm"
    run 0 convert in.landmarks.jsonl -o landmarks.glb
    ls "$dir" "${TMPDIR:-/tmp}" | grep -F "avatarmap-builtin-" | grep -q . &&
      fail "the built-in avatar's temporary file was left: $(ls "${TMPDIR:-/tmp}" | grep builtin)"
    run 0 inspect default.glb --json
    python3 - out.txt builtin.vrm default.glb <<'PY' || fail "default.glb is not the built-in avatar animated"
import json, struct, sys
def glb_json(path):
    b = open(path, "rb").read()
    assert b[:4] == b"glTF", path
    n, kind = struct.unpack_from("<II", b, 12)
    assert kind == 0x4E4F534A, "first chunk is not JSON"
    return json.loads(b[20:20 + n]), b[20 + n + 8:]
info = json.load(open(sys.argv[1]))
assert info["format"] == "vrm1", info["format"]
avatar, _ = glb_json(sys.argv[2])
out, binary = glb_json(sys.argv[3])
human = avatar["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"]
names = {avatar["nodes"][v["node"]]["name"]: k for k, v in human.items()}
assert [n["name"] for n in out["nodes"]] == [n["name"] for n in avatar["nodes"]], "nodes differ"
anims = out.get("animations", [])
assert len(anims) == 1, "%d animations" % len(anims)
rotated = set()
for ch in anims[0]["channels"]:
    if ch["target"]["path"] != "rotation":
        continue
    node = out["nodes"][ch["target"]["node"]]["name"]
    assert node in names, "a channel drives %s, no humanoid bone" % node
    acc = out["accessors"][anims[0]["samplers"][ch["sampler"]]["output"]]
    view = out["bufferViews"][acc["bufferView"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    q = struct.unpack_from("<%df" % (4 * acc["count"]), binary, start)
    frames = [q[i:i + 4] for i in range(0, len(q), 4)]
    if max(abs(a - b) for f in frames for a, b in zip(f, frames[0])) > 0.05:
        rotated.add(names[node])
for bone in ("hips", "leftUpperArm", "rightLowerArm", "leftUpperLeg", "head"):
    assert bone in rotated, "%s does not move (moving: %s)" % (bone, sorted(rotated))
print("channels on", len(rotated), "moving bones")
PY
    if needs data models; then
      run 0 animate "$AVATARMAP_TEST_DATA/motion/tfjs-models/pose_squats.mp4" -o squats.glb \
        --models "$AVATARMAP_MODELS/onnx" --body-only --seconds 1
      expect_in err.txt "avatar (built-in):"
      run 0 inspect squats.glb
      expect_in out.txt "declared: 55 of 55 bones"
    fi
    ;;
  help_tables)
    # --help against what each command takes. 1. The top-level usage: each flag it shows for a
    # command is one that command lists in its own --help and accepts. 2. Each flag a command's
    # source declares by hand (a "--name" literal in src/cli; the option tables' flags are
    # listed from the tables themselves) and that the command accepts is in its --help.
    # "Accepts": given with a dummy value and an input that does not exist, the command does
    # not answer "unknown option" (case help_options checks each listed flag the same way).
    src_cli="$(cd "$(dirname "$0")/../../src/cli" && pwd)"
    accepts() {  # accepts CMD FLAG
      timeout 20 "$exe" "$1" missing-input.nothing "$2" x >acc_out.txt 2>acc_err.txt </dev/null
      ! grep -qE -- "unknown option $2( |\$)" acc_err.txt
    }
    listed() {  # listed CMD FLAG: FLAG in a usage line or the option column of CMD --help
      [ -f "help.$1.txt" ] || "$exe" "$1" --help 2>/dev/null |
        grep -E '^( {1,4}-|Usage: |  avatarmap )' | sed -E 's/^ +//; s/  .*//' >"help.$1.txt"
      grep -qE -- "(^|[][ /,|])$2([][ ,=/|]|\$)" "help.$1.txt"
    }
    run 0 --help
    grep -E '^  avatarmap [a-z]' out.txt >usage_lines.txt
    [ -s usage_lines.txt ] || fail "avatarmap --help lists no commands"
    while read -r _ cmd rest; do
      for flag in $(printf '%s\n' "$rest" | grep -oE -- '(^| |\[)--?[a-zA-Z][a-zA-Z0-9-]*' |
        grep -oE -- '--?[a-zA-Z][a-zA-Z0-9-]*' | sort -u); do
        listed "$cmd" "$flag" ||
          fail "avatarmap --help shows $cmd $flag, which \`avatarmap $cmd --help\` does not list"
        accepts "$cmd" "$flag" || fail "avatarmap --help shows $cmd $flag, which $cmd refuses"
      done
    done <usage_lines.txt
    # Hidden on purpose: convert --dump-positions (a diagnostic, see convert_command.cpp).
    hidden=" --dump-positions "
    declare -A files=(
      [solve]="solve_command.cpp solve_job.cpp" [convert]="convert_command.cpp"
      [capture]="capture_command.cpp capture_setup.cpp overlay_output.cpp"
      [animate]="animate_command.cpp" [live]="live_command.cpp live_vmc.cpp"
      [view]="view_command.cpp viewer_setup.cpp" [synth]="synth_command.cpp"
      [demo]="demo_command.cpp" [import-tfjs]="synth_command.cpp"
      [eval-pose]="eval_command.cpp" [eval-world]="eval_world_command.cpp"
      [inspect]="inspect_command.cpp" [avatar]="avatar_command.cpp"
      [backends]="other_commands.cpp" [options]="other_commands.cpp" [render]="render_command.cpp")
    checked=0
    for cmd in "${!files[@]}"; do
      flags=$(cd "$src_cli" && cat ${files[$cmd]} 2>/dev/null |
        grep -oE -- '"--[a-z][a-z0-9-]*"' | tr -d '"' | sort -u)
      for flag in $flags; do
        case "$hidden" in *" $flag "*) continue ;; esac
        case "$flag" in --help) continue ;; esac
        if accepts "$cmd" "$flag"; then
          checked=$((checked + 1))
          listed "$cmd" "$flag" || fail "$cmd accepts $flag, which its --help does not list"
        fi
      done
    done
    [ "$checked" -ge 60 ] || fail "only $checked accepted flags found in the sources"
    ;;
  help)
    run 0 --help
    expect_in out.txt "Usage:"
    expect_in out.txt "avatarmap solve"
    run 0 -h
    expect_in out.txt "Usage:"
    for cmd in solve synth demo import-tfjs backends avatar; do
      run 0 "$cmd" --help
      expect_in out.txt "Usage: avatarmap $cmd"
    done
    ;;
  version)
    run 0 --version
    expect_in out.txt "avatarmap "
    if ! grep -qE '^avatarmap [0-9]+\.[0-9]+\.[0-9]+' out.txt; then
      fail "--version prints no version number: $(cat out.txt)"
    fi
    ;;
  no_command)
    run 2
    expect_in err.txt "Usage:"
    ;;
  unknown_command)
    run 2 frobnicate
    expect_in err.txt "unknown command 'frobnicate'"
    ;;
  unknown_option)
    run 2 solve in.landmarks.jsonl -o out.pose.jsonl --frobnicate
    expect_in err.txt "unknown option --frobnicate"
    run 2 synth -o x.landmarks.jsonl --frobnicate
    expect_in err.txt "unknown option --frobnicate"
    run 2 demo --frobnicate
    expect_in err.txt "unknown option --frobnicate"
    ;;
  solve_usage)
    synth_input in.landmarks.jsonl 1 || exit 1
    run 2 solve in.landmarks.jsonl
    expect_in err.txt "-o"
    [ -e out.pose.jsonl ] && fail "solve without -o wrote a file"
    run 2 solve -o out.pose.jsonl
    expect_in err.txt "input"
    run 2 solve a.landmarks.jsonl b.landmarks.jsonl -o out.pose.jsonl
    expect_in err.txt "exactly one input"
    run 2 solve in.landmarks.jsonl -o
    expect_in err.txt "needs a value"
    run 2 solve in.landmarks.jsonl -o out.pose.jsonl --image-size 12x
    expect_in err.txt "--image-size"
    run 2 solve in.landmarks.jsonl -o out.pose.jsonl --image-size 12x34x
    expect_in err.txt "--image-size"
    run 2 solve in.landmarks.jsonl -o out.pose.jsonl --fps abc
    expect_in err.txt "--fps"
    run 2 solve in.landmarks.jsonl -o out.pose.jsonl --fps -1
    expect_in err.txt "--fps must be 0 or in (0, 1000], got -1"
    run 2 solve in.landmarks.jsonl -o out.pose.jsonl --fps 1001
    expect_in err.txt "--fps"
    run 2 solve in.landmarks.jsonl -o out.pose.jsonl --parts body,tail
    expect_in err.txt "tail"
    run 2 solve in.landmarks.jsonl -o out.pose.jsonl --filter kalman
    expect_in err.txt "kalman"
    run 2 solve in.landmarks.jsonl -o out.pose.jsonl --min-cutoff 0
    expect_in err.txt "--min-cutoff"
    [ -e out.pose.jsonl ] && fail "a usage error wrote the output file"
    ;;
  synth_solve)
    run 0 synth -o in.landmarks.jsonl --seconds 2
    expect_in err.txt "wrote 60 synthetic frames"
    n=$(lines in.landmarks.jsonl)
    [ "$n" -eq 61 ] || fail "synth wrote $n lines, expected 61 (header + 60 frames)"
    expect_in in.landmarks.jsonl '"format":"avatarmap.landmarks"'
    run 0 solve in.landmarks.jsonl -o out.pose.jsonl
    expect_in err.txt "solved 60 frames"
    expect_in err.txt "wrote 60 poses to out.pose.jsonl"
    n=$(lines out.pose.jsonl)
    [ "$n" -eq 61 ] || fail "solve wrote $n lines, expected 61 (header + 60 frames)"
    expect_in out.pose.jsonl '"format":"avatarmap.pose"'
    ls out.pose.jsonl.tmp.* >/dev/null 2>&1 && fail "a temporary file was left beside the output"
    # --quiet and a second run over an existing output: replaced.
    run 0 solve in.landmarks.jsonl -o out.pose.jsonl --quiet --filter none --mirror --confidence
    n=$(lines out.pose.jsonl)
    [ "$n" -eq 61 ] || fail "second solve wrote $n lines, expected 61"
    # Foot contacts (docs/contacts.md): the demo motion stands, so its feet are planted; the
    # flags turn the stage off (foot_contact 0) or only the hips' following (same contacts,
    # the solver's hips).
    run 0 solve in.landmarks.jsonl -o on.pose.jsonl
    run 0 solve in.landmarks.jsonl -o off.pose.jsonl --no-foot-contacts
    run 0 solve in.landmarks.jsonl -o nofollow.pose.jsonl --no-root-follow
    expect_in on.pose.jsonl '"foot_contact":[1,1]'
    grep -q '"foot_contact":\[1' off.pose.jsonl && fail "--no-foot-contacts still planted a foot"
    expect_in off.pose.jsonl '"foot_contact":[0,0]'
    python3 -c 'import json, sys
def load(p):
    return [json.loads(l) for l in open(p) if "\"t\"" in l]
on, off, nf = load("on.pose.jsonl"), load("off.pose.jsonl"), load("nofollow.pose.jsonl")
assert [a["foot_contact"] for a in nf] == [a["foot_contact"] for a in on]
assert [a["hips_position"] for a in nf] == [a["hips_position"] for a in off]
assert [a["hips_position"] for a in on] != [a["hips_position"] for a in off]' ||
      fail "--no-root-follow is not the contacts with the solver's hips"
    ;;
  solve_threads)
    # Parsing on a second thread changes nothing in the output, and bad lines still stop it.
    synth_input in.landmarks.jsonl 3 || exit 1
    run 0 solve in.landmarks.jsonl -o one.pose.jsonl --threads 1
    run 0 solve in.landmarks.jsonl -o two.pose.jsonl --threads 2
    cmp -s one.pose.jsonl two.pose.jsonl || fail "--threads 1 and 2 wrote different poses"
    { head -n 20 in.landmarks.jsonl; echo '{"t": oops'; tail -n +21 in.landmarks.jsonl; } >bad.landmarks.jsonl
    run 1 solve bad.landmarks.jsonl -o bad.pose.jsonl --threads 2
    expect_in err.txt "bad.landmarks.jsonl:21:"
    run 0 solve bad.landmarks.jsonl -o bad.pose.jsonl --threads 2 --skip-bad-lines
    expect_in err.txt "solved 90 frames"
    run 2 solve in.landmarks.jsonl -o x.pose.jsonl --threads 3
    ;;
  convert)
    synth_input in.landmarks.jsonl 2 || exit 1
    run 0 convert in.landmarks.jsonl -o out.vrma
    expect_in err.txt "into 60 frames at 30 fps"
    [ "$(head -c 4 out.vrma)" = "glTF" ] || fail "out.vrma is not a binary glTF"
    run 0 convert out.vrma -o back.pose.jsonl --fps 30
    expect_in err.txt "wrote back.pose.jsonl"
    run 0 convert in.landmarks.jsonl -o out.bvh --fps 60
    expect_in out.bvh "HIERARCHY"
    expect_in out.bvh "Frame Time: 0.01666"
    run 0 convert in.landmarks.jsonl -o out.pose.jsonl
    # .glb without --avatar: the built-in avatar (case glb_builtin).
    run 2 convert in.landmarks.jsonl -o out.fbx
    expect_in err.txt ".vrma, .glb, .bvh or .pose.jsonl"
    run 1 convert missing.landmarks.jsonl -o x.vrma
    expect_in err.txt "missing.landmarks.jsonl"
    run 1 convert in.landmarks.jsonl -o x.glb --avatar no-such-avatar.vrm
    expect_in err.txt "no-such-avatar.vrm"
    [ -e x.glb ] && fail "a failed convert wrote its output"
    if needs data; then
      run 0 convert in.landmarks.jsonl -o robot.glb --avatar "$AVATARMAP_TEST_DATA/avatars/vrm1_debug_robot.vrm"
      expect_in err.txt "humanoid declared by the file (53 bones)"
      [ "$(head -c 4 robot.glb)" = "glTF" ] || fail "robot.glb is not a binary glTF"
      run 0 convert in.landmarks.jsonl -o robot.bvh --avatar "$AVATARMAP_TEST_DATA/avatars/vrm1_debug_robot.vrm"
      expect_in robot.bvh "HIERARCHY"
      expect_in robot.bvh "Frames: 60"
      # A rig no table fits, driven by --bind alone; bad --bind values.
      fig="$AVATARMAP_TEST_DATA/avatars/gltf_rigged_figure.glb"
      run 0 convert in.landmarks.jsonl -o figure.glb --avatar "$fig" --bind hips=torso_joint_1 \
        --bind spine=torso_joint_2 --bind leftUpperArm=arm_joint_L_1 --bind leftLowerArm=arm_joint_L_2
      expect_in err.txt "4 binding(s) from --bind"
      run 1 convert in.landmarks.jsonl -o f2.glb --avatar "$fig" --bind hips=nope
      expect_in err.txt "no joint 'nope'"
      run 2 convert in.landmarks.jsonl -o f2.glb --avatar "$fig" --bind tail=torso_joint_1
      expect_in err.txt "VRM 1.0 bone name"
      run 1 convert in.landmarks.jsonl -o man.glb --avatar "$AVATARMAP_TEST_DATA/avatars/gltf_cesium_man.glb"
      expect_in err.txt "no mapping table fits"
      run 1 convert in.landmarks.jsonl -o v.glb --rig nonexistent --avatar "$AVATARMAP_TEST_DATA/avatars/gltf_cesium_man.glb"
      expect_in err.txt "unknown rig table 'nonexistent'"
      # BVH mocap in (on its own skeleton) and a BVH skeleton as the avatar.
      walk="$AVATARMAP_TEST_DATA/motion/cmu-bvh/131_02.bvh"
      run 0 convert "$walk" -o truth.pose.jsonl
      expect_in err.txt "converted 1247 input frames"
      expect_in truth.pose.jsonl '"fps":120'
      run 0 convert "$walk" -o walk.vrma
      run 0 convert in.landmarks.jsonl -o self.bvh --avatar "$walk"
      expect_in err.txt "detected cmu"
      expect_in self.bvh "JOINT LHipJoint"
      run 2 convert in.landmarks.jsonl -o self.glb --avatar "$walk"
      expect_in err.txt "BVH skeleton"
    fi
    ;;
  capture)
    run 0 capture --help
    expect_in out.txt "Usage: avatarmap capture"
    expect_in out.txt "--overlay"
    run 2 capture
    run 2 capture in.mp4
    expect_in err.txt "-o OUT.landmarks.jsonl"
    run 2 capture in.mp4 -o out.landmarks.jsonl --model huge
    expect_in err.txt "--model is lite, full or heavy"
    run 2 capture in.mp4 -o out.landmarks.jsonl --hand-model heavy
    run 2 capture in.mp4 -o out.landmarks.jsonl --precision fp16
    expect_in err.txt "--precision is float or int8"
    run 2 capture in.mp4 -o out.landmarks.jsonl --lanes 3
    expect_in err.txt "option --lanes needs a whole number in 1..2, got '3'"
    run 2 capture in.mp4 -o out.landmarks.jsonl --threads 0x4
    expect_in err.txt "option --threads needs a whole number in 1..64"
    run 2 capture in.mp4 -o out.landmarks.jsonl --loop 0
    run 1 capture missing.mp4 -o out.landmarks.jsonl
    expect_in err.txt "missing.mp4"
    [ -e out.landmarks.jsonl ] && fail "a failed capture wrote its output"
    models="${AVATARMAP_MODELS:-}/onnx"
    if needs data models; then
      tfjs="$AVATARMAP_TEST_DATA/motion/tfjs-models"
      run 0 capture "$tfjs/pose.jpg" -o pose.landmarks.jsonl --models "$models" --static
      expect_in err.txt "captured 1 frames (1000x667"
      expect_in err.txt "found: body in 1 frames"
      expect_in pose.landmarks.jsonl '"pose_world"'
      run 0 solve pose.landmarks.jsonl -o pose.pose.jsonl
      # Hands and face, with an overlay image and an overlay video.
      run 0 capture "$tfjs/hands.jpg" -o hands.landmarks.jsonl --models "$models" --static \
        --hands --face --overlay hands.png
      expect_in err.txt "left hand 1, right hand 1"
      expect_in hands.landmarks.jsonl '"left_hand_world"'
      expect_in hands.landmarks.jsonl '"right_hand"'
      [ -s hands.png ] || fail "no overlay image"
      run 0 capture "$tfjs/portrait.jpg" -o face.landmarks.jsonl --models "$models" --static --face
      expect_in err.txt "face 1"
      expect_in face.landmarks.jsonl '"face"'
      run 0 capture "$tfjs/pose_squats.mp4" -o squats.landmarks.jsonl --models "$models" \
        --hands --face --overlay squats.mp4
      expect_in err.txt "captured 65 frames (720x1280, h264)"
      expect_in err.txt "face 65"
      expect_in err.txt "hand landmarks"
      [ "$(lines squats.landmarks.jsonl)" -eq 66 ] || fail "expected 65 frames and a header"
      run 0 capture squats.mp4 -o overlay.landmarks.jsonl --models "$models" --quiet
      [ "$(lines overlay.landmarks.jsonl)" -eq 66 ] || fail "the overlay video has not 65 frames"
      # Bad models: missing and corrupt files are named, nothing is written.
      mkdir -p bad
      cp "$models"/pose_detection.onnx "$models"/pose_landmark_full.onnx bad/
      run 1 capture "$tfjs/pose.jpg" -o bad.landmarks.jsonl --models bad --hands
      expect_in err.txt "palm_detection_full.onnx"
      expect_in err.txt "prepare_capture.sh"
      head -c 1000 "$models/pose_landmark_full.onnx" >bad/pose_landmark_full.onnx
      run 1 capture "$tfjs/pose.jpg" -o bad.landmarks.jsonl --models bad
      expect_in err.txt "pose_landmark_full.onnx"
      [ -e bad.landmarks.jsonl ] && fail "a failed capture wrote its output"
      # int8 models missing: the error names the file and the script that builds them.
      run 1 capture "$tfjs/pose.jpg" -o bad.landmarks.jsonl --models bad --precision int8
      expect_in err.txt "pose_detection.int8.onnx"
      expect_in err.txt "scripts/prepare_capture.sh"
      [ -e bad.landmarks.jsonl ] && fail "a failed capture wrote its output"
      # int8 models present (scripts/prepare_capture.sh builds them): the body is found.
      if [ -f "$models/pose_landmark_full.int8.onnx" ]; then
        run 0 capture "$tfjs/pose.jpg" -o int8.landmarks.jsonl --models "$models" --static \
          --precision int8
        expect_in err.txt "found: body in 1 frames"
      fi
      # No person: a black image gives a frame with no parts.
      if command -v /usr/bin/python3 >/dev/null; then
        /usr/bin/python3 -c "
import zlib,struct
w,h=64,48
raw=b''.join(b'\\x00'+b'\\x00'*w*3 for _ in range(h))
def chunk(t,d): return struct.pack('>I',len(d))+t+d+struct.pack('>I',zlib.crc32(t+d)&0xffffffff)
open('black.png','wb').write(b'\\x89PNG\\r\\n\\x1a\\n'+chunk(b'IHDR',struct.pack('>IIBBBBB',w,h,8,2,0,0,0))+chunk(b'IDAT',zlib.compress(raw))+chunk(b'IEND',b''))"
        run 0 capture black.png -o black.landmarks.jsonl --models "$models" --hands --face
        expect_in err.txt "found: body in 0 frames, left hand 0, right hand 0, face 0"
      fi
    fi
    ;;
  animate)
    run 0 animate --help
    expect_in out.txt "Usage: avatarmap animate"
    run 2 animate
    run 2 animate in.mp4
    run 2 animate in.mp4 -o out.txt
    expect_in err.txt ".vrma, .glb, .bvh or .pose.jsonl"
    run 1 animate missing.mp4 -o out.glb  # .glb needs no --avatar (the built-in avatar)
    expect_in err.txt "missing.mp4"
    [ -e out.glb ] && fail "a failed animate wrote its output"
    run 2 animate in.mp4 -o out.vrma --bogus
    expect_in err.txt "unknown option --bogus"
    # Every option `animate --help` lists is taken: case help_options (all commands).
    run 1 animate missing.mp4 -o out.vrma
    [ -e out.vrma ] && fail "a failed animate wrote its output"
    models="${AVATARMAP_MODELS:-}/onnx"
    if needs data models; then
      tfjs="$AVATARMAP_TEST_DATA/motion/tfjs-models"
      avatar="$AVATARMAP_TEST_DATA/avatars/vrm1_spec_53bones.vrm"
      run 0 animate "$tfjs/pose_squats.mp4" --avatar "$avatar" -o squats.glb --models "$models" \
        --keep-landmarks squats.landmarks.jsonl --fps 10
      expect_in err.txt "captured 65 frames"
      expect_in err.txt "wrote squats.glb"
      [ -s squats.glb ] || fail "no .glb written"
      expect_in squats.landmarks.jsonl '"left_hand"'
      expect_in squats.landmarks.jsonl '"face"'
      run 0 animate "$tfjs/pose_squats.mp4" -o squats.vrma --models "$models" --body-only --quiet
      [ -s squats.vrma ] || fail "no .vrma written"
      [ -s err.txt ] && fail "--quiet printed: $(head -c 300 err.txt)"
      ls "${TMPDIR:-/tmp}"/avatarmap-animate-* 2>/dev/null | grep -q . &&
        echo "note: temporary landmark files of other runs exist" >&2
    fi
    ;;
  live)
    run 0 live --help
    expect_in out.txt "Usage: avatarmap live"
    run 2 live
    run 2 live in.mp4 --fps 0
    run 1 live missing.mp4
    models="${AVATARMAP_MODELS:-}/onnx"
    if needs data models; then
      tfjs="$AVATARMAP_TEST_DATA/motion/tfjs-models"
      # Unpaced: frames arrive faster than they are processed, so some are dropped; every
      # frame is either processed or dropped.
      run 0 live "$tfjs/pose_squats.mp4" --unpaced --models "$models" -o live.pose.jsonl --fps 60
      expect_in err.txt "65 frames delivered"
      expect_in err.txt "latency (frame delivered -> pose ready)"
      processed=$(sed -n 's/.* \([0-9]*\) processed.*/\1/p' err.txt)
      dropped=$(sed -n 's/.*, \([0-9]*\) dropped.*/\1/p' err.txt)
      [ $((processed + dropped)) -eq 65 ] || fail "processed $processed + dropped $dropped != 65"
      expect_in live.pose.jsonl '"fps":60'
      # Paced for 1 second: about 5 frames of a 5 fps video, output at 60 fps.
      run 0 live "$tfjs/pose_squats.mp4" --seconds 1 --models "$models" -o paced.pose.jsonl
      n=$(($(lines paced.pose.jsonl) - 1))
      if [ "$n" -lt 30 ] || [ "$n" -gt 61 ]; then
        fail "1 s at 60 fps wrote $n poses"
      fi
    fi
    ;;
  live_vmc)
    # Destinations that are not one, and --avatar without --vmc: usage errors (exit 2) before
    # any input is opened; a name that does not resolve or an avatar that cannot be read: 1.
    for bad in "host:0" "host:65536" "host:" ":39539" "[::1" "[::1]x" "127.0.0.1:39539:1" ""; do
      run 2 live in.mp4 --vmc "$bad"
      expect_in err.txt "HOST:PORT"
    done
    run 2 live in.mp4 --avatar me.vrm
    expect_in err.txt "use it with --vmc"
    run 2 live in.mp4 --vmc 127.0.0.1 --vmc-blendshapes bad
    expect_in err.txt "vrm0"
    run 2 live in.mp4 --vmc-blendshapes arkit
    expect_in err.txt "--vmc"
    run 2 live in.mp4 --vmc 127.0.0.1 --avatar ""
    run 1 live in.mp4 --vmc no-such-host.invalid
    expect_in err.txt "cannot resolve host 'no-such-host.invalid'"
    run 1 live in.mp4 --vmc 127.0.0.1 --avatar missing.vrm
    expect_in err.txt "missing.vrm"
    run 0 live --help
    expect_in out.txt "--vmc HOST[:PORT]"
    if needs data; then
      run 1 live in.mp4 --vmc 127.0.0.1 --avatar "$AVATARMAP_TEST_DATA/avatars/gltf_rigged_simple.glb"
      expect_in err.txt "For --vmc, --avatar takes a VRM model"
    fi
    models="${AVATARMAP_MODELS:-}/onnx"
    if needs data models; then
      input="$AVATARMAP_TEST_DATA/motion/tfjs-models/asl_hand.25fps.mp4"
      free_port() {
        python3 -c 'import socket; s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
      }
      # A receiver that is not running: the loop runs as it does without --vmc (1 s at 60 fps:
      # 30..61 poses) and the refusals are counted.
      closed=$(free_port)
      run 0 live "$input" --seconds 1 --models "$models" -o closed.pose.jsonl --vmc "127.0.0.1:$closed"
      n=$(($(lines closed.pose.jsonl) - 1))
      if [ "$n" -lt 30 ] || [ "$n" -gt 61 ]; then fail "1 s at 60 fps with no receiver wrote $n poses"; fi
      refused=$(sed -n 's/.* dropped, \([0-9]*\) refused.*/\1/p' err.txt)
      [ "${refused:-0}" -gt 0 ] || fail "no refusal counted: $(grep vmc err.txt)"
      if command -v oscdump >/dev/null && command -v oscsend >/dev/null; then
        # oscdump (liblo-tools) as the independent receiver: every output frame must arrive
        # as one bundle with every bone, the blend values, Apply, OK and T.
        for avatar in "" "$AVATARMAP_TEST_DATA/avatars/vrm1_spec_53bones.vrm"; do
          port=$(free_port)
          oscdump -L "$port" >dump.txt 2>/dev/null &
          dump_pid=$!
          wait_dump() {
            for _ in $(seq 200); do
              oscsend 127.0.0.1 "$port" "$1" 2>/dev/null
              sleep 0.05
              grep -q "$1" dump.txt && return 0
            done
            return 1
          }
          wait_dump /ready || fail "oscdump did not start"
          if [ -n "$avatar" ]; then
            # With the receiver's avatar, both name sets: the 16 VRM 0.x presets and ARKit's 52.
            run 0 live "$input" --seconds 2 --models "$models" -o vmc.pose.jsonl --vmc "127.0.0.1:$port" --avatar "$avatar" --vmc-blendshapes both
            bones=53
            blends=68
          else
            run 0 live "$input" --seconds 2 --models "$models" -o vmc.pose.jsonl --vmc "127.0.0.1:$port"
            bones=55
            blends=16
          fi
          wait_dump /done || fail "oscdump stopped receiving"
          kill "$dump_pid" 2>/dev/null
          wait "$dump_pid" 2>/dev/null
          poses=$(($(lines vmc.pose.jsonl) - 1))
          sent=$(sed -n 's/^vmc: \([0-9]*\) bundles sent.*/\1/p' err.txt)
          expect_in err.txt "vmc latency (frame delivered -> first packet with its pose"
          [ "$sent" = "$poses" ] || fail "vmc sent ${sent:-?} bundles for $poses output poses"
          python3 - "$poses" "$bones" "$blends" dump.txt <<'PY' || fail "oscdump's bundles (see above)"
import sys
want, bones, blends, path = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
groups, last = [], None
for line in open(path):
    f = line.split()
    if len(f) < 2 or f[1] in ("/ready", "/done"):
        continue
    if f[0] != last:
        groups.append([])
    last = f[0]
    groups[-1].append(f)
bad = []
times = []
for g in groups:
    addr = [f[1] for f in g]
    names = {f[3].strip('"') for f in g if f[1] == "/VMC/Ext/Bone/Pos"}
    if (addr.count("/VMC/Ext/Bone/Pos") != bones or len(names) != bones
            or addr.count("/VMC/Ext/Root/Pos") != 1 or addr.count("/VMC/Ext/Blend/Val") != blends
            or addr.count("/VMC/Ext/Blend/Apply") != 1 or addr[-1] != "/VMC/Ext/T"
            or ["/VMC/Ext/OK", "i", "1"] != next(f[1:] for f in g if f[1] == "/VMC/Ext/OK")):
        bad.append(addr[:3])
    times.append(float(g[-1][3]))  # T parses as a number
if len(groups) != want or bad or "Hips" not in names:
    print("bundles at oscdump: %d (want %d), malformed: %d %s" % (len(groups), want, len(bad), bad[:2]))
    sys.exit(1)
# /VMC/Ext/T strictly increasing, as oscdump prints it (six decimals).
same = [(i, a) for i, (a, b) in enumerate(zip(times, times[1:])) if not b > a]
if same:
    print("/VMC/Ext/T not increasing at bundle(s) %s" % same[:5])
    sys.exit(1)
blend_names = [f[3].strip('"') for f in groups[-1] if f[1] == "/VMC/Ext/Blend/Val"]
if blends == 68 and (blend_names[0] != "Blink" or blend_names[16] != "browDownLeft"
                     or blend_names[-1] != "tongueOut" or "Joy" not in blend_names):
    print("blend names: %s ... %s" % (blend_names[:17], blend_names[-1]))
    sys.exit(1)
print("oscdump: %d bundles of %d bones, %d blend values" % (len(groups), bones, blends))
PY
        done
      else
        skipped="${skipped:+$skipped; }oscdump/oscsend not found (Debian liblo-tools): the live VMC receiver check"
      fi
    fi
    ;;
  solve_stdio)
    synth_input in.landmarks.jsonl 1 || exit 1
    "$exe" solve - -o - <in.landmarks.jsonl >out.pose.jsonl 2>err.txt ||
      fail "solve - -o - failed: $(cat err.txt)"
    n=$(lines out.pose.jsonl)
    [ "$n" -eq 31 ] || fail "solve - -o - wrote $n lines, expected 31"
    expect_in err.txt "solved 30 frames"
    ;;
  solve_fps)
    synth_input in.landmarks.jsonl 2 || exit 1
    run 0 solve in.landmarks.jsonl -o out.pose.jsonl --fps 60
    expect_in err.txt "solved 60 frames"
    expect_in err.txt "(resampled)"
    n=$(($(lines out.pose.jsonl) - 1))
    # 60 frames at 30 fps span 59/30 s: 60 fps gives 119 poses, give or take the first.
    if [ "$n" -lt 116 ] || [ "$n" -gt 121 ]; then
      fail "--fps 60 on 30 fps input wrote $n poses, expected about 120"
    fi
    expect_in err.txt "wrote $n poses"
    expect_in out.pose.jsonl '"fps":60'
    run 0 solve in.landmarks.jsonl -o half.pose.jsonl --fps=15
    n=$(($(lines half.pose.jsonl) - 1))
    if [ "$n" -lt 28 ] || [ "$n" -gt 31 ]; then
      fail "--fps=15 on 30 fps input wrote $n poses, expected about 30"
    fi
    ;;
  solve_parts)
    synth_input in.landmarks.jsonl 1 || exit 1
    run 0 solve in.landmarks.jsonl -o body.pose.jsonl --parts body
    expect_in err.txt "solved 30 frames"
    n=$(lines body.pose.jsonl)
    [ "$n" -eq 31 ] || fail "--parts body wrote $n lines, expected 31"
    run 0 solve in.landmarks.jsonl -o some.pose.jsonl --parts body,hands,root --image-size 1280x720
    expect_in err.txt "solved 30 frames"
    ;;
  bad_line)
    synth_input in.landmarks.jsonl 1 || exit 1
    sed '3s/.*/{"t": 0.0333, "pose": [[1, 2]]}/' in.landmarks.jsonl >bad.landmarks.jsonl
    printf 'previous output\n' >out.pose.jsonl
    cp out.pose.jsonl before.pose.jsonl
    run 1 solve bad.landmarks.jsonl -o out.pose.jsonl
    expect_in err.txt "bad.landmarks.jsonl:3:"
    expect_in err.txt "--skip-bad-lines"
    cmp -s out.pose.jsonl before.pose.jsonl ||
      fail "a failed solve changed the existing output file"
    ls out.pose.jsonl.tmp.* >/dev/null 2>&1 && fail "a failed solve left a temporary file"
    run 0 solve bad.landmarks.jsonl -o out.pose.jsonl --skip-bad-lines
    expect_in err.txt "bad.landmarks.jsonl:3:"
    expect_in err.txt "skipped 1 malformed lines"
    expect_in err.txt "solved 29 frames"
    n=$(lines out.pose.jsonl)
    [ "$n" -eq 30 ] || fail "--skip-bad-lines wrote $n lines, expected 30 (header + 29 frames)"
    ;;
  missing_input)
    run 1 solve "$dir/no-such.landmarks.jsonl" -o out.pose.jsonl
    expect_in err.txt "$dir/no-such.landmarks.jsonl"
    [ -e out.pose.jsonl ] && fail "a failed solve wrote the output file"
    ;;
  unwritable_output)
    synth_input in.landmarks.jsonl 1 || exit 1
    run 1 solve in.landmarks.jsonl -o "$dir/no-such-dir/out.pose.jsonl"
    expect_in err.txt "no-such-dir/out.pose.jsonl"
    run 1 synth -o "$dir/no-such-dir/x.landmarks.jsonl" --seconds 1
    expect_in err.txt "no-such-dir/x.landmarks.jsonl"
    ;;
  synth_usage)
    run 2 synth
    expect_in err.txt "-o"
    run 2 synth -o x.landmarks.jsonl --seconds 0
    expect_in err.txt "--seconds"
    run 2 synth -o x.landmarks.jsonl --fps -3
    expect_in err.txt "--fps"
    run 2 synth -o x.landmarks.jsonl --seed -1
    expect_in err.txt "--seed"
    run 2 synth -o x.landmarks.jsonl --seed 1.5
    expect_in err.txt "--seed"
    run 2 synth -o x.landmarks.jsonl extra
    expect_in err.txt "unexpected argument"
    [ -e x.landmarks.jsonl ] && fail "a synth usage error wrote the output file"
    ;;
  demo)
    # The synthetic path (no video): what the demo falls back to without models or Chromium.
    mkdir tmp
    TMPDIR="$dir/tmp" run 0 demo --synthetic
    [ -z "$(ls -A tmp)" ] || fail "demo left files in TMPDIR: $(ls -A tmp)"
    expect_in out.txt "solved 240 frames"
    expect_in out.txt "wrote 240 poses"
    # The solve's error against the truth the synthesiser played (2 mm noise): small.
    err_deg=$(sed -nE 's/.*error against the motion played \(240 frames\): bone directions ([0-9.]+) deg.*/\1/p' out.txt)
    [ -n "$err_deg" ] || fail "demo printed no error against the motion played"
    awk -v e="${err_deg:-99}" 'BEGIN { exit !(e < 5) }' || fail "demo's solve error $err_deg deg, expected < 5"
    # The motion on the built-in avatar, in ./avatarmap-demo by default.
    for f in avatar.vrm demo.glb demo.vrma; do
      [ "$(head -c 4 "avatarmap-demo/$f" 2>/dev/null)" = glTF ] || fail "demo did not write avatarmap-demo/$f"
    done
    [ -e avatarmap-demo/demo.mp4 ] && fail "demo --synthetic wrote a video"
    expect_in out.txt "avatarmap-demo/demo.glb (240 frames on it)"
    # The command it prints runs: the binary's path while `avatarmap` on the PATH is another
    # program (or none), `avatarmap` when it is this one.
    expect_in out.txt "  $(realpath "$exe") view avatarmap-demo/demo.glb    (then open"
    mkdir -p onpath && ln -sf "$exe" onpath/avatarmap
    PATH="$dir/onpath:$PATH" run 0 demo --synthetic --seconds 2
    expect_in out.txt "  avatarmap view avatarmap-demo/demo.glb    (then open"
    expect_in out.txt "solved 60 frames"
    run 0 inspect avatarmap-demo/demo.glb
    expect_in out.txt "declared: 55 of 55 bones"
    run 0 demo --synthetic --keep --out "$dir/kept/new" --seconds 2
    for f in truth.pose.jsonl demo.landmarks.jsonl demo.pose.jsonl demo.glb; do
      [ -s "$dir/kept/new/$f" ] || fail "demo --keep did not keep $f"
    done
    run 0 demo --synthetic --out "$dir/elsewhere" --seconds 2
    [ -s "$dir/elsewhere/demo.glb" ] && [ -s "$dir/elsewhere/avatar.vrm" ] ||
      fail "demo --out did not write there"
    : >blocker
    run 1 demo --synthetic --out blocker/x
    expect_in err.txt "blocker/x"
    run 2 demo --seconds 0
    expect_in err.txt "--seconds"
    run 2 demo a.mp4 b.mp4
    expect_in err.txt "at most one VIDEO"
    run 2 demo missing.mp4
    expect_in err.txt "missing.mp4"
    run 2 demo --frobnicate
    ;;
  demo_video)
    # The README's first command's real path: the built-in avatar rendered (Chromium), captured
    # back (the models), solved and rendered beside its source; a short, small clip.
    if needs models && command -v chromium >/dev/null && command -v ffprobe >/dev/null; then
      run 0 demo --seconds 3 --size 320x240 --out out
      for f in source.mp4 demo.mp4 demo.glb demo.vrma avatar.vrm; do
        [ -s "out/$f" ] || fail "demo did not write out/$f"
      done
      frames() { ffprobe -v error -count_frames -select_streams v:0 -show_entries \
        stream=nb_read_frames,width -of csv=p=0 "$1"; }
      [ "$(frames out/source.mp4)" = "320,90" ] || fail "source.mp4: $(frames out/source.mp4), expected 320 wide, 90 frames"
      [ "$(frames out/demo.mp4)" = "640,90" ] || fail "demo.mp4: $(frames out/demo.mp4), expected 640 wide (side by side), 90 frames"
      expect_in out.txt "round trip (render -> capture -> solve) error against the motion played (90 frames)"
      # The body comes back (hands at 320x240 are a few pixels: not checked).
      torso=$(sed -nE 's/.*round trip.*\(torso ([0-9.]+), arms ([0-9.]+), legs ([0-9.]+).*/\1 \2 \3/p' out.txt)
      awk -v t="$torso" 'BEGIN { split(t, v, " "); exit !(v[1] != "" && v[1] < 20 && v[2] < 35 && v[3] < 30) }' ||
        fail "round trip torso/arms/legs errors too large: $torso"
      expect_in out.txt "view out/demo.glb --video out/source.mp4"
    else
      command -v chromium >/dev/null || skipped="${skipped:+$skipped; }no chromium"
      command -v ffprobe >/dev/null || skipped="${skipped:+$skipped; }no ffprobe"
    fi
    ;;
  closeup)
    # A hand close-up (a forearm in the frame) animated with the defaults: the body's points
    # are guesses, so the hips and legs stay at rest while the fingers move.
    if needs data models; then
      run 0 animate "$AVATARMAP_TEST_DATA/motion/tfjs-models/asl_hand.25fps.mp4" -o asl.pose.jsonl --quiet
      /usr/bin/python3 - asl.pose.jsonl <<'PY' || fail "the close-up's body moved (see above)"
import json, math, sys
bones = ("hips", "leftUpperLeg", "rightUpperLeg", "leftLowerLeg", "rightLowerLeg")
first, hy, worst, fingers = {}, [], 0.0, 0.0
def angle(a, b):
    d = abs(sum(x * y for x, y in zip(a, b)))
    return math.degrees(2 * math.acos(min(1.0, d)))
f0 = None
for line in open(sys.argv[1]):
    p = json.loads(line)
    if "hips_position" not in p:
        continue
    hy.append(p["hips_position"][1])
    r = p["bones"]
    for b in bones:
        first.setdefault(b, r[b])
        worst = max(worst, angle(first[b], r[b]))
    f0 = f0 or r["rightIndexProximal"]
    fingers = max(fingers, angle(f0, r["rightIndexProximal"]), angle(f0, r.get("leftIndexProximal", f0)))
print("frames %d, hips height range %.2f cm, largest hips/leg change %.2f deg, finger change %.1f deg"
      % (len(hy), 100 * (max(hy) - min(hy)), worst, fingers))
sys.exit(0 if len(hy) > 100 and max(hy) - min(hy) < 0.01 and worst < 1.0 and fingers > 20 else 1)
PY
    fi
    ;;
  avatar)
    run 0 avatar -o me.vrm
    expect_in err.txt "wrote the built-in avatar (1.70 m, VRM 1.0) to me.vrm"
    [ "$(head -c 4 me.vrm)" = glTF ] || fail "avatar did not write a binary glTF"
    run 0 inspect me.vrm
    expect_in out.txt "format: VRM 1.0"
    expect_in out.txt "declared: 55 of 55 bones"
    expect_in out.txt "missing required: none"
    run 0 avatar -o tall.vrm --height 1.9
    cmp -s me.vrm tall.vrm && fail "--height 1.9 wrote the 1.70 m avatar"
    # The avatar drives like any other: a synthetic motion onto it as an animated .glb.
    synth_input in.landmarks.jsonl 1 || exit 1
    run 0 convert in.landmarks.jsonl -o moving.glb --avatar me.vrm
    [ "$(head -c 4 moving.glb)" = glTF ] || fail "convert onto the built-in avatar wrote no .glb"
    run 2 avatar
    expect_in err.txt "-o OUT.vrm"
    run 2 avatar -o x.vrm --height 9
    expect_in err.txt "--height must be in [0.50, 3.00] metres"
    run 2 avatar -o x.vrm --height tall
    expect_in err.txt "--height needs a number"
    run 2 avatar -o x.vrm --frobnicate
    expect_in err.txt "unknown option --frobnicate"
    [ -e x.vrm ] && fail "an avatar usage error wrote the output file"
    run 1 avatar -o no-such-dir/x.vrm
    expect_in err.txt "no-such-dir/x.vrm"
    ;;
  backends)
    run 0 backends
    expect_in out.txt "replay"
    if ! grep -qE '^replay +[^ ]' out.txt; then fail "backends lists replay without a description"; fi
    run 2 backends --frobnicate
    expect_in err.txt "unknown option --frobnicate"
    run 2 backends extra
    expect_in err.txt "no arguments"
    ;;
  import_tfjs_usage)
    run 2 import-tfjs
    expect_in err.txt "import-tfjs"
    run 2 import-tfjs a.json b.json --size 640x480 --fps 30
    expect_in err.txt "-o"
    run 2 import-tfjs a.json b.json --size 640 --fps 30 -o x.landmarks.jsonl
    run 2 import-tfjs a.json b.json --size 640x480 --fps 0 -o x.landmarks.jsonl
    run 2 import-tfjs a.json --size 640x480 --fps 30 -o x.landmarks.jsonl
    run 2 import-tfjs a.json b.json --size 640x480 --fps 30 -o x.landmarks.jsonl --frobnicate
    expect_in err.txt "frobnicate"
    run 1 import-tfjs no-such-image.json no-such-world.json --size 640x480 --fps 30 \
      -o x.landmarks.jsonl
    expect_in err.txt "no-such-"
    [ -e x.landmarks.jsonl ] && fail "a failed import-tfjs wrote the output file"
    ;;
  inspect)
    run 0 inspect --help
    expect_in out.txt "Usage: avatarmap inspect"
    run 2 inspect
    expect_in err.txt "Usage: avatarmap inspect"
    run 2 inspect a.vrm b.vrm
    expect_in err.txt "exactly one"
    run 2 inspect a.vrm --frobnicate
    expect_in err.txt "unknown option --frobnicate"
    run 1 inspect "$dir/no-such.vrm"
    expect_in err.txt "$dir/no-such.vrm"
    printf 'not a model' >bad.vrm
    run 1 inspect bad.vrm
    expect_in err.txt "bad.vrm: not a glTF file"
    printf '{"asset":{"version":"2.0"},"nodes":[{"name":"root","children":[1]},{"name":"j"}]}' \
      >tiny.gltf
    run 0 inspect tiny.gltf
    expect_in out.txt "format: glTF"
    expect_in out.txt "joints: 2"
    expect_in out.txt "humanoid: not declared by the file"
    printf '{"asset":{"version":"2.0"},"nodes":[{"name":"h"}],%s}' \
      '"extensions":{"VRMC_vrm":{"humanoid":{"humanBones":{"hips":{"node":7}}}}}' >range.vrm
    run 1 inspect range.vrm
    expect_in err.txt "range.vrm"
    expect_in err.txt "out of range"
    if needs data; then
      avatar="$AVATARMAP_TEST_DATA/avatars/vrm1_spec_53bones.vrm"
      run 0 inspect "$avatar"
      expect_in out.txt "format: VRM 1.0"
      expect_in out.txt "joints: 58"
      expect_in out.txt "declared: 53 of 55"
      expect_in out.txt "missing required: none"
      expect_in out.txt "hips height: 0.850"
      run 0 inspect --json "$avatar"
      expect_in out.txt '"format":"vrm1"'
      expect_in out.txt '"joints":58'
      expect_in out.txt '"declared":53'
      expect_in out.txt '"hips":"hips"'
      expect_in out.txt '"missing_required":[]'
    fi
    ;;
  help_options)
    # Every option each command's --help lists is one its parser takes (animate once kept an
    # older copy of capture's flags: --precision, --lanes and --spin, listed, were refused as
    # unknown). Each option is given with a dummy value and an input that does not exist, so
    # that nothing runs for long; any answer but "unknown option" will do.
    run 0 --help
    commands=$(grep -oE '^  avatarmap [a-z][a-z-]*' out.txt | awk '{print $2}' | sort -u)
    [ -n "$commands" ] || fail "avatarmap --help lists no commands"
    for cmd in $commands; do
      run 0 "$cmd" --help
      # The flag column of each option line: "  -o, --output PATH    help..." -> -o --output.
      opts=$(grep -E '^ {1,4}-' out.txt | sed -E 's/^ +//; s/  .*//' |
        grep -oE -- '(^| |/|,)--?[a-zA-Z][a-zA-Z0-9-]*' | grep -oE -- '--?[a-zA-Z][a-zA-Z0-9-]*' |
        sort -u)
      for opt in $opts; do
        case "$opt" in --help | -h) continue ;; esac
        timeout 20 "$exe" "$cmd" missing-input.nothing "$opt" x >opt_out.txt 2>opt_err.txt \
          </dev/null
        if grep -qE -- "unknown option $opt( |\$)" opt_err.txt; then
          fail "$cmd refuses $opt, which its --help lists: $(head -c 300 opt_err.txt)"
        fi
      done
    done
    ;;
  options)
    run 0 options --json
    python3 -c 'import json
t = json.load(open("out.txt"))
assert t["limits"]["max_fps"] == 1000
assert {s["set"] for s in t["sets"]} >= {"solver", "solve_file", "estimator"}' ||
      fail "options --json is not the option tables as JSON: $(head -c 300 out.txt)"
    run 0 options
    expect_in out.txt "horizontal_fov_degrees"
    run 2 options --frobnicate
    expect_in err.txt "unknown option --frobnicate"
    run 0 backends
    expect_in out.txt "folders (environment, else installed, else source tree):"
    expect_in out.txt "mappings"
    AVATARMAP_MAPPINGS="$PWD/tables" run 0 backends
    expect_in out.txt "$PWD/tables (environment AVATARMAP_MAPPINGS)"
    AVATARMAP_MODELS="$PWD/cache" run 0 backends
    expect_in out.txt "$PWD/cache/onnx (environment AVATARMAP_MODELS)"
    ;;
  *)
    fail "unknown case"
    ;;
esac

if [ "$failures" -eq 0 ] && [ -n "$skipped" ]; then
  rm -rf "$dir"
  echo "skipped [$case_name]: $skipped (the checks that need none of it passed)"
  exit 77
fi
if [ "$failures" -eq 0 ]; then
  rm -rf "$dir"
  echo "ok [$case_name]"
  exit 0
fi
exit 1
