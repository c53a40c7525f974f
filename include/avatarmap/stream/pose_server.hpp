// The browser viewer's server (docs/viewer.md): serves the viewer page (the project's
// viewer/ folder), the JavaScript modules it imports (three.js and three-vrm, fetched from npm
// by scripts/fetch_viewer_modules.sh) and the avatar and clip it shows, and broadcasts proxy
// poses to every connected page over a WebSocket. Bound to 127.0.0.1 by default; bound beyond
// loopback it answers only requests that name this machine in their Host header
// (docs/security.md).
//
// Several people: each person's poses are published in the person's slot (0 to
// k_pose_server_slots - 1, stable while the person stays; live/live_session.hpp), and every
// page gets each slot's newest pose, tagged with the person's id and slot (docs/viewer.md).
//
// Threads: start() runs the server on a thread of its own; publish() may be called from any
// thread (the live loop's) and never waits for a client: it replaces the slot's newest pose, and
// each page is sent each slot's newest pose when its connection can take one, so a slow page
// skips poses instead of queueing them. A page that disconnects, mid-message or not, only ends
// its own connection.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

/// The WebSocket subprotocol a page asks for (new WebSocket(url, k_pose_socket_protocol)); a
/// connection without it is refused. Each message the server sends is one text frame holding
/// one line of *.pose.jsonl (docs/file-formats.md) without its newline.
inline constexpr const char* k_pose_socket_protocol = "avatarmap.pose";
/// The WebSocket's path.
inline constexpr const char* k_pose_socket_path = "/pose";
/// People (slots) a pose server keeps a newest pose for: publish()'s slot is 0 to this - 1.
inline constexpr int k_pose_server_slots = 8;

struct pose_server_options {
  /// Address to listen on: an IPv4 or IPv6 literal, or "localhost" (= 127.0.0.1). Anything
  /// but a loopback address makes the page, avatar and poses visible to the network
  /// (pose_server::exposed()); 0.0.0.0 and :: listen on every address of the machine.
  std::string host = "127.0.0.1";
  /// TCP port, 0 to 65535; 0 lets the system choose a free one (see pose_server::port()).
  int port = 8080;
  /// The command-line option that sets the port, named in the port-in-use message ("--port",
  /// "--serve"); empty = none named.
  std::string port_option = "--port";
  /// Further names (DNS names, addresses) a request's Host header may give when listening
  /// beyond loopback, compared without case and port; beside them only loopback names, the
  /// machine's own addresses and host name are answered (docs/security.md).
  std::vector<std::string> allowed_hosts;
  /// Folder with the viewer page (index.html, viewer.js): required.
  std::string page_dir;
  /// Folder with three/, three-vrm/, three-vrm-animation/ (scripts/fetch_viewer_modules.sh):
  /// required.
  std::string modules_dir;
  /// Avatar (.vrm) the page loads, served as /avatar.vrm; empty = avatar_data, else none (the
  /// page asks for one to be dropped on it).
  std::string avatar_path;
  /// The avatar's bytes, served from memory as /avatar.vrm when avatar_path is empty (the
  /// built-in avatar: no file is written anywhere).
  std::string avatar_data;
  /// The avatar's name the page shows; empty = avatar_path's file name, or "avatar.vrm".
  std::string avatar_name;
  /// VRM Animation (.vrma) the page plays in a loop, served as /clip.vrma; empty = none.
  std::string clip_path;
  /// The avatar file holds its own animation (a .glb as `avatarmap convert -o x.glb` writes):
  /// the page plays the first glTF animation on it with its controls.
  bool avatar_animated = false;
  /// Proxy poses (*.pose.jsonl text) the page fetches whole and plays itself by their time
  /// stamps with its controls, served as /poses.pose.jsonl: the file poses_path, else the bytes
  /// of poses_data from memory; empty = none. poses_name: the name the page shows.
  std::string poses_path;
  std::string poses_data;
  std::string poses_name;
  /// A video (.mp4, .webm, .ogv, .mov) the page shows beside the avatar in step with the
  /// animation's time, served whole (no Range requests) as /video; empty = none.
  std::string video_path;
  /// WebSocket URL the page takes its poses from; empty = this server's own k_pose_socket_path.
  /// (`avatarmap view --connect PORT` points the page at a `live --serve PORT`.)
  std::string pose_socket_url;
  /// Called on the server's thread with one line about each page that connects, leaves or
  /// reports its first posed frame, and about requests refused for their Host or Origin (the
  /// first few, then one summary line per 10 s at most, so that a hostile page cannot flood
  /// the log); may be empty. Must not call back into the server.
  std::function<void(std::string_view)> on_event;

