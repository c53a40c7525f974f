#!/usr/bin/env bash
# Live inputs of `avatarmap live` and `capture` (docs/live.md): live_input_test.sh EXE WORK CASE.
# Streams come from the ffmpeg command-line tool (-re: real time) on loopback addresses; a
# device is FFmpeg's lavfi test pattern. Cases that need the ffmpeg tool, a protocol, lavfi,
# the models or the shared test data exit 77 (CTest: skipped) with a message when they are
# missing. Registered by tests/cli/CMakeLists.txt.
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
skip() {  # what ran before the skip still counts
  [ "$failures" -eq 0 ] || exit 1
  echo "skipped [$case_name]: $*"
  exit 77
}

# run EXPECTED_STATUS ARGS...: the tool (at most 120 s), stdout to out.txt, stderr to err.txt.
run() {
  local want=$1
  shift
  timeout 120 "$exe" "$@" >out.txt 2>err.txt
  local got=$?
  if [ "$got" -ne "$want" ]; then
    fail "avatarmap $* exited $got, expected $want"
    echo "--- stderr:" >&2
    head -c 2000 err.txt >&2
  fi
}

# expect_in FILE TEXT: FILE contains TEXT (fixed string).
expect_in() {
  if ! grep -qF -- "$2" "$1"; then
    fail "$1 does not contain '$2'"
    echo "--- $1:" >&2
    head -c 2000 "$1" >&2
  fi
}

# free_port udp|tcp: a port nothing listens on now.
free_port() {
  python3 -c 'import socket, sys
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM if sys.argv[1] == "udp" else socket.SOCK_STREAM)
s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])' "$1"
}

need_ffmpeg() {
  command -v ffmpeg >/dev/null || skip "the ffmpeg tool is not installed (scripts/setup.sh installs it)"
  command -v python3 >/dev/null || skip "python3 is not installed (it picks free ports)"
}
need_scheme() {  # the tool lists what this build reads when given an unknown scheme
  "$exe" live nosuchscheme://x >/dev/null 2>schemes.txt
  grep -qE "reads .*\\b$1\\b" schemes.txt || skip "this build reads no $1:// ($(cat schemes.txt))"
}
need_lavfi() {
  "$exe" live nosuchdevice:x >/dev/null 2>devices.txt
  grep -qE "devices: .*\\blavfi\\b" devices.txt || skip "no lavfi input device: $(cat devices.txt)"
}
models="${AVATARMAP_MODELS:-}/onnx"
need_models() {
  [ -f "$models/pose_detection.onnx" ] ||
    skip "no models in \$AVATARMAP_MODELS/onnx (scripts/prepare_capture.sh makes them)"
  "$exe" backends 2>/dev/null | grep -q '^ *onnx' || skip "this build has no onnx backend"
}
video="${AVATARMAP_TEST_DATA:-}/motion/tfjs-models/pose_squats.mp4"
need_video() {
  if [ -z "${AVATARMAP_TEST_DATA:-}" ] || [ ! -f "$video" ]; then
    skip "AVATARMAP_TEST_DATA is not set (the shared data folder has pose_squats.mp4)"
  fi
}

# sender ARGS...: ffmpeg in the background (its pid in $sender_pid, its log in ffmpeg.log).
sender() {
  ffmpeg -hide_banner -loglevel error -nostdin "$@" >ffmpeg.log 2>&1 &
  sender_pid=$!
}
stop_sender() {
  kill "$sender_pid" 2>/dev/null
  wait "$sender_pid" 2>/dev/null
}

# Key frames every second (MPEG-2, in every FFmpeg): a receiver that starts late still
# finds one quickly.
encode=(-c:v mpeg2video -q:v 3 -g 5 -an)

