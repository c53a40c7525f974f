// pose_server (include/avatarmap/stream/pose_server.hpp) through plain sockets: HTTP GETs of
// the page, a module and the config; paths outside the served folders and foreign Host or
// Origin headers refused; the WebSocket handshake against RFC 6455's own example; pose
// messages read back by the pose reader (bit-exact); every page served; a page that stops
// reading gets the newest pose instead of a queue; a page that vanishes mid-stream; a port in
// use; publish() allocating nothing.
#include "avatarmap/stream/pose_server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/synth/random_pose.hpp"
// The counter only: stream_allocation_test.cpp defines the counting operator new.
#define AVATARMAP_COUNTING_NEW_COUNTER_ONLY
#include "support/counting_new.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

using namespace std::chrono_literals;

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

int connect_to(int port, int rcvbuf = 0) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (rcvbuf > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  timeval tv{10, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

void send_all(int fd, const std::string& s) {
  std::size_t off = 0;
  while (off < s.size()) {
    const ssize_t n = ::send(fd, s.data() + off, s.size() - off, MSG_NOSIGNAL);
    if (n <= 0) return;
    off += static_cast<std::size_t>(n);
  }
}

struct http_answer {
  int status = 0;
  std::string head, body;
  std::string header(const std::string& name) const {
    std::string lower = head;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const auto p = lower.find("\r\n" + name + ":");
    if (p == std::string::npos) return {};
    const auto start = head.find_first_not_of(' ', p + name.size() + 3);
    return head.substr(start, head.find("\r\n", start) - start);
  }
};

// Sends a raw request, reads the answer (head + Content-Length bytes, or until closed).
http_answer request(int port, const std::string& raw) {
  http_answer r;
  const int fd = connect_to(port);
  if (fd < 0) return r;
  send_all(fd, raw);
  std::string data;
  char buf[65536];
  for (;;) {
    const auto end = data.find("\r\n\r\n");
    if (end != std::string::npos) {
      r.head = data.substr(0, end + 2);
      const std::string len = r.header("content-length");
      if (!len.empty() && data.size() - end - 4 >= std::stoul(len)) break;
    }
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    data.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  const auto end = data.find("\r\n\r\n");
  if (end == std::string::npos) return r;
  r.head = data.substr(0, end + 2);
  r.body = data.substr(end + 4);
  if (r.head.size() > 12) r.status = std::atoi(r.head.c_str() + 9);
  return r;
}

http_answer get(int port, const std::string& path, const std::string& host = "127.0.0.1") {
  return request(port, "GET " + path + " HTTP/1.1\r\nHost: " + host + ":" + std::to_string(port) +
                           "\r\nConnection: close\r\n\r\n");
}

// A WebSocket client on a raw socket (RFC 6455): the handshake, then whole text messages.
struct ws_client {
  int fd = -1;
  std::string pending;   // bytes read past the last message
  std::string response;  // the handshake's answer

  bool open(int port, const std::string& extra_headers, int rcvbuf = 0,
            const std::string& key = "dGhlIHNhbXBsZSBub25jZQ==") {
    fd = connect_to(port, rcvbuf);
    if (fd < 0) return false;
    send_all(fd, "GET /pose HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                     "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: " + key +
                     "\r\nSec-WebSocket-Version: 13\r\n" + extra_headers + "\r\n");
    char buf[4096];
    while (pending.find("\r\n\r\n") == std::string::npos) {
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n <= 0) return false;
      pending.append(buf, static_cast<std::size_t>(n));
    }
    const auto end = pending.find("\r\n\r\n");
    response = pending.substr(0, end + 2);
    pending.erase(0, end + 4);
    return response.rfind("HTTP/1.1 101", 0) == 0;
  }
  bool read_bytes(std::size_t n) {
    char buf[65536];
    while (pending.size() < n) {
      const ssize_t got = ::recv(fd, buf, sizeof buf, 0);
      if (got <= 0) return false;
      pending.append(buf, static_cast<std::size_t>(got));
    }
    return true;
  }
  // The next text message (server frames are unmasked); false on close or time-out.
  bool read(std::string& out) {
    out.clear();
    for (;;) {
      if (!read_bytes(2)) return false;
      const auto b0 = static_cast<unsigned char>(pending[0]);
      const auto b1 = static_cast<unsigned char>(pending[1]);
      std::size_t header = 2, len = b1 & 0x7f;
      if (len == 126) {
        if (!read_bytes(4)) return false;
        len =
            (static_cast<unsigned char>(pending[2]) << 8) | static_cast<unsigned char>(pending[3]);
        header = 4;
      } else if (len == 127) {
        if (!read_bytes(10)) return false;
        len = 0;
        for (int i = 2; i < 10; ++i) len = (len << 8) | static_cast<unsigned char>(pending[i]);
        header = 10;
      }
      if (b1 & 0x80) return false;  // a server never masks
      if (!read_bytes(header + len)) return false;
      const int opcode = b0 & 0x0f;
      out += pending.substr(header, len);
      pending.erase(0, header + len);
      if (opcode == 8) return false;
      if (b0 & 0x80) return true;
    }
  }
  void close() {
    if (fd >= 0) ::close(fd);
    fd = -1;
  }
  ~ws_client() { close(); }
};

const std::string k_protocol_header =
    std::string("Sec-WebSocket-Protocol: ") + k_pose_socket_protocol + "\r\n";

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

}  // namespace
}  // namespace avatarmap