  /// ok, or a message naming the field and its allowed range (a missing folder or file, both
  /// avatar_path and avatar_data given).
  status validate() const;
};

/// Counters since start(), readable from any thread.
struct pose_server_stats {
  int pages_connected = 0;  // WebSocket connections accepted and open now
  long connections = 0;     // WebSocket connections accepted in all
  long refused = 0;         // requests and WebSocket handshakes refused for their Host or Origin
  long published = 0;       // publish() calls (a slot out of range counted, never sent)
  long sent = 0;            // pose messages handed to connections, all together
  long skipped = 0;         // poses a connection never got because a newer one came first
  double first_posed_frame_ms = -1;  // the latest page's report: page load -> first posed frame
};

class pose_server {
 public:
  pose_server();
  ~pose_server();  // stop()s
  pose_server(const pose_server&) = delete;
  pose_server& operator=(const pose_server&) = delete;

  /// Validates the options, binds host:port and starts the server's thread. Fails with a
  /// message that says what to do: invalid options, the port in use, an address that is not
  /// this machine's, a port below 1024 without the right, a build without the server library.
  /// Call at most once.
  status start(const pose_server_options& options);
  /// Stops the thread and closes every connection; idempotent.
  void stop();

  /// The port listened on (the chosen one when options.port was 0); 0 before start().
  int port() const;
  /// A URL that opens the page on this machine: http://HOST:PORT/ with the address listened
  /// on (IPv6 in brackets), or with 127.0.0.1 (::1) when that is 0.0.0.0 (::); empty before
  /// start().
  std::string url() const;
  /// The address and port listened on, as bound: "127.0.0.1:8080", "0.0.0.0:8080",
  /// "[::]:8080"; empty before start().
  std::string listen_address() const;
  /// True when listening beyond loopback: other machines may load the page, the avatar and the
  /// poses. False before start().
  bool exposed() const;
  /// When exposed(): the URLs by which other machines reach the server (the address listened
  /// on, or for 0.0.0.0 / :: each non-loopback address of the machine's interfaces when it
  /// started; link-local IPv6 left out); else empty.
  std::vector<std::string> network_urls() const;

  /// Makes `pose` the newest pose and wakes the server to send it to every page: one person,
  /// the same as publish(pose, -1, 0). Any thread, before, during or after start(); never
  /// blocks on a client, never allocates.
  void publish(const proxy_pose& pose) { publish(pose, -1, 0); }
  /// Makes `pose` the newest pose of `slot` (0 to k_pose_server_slots - 1: the person's place,
  /// live_output_report::slot) and wakes the server to send it to every page; each slot keeps
  /// its own newest pose, so every person in view reaches every page. The message is the pose's
  /// line with `"person":PERSON,"slot":SLOT` added as its last keys when `person` >= 0 (the
  /// person's id); with `person` < 0 (one person) it is the plain line, as publish(pose) sends.
  /// A slot out of range is ignored (counted in stats().published only). Any thread; never
  /// blocks on a client, never allocates.
  void publish(const proxy_pose& pose, int person, int slot);
  /// The person `person` has left `slot` (live_session_options::on_person_gone): the slot's
  /// newest message becomes `{"gone":true,"person":PERSON,"slot":SLOT}`, sent to every page
  /// in place of the person's last pose (the viewer hides that avatar at once; a page that
  /// connects later gets it too, not the stale pose). A slot out of range is ignored. Any
  /// thread; never blocks on a client, never allocates.
  void clear(int person, int slot);

  pose_server_stats stats() const;

  /// False in a build without the server library (libwebsockets): start() then fails.
  static bool available();

 private:
  struct impl;
  std::unique_ptr<impl> impl_;
};

}  // namespace avatarmap