case $case_name in
  errors)
    # Bad inputs and options: clear messages, exit 1 (or 2 for a usage error), no crash.
    run 1 live foo://127.0.0.1/x
    expect_in err.txt "foo://127.0.0.1/x: unknown URL scheme 'foo': this build reads"
    expect_in err.txt "udp"
    run 1 live concat://a.mp4
    expect_in err.txt "unknown URL scheme 'concat'"
    run 1 live rtsp://127.0.0.1:1/x
    expect_in err.txt "rtsp://127.0.0.1:1/x: cannot open the stream"
    expect_in err.txt "no server at this address and port"
    run 1 live v4l2:/dev/video99
    expect_in err.txt "v4l2:/dev/video99: "
    if ! grep -q "built without libavdevice" err.txt; then
      expect_in err.txt "no camera at /dev/video99"
    fi
    run 1 live nosuchdevice:0
    expect_in err.txt "nosuchdevice:0: no such file, and "
    if command -v python3 >/dev/null; then
      port=$(free_port udp)
      run 1 live "udp://127.0.0.1:$port" --open-seconds 0.5
      expect_in err.txt "udp://127.0.0.1:$port: nothing came within 0.5 s (--open-seconds)"
    fi
    run 1 capture foo://x -o out.landmarks.jsonl
    expect_in err.txt "unknown URL scheme 'foo'"
    run 2 live in.mp4 --video-size 640
    expect_in err.txt "--video-size wants WIDTHxHEIGHT"
    run 2 live in.mp4 --stall-seconds 0
    expect_in err.txt "--stall-seconds"
    run 2 live in.mp4 --framerate x
    run 2 capture in.mp4 -o out.landmarks.jsonl --seconds -1
    [ -e out.landmarks.jsonl ] && fail "a failed capture left out.landmarks.jsonl"
    run 0 live --help
    expect_in out.txt "--stall-seconds S"
    expect_in out.txt "udp://127.0.0.1:5000"
    run 0 capture --help
    expect_in out.txt "--video-size WxH"
    ;;
  lavfi)
    need_lavfi
    run 1 live lavfi:testsrc --video-size 320x240
    expect_in err.txt "the device 'lavfi' takes no video size (--video-size)"
    run 2 capture lavfi:testsrc --loop 2 -o x.landmarks.jsonl
    expect_in err.txt "--loop is for files"
    need_models
    # A test pattern as a camera: frames arrive (no body in it), poses are written.
    run 0 live lavfi:testsrc=size=320x240:rate=10,realtime --seconds 2 --models "$models" \
      -o live.pose.jsonl
    expect_in err.txt "frames delivered"
    delivered=$(sed -n 's/^live: \([0-9]*\) frames delivered.*/\1/p' err.txt)
    if [ -z "$delivered" ] || [ "$delivered" -lt 5 ] || [ "$delivered" -gt 25 ]; then
      fail "2 s of a 10 fps real-time pattern delivered '$delivered' frames"
    fi
    expect_in live.pose.jsonl '"fps":60'
    # capture reads a device for --seconds of its time: 10 fps for 1 s is frames 0..9.
    run 0 capture lavfi:testsrc=size=160x120:rate=10 --seconds 1 --models "$models" \
      -o pattern.landmarks.jsonl
    expect_in err.txt "captured 10 frames (160x120"
    ;;
  udp)
    need_ffmpeg
    need_scheme udp
    need_models
    need_video
    # pose_squats.mp4 (13 s at 5 fps) streamed in real time as MPEG-TS over UDP; live reads
    # it for 8 s with body, hands and face.
    port=$(free_port udp)
    timeout 120 "$exe" live "udp://127.0.0.1:$port" --seconds 8 --hands --face \
      --models "$models" -o udp.pose.jsonl >out.txt 2>err.txt &
    live_pid=$!
    sleep 1
    sender -re -i "$video" "${encode[@]}" -f mpegts "udp://127.0.0.1:$port"
    wait "$live_pid"
    status=$?
    stop_sender
    [ "$status" -eq 0 ] || fail "live exited $status: $(head -c 2000 err.txt)"
    expect_in err.txt "latency (frame delivered -> pose ready): mean"
    body=$(sed -n 's/.*; body in \([0-9]*\)$/\1/p' err.txt)
    delivered=$(sed -n 's/^live: \([0-9]*\) frames delivered.*/\1/p' err.txt)
    # 8 s minus the start of the stream at 5 fps: about 35 frames, each with the person.
    if [ -z "$body" ] || [ "$body" -lt 15 ]; then
      fail "body found in '$body' frames (delivered '$delivered')"
    fi
    n=$(($(wc -l <udp.pose.jsonl) - 1))
    [ "$n" -ge 200 ] || fail "udp.pose.jsonl has $n poses, expected ~7 s at 60 fps"
    expect_in udp.pose.jsonl '"leftIndexProximal"'
    cat err.txt
    ;;
  stall)
    need_ffmpeg
    need_scheme udp
    need_models
    need_video
    # The sender is killed 4 s into an endless stream: live stops about --stall-seconds
    # later with the message, exit 0, and writes what it captured.
    port=$(free_port udp)
    timeout 120 "$exe" live "udp://127.0.0.1:$port" --stall-seconds 2 --models "$models" \
      -o stall.pose.jsonl >out.txt 2>err.txt &
    live_pid=$!
    sleep 1
    sender -re -stream_loop -1 -i "$video" "${encode[@]}" -f mpegts "udp://127.0.0.1:$port"
    sleep 4
    stop_sender
    killed=$(date +%s.%N)
    wait "$live_pid"
    status=$?
    ended=$(date +%s.%N)
    [ "$status" -eq 0 ] || fail "live exited $status: $(head -c 2000 err.txt)"
    expect_in err.txt "live: no frame from udp://127.0.0.1:$port for 2 s: the stream stalled or ended"
    # Not a timing test: only that it stopped through the stall (2 s), not through the
    # 120 s guard, with a wide margin for a loaded machine.
    awk -v a="$killed" -v b="$ended" 'BEGIN { exit !(b - a < 10) }' ||
      fail "live took $(awk -v a="$killed" -v b="$ended" 'BEGIN { print b - a }') s to stop after the sender"
    n=$(($(wc -l <stall.pose.jsonl) - 1))
    [ "$n" -ge 60 ] || fail "stall.pose.jsonl has $n poses"
    cat err.txt
    ;;
  capture_url)
    need_ffmpeg
    need_scheme tcp
    need_models
    need_video
    # capture reads a URL until it ends: every frame of a TCP stream (no loss), as from the file.
    port=$(free_port tcp)
    timeout 120 "$exe" capture "tcp://127.0.0.1:$port?listen=1" --models "$models" \
      -o url.landmarks.jsonl >out.txt 2>err.txt &
    cap_pid=$!
    sleep 1
    sender -i "$video" -c copy -f mpegts "tcp://127.0.0.1:$port"
    wait "$cap_pid"
    status=$?
    stop_sender
    [ "$status" -eq 0 ] || fail "capture exited $status: $(head -c 2000 err.txt)"
    expect_in err.txt "capture: tcp://127.0.0.1:$port?listen=1: the stream ended"
    expect_in err.txt "captured 65 frames (720x1280, h264)"
    ;;
  *)
    fail "unknown case"
    ;;
esac

if [ "$failures" -eq 0 ]; then
  rm -rf "$dir"
  echo "ok [$case_name]"
  exit 0
fi
exit 1
