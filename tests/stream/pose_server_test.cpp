// pose_server (include/avatarmap/stream/pose_server.hpp) through plain sockets: HTTP GETs of
// the page, a module and the config; an avatar served from memory; paths outside the served
// folders and foreign Host or Origin headers refused, also when listening on 0.0.0.0 (forged
// Host headers, sent to 127.0.0.1 only); refused WebSockets not counted as pages and their log
// bounded; the WebSocket handshake against RFC 6455's own example; pose messages read back by
// the pose reader (bit-exact); every page served; a page that stops reading gets the newest
// pose instead of a queue; a page that vanishes mid-stream; a port in use, naming the option
// that sets it; publish() allocating nothing. The load test: pose_server_load_test.cpp.
#include "avatarmap/stream/pose_server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/synth/random_pose.hpp"
// The counter only: stream_allocation_test.cpp defines the counting operator new.
#define AVATARMAP_COUNTING_NEW_COUNTER_ONLY
#include "http_test_client.hpp"
#include "support/counting_new.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

using namespace std::chrono_literals;
using test::get;
using test::http_answer;
using test::k_protocol_header;
using test::request;
using test::ws_client;

std::string source_dir() {
  const char* s = std::getenv("AVATARMAP_SOURCE_DIR");
  return s ? s : ".";
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// A modules folder with small stand-ins for the npm files (the server only serves them).
struct fixture_dirs {
  test::temp_dir dir{"pose_server"};
  std::string modules = dir.file("modules");
  fixture_dirs() {
    for (const char* d : {"/three", "/three/build", "/three-vrm", "/three-vrm/lib",
                          "/three-vrm-animation", "/three-vrm-animation/lib"})
      std::filesystem::create_directories(modules + d);
    write_file(modules + "/three/build/three.module.js", "export const marker = 'three';\n");
    write_file(modules + "/three-vrm/lib/three-vrm.module.js", "export const vrm = 1;\n");
    write_file(modules + "/three-vrm-animation/lib/three-vrm-animation.module.js", "x\n");
    write_file(dir.file("secret.js"), "SECRET\n");
    write_file(modules + "/three/secret.txt", "SECRET\n");
  }
  pose_server_options options() const {
    pose_server_options o;
    o.port = 0;
    o.page_dir = source_dir() + "/viewer";
    o.modules_dir = modules;
    return o;
  }
};

double message_t(const std::string& m) { return std::atof(m.c_str() + m.find("\"t\":") + 4); }

proxy_pose pose_at(double t, unsigned seed = 1) {
  std::mt19937 rng(seed);
  proxy_pose p = random_pose(rng);
  p.t = t;
  p.hips_position = {0.1f, 0.9f, -0.2f};
  return p;
}

template <class F>
bool eventually(F&& condition) {
  for (int i = 0; i < 500; ++i) {
    if (condition()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

TEST(pose_server, serves_the_page_a_module_and_the_config) {
  fixture_dirs f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  ASSERT_GT(server.port(), 0);
  EXPECT_EQ(server.url(), "http://127.0.0.1:" + std::to_string(server.port()) + "/");
  EXPECT_EQ(server.listen_address(), "127.0.0.1:" + std::to_string(server.port()));
  EXPECT_FALSE(server.exposed());
  EXPECT_TRUE(server.network_urls().empty());

  const http_answer page = get(server.port(), "/");
  EXPECT_EQ(page.status, 200);
  EXPECT_EQ(page.header("content-type"), "text/html; charset=utf-8");
  EXPECT_NE(page.body.find("importmap"), std::string::npos);
  EXPECT_EQ(page.header("x-content-type-options"), "nosniff");

  const http_answer module = get(server.port(), "/modules/three/build/three.module.js");
  EXPECT_EQ(module.status, 200);
  EXPECT_EQ(module.header("content-type"), "text/javascript; charset=utf-8");
  EXPECT_EQ(module.body, "export const marker = 'three';\n");
  EXPECT_EQ(get(server.port(), "/viewer.js").status, 200);

  const http_answer config = get(server.port(), "/config.json");
  EXPECT_EQ(config.status, 200);
  EXPECT_NE(config.body.find("\"avatar\":null"), std::string::npos) << config.body;
  EXPECT_NE(config.body.find("\"protocol\":\"avatarmap.pose\""), std::string::npos);
  EXPECT_EQ(get(server.port(), "/avatar.vrm").status, 404);  // none configured

  // The avatar given is served as /avatar.vrm whatever its name ends with.
  write_file(f.dir.file("Robot.VRM"), "glTF-bytes");
  pose_server_options o = f.options();
  o.avatar_path = f.dir.file("Robot.VRM");
  pose_server with_avatar;
  ASSERT_TRUE(with_avatar.start(o).ok());
  const http_answer avatar = get(with_avatar.port(), "/avatar.vrm");
  EXPECT_EQ(avatar.status, 200);
  EXPECT_EQ(avatar.header("content-type"), "model/gltf-binary");
  EXPECT_EQ(avatar.body, "glTF-bytes");
  const http_answer config2 = get(with_avatar.port(), "/config.json");
  EXPECT_NE(config2.body.find("\"avatar\":\"/avatar.vrm\""), std::string::npos) << config2.body;
  EXPECT_NE(config2.body.find("\"avatar_name\":\"Robot.VRM\""), std::string::npos);
}

TEST(pose_server, refuses_paths_outside_its_folders_and_foreign_hosts) {
  fixture_dirs f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  for (const char* path :
       {"/modules/three/../../secret.js", "/modules/three/../secret.js", "/../secret.js",
        "/modules/../secret.js", "/modules/three/%2e%2e/%2e%2e/secret.js",
        "/modules/three/secret.txt", "/modules/other/x.js", "/modules/three/.hidden.js",
        "/nothing.html", "//etc/passwd", "/modules/three/build/../../../secret.js"}) {
    const http_answer r = get(server.port(), path);
    EXPECT_TRUE(r.status == 404 || r.status == 403 || r.status == 400) << path << " " << r.status;
    EXPECT_EQ(r.body.find("SECRET"), std::string::npos) << path;
  }
  // DNS rebinding: a page whose own name points at 127.0.0.1 may not read anything.
  EXPECT_EQ(get(server.port(), "/", "evil.example").status, 403);
  EXPECT_EQ(get(server.port(), "/", "localhost").status, 200);
}

TEST(pose_server, websocket_handshake_matches_rfc_6455s_example) {
  fixture_dirs f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  ws_client c;
  ASSERT_TRUE(c.open(server.port(), k_protocol_header)) << c.response;
  // RFC 6455 section 1.3: key "dGhlIHNhbXBsZSBub25jZQ==" -> accept "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=".
  http_answer h;
  h.head = c.response;
  EXPECT_EQ(h.header("sec-websocket-accept"), "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=");
  EXPECT_EQ(h.header("sec-websocket-protocol"), k_pose_socket_protocol);

  ws_client no_protocol;
  EXPECT_FALSE(no_protocol.open(server.port(), ""));
  ws_client foreign;
  EXPECT_FALSE(foreign.open(server.port(), k_protocol_header + "Origin: http://evil.example\r\n"));
  ws_client local_page;
  EXPECT_TRUE(
      local_page.open(server.port(), k_protocol_header + "Origin: http://localhost:9999\r\n"));
}

TEST(pose_server, pose_messages_read_back_bit_exact_to_every_page) {
  fixture_dirs f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  const proxy_pose before = pose_at(0.5, 7);
  server.publish(before);  // before anyone connects: a new page gets it at once
  ws_client a, b;
  ASSERT_TRUE(a.open(server.port(), k_protocol_header));
  ASSERT_TRUE(b.open(server.port(), k_protocol_header));
  std::string m;
  ASSERT_TRUE(a.read(m));
  EXPECT_DOUBLE_EQ(message_t(m), 0.5);
  ASSERT_TRUE(b.read(m));
  EXPECT_DOUBLE_EQ(message_t(m), 0.5);

  const proxy_pose sent = pose_at(1.25, 11);
  server.publish(sent);
  for (ws_client* c : {&a, &b}) {
    ASSERT_TRUE(c->read(m));
    pose_reader reader;
    ASSERT_TRUE(reader.open_memory(m.data(), m.size()).ok());
    proxy_pose got;
    ASSERT_EQ(reader.next(got), read_result::frame) << reader.error();
    EXPECT_EQ(got.t, sent.t);
    EXPECT_EQ(got.hips_position, sent.hips_position);
    for (int i = 0; i < k_bone_count; ++i) {
      // The reader keeps a unit quaternion bit for bit; the sign is the writer's.
      EXPECT_EQ(got.rotations[i], sent.rotations[i]) << bone_name(static_cast<bone>(i));
    }
    EXPECT_EQ(got.expressions, sent.expressions);
  }
  EXPECT_TRUE(eventually([&] { return server.stats().pages_connected == 2; }));
  EXPECT_EQ(server.stats().published, 2);
}

TEST(pose_server, a_page_that_stops_reading_gets_the_newest_pose_not_a_queue) {
  fixture_dirs f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  ws_client slow, fast;
  ASSERT_TRUE(slow.open(server.port(), k_protocol_header, 4096));
  ASSERT_TRUE(fast.open(server.port(), k_protocol_header));
  // ~80 MB of messages: far more than the sockets' buffers hold (the kernel grows a loopback
  // send buffer to 4 MiB at most, ~1000 messages), so a queue would show.
  constexpr int k_poses = 20000;
  std::thread reader([&] {
    std::string m;
    while (fast.read(m))
      if (message_t(m) >= 1e6) return;
  });
  for (int i = 0; i < k_poses; ++i) server.publish(pose_at(i, 3));
  server.publish(pose_at(1e6, 3));
  reader.join();  // the fast page got the last pose while the slow one read nothing
  int got = 0;
  std::string m;
  double last = -1;
  while (last < 1e6 && slow.read(m)) {
    ++got;
    last = message_t(m);
  }
  std::printf("the slow page read %d messages for %d published poses\n", got, k_poses + 1);
  EXPECT_EQ(last, 1e6) << "the slow page never got the newest pose";
  EXPECT_LT(got, k_poses / 10) << "the slow page was sent a queue of old poses";
  EXPECT_GT(server.stats().skipped, 0);
}

TEST(pose_server, a_page_that_vanishes_mid_stream_leaves_the_others_served) {
  fixture_dirs f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  {
    ws_client gone;
    ASSERT_TRUE(gone.open(server.port(), k_protocol_header));
    server.publish(pose_at(1, 1));
    std::string m;
    ASSERT_TRUE(gone.read(m));
    linger hard{1, 0};  // close with a reset, as a killed browser's system does
    ::setsockopt(gone.fd, SOL_SOCKET, SO_LINGER, &hard, sizeof hard);
    for (int i = 0; i < 50; ++i) server.publish(pose_at(2 + i, 1));
  }
  for (int i = 0; i < 50; ++i) server.publish(pose_at(100 + i, 1));
  EXPECT_TRUE(eventually([&] { return server.stats().pages_connected == 0; }));
  ws_client next;
  ASSERT_TRUE(next.open(server.port(), k_protocol_header));
  std::string m;
  ASSERT_TRUE(next.read(m));
  EXPECT_EQ(message_t(m), 149);
  server.publish(pose_at(500, 1));
  ASSERT_TRUE(next.read(m));
  EXPECT_EQ(message_t(m), 500);
}

TEST(pose_server, a_port_in_use_is_a_clear_error) {
  const int holder = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(holder, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(::listen(holder, 1), 0);
  socklen_t len = sizeof a;
  ::getsockname(holder, reinterpret_cast<sockaddr*>(&a), &len);
  fixture_dirs f;
  pose_server_options o = f.options();
  o.port = ntohs(a.sin_port);
  pose_server server;
  const status st = server.start(o);
  ::close(holder);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("port " + std::to_string(o.port) + " is in use"), std::string::npos)
      << st.message();
  EXPECT_NE(st.message().find("--port"), std::string::npos) << st.message();

  // `live --serve` sets the port with --serve: the message names that option, not --port.
  const int holder2 = ::socket(AF_INET, SOCK_STREAM, 0);
  a.sin_port = 0;
  ASSERT_EQ(::bind(holder2, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(::listen(holder2, 1), 0);
  len = sizeof a;
  ::getsockname(holder2, reinterpret_cast<sockaddr*>(&a), &len);
  o.port = ntohs(a.sin_port);
  o.port_option = "--serve";
  pose_server served;
  const status st2 = served.start(o);
  ::close(holder2);
  ASSERT_FALSE(st2.ok());
  EXPECT_NE(st2.message().find("(--serve; port 0 picks a free one)"), std::string::npos)
      << st2.message();
  EXPECT_EQ(st2.message().find("--port"), std::string::npos) << st2.message();
}

TEST(pose_server, options_are_checked_before_binding) {
  fixture_dirs f;
  pose_server_options o = f.options();
  o.host = "example.com";
  EXPECT_NE(o.validate().message().find("not an IPv4 or IPv6 address"), std::string::npos);
  o = f.options();
  o.port = 70000;
  EXPECT_NE(o.validate().message().find("0..65535"), std::string::npos);
  o = f.options();
  o.modules_dir = f.dir.file("none");
  EXPECT_NE(o.validate().message().find("fetch_viewer_modules.sh"), std::string::npos);
  o = f.options();
  o.avatar_path = f.dir.file("missing.vrm");
  EXPECT_NE(o.validate().message().find("missing.vrm"), std::string::npos);
  o = f.options();
  o.host = "192.0.2.1";  // TEST-NET-1: never this machine's
  o.port = 45678;
  pose_server server;
  EXPECT_NE(server.start(o).message().find("not an address of this machine"), std::string::npos);
}

TEST(pose_server, publish_allocates_nothing) {
  fixture_dirs f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  ws_client c;
  ASSERT_TRUE(c.open(server.port(), k_protocol_header));
  const proxy_pose p = pose_at(1, 5);
  server.publish(p);
  std::string m;
  ASSERT_TRUE(c.read(m));
  const long before = g_allocations.load();
  for (int i = 0; i < 200; ++i) server.publish(p);
  EXPECT_EQ(g_allocations.load() - before, 0);
}

// The event lines a server reports, for the tests that count them.
struct event_log {
  std::mutex m;
  std::vector<std::string> lines;
  std::function<void(std::string_view)> sink() {
    return [this](std::string_view l) {
      std::lock_guard<std::mutex> lock(m);
      lines.emplace_back(l);
    };
  }
  int count(const std::string& start) {
    std::lock_guard<std::mutex> lock(m);
    int n = 0;
    for (const std::string& l : lines) n += l.rfind(start, 0) == 0;
    return n;
  }
};

TEST(pose_server, the_avatar_can_be_served_from_memory_to_every_load) {
  fixture_dirs f;
  pose_server_options o = f.options();
  // 1 MB: many chunks of the body writer; every byte value.
  std::string bytes(1 << 20, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>((i * 7919) >> 3);
  o.avatar_data = bytes;
  o.avatar_name = "builtin.vrm";
  pose_server server;
  ASSERT_TRUE(server.start(o).ok());
  for (int load = 0; load < 3; ++load) {  // page reloads keep getting it
    const http_answer avatar = get(server.port(), "/avatar.vrm");
    EXPECT_EQ(avatar.status, 200);
    EXPECT_EQ(avatar.header("content-type"), "model/gltf-binary");
    EXPECT_EQ(avatar.header("x-content-type-options"), "nosniff");
    EXPECT_TRUE(avatar.body == bytes) << "load " << load << ": " << avatar.body.size() << " bytes";
    const http_answer config = get(server.port(), "/config.json");
    EXPECT_NE(config.body.find("\"avatar\":\"/avatar.vrm\""), std::string::npos) << config.body;
    EXPECT_NE(config.body.find("\"avatar_name\":\"builtin.vrm\""), std::string::npos);
  }
  // Both at once is a mistake.
  write_file(f.dir.file("me.vrm"), "glTF");
  o.avatar_path = f.dir.file("me.vrm");
  EXPECT_NE(o.validate().message().find("not both"), std::string::npos);
}

TEST(pose_server, refused_websockets_are_not_counted_and_their_log_is_bounded) {
  fixture_dirs f;
  event_log log;
  pose_server_options o = f.options();
  o.on_event = log.sink();
  pose_server server;
  ASSERT_TRUE(server.start(o).ok());
  ws_client page;
  ASSERT_TRUE(page.open(server.port(), k_protocol_header));
  constexpr int k_origin = 60, k_host = 40;
  for (int i = 0; i < k_origin; ++i) {
    ws_client c;
    EXPECT_FALSE(c.open(server.port(), k_protocol_header + "Origin: http://evil.example\r\n"));
  }
  for (int i = 0; i < k_host; ++i) {
    ws_client c;
    EXPECT_FALSE(c.open(server.port(), k_protocol_header, 0,
                        "dGhlIHNhbXBsZSBub25jZQ==", "rebound.evil.example"));
  }
  ws_client second;
  ASSERT_TRUE(second.open(server.port(), k_protocol_header));
  EXPECT_TRUE(eventually([&] { return server.stats().refused == k_origin + k_host; }))
      << server.stats().refused;
  EXPECT_TRUE(eventually([&] { return server.stats().pages_connected == 2; }))
      << server.stats().pages_connected;
  EXPECT_EQ(server.stats().connections, 2);
  second.close();
  EXPECT_TRUE(eventually([&] { return server.stats().pages_connected == 1; }))
      << server.stats().pages_connected;
  server.stop();
  EXPECT_EQ(server.stats().pages_connected, 0);
  // Five refusals one by one, the rest in one summary as the server stops.
  EXPECT_EQ(log.count("refused a WebSocket"), 5);
  EXPECT_EQ(log.count("refused " + std::to_string(k_origin + k_host - 5) + " more"), 1);
  EXPECT_EQ(log.count("refused"), 6);
  EXPECT_EQ(log.count("page connected"), 2);
  EXPECT_EQ(log.count("page at"), 2);  // both left
}

// The machine's own non-loopback addresses, as a Host header writes them.
std::vector<std::string> own_addresses() {
  std::vector<std::string> r;
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) != 0) return r;
  for (const ifaddrs* i = list; i; i = i->ifa_next) {
    if (!i->ifa_addr || i->ifa_addr->sa_family != AF_INET) continue;
    char text[INET_ADDRSTRLEN] = {};
    const auto* v4 = reinterpret_cast<const sockaddr_in*>(i->ifa_addr);
    inet_ntop(AF_INET, &v4->sin_addr, text, sizeof text);
    if (std::string(text).rfind("127.", 0) != 0) r.emplace_back(text);
  }
  ::freeifaddrs(list);
  return r;
}

TEST(pose_server, beyond_loopback_it_answers_only_to_this_machines_names) {
  // Listens on every address, but every request of this test goes to 127.0.0.1: what differs
  // is only the Host header a browser would send (forged here).
  fixture_dirs f;
  event_log log;
  pose_server_options o = f.options();
  o.host = "0.0.0.0";
  o.allowed_hosts = {"Viewer.Example"};
  o.on_event = log.sink();
  pose_server server;
  ASSERT_TRUE(server.start(o).ok());
  const int port = server.port();
  EXPECT_TRUE(server.exposed());
  EXPECT_EQ(server.listen_address(), "0.0.0.0:" + std::to_string(port));
  EXPECT_EQ(server.url(), "http://127.0.0.1:" + std::to_string(port) + "/");
  for (const std::string& u : server.network_urls())
    EXPECT_EQ(u.find("127."), std::string::npos) << u;  // loopback is url(), not a network URL

  std::vector<std::string> allowed = {"127.0.0.1", "localhost",      "[::1]",
                                      "127.1.2.3", "viewer.example", "VIEWER.EXAMPLE."};
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) == 0 && name[0]) allowed.emplace_back(name);
  for (const std::string& a : own_addresses()) allowed.push_back(a);
  for (const std::string& h : allowed) EXPECT_EQ(get(port, "/", h).status, 200) << "Host: " << h;

  // DNS rebinding and foreign names: a name that merely contains an allowed one, a Host that
  // is missing or empty, an address that is not this machine's.
  int refused = 0;
  const std::vector<std::string> foreign_hosts = {
      "evil.example",        "127.0.0.1.evil.example", std::string(name) + ".evil.example",
      "viewer.example.evil", "198.51.100.77",          "[2001:db8::1]"};
  for (const std::string& h : foreign_hosts) {
    EXPECT_EQ(get(port, "/", h).status, 403) << "Host: " << h;
    ++refused;
  }
  EXPECT_EQ(request(port, test::get_request("/avatar.vrm", "")).status, 403);
  EXPECT_EQ(request(port, "GET / HTTP/1.1\r\nConnection: close\r\n\r\n").status, 403);
  refused += 2;
  // WebSockets: a foreign Host is refused; a page served by this machine's name may connect.
  ws_client rebound;
  EXPECT_FALSE(
      rebound.open(port, k_protocol_header, 0, "dGhlIHNhbXBsZSBub25jZQ==", "evil.example"));
  ws_client foreign;
  EXPECT_FALSE(foreign.open(port, k_protocol_header + "Origin: http://evil.example\r\n"));
  refused += 2;
  ws_client named;
  EXPECT_TRUE(named.open(
      port, k_protocol_header + "Origin: http://viewer.example:" + std::to_string(port) + "\r\n", 0,
      "dGhlIHNhbXBsZSBub25jZQ==", "viewer.example"))
      << named.response;
  EXPECT_EQ(server.stats().refused, refused);
  EXPECT_TRUE(eventually([&] { return server.stats().pages_connected == 1; }));
  server.stop();
  EXPECT_EQ(log.count("refused a request from 127.0.0.1: Host 'evil.example:"), 1);
}

}  // namespace
}  // namespace avatarmap
