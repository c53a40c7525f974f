#!/usr/bin/env bash
# `avatarmap view` and `live --serve` (docs/viewer.md): bad usage, avatars that are not VRM,
# malformed pose files, a port in use, missing modules: a clear error (exit 1 or 2, never a
# signal) that says what to do. The browser side is tests/viewer/viewer_e2e_test.py.
# Usage: hostile_view_test.sh EXE WORK_DIR
# shellcheck source=hostile_lib.sh
source "$(dirname "$0")/hostile_lib.sh"

run ok view --help
expect_in out.txt "--connect"
run 2 view take.mp4 --avatar me.vrm
expect_in err.txt "FILE must be a .pose.jsonl or a .vrma"
printf '{"t":0}\n' >one.pose.jsonl
run 2 view one.pose.jsonl --avatar me.vrm --connect 9000
expect_in err.txt "two sources of poses"
run 2 view --avatar me.vrm --port 70000
expect_in err.txt "--port must be an integer in 0..65535"
run 2 view --avatar me.vrm --port 80.5
run 2 view --avatar me.vrm --connect nowhere:port
expect_in err.txt "PORT or HOST:PORT"
run 2 live take.mp4 --serve nope
expect_in err.txt "--serve"
printf 'not a glTF file' >junk.vrm
run 1 view --avatar junk.vrm
expect_in err.txt "junk.vrm"

data="${AVATARMAP_TEST_DATA:-}"
robot="$data/avatars/vrm1_debug_robot.vrm"
if [ -z "$data" ] || [ ! -f "$robot" ]; then
  echo "note: AVATARMAP_TEST_DATA unset: the cases with a real avatar are skipped"
  finish
  exit
fi
run 1 view --avatar "$data/avatars/gltf_rigged_simple.glb"
expect_in err.txt "not a VRM avatar"
printf '{"t":0}\n{"t":0.1,"bones":{"hips":[0,0,0]}}\n' >bad.pose.jsonl
run 1 view bad.pose.jsonl --avatar "$robot"
expect_in err.txt "bad.pose.jsonl:2"
printf '{"format":"avatarmap.pose","version":1}\n' >empty.pose.jsonl
run 1 view empty.pose.jsonl --avatar "$robot"
expect_in err.txt "holds no pose"
AVATARMAP_VIEWER_MODULES="$PWD/none" run 1 view --avatar "$robot" --port 0
expect_in err.txt "fetch_viewer_modules.sh"
run 1 view --avatar "$robot" --host example.com --port 0
expect_in err.txt "not an IPv4 or IPv6 address"

# A port in use: a first server holds it, a second one says so and exits; the first goes on.
modules="${AVATARMAP_VIEWER_MODULES:-}"
timeout 60 "$exe" view --avatar "$robot" --port 0 --seconds 20 --quiet >first.txt 2>first.err &
first=$!
for _ in $(seq 100); do [ -s first.txt ] && break; sleep 0.1; done
if grep -q "fetch_viewer_modules" first.err; then
  echo "note: the viewer's modules are missing: the port-in-use case is skipped ($modules)"
  wait "$first"
  finish
  exit
fi
port=$(sed -n 's|^http://127.0.0.1:\([0-9]*\)/$|\1|p' first.txt)
[ -n "$port" ] && pass || fail "the first view printed no URL: $(cat first.txt first.err)"
run 1 view --avatar "$robot" --port "$port"
expect_in err.txt "port $port is in use by another program"
expect_in err.txt "--port"
run 1 live take.mp4 --serve "$port"
expect_in err.txt "port $port is in use"
kill -0 "$first" 2>/dev/null && pass || fail "the first server died"
kill -INT "$first"
wait "$first"
[ $? -eq 0 ] && pass || fail "view did not stop cleanly on SIGINT"
finish
