// End to end against an independent receiver: liblo's `oscdump` (Debian liblo-tools) listens on
// a loopback port while a vmc_stream sends bundles to it; its text output is parsed and checked
// (one bundle per frame, every bone by name with the values sent, blend values, Apply, OK, T).
// Skipped with a message when oscdump is not installed.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "avatarmap/stream/unity_space.hpp"
#include "avatarmap/stream/vmc_names.hpp"
#include "avatarmap/stream/vmc_stream.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

std::string find_oscdump() {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/oscdump";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return {};
}

// A loopback UDP port that was free a moment ago.
int free_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t n = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &n);
  ::close(fd);
  return ntohs(a.sin_port);
}

std::string read_all(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// oscdump as a child process writing to a file; stopped (SIGTERM to its pid) on destruction.
class oscdump_process {
 public:
  oscdump_process(const std::string& exe, int port, const std::string& out_path)
      : out_path_(out_path) {
    pid_ = ::fork();
    if (pid_ == 0) {
      if (!std::freopen(out_path.c_str(), "w", stdout)) std::_Exit(127);
      const std::string p = std::to_string(port);
      ::execl(exe.c_str(), "oscdump", "-L", p.c_str(), static_cast<char*>(nullptr));
      std::_Exit(127);
    }
  }
  ~oscdump_process() { stop(); }
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    int st = 0;
    ::waitpid(pid_, &st, 0);
    pid_ = -1;
  }
  bool started() const { return pid_ > 0; }
  // Sends `address` (a message without arguments) until it shows in the output; false after 10 s.
  bool wait_for(udp_sender& tx, const std::string& address) {
    std::uint8_t msg[64] = {};
    osc_writer w(msg, sizeof msg);
    w.begin_message(address, "");
    w.end_message();
    for (int i = 0; i < 500; ++i) {
      tx.send(w.data(), w.size());
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      if (read_all(out_path_).find(address) != std::string::npos) return true;
    }
    return false;
  }

 private:
  std::string out_path_;
  pid_t pid_ = -1;
};

struct dumped_message {
  std::string stamp, address, types;
  std::vector<std::string> args;  // strings without their quotes
};

std::vector<dumped_message> parse_dump(const std::string& text) {
  std::vector<dumped_message> out;
  std::stringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::stringstream ls(line);
    dumped_message m;
    if (!(ls >> m.stamp >> m.address)) continue;
    ls >> m.types;
    std::string a;
    while (ls >> a) {
      if (a.size() >= 2 && a.front() == '"' && a.back() == '"') a = a.substr(1, a.size() - 2);
      m.args.push_back(a);
    }
    out.push_back(std::move(m));
  }
  return out;
}

TEST(vmc_oscdump, bundles_arrive_at_an_independent_receiver) {
  const std::string exe = find_oscdump();
  if (exe.empty())
    GTEST_SKIP() << "oscdump not found (Debian package liblo-tools; scripts/setup.sh installs "
                    "it): the end-to-end VMC test needs an independent OSC receiver";
  test::temp_dir dir("vmc_oscdump");
  const std::string dump_path = (dir.path() / "dump.txt").string();
  const int port = free_port();
  oscdump_process rx(exe, port, dump_path);
  ASSERT_TRUE(rx.started());
  vmc_stream stream;
  const proxy_skeleton ps = make_proxy_skeleton();
  ASSERT_TRUE(stream.open({"127.0.0.1", port}, make_vmc_skeleton(ps)).ok());
  udp_sender probe;
  ASSERT_TRUE(probe.open({"127.0.0.1", port}).ok());
  ASSERT_TRUE(rx.wait_for(probe, "/ready")) << "oscdump did not start: " << read_all(dump_path);

  const int frames = 20;
  proxy_pose pose;
  for (int i = 0; i < frames; ++i) {
    const float angle = 0.05f * static_cast<float>(i);
    pose[bone::left_upper_arm] = glm::angleAxis(angle, glm::vec3(0, 0, 1));
    pose.hips_position = glm::vec3(0.01f * static_cast<float>(i), 0.9f, 0.f);
    pose[expression::aa] = 0.05f * static_cast<float>(i);
    ASSERT_TRUE(stream.send(pose, 0.25f * static_cast<float>(i)));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));  // oscdump prints slowly
  }
  ASSERT_TRUE(rx.wait_for(probe, "/done"));
  rx.stop();

  // Group by oscdump's time stamp: the messages of one bundle share it, separate datagrams
  // do not.
  std::vector<std::vector<dumped_message>> bundles;
  std::string last;
  for (auto& m : parse_dump(read_all(dump_path))) {
    if (m.address == "/ready" || m.address == "/done") continue;
    if (bundles.empty() || m.stamp != last) bundles.emplace_back();
    last = m.stamp;
    bundles.back().push_back(std::move(m));
  }
  ASSERT_EQ(static_cast<int>(bundles.size()), frames);
  for (int i = 0; i < frames; ++i) {
    const auto& b = bundles[static_cast<size_t>(i)];
    std::map<std::string, const dumped_message*> bones;
    int blends = 0, apply = 0, ok = 0, t = 0, root = 0;
    for (const auto& m : b) {
      if (m.address == "/VMC/Ext/Bone/Pos") {
        ASSERT_EQ(m.types, "sfffffff");
        ASSERT_EQ(m.args.size(), 8u);
        bones[m.args[0]] = &m;
      }
      blends += m.address == "/VMC/Ext/Blend/Val";
      apply += m.address == "/VMC/Ext/Blend/Apply";
      root += m.address == "/VMC/Ext/Root/Pos";
      if (m.address == "/VMC/Ext/OK") {
        ++ok;
        EXPECT_EQ(m.args.at(0), "1");
      }
      if (m.address == "/VMC/Ext/T") {
        ++t;
        EXPECT_NEAR(std::stod(m.args.at(0)), 0.25 * i, 1e-6);
      }
    }
    EXPECT_EQ(root, 1);
    EXPECT_EQ(bones.size(), 55u);
    EXPECT_EQ(blends, 16);  // the VRM 0.x presets (default set)
    EXPECT_EQ(apply, 1);
    EXPECT_EQ(ok, 1);
    EXPECT_EQ(t, 1);
    EXPECT_EQ(b.back().address, "/VMC/Ext/T");
    for (int k = 0; k < k_bone_count; ++k)
      EXPECT_EQ(bones.count(std::string(unity_bone_name(static_cast<bone>(k)))), 1u);
    // Values as oscdump prints them (6 decimals): the arm's rotation in Unity space and the
    // hips' position.
    const glm::quat want =
        vrm_to_unity_rotation(glm::angleAxis(0.05f * static_cast<float>(i), glm::vec3(0, 0, 1)));
    const dumped_message& arm = *bones.at("LeftUpperArm");
    EXPECT_NEAR(std::stod(arm.args[4]), want.x, 2e-6);
    EXPECT_NEAR(std::stod(arm.args[6]), want.z, 2e-6);
    EXPECT_NEAR(std::stod(arm.args[7]), want.w, 2e-6);
    EXPECT_NEAR(std::stod(arm.args[1]), -ps.offsets[idx(bone::left_upper_arm)].x, 2e-6);
    const dumped_message& hips = *bones.at("Hips");
    EXPECT_NEAR(std::stod(hips.args[1]), -0.01 * i, 2e-6);
    EXPECT_NEAR(std::stod(hips.args[2]), 0.9, 2e-6);
  }
}

