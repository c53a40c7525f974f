// `live --vmc A --vmc B`: one VMC destination per person (cli/live_vmc.hpp, docs/vmc.md). The
// options are read from a command line as the tool gets it; poses tagged with their slot go to
// the slot's destination, read back by two loopback UDP sockets and decoded by the tests' own OSC
// reader (written from the OSC 1.0 specification, independent of the encoder).
#include "cli/live_vmc.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "avatarmap/stream/unity_space.hpp"
#include "stream/osc_test_reader.hpp"
#include "stream/udp_test_receiver.hpp"

namespace avatarmap::cli {
namespace {

// A command line `avatarmap live ARGS...` as read_options() takes it.
struct command_line {
  explicit command_line(std::vector<std::string> words) : words_(std::move(words)) {
    for (std::string& w : words_) argv_.push_back(w.data());
  }
  args scanner() { return args(static_cast<int>(argv_.size()), argv_.data(), 0); }

 private:
  std::vector<std::string> words_;
  std::vector<char*> argv_;
};

// A bone's /VMC/Ext/Bone/Pos arguments in one received bundle.
struct received_bone {
  bool found = false;
  glm::vec3 position{0.f};
  glm::quat rotation{1.f, 0.f, 0.f, 0.f};
};
struct received_bundle {
  received_bone arm;  // LeftUpperArm
  received_bone hips;
};

// The next datagram `rx` receives (waiting up to 2 s), decoded.
received_bundle receive_bundle(test::udp_receiver& rx) {
  received_bundle out;
  const std::vector<std::uint8_t> bytes = rx.receive();
  test::osc_packet packet;
  if (bytes.empty() || !test::read_osc_packet(bytes.data(), bytes.size(), packet)) return out;
  for (const test::osc_message& m : packet.messages) {
    if (m.address != "/VMC/Ext/Bone/Pos" || m.types != "sfffffff") continue;
    received_bone* b = m.args[0].s == "LeftUpperArm" ? &out.arm
                       : m.args[0].s == "Hips"       ? &out.hips
                                                     : nullptr;
    if (!b) continue;
    b->found = true;
    b->position = {m.args[1].f, m.args[2].f, m.args[3].f};
    b->rotation = glm::quat(m.args[7].f, m.args[4].f, m.args[5].f, m.args[6].f);
  }
  return out;
}

proxy_pose pose_with(float t, const glm::quat& arm, float hips_x) {
  proxy_pose p;
  p.t = t;
  p[bone::left_upper_arm] = arm;
  p.hips_position = glm::vec3(hips_x, 0.9f, 0.f);
  return p;
}

void expect_pose(const received_bundle& got, const proxy_pose& sent) {
  const received_bone& arm = got.arm;
  const received_bone& hips = got.hips;
  ASSERT_TRUE(arm.found) << "no bundle, or no LeftUpperArm in it";
  ASSERT_TRUE(hips.found);
  const glm::quat want = vrm_to_unity_rotation(sent[bone::left_upper_arm]);
  EXPECT_NEAR(arm.rotation.x, want.x, 1e-6f);
  EXPECT_NEAR(arm.rotation.y, want.y, 1e-6f);
  EXPECT_NEAR(arm.rotation.z, want.z, 1e-6f);
  EXPECT_NEAR(arm.rotation.w, want.w, 1e-6f);
  EXPECT_NEAR(hips.position.x, -sent.hips_position.x, 1e-6f);
}

live_output_report report_for(int person, int slot) {
  live_output_report r;
  r.person = person;
  r.slot = slot;
  return r;
}

TEST(live_vmc, each_destination_receives_its_slots_person) {
  test::udp_receiver rx0, rx1;
  ASSERT_TRUE(rx0.ok() && rx1.ok());
  command_line line({"in.mp4", "--vmc", "127.0.0.1:" + std::to_string(rx0.port()), "--fps", "30",
                     "--vmc=127.0.0.1:" + std::to_string(rx1.port())});
  args a = line.scanner();
  live_vmc vmc;
  ASSERT_EQ(vmc.read_options(a), 0);
  ASSERT_EQ(a.rest(), (std::vector<std::string>{"in.mp4", "--fps", "30"}));
  ASSERT_EQ(vmc.open(), 0);
  ASSERT_TRUE(vmc.enabled());
  ASSERT_EQ(vmc.destination_count(), 2);

  // Two people posed differently, a third without a destination, then the first two again with
  // new poses: each socket must see its own person's poses, in order, and nothing else.
  const proxy_pose a0 = pose_with(0.5f, glm::angleAxis(0.3f, glm::vec3(0, 0, 1)), 0.1f);
  const proxy_pose b0 = pose_with(0.5f, glm::angleAxis(-0.7f, glm::vec3(1, 0, 0)), -0.2f);
  const proxy_pose c0 = pose_with(0.5f, glm::angleAxis(1.1f, glm::vec3(0, 1, 0)), 0.4f);
  const proxy_pose a1 = pose_with(0.6f, glm::angleAxis(0.4f, glm::vec3(0, 0, 1)), 0.15f);
  const proxy_pose b1 = pose_with(0.6f, glm::angleAxis(-0.9f, glm::vec3(1, 0, 0)), -0.25f);
  vmc.send(a0, report_for(7, 0));
  vmc.send(b0, report_for(3, 1));
  vmc.send(c0, report_for(12, 2));
  vmc.send(a1, report_for(7, 0));
  vmc.send(b1, report_for(3, 1));

  for (const proxy_pose* want : {&a0, &a1}) expect_pose(receive_bundle(rx0), *want);
  for (const proxy_pose* want : {&b0, &b1}) expect_pose(receive_bundle(rx1), *want);

  // The summary: one line per destination, and the person without one.
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  vmc.print_summary(out);
  std::rewind(out);
  std::string text;
  char buf[512];
  while (std::fgets(buf, sizeof buf, out)) text += buf;
  std::fclose(out);
  EXPECT_NE(
      text.find("vmc: 2 bundles sent to 127.0.0.1:" + std::to_string(rx0.port()) + " for slot 0"),
      std::string::npos)
      << text;
  EXPECT_NE(
      text.find("vmc: 2 bundles sent to 127.0.0.1:" + std::to_string(rx1.port()) + " for slot 1"),
      std::string::npos)
      << text;
  EXPECT_NE(text.find("vmc: 1 poses of 1 more people not sent"), std::string::npos) << text;
}

TEST(live_vmc, one_destination_takes_slot_zero_with_its_old_summary) {
  test::udp_receiver rx;
  ASSERT_TRUE(rx.ok());
  command_line line({"--vmc", "127.0.0.1:" + std::to_string(rx.port())});
  args a = line.scanner();
  live_vmc vmc;
  ASSERT_EQ(vmc.read_options(a), 0);
  ASSERT_EQ(vmc.open(), 0);
  const proxy_pose p = pose_with(1.0f, glm::angleAxis(0.2f, glm::vec3(0, 0, 1)), 0.05f);
  vmc.send(p, live_output_report{});  // a single-person session: person -1, slot 0
  expect_pose(receive_bundle(rx), p);
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  vmc.print_summary(out);
  std::rewind(out);
  char buf[512] = {};
  ASSERT_NE(std::fgets(buf, sizeof buf, out), nullptr);
  std::fclose(out);
  const std::string first = buf;
  EXPECT_EQ(first.rfind("vmc: 1 bundles sent to 127.0.0.1:" + std::to_string(rx.port()) + " (", 0),
            0u)
      << first;
}

TEST(live_vmc, a_malformed_second_destination_is_a_usage_error) {
  command_line line({"--vmc", "127.0.0.1", "--vmc", "127.0.0.1:99999"});
  args a = line.scanner();
  live_vmc vmc;
  ASSERT_EQ(vmc.read_options(a), 0);
  EXPECT_EQ(vmc.open(), 2);
  EXPECT_FALSE(vmc.enabled());
}

}  // namespace
}  // namespace avatarmap::cli
