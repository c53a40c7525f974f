// A bounded load test of pose_server (include/avatarmap/stream/pose_server.hpp) on loopback
// only (127.0.0.1; never another address): a few hundred HTTP requests in flight at once, open
// WebSockets, refused WebSocket handshakes and slowloris-style partial requests that never
// finish; then the server must still answer a normal request quickly, count exactly the pages
// that are open, keep its log short and stop promptly with everything still connected. Sized
// to take a few seconds and to fit a 1024-descriptor limit (client and server share the
// process).
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/resource.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "avatarmap/stream/pose_server.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "http_test_client.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

using namespace std::chrono_literals;
using clock_type = std::chrono::steady_clock;

constexpr int k_http_requests = 300;  // in flight at once
constexpr int k_pages = 24;           // WebSockets accepted and held open
constexpr int k_refused = 150;        // WebSocket handshakes refused (foreign Origin)
constexpr int k_slowloris = 48;       // requests whose header never ends

double ms_since(clock_type::time_point t) {
  return std::chrono::duration<double, std::milli>(clock_type::now() - t).count();
}

std::string source_dir() {
  const char* s = std::getenv("AVATARMAP_SOURCE_DIR");
  return s ? s : ".";
}

struct load_fixture {
  test::temp_dir dir{"pose_server_load"};
  std::string modules = dir.file("modules");
  std::mutex m;
  std::vector<std::string> events;
  load_fixture() {
    // Client and server sockets live in this one process.
    rlimit r{};
    if (::getrlimit(RLIMIT_NOFILE, &r) == 0 && r.rlim_cur < 1024 && r.rlim_max >= 1024) {
      r.rlim_cur = 1024;
      ::setrlimit(RLIMIT_NOFILE, &r);
    }
    for (const char* d : {"/three/build", "/three-vrm/lib", "/three-vrm-animation/lib"})
      std::filesystem::create_directories(modules + d);
    for (const char* f : {"/three/build/three.module.js", "/three-vrm/lib/three-vrm.module.js",
                          "/three-vrm-animation/lib/three-vrm-animation.module.js"})
      std::ofstream(modules + f) << "export const x = 1;\n";
  }
  pose_server_options options() {
    pose_server_options o;
    o.host = "127.0.0.1";  // loopback only, whatever the default becomes
    o.port = 0;
    o.page_dir = source_dir() + "/viewer";
    o.modules_dir = modules;
    o.on_event = [this](std::string_view line) {
      std::lock_guard<std::mutex> lock(m);
      events.emplace_back(line);
    };
    return o;
  }
  std::size_t event_count() {
    std::lock_guard<std::mutex> lock(m);
    return events.size();
  }
  int count(const std::string& start) {
    std::lock_guard<std::mutex> lock(m);
    int n = 0;
    for (const std::string& e : events) n += e.rfind(start, 0) == 0;
    return n;
  }
};