// --vmc-blendshapes both, as a Perfect Sync receiver gets it: the VRM 0.x presets and ARKit's
// 52 by Apple's names with their values, and the eye bones with the gaze, in one datagram each.
TEST(vmc_oscdump, perfect_sync_names_and_eye_bones_arrive) {
  const std::string exe = find_oscdump();
  if (exe.empty()) GTEST_SKIP() << "oscdump not found (Debian package liblo-tools)";
  test::temp_dir dir("vmc_oscdump_arkit");
  const std::string dump_path = (dir.path() / "dump.txt").string();
  const int port = free_port();
  oscdump_process rx(exe, port, dump_path);
  ASSERT_TRUE(rx.started());
  vmc_stream stream;
  ASSERT_TRUE(stream
                  .open({"127.0.0.1", port}, make_vmc_skeleton(make_proxy_skeleton()), {},
                        vmc_blend_set::both)
                  .ok());
  EXPECT_EQ(stream.blend_messages(), 68);
  udp_sender probe;
  ASSERT_TRUE(probe.open({"127.0.0.1", port}).ok());
  ASSERT_TRUE(rx.wait_for(probe, "/ready")) << "oscdump did not start: " << read_all(dump_path);

  const int frames = 5;
  proxy_pose pose;
  for (int i = 0; i < frames; ++i) {
    pose[blendshape::jaw_open] = 0.125f * static_cast<float>(i);
    pose[blendshape::eye_blink_left] = 0.25f;
    pose[blendshape::mouth_smile_right] = 0.5f;
    pose[expression::happy] = 0.375f;
    pose[bone::left_eye] = glm::angleAxis(0.1f * static_cast<float>(i), glm::vec3(0, 1, 0));
    ASSERT_TRUE(stream.send(pose, 0.5f * static_cast<float>(i)));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(rx.wait_for(probe, "/done"));
  rx.stop();

  std::vector<std::vector<dumped_message>> bundles;
  std::string last;
  for (auto& m : parse_dump(read_all(dump_path))) {
    if (m.address == "/ready" || m.address == "/done") continue;
    if (bundles.empty() || m.stamp != last) bundles.emplace_back();
    last = m.stamp;
    bundles.back().push_back(std::move(m));
  }
  ASSERT_EQ(static_cast<int>(bundles.size()), frames);
  for (int i = 0; i < frames; ++i) {
    std::map<std::string, double> blends;
    const dumped_message* eye = nullptr;
    for (const auto& m : bundles[static_cast<size_t>(i)]) {
      if (m.address == "/VMC/Ext/Blend/Val") {
        ASSERT_EQ(m.types, "sf");
        blends[m.args.at(0)] = std::stod(m.args.at(1));
      }
      if (m.address == "/VMC/Ext/Bone/Pos" && m.args.at(0) == "LeftEye") eye = &m;
    }
    EXPECT_EQ(blends.size(), 68u);
    EXPECT_NEAR(blends.at("jawOpen"), 0.125 * i, 1e-6);
    EXPECT_NEAR(blends.at("eyeBlinkLeft"), 0.25, 1e-6);
    EXPECT_NEAR(blends.at("mouthSmileRight"), 0.5, 1e-6);
    EXPECT_NEAR(blends.at("tongueOut"), 0.0, 1e-6);
    EXPECT_NEAR(blends.at("Joy"), 0.375, 1e-6);
    EXPECT_NEAR(blends.at("A"), 0.0, 1e-6);
    ASSERT_NE(eye, nullptr);
    // A turn about VRM's +Y arrives about Unity's Y reversed: {0, -sin(a/2), 0, cos(a/2)}.
    const double a = 0.1 * i;
    EXPECT_NEAR(std::stod(eye->args.at(5)), -std::sin(a / 2), 2e-6);
    EXPECT_NEAR(std::stod(eye->args.at(7)), std::cos(a / 2), 2e-6);
  }
}

}  // namespace
}  // namespace avatarmap
