// A BVH as convert_file_job's motion input (include/avatarmap/jobs/convert_file.hpp,
// rig/bvh_rig.hpp): the CMU walk 131_02 read on its own skeleton, then played on the built-in
// avatar walks like the mocap (on the floor, facing and stepping forward); its pose file holds
// the frames read_bvh_motion reads, at the file's 120 fps; a .bvh skeleton is refused as the
// avatar of a .glb.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "avatarmap/avatar/builtin_avatar.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/jobs/convert_file.hpp"
#include "avatarmap/rig/bvh_rig.hpp"
#include "support/rig_fk.hpp"
#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

TEST(ConvertBvh, CmuWalkPlaysOnTheBuiltinAvatar) {
  const std::string walk = test::test_data_path("motion/cmu-bvh/131_02.bvh");
  if (walk.empty()) GTEST_SKIP() << test::k_no_test_data;
  test::temp_dir dir("convert_bvh");
  // The pose file: every frame read_bvh_motion reads, at their times, with the file's rate.
  convert_file_job j;
  j.input = walk;
  j.output = dir.file("truth.pose.jsonl");
  convert_file_summary s;
  ASSERT_TRUE(j.run(s).ok());
  EXPECT_EQ(s.input->kind, motion_input::bvh);
  EXPECT_EQ(s.frames_read, 1247u);
  EXPECT_DOUBLE_EQ(s.source_fps, 120.0);
  std::vector<proxy_pose> direct;
  ASSERT_TRUE(read_bvh_motion(walk, {}, direct).ok());
  pose_reader reader;
  ASSERT_TRUE(reader.open(j.output).ok());
  EXPECT_DOUBLE_EQ(reader.header().fps, 120.0);
  proxy_pose p;
  std::size_t n = 0;
  while (reader.next(p) == read_result::frame) {
    ASSERT_LT(n, direct.size());
    EXPECT_NEAR(p.t, direct[n].t, 1e-9);
    EXPECT_LT(glm::length(p.hips_position - direct[n].hips_position), 1e-6f);
    ++n;
  }
  EXPECT_EQ(n, direct.size());

  // On the built-in avatar (.glb): its feet on the floor, facing and stepping forward.
  const std::string avatar = dir.file("builtin.vrm");
  ASSERT_TRUE(write_builtin_avatar(avatar).ok());
  std::vector<rig_pose> rig_poses;
  j.output = dir.file("walk.glb");
  j.avatar = avatar;
  j.out_rig_poses = &rig_poses;
  ASSERT_TRUE(j.run(s).ok());
  ASSERT_NE(s.avatar, nullptr);
  ASSERT_GT(rig_poses.size(), 300u);  // 10.4 s at 30 fps
  const rig& r = s.avatar->rig;
  const bone_binding& b = s.avatar->binding;
  const int lf = b[idx(bone::left_foot)], rf = b[idx(bone::right_foot)];
  const int lt = b[idx(bone::left_toes)], rt = b[idx(bone::right_toes)];
  const int hips = b[idx(bone::hips)], lu = b[idx(bone::left_upper_leg)];
  std::vector<float> lowest;
  int left_ahead = 0;
  for (const rig_pose& rp : rig_poses) {
    const std::vector<glm::vec3> at = test::posed_positions(r, rp);
    lowest.push_back(std::min({at[lf].y, at[rf].y, at[lt].y, at[rt].y}));
    left_ahead += at[lf].z > at[rf].z;
  }
  std::sort(lowest.begin(), lowest.end());
  std::printf(
      "built-in avatar: lowest foot/toe joint 5%% %.3f median %.3f 95%% %.3f m; left foot "
      "ahead %d of %zu frames\n",
      lowest[lowest.size() / 20], lowest[lowest.size() / 2], lowest[lowest.size() * 19 / 20],
      left_ahead, rig_poses.size());
  // The lowest foot or toe joint stays near the floor (the avatar's rest feet height, ~0..10
  // cm: the hips are scaled by the avatar's leg length over the performer's).
  const float rest_floor =
      std::min({glm::vec3(r.rest_world[lt][3]).y, glm::vec3(r.rest_world[rt][3]).y});
  EXPECT_GT(lowest[lowest.size() / 20], rest_floor - 0.06f);
  EXPECT_LT(lowest[lowest.size() * 19 / 20], rest_floor + 0.12f);
  // Steps: each foot ahead of the other for a fifth of the clip at least.
  EXPECT_GT(left_ahead, static_cast<int>(rig_poses.size() / 5));
  EXPECT_LT(left_ahead, static_cast<int>(rig_poses.size() * 4 / 5));
  // Travels forward (+Z) and faces +Z: the left hip to the avatar's left (+X).
  const std::vector<glm::vec3> first = test::posed_positions(r, rig_poses.front());
  const std::vector<glm::vec3> last = test::posed_positions(r, rig_poses.back());
  EXPECT_GT(last[hips].z - first[hips].z, 1.f);
  const std::vector<glm::vec3> mid = test::posed_positions(r, rig_poses[rig_poses.size() / 2]);
  EXPECT_GT(mid[lu].x - mid[hips].x, 0.03f);

  // A .bvh skeleton has no mesh: refused as the avatar of a .glb before anything is read.
  j.avatar = walk;
  const status st = j.validate();
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::invalid_argument);
  EXPECT_NE(st.message().find("BVH skeleton"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace avatarmap