template <class F>
bool eventually(F&& condition, std::chrono::milliseconds limit = 5000ms) {
  const auto start = clock_type::now();
  while (ms_since(start) < static_cast<double>(limit.count())) {
    if (condition()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return condition();
}

TEST(pose_server_load, stays_responsive_counts_right_and_stops_under_load) {
  load_fixture f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  const int port = server.port();
  const auto begin = clock_type::now();

  // Slowloris: a request line and one header, then nothing more, held to the end.
  std::vector<int> slow;
  for (int i = 0; i < k_slowloris; ++i) {
    const int fd = test::connect_to(port);
    ASSERT_GE(fd, 0);
    test::send_all(fd, "GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ");
    slow.push_back(fd);
  }

  // Pages that stay connected.
  std::vector<test::ws_client> pages(k_pages);
  for (auto& p : pages) ASSERT_TRUE(p.open(port, test::k_protocol_header)) << p.response;
  EXPECT_TRUE(eventually([&] { return server.stats().pages_connected == k_pages; }))
      << server.stats().pages_connected;

  // Refused handshakes from a foreign page, from a few threads at once.
  std::atomic<int> refused_ok{0};
  std::vector<std::thread> refusers;
  for (int t = 0; t < 3; ++t)
    refusers.emplace_back([&] {
      for (int i = 0; i < k_refused / 3; ++i) {
        test::ws_client c;
        if (!c.open(port, test::k_protocol_header + "Origin: http://evil.example\r\n"))
          ++refused_ok;
      }
    });

  // A few hundred requests sent before any answer is read.
  std::vector<int> fds;
  for (int i = 0; i < k_http_requests; ++i) {
    const int fd = test::connect_to(port);
    ASSERT_GE(fd, 0) << "connection " << i;
    const char* path = i % 3 == 0 ? "/" : i % 3 == 1 ? "/config.json" : "/viewer.js";
    test::send_all(fd, test::get_request(path, "127.0.0.1:" + std::to_string(port)));
    fds.push_back(fd);
  }
  int answered = 0;
  for (int fd : fds) answered += test::read_answer(fd).status == 200;
  for (auto& t : refusers) t.join();
  EXPECT_EQ(answered, k_http_requests);
  EXPECT_EQ(refused_ok.load(), k_refused / 3 * 3);

  // With the slow requests still held: a normal request is answered at once, the count is the
  // pages really open, and a pose reaches every page.
  const auto t0 = clock_type::now();
  const test::http_answer page = test::get(port, "/");
  const double page_ms = ms_since(t0);
  EXPECT_EQ(page.status, 200);
  EXPECT_LT(page_ms, 1000.0) << "a normal request waited behind the load";
  EXPECT_TRUE(eventually([&] { return server.stats().pages_connected == k_pages; }))
      << server.stats().pages_connected;
  std::mt19937 rng(1);
  proxy_pose pose = random_pose(rng);
  pose.t = 42;
  server.publish(pose);
  int got = 0;
  for (auto& p : pages) {
    std::string m;
    got += p.read(m) && m.find("\"t\":42") != std::string::npos;
  }
  EXPECT_EQ(got, k_pages);

  // Half the pages leave: the count follows.
  for (int i = 0; i < k_pages / 2; ++i) pages[static_cast<std::size_t>(i)].close();
  EXPECT_TRUE(eventually([&] { return server.stats().pages_connected == k_pages - k_pages / 2; }))
      << server.stats().pages_connected;
  const pose_server_stats stats = server.stats();
  EXPECT_EQ(stats.connections, k_pages);
  EXPECT_EQ(stats.refused, k_refused);

  // The log: a line per page connecting and leaving, and five about refusals (a summary of the
  // rest comes every 10 s at most, or as the server stops).
  const std::size_t lines = f.event_count();
  std::printf("%d requests, %d pages, %d refused, %d slow: normal request %.1f ms, %zu log lines\n",
              k_http_requests, k_pages, k_refused, k_slowloris, page_ms, lines);
  EXPECT_EQ(f.count("refused a WebSocket"), 5);
  EXPECT_LE(lines, static_cast<std::size_t>(k_pages + k_pages / 2 + 6));

  // Stopping with slow requests and pages still connected is prompt.
  const auto s0 = clock_type::now();
  server.stop();
  const double stop_ms = ms_since(s0);
  EXPECT_LT(stop_ms, 2000.0);
  EXPECT_EQ(server.stats().pages_connected, 0);
  EXPECT_EQ(f.count("refused " + std::to_string(k_refused - 5) + " more"), 1);
  EXPECT_EQ(f.count("page at"), k_pages);
  for (int fd : slow) ::close(fd);
  std::printf("stop %.1f ms, %.0f ms in all\n", stop_ms, ms_since(begin));
  EXPECT_LT(ms_since(begin), 20000.0);
}

}  // namespace
}  // namespace avatarmap
