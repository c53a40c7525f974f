#!/usr/bin/env bash
# `avatarmap view` and `live --serve` (docs/viewer.md): bad usage, avatars that are not VRM,
# malformed pose files, a port in use (named by the option that sets it), missing modules: a
# clear error (exit 1 or 2, never a signal) that says what to do. Then the server's own
# exposure (docs/security.md): the built-in avatar served from memory (nothing in $TMPDIR, a
# file planted there changes nothing, reloads work), foreign Host headers and a flood of
# refused WebSockets (bounded log, no negative count), and listening on 0.0.0.0 (the address
# and a warning printed, forged Host headers refused). Every request goes to 127.0.0.1. The
# browser side is tests/viewer/viewer_e2e_test.py.
# Usage: hostile_view_test.sh EXE WORK_DIR
# shellcheck source=hostile_lib.sh
source "$(dirname "$0")/hostile_lib.sh"

run ok view --help
expect_in out.txt "--connect"
expect_in out.txt "--allow-host"
run 2 view take.mp4 --avatar me.vrm
expect_in err.txt "FILE must be a .pose.jsonl, .vrma, .glb (an avatar with its animation) or .bvh"
printf '{"t":0}\n' >one.pose.jsonl
run 2 view one.pose.jsonl --avatar me.vrm --connect 9000
expect_in err.txt "two sources of poses"
run 2 view --avatar me.vrm --port 70000
expect_in err.txt "option --port needs a whole number in 0..65535, got '70000'"
run 2 view --avatar me.vrm --port 80.5
run 2 view --avatar me.vrm --seconds -1
expect_in err.txt "--seconds must be >= 0"
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
  skip_part "AVATARMAP_TEST_DATA is not set: the cases with a real avatar"
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
  skip_part "the viewer's modules are missing ($modules): the port-in-use case and those after it"
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
expect_in err.txt "(--serve; port 0 picks a free one)"
expect_not_in err.txt "--port"
kill -0 "$first" 2>/dev/null && pass || fail "the first server died"
kill -INT "$first"
wait "$first"
[ $? -eq 0 ] && pass || fail "view did not stop cleanly on SIGINT"

# http_get PORT PATH HOST OUT: GET PATH from 127.0.0.1:PORT with the header "Host: HOST" (any
# text: forged on purpose); the whole answer in OUT; prints the status code (0: none).
http_get() {
  local code
  if ! exec 3<>"/dev/tcp/127.0.0.1/$1"; then
    echo 0
    return
  fi
  printf 'GET %s HTTP/1.1\r\nHost: %s\r\nConnection: close\r\n\r\n' "$2" "$3" >&3
  timeout 10 cat <&3 >"$4"
  exec 3<&- 3>&-
  code=$(head -1 "$4" | sed -n 's|^HTTP/1.1 \([0-9]*\).*|\1|p')
  echo "${code:-0}"
}
# ws_refused PORT ORIGIN: a WebSocket handshake from a page of ORIGIN; its answer's first line.
ws_refused() {
  exec 3<>"/dev/tcp/127.0.0.1/$1" || return
  printf 'GET /pose HTTP/1.1\r\nHost: 127.0.0.1:%s\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: avatarmap.pose\r\nOrigin: %s\r\n\r\n' "$1" "$2" >&3
  timeout 10 head -c 200 <&3 | head -1
  exec 3<&- 3>&-
}
# start_view OUT ERR ARGS...: `view ARGS` in the background ($viewer), its port in $vport.
start_view() {
  local out=$1 err=$2
  shift 2
  timeout 60 "$exe" view "$@" >"$out" 2>"$err" &
  viewer=$!
  for _ in $(seq 150); do [ -s "$out" ] && break; sleep 0.1; done
  vport=$(sed -n 's|^http://[^/]*:\([0-9]*\)/$|\1|p' "$out" | head -1)
}

