// Retargeting a known motion onto every shared VRM avatar (their own humanoid maps): the
// rig's world bone directions must follow the proxy's within 1 degree. Skipped without
// AVATARMAP_TEST_DATA.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "support/rig_fk.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = k_pi / 180.f;

using test::posed_positions;

class RetargetAvatars : public ::testing::TestWithParam<const char*> {};

TEST_P(RetargetAvatars, BoneDirectionsFollowTheProxy) {
  const std::string path = test::test_data_path(std::string("avatars/") + GetParam());
  if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
  raw_rig raw;
  ASSERT_TRUE(load_avatar(path, raw).ok());
  rig r;
  ASSERT_TRUE(build_rig(raw, r).ok());
  retargeter rt;
  status st = rt.build(r, r.declared_humanoid);
  ASSERT_TRUE(st.ok()) << st.message();
  rig_pose rp;
  rt.prepare(rp);
  const glm::quat basis =
      r.source == rig_source::vrm0 ? axis_angle(glm::vec3(0, 1, 0), k_pi) : identity_quat();
  std::mt19937 rng(17);
  double sum = 0, worst = 0;
  long n = 0;
  for (int i = 0; i < 200; ++i) {
    proxy_pose p = random_pose(rng);
    rt.apply(p, rp);
    std::array<glm::quat, k_bone_count> pw;
    compute_world_rotations(p, pw);
    const std::vector<glm::vec3> pos = posed_positions(r, rp);
    for (int b = 1; b < k_bone_count; ++b) {
      const bone bb = static_cast<bone>(b);
      if (bb == bone::left_foot || bb == bone::right_foot || bb == bone::left_eye ||
          bb == bone::right_eye || bb == bone::jaw)
        continue;
      // The bone's direction: its joint to the joint of its primary proxy child, when bound.
      int child = -1;
      for (int c = b + 1; c < k_bone_count && child < 0; ++c) {
        if (bone_parent(c) != b || r.declared_humanoid[c] < 0) continue;
        // The hand's direction is wrist -> middle knuckle (REFERENCE §3).
        if (bb == bone::left_hand || bb == bone::right_hand) {
          if (c == idx(bone::left_middle_proximal) || c == idx(bone::right_middle_proximal))
            child = c;
          continue;
        }
        const glm::vec3 rd = bone_rest_direction(static_cast<bone>(c));
        if (glm::dot(rd, bone_rest_direction(bb)) > 0.99f || c == idx(bone::spine) ||
            c == idx(bone::neck))
          child = c;
      }
      if (child < 0 || r.declared_humanoid[b] < 0) continue;
      const glm::vec3 rig_dir =
          basis * glm::normalize(pos[r.declared_humanoid[child]] - pos[r.declared_humanoid[b]]);
      const glm::vec3 proxy_dir = pw[b] * bone_rest_direction(bb);
      const double e =
          std::atan2(glm::length(glm::cross(rig_dir, proxy_dir)), glm::dot(rig_dir, proxy_dir)) /
          k_deg;
      if (e > 1.0 && std::getenv("AVM_DEBUG"))
        std::printf("  %s -> %s: %.2f\n", std::string(bone_name(bb)).c_str(),
                    std::string(bone_name(static_cast<bone>(child))).c_str(), e);
      sum += e;
      worst = std::max(worst, e);
      ++n;
    }
  }
  std::printf("[figures] retarget onto %s: %ld bone directions, mean %.4f max %.4f deg\n",
              GetParam(), n, sum / std::max(1L, n), worst);
  EXPECT_GT(n, 0);
  EXPECT_LT(worst, 1.0);
}

INSTANTIATE_TEST_SUITE_P(Shared, RetargetAvatars,
                         ::testing::Values("vrm0_sphere.vrm", "vrm1_debug_robot.vrm",
                                           "vrm1_spec_53bones.vrm", "vrm1_spec_expressions.vrm"));

}  // namespace
}  // namespace avatarmap
