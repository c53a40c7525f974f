// pose_server with several people (include/avatarmap/stream/pose_server.hpp, docs/viewer.md):
// each slot keeps its own newest pose and every page gets each slot's, tagged with the person's
// id and slot as the last keys of the line. Messages are read through a raw WebSocket and read
// back twice: by nlohmann::json (an independent parser: the keys and their values) and by the
// project's pose reader (the pose itself; it skips keys it does not know).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/stream/pose_server.hpp"
#include "avatarmap/synth/random_pose.hpp"
// The counter only: stream_allocation_test.cpp defines the counting operator new.
#define AVATARMAP_COUNTING_NEW_COUNTER_ONLY
#include "http_test_client.hpp"
#include "support/counting_new.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

using test::k_protocol_header;
using test::ws_client;

// The page folder and small stand-ins for the npm modules (the server only serves them).
struct people_fixture {
  test::temp_dir dir{"pose_server_people"};
  pose_server_options options() const {
    const std::string modules = dir.file("modules");
    for (const char* d : {"/three/build", "/three-vrm/lib", "/three-vrm-animation/lib"})
      std::filesystem::create_directories(modules + d);
    std::ofstream(modules + "/three/build/three.module.js") << "export const three = 1;\n";
    std::ofstream(modules + "/three-vrm/lib/three-vrm.module.js") << "export const vrm = 1;\n";
    std::ofstream(modules + "/three-vrm-animation/lib/three-vrm-animation.module.js") << "x\n";
    const char* source = std::getenv("AVATARMAP_SOURCE_DIR");
    pose_server_options o;
    o.port = 0;
    o.page_dir = std::string(source ? source : ".") + "/viewer";
    o.modules_dir = modules;
    return o;
  }
};

proxy_pose pose_at(double t, unsigned seed) {
  std::mt19937 rng(seed);
  proxy_pose p = random_pose(rng);
  p.t = t;
  p.hips_position = {0.1f * static_cast<float>(seed), 0.9f, -0.2f};
  return p;
}

double message_t(const std::string& m) { return std::atof(m.c_str() + m.find("\"t\":") + 4); }

// One message as both readers see it.
struct read_back {
  nlohmann::json json;
  proxy_pose pose;
};
::testing::AssertionResult read_message(ws_client& c, read_back& out) {
  std::string m;
  if (!c.read(m)) return ::testing::AssertionFailure() << "no message";
  out.json = nlohmann::json::parse(m, nullptr, false);
  if (out.json.is_discarded()) return ::testing::AssertionFailure() << "not JSON: " << m;
  pose_reader reader;
  if (!reader.open_memory(m.data(), m.size()).ok() || reader.next(out.pose) != read_result::frame)
    return ::testing::AssertionFailure() << "the pose reader refuses it: " << reader.error();
  return ::testing::AssertionSuccess();
}

void expect_same_pose(const proxy_pose& got, const proxy_pose& sent) {
  EXPECT_EQ(got.t, sent.t);
  EXPECT_EQ(got.hips_position, sent.hips_position);
  for (int i = 0; i < k_bone_count; ++i)
    EXPECT_EQ(got.rotations[i], sent.rotations[i]) << bone_name(static_cast<bone>(i));
}

TEST(pose_server_people, every_slot_reaches_a_page_tagged_with_its_person) {
  people_fixture f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  const proxy_pose a = pose_at(0.5, 1), b = pose_at(0.5, 2);
  server.publish(a, 7, 0);  // before the page connects: it gets both at once
  server.publish(b, 3, 1);
  ws_client page;
  ASSERT_TRUE(page.open(server.port(), k_protocol_header));
  read_back m;
  ASSERT_TRUE(read_message(page, m));  // the longest waiting first
  EXPECT_EQ(m.json.at("person"), 7);
  EXPECT_EQ(m.json.at("slot"), 0);
  expect_same_pose(m.pose, a);
  ASSERT_TRUE(read_message(page, m));
  EXPECT_EQ(m.json.at("person"), 3);
  EXPECT_EQ(m.json.at("slot"), 1);
  expect_same_pose(m.pose, b);

  // A new pose in one slot: only that slot's is sent (the other's was sent already); the keys
  // are the line's last, after every key of the pose.
  const proxy_pose b2 = pose_at(0.75, 4);
  server.publish(b2, 3, 1);
  std::string text;
  ASSERT_TRUE(page.read(text));
  const std::string keys = ",\"person\":3,\"slot\":1}";
  ASSERT_GT(text.size(), keys.size());
  EXPECT_EQ(text.substr(text.size() - keys.size()), keys) << text;
  EXPECT_EQ(message_t(text), 0.75);
}