# The built-in avatar comes from memory: a folder planted in $TMPDIR under the name the viewer
# once used (avatarmap-viewer-PID.vrm: the shell's PID is the viewer's after exec) changes
# nothing, nothing is written there during the run nor left after SIGHUP, and the page's avatar
# loads again and again under one name.
mkdir tmp
"$exe" avatar -o builtin.vrm >/dev/null 2>&1
TMPDIR="$PWD/tmp" timeout 60 bash -c 'mkdir "$TMPDIR/avatarmap-viewer-$$.vrm" && exec "$0" view --port 0 --seconds 20' "$exe" >b.txt 2>b.err &
viewer=$!
for _ in $(seq 150); do [ -s b.txt ] && break; sleep 0.1; done
vport=$(sed -n 's|^http://127.0.0.1:\([0-9]*\)/$|\1|p' b.txt)
[ -n "$vport" ] && pass || fail "view with a planted temporary name printed no URL: $(cat b.err)"
planted=$(ls tmp)
[ "$(http_get "$vport" /config.json "127.0.0.1:$vport" config.txt)" = 200 ] && pass || fail "no /config.json"
expect_in config.txt '"avatar_name":"built-in avatar"'
for load in 1 2 3; do
  [ "$(http_get "$vport" /avatar.vrm "localhost:$vport" "avatar$load.txt")" = 200 ] && pass ||
    fail "load $load of /avatar.vrm failed"
  expect_in "avatar$load.txt" "content-length: $(wc -c <builtin.vrm)"
done
[ "$(ls tmp)" = "$planted" ] && pass || fail "view wrote to TMPDIR: $(ls tmp)"
kill -HUP "$viewer"
wait "$viewer"
[ "$(ls tmp)" = "$planted" ] && pass || fail "view left files in TMPDIR after SIGHUP: $(ls tmp)"

# A foreign page: a forged Host and a flood of WebSockets from another Origin are refused; the
# log says so a few times, then sums up; the count of open pages never goes below zero.
start_view r.txt r.err --port 0 --seconds 20
[ "$(http_get "$vport" / "evil.example:$vport" evil.txt)" = 403 ] && pass || fail "a foreign Host was answered"
for _ in $(seq 40); do ws_refused "$vport" "http://evil.example" >>ws.txt; done
expect_not_in ws.txt "101 Switching"
kill -INT "$viewer"
wait "$viewer"
[ $? -eq 0 ] && pass || fail "view did not stop cleanly after refusals"
[ "$(grep -c "^view: refused" r.err)" -le 6 ] && pass ||
  fail "the refusals flooded the log: $(grep -c "^view: refused" r.err) lines"
expect_in r.err "refused a request from 127.0.0.1: Host 'evil.example:"
expect_in r.err "refused 36 more"
expect_in r.err "41 requests refused for their Host or Origin"
expect_not_in r.err "(-"

# Beyond loopback: the address listened on and a warning, the loopback URL on standard output;
# requests must name this machine (forged Host headers, sent to 127.0.0.1 all the same).
start_view w.txt w.err --host 0.0.0.0 --port 0 --seconds 20 --quiet
[ -n "$vport" ] && pass || fail "view --host 0.0.0.0 printed no URL: $(cat w.err)"
expect_in w.txt "http://127.0.0.1:$vport/"
expect_in w.err "view: listening on 0.0.0.0:$vport (every IPv4 address of this machine)"
expect_in w.err "warning: the page, the avatar and the poses are readable"
for h in "127.0.0.1:$vport" "localhost:$vport" "$(hostname):$vport"; do
  [ "$(http_get "$vport" / "$h" ok.txt)" = 200 ] && pass || fail "Host $h was refused"
done
for h in "evil.example:$vport" "127.0.0.1.evil.example" "$(hostname).evil.example" "198.51.100.77"; do
  [ "$(http_get "$vport" / "$h" no.txt)" = 403 ] && pass || fail "Host $h was answered"
done
kill -INT "$viewer"
wait "$viewer"
[ $? -eq 0 ] && pass || fail "view --host 0.0.0.0 did not stop cleanly"
finish
