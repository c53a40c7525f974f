// pose_file_player (include/avatarmap/stream/pose_file_player.hpp): bad files refused with the
// reader's message; poses handed over in the file's order, with the file's t, looping.
#include "avatarmap/stream/pose_file_player.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

TEST(pose_file_player, refuses_missing_empty_and_malformed_files) {
  test::temp_dir dir("player");
  pose_file_player p;
  EXPECT_FALSE(p.open(dir.file("none.pose.jsonl")).ok());
  std::ofstream(dir.file("empty.pose.jsonl")) << "{\"format\":\"avatarmap.pose\",\"version\":1}\n";
  const status empty = p.open(dir.file("empty.pose.jsonl"));
  EXPECT_NE(empty.message().find("holds no pose"), std::string::npos) << empty.message();
  std::ofstream(dir.file("bad.pose.jsonl"))
      << "{\"t\":0}\n{\"t\":1,\"bones\":{\"elbow\":[0,0,0,1]}}\n";
  const status bad = p.open(dir.file("bad.pose.jsonl"));
  EXPECT_NE(bad.message().find(":2:"), std::string::npos) << bad.message();
  EXPECT_NE(bad.message().find("elbow"), std::string::npos) << bad.message();
}

TEST(pose_file_player, plays_the_file_in_order_and_loops) {
  test::temp_dir dir("player");
  {
    std::ofstream f(dir.file("p.pose.jsonl"));
    f << "{\"format\":\"avatarmap.pose\",\"version\":1,\"fps\":100}\n";
    for (int i = 0; i < 5; ++i) f << "{\"t\":" << 2 + i * 0.01 << "}\n";
  }
  pose_file_player p;
  ASSERT_TRUE(p.open(dir.file("p.pose.jsonl")).ok());
  EXPECT_EQ(p.frames(), 5);
  EXPECT_NEAR(p.duration(), 0.04, 1e-9);
  std::mutex m;
  std::vector<double> ts;
  p.start([&](const proxy_pose& pose) {
    std::lock_guard<std::mutex> lock(m);
    ts.push_back(pose.t);
  });
  for (int i = 0; i < 500; ++i) {
    {
      std::lock_guard<std::mutex> lock(m);
      if (ts.size() >= 12) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  p.stop();
  ASSERT_GE(ts.size(), 12u);
  for (std::size_t i = 0; i < 12; ++i) EXPECT_NEAR(ts[i], 2 + (i % 5) * 0.01, 1e-9) << i;
  EXPECT_TRUE(p.error().ok());
}

}  // namespace
}  // namespace avatarmap