TEST(pose_server_people, one_person_sends_the_plain_line_and_bad_slots_are_ignored) {
  people_fixture f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  ws_client page;
  ASSERT_TRUE(page.open(server.port(), k_protocol_header));
  server.publish(pose_at(0.1, 5), 2, k_pose_server_slots);  // out of range: never sent
  server.publish(pose_at(0.2, 6), 2, -1);
  const proxy_pose one = pose_at(0.3, 7);
  server.publish(one);  // one person: person -1, slot 0
  read_back m;
  ASSERT_TRUE(read_message(page, m));
  EXPECT_FALSE(m.json.contains("person"));
  EXPECT_FALSE(m.json.contains("slot"));
  expect_same_pose(m.pose, one);
  EXPECT_EQ(server.stats().published, 3);
}

TEST(pose_server_people, a_slow_page_gets_each_slots_newest_pose) {
  people_fixture f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  ws_client page;
  ASSERT_TRUE(page.open(server.port(), k_protocol_header, 4096));
  constexpr int k_poses = 20000;  // ~100 MB: far more than the socket buffers hold
  for (int i = 0; i < k_poses; ++i) server.publish(pose_at(i, 3), 10 + i % 3, i % 3);
  // The last pose of each slot, published after the page fell behind: each must arrive.
  for (int s = 0; s < 3; ++s) server.publish(pose_at(1e6 + s, 3), 10 + s, s);
  bool newest[3] = {false, false, false};
  int got = 0;
  read_back m;
  while (!(newest[0] && newest[1] && newest[2]) && read_message(page, m)) {
    ++got;
    const int slot = m.json.at("slot");
    ASSERT_EQ(m.json.at("person"), 10 + slot);
    if (m.pose.t == 1e6 + slot) newest[slot] = true;
  }
  EXPECT_TRUE(newest[0] && newest[1] && newest[2]) << "a slot's newest pose never arrived";
  EXPECT_LT(got, k_poses / 10) << "the slow page was sent a queue of old poses";
}

TEST(pose_server_people, a_person_gone_is_told_to_open_pages_and_never_shown_to_new_ones) {
  people_fixture f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  ws_client page;
  ASSERT_TRUE(page.open(server.port(), k_protocol_header));
  server.publish(pose_at(0.5, 1), 7, 0);
  server.publish(pose_at(0.5, 2), 3, 1);
  read_back m;
  ASSERT_TRUE(read_message(page, m));
  ASSERT_TRUE(read_message(page, m));
  server.clear(3, 1);
  server.clear(3, k_pose_server_slots);  // out of range: ignored
  std::string text;
  ASSERT_TRUE(page.read(text));
  const nlohmann::json gone = nlohmann::json::parse(text, nullptr, false);
  ASSERT_FALSE(gone.is_discarded()) << text;
  EXPECT_EQ(gone, nlohmann::json::parse(R"({"person":3,"slot":1,"gone":true})"));

  // A page that connects now gets slot 0's pose and slot 1's notice, not person 3's old pose.
  ws_client later;
  ASSERT_TRUE(later.open(server.port(), k_protocol_header));
  std::string first, second;
  ASSERT_TRUE(later.read(first));
  ASSERT_TRUE(later.read(second));
  EXPECT_EQ(nlohmann::json::parse(first).at("person"), 7);
  EXPECT_EQ(second, text);

  // The slot's next person is sent as usual.
  server.publish(pose_at(0.9, 4), 9, 1);
  ASSERT_TRUE(read_message(page, m));
  EXPECT_EQ(m.json.at("person"), 9);
  EXPECT_EQ(m.pose.t, 0.9);
}

TEST(pose_server_people, publish_to_a_slot_allocates_nothing) {
  people_fixture f;
  pose_server server;
  ASSERT_TRUE(server.start(f.options()).ok());
  ws_client page;
  ASSERT_TRUE(page.open(server.port(), k_protocol_header));
  const proxy_pose p = pose_at(1, 5);
  server.publish(p, 4, 2);
  std::string m;
  ASSERT_TRUE(page.read(m));
  const long before = g_allocations.load();
  for (int i = 0; i < 200; ++i) server.publish(p, 100000 + i, i % k_pose_server_slots);
  EXPECT_EQ(g_allocations.load() - before, 0);
}

}  // namespace
}  // namespace avatarmap
