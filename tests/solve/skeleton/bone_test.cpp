// The proxy skeleton's tables (avatarmap/skeleton/bone.hpp, expression.hpp) against
// REFERENCE §3 and §5: topology, names, mirroring and rest directions.
#include "avatarmap/skeleton/bone.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <set>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/expression.hpp"

namespace avatarmap {
namespace {

std::string swap_side(std::string_view n) {
  std::string s(n);
  if (s.rfind("left", 0) == 0) return "right" + s.substr(4);
  if (s.rfind("right", 0) == 0) return "left" + s.substr(5);
  return s;
}

TEST(bone, parents_come_before_children_and_hips_is_the_only_root) {
  EXPECT_EQ(bone_parent(idx(bone::hips)), k_no_parent);
  for (int b = 1; b < k_bone_count; ++b) {
    EXPECT_NE(bone_parent(b), k_no_parent) << bone_name(bone(b));
    EXPECT_GE(bone_parent(b), 0);
    EXPECT_LT(bone_parent(b), b) << bone_name(bone(b));
  }
  // Spot checks of the VRM hierarchy.
  EXPECT_EQ(bone_parent(idx(bone::left_upper_arm)), idx(bone::left_shoulder));
  EXPECT_EQ(bone_parent(idx(bone::left_shoulder)), idx(bone::upper_chest));
  EXPECT_EQ(bone_parent(idx(bone::right_upper_leg)), idx(bone::hips));
  EXPECT_EQ(bone_parent(idx(bone::left_thumb_metacarpal)), idx(bone::left_hand));
  EXPECT_EQ(bone_parent(idx(bone::right_little_distal)), idx(bone::right_little_intermediate));
  EXPECT_EQ(bone_parent(idx(bone::jaw)), idx(bone::head));
}

TEST(bone, names_round_trip_and_are_unique_vrm_names) {
  std::set<std::string_view> seen;
  for (int b = 0; b < k_bone_count; ++b) {
    const std::string_view n = bone_name(bone(b));
    EXPECT_TRUE(seen.insert(n).second) << n;
    EXPECT_EQ(bone_from_name(n), bone(b));
  }
  EXPECT_EQ(bone_name(bone::upper_chest), "upperChest");
  EXPECT_EQ(bone_name(bone::left_thumb_metacarpal), "leftThumbMetacarpal");
  EXPECT_EQ(bone_name(bone::right_little_distal), "rightLittleDistal");
  EXPECT_FALSE(bone_from_name("Hips").has_value());                   // case-sensitive
  EXPECT_FALSE(bone_from_name("leftThumbIntermediate").has_value());  // VRM 0.x only
  EXPECT_FALSE(bone_from_name("").has_value());
}

TEST(bone, mirror_is_an_involution_swapping_sides) {
  int left = 0, right = 0;
  for (int i = 0; i < k_bone_count; ++i) {
    const bone b = bone(i);
    const bone m = mirror_bone(b);
    EXPECT_EQ(mirror_bone(m), b) << bone_name(b);
    EXPECT_EQ(bone_name(m), swap_side(bone_name(b))) << bone_name(b);
    EXPECT_EQ(is_left(m), is_right(b));
    EXPECT_FALSE(is_left(b) && is_right(b));
    left += is_left(b);
    right += is_right(b);
    // Mirrored bones have mirrored parents.
    if (bone_parent(i) != k_no_parent) {
      EXPECT_EQ(idx(mirror_bone(bone(bone_parent(i)))), bone_parent(idx(m))) << bone_name(b);
    }
    // And mirrored rest directions.
    EXPECT_LT(glm::length(bone_rest_direction(m) - mirror_x(bone_rest_direction(b))), 1e-6f);
  }
  EXPECT_EQ(left, right);
  EXPECT_EQ(left, 4 + 4 + 1 + 15);  // leg 4, shoulder..hand 4, eye 1, fingers 15
}

TEST(bone, rest_directions_are_unit_and_match_reference) {
  const float r2 = std::sqrt(0.5f);
  const glm::vec3 up(0.f, 1.f, 0.f), down(0.f, -1.f, 0.f), fwd(0.f, 0.f, 1.f);
  const glm::vec3 foot = glm::normalize(glm::vec3(0.f, -1.f, 2.f));
  auto expect_dir = [](bone b, glm::vec3 d) {
    EXPECT_LT(glm::length(bone_rest_direction(b) - d), 1e-6f) << bone_name(b);
  };
  for (int i = 0; i < k_bone_count; ++i)
    EXPECT_NEAR(glm::length(bone_rest_direction(bone(i))), 1.f, 1e-6f) << bone_name(bone(i));
  for (bone b : {bone::hips, bone::spine, bone::chest, bone::upper_chest, bone::neck, bone::head})
    expect_dir(b, up);
  for (bone b : {bone::left_eye, bone::right_eye, bone::jaw}) expect_dir(b, fwd);
  for (bone b :
       {bone::left_upper_leg, bone::left_lower_leg, bone::right_upper_leg, bone::right_lower_leg})
    expect_dir(b, down);
  for (bone b : {bone::left_foot, bone::left_toes, bone::right_foot, bone::right_toes})
    expect_dir(b, foot);
  EXPECT_NEAR(std::atan2(-foot.y, foot.z) * 180.f / k_pi, 26.565f, 1e-3f);  // 26.6 deg down
  for (bone b : {bone::left_shoulder, bone::left_upper_arm, bone::left_lower_arm, bone::left_hand,
                 bone::left_index_proximal, bone::left_middle_distal, bone::left_little_distal})
    expect_dir(b, {1.f, 0.f, 0.f});
  for (bone b : {bone::right_shoulder, bone::right_upper_arm, bone::right_lower_arm,
                 bone::right_hand, bone::right_ring_intermediate})
    expect_dir(b, {-1.f, 0.f, 0.f});
  for (bone b : {bone::left_thumb_metacarpal, bone::left_thumb_proximal, bone::left_thumb_distal})
    expect_dir(b, {r2, 0.f, r2});
  for (bone b :
       {bone::right_thumb_metacarpal, bone::right_thumb_proximal, bone::right_thumb_distal})
    expect_dir(b, {-r2, 0.f, r2});
}

TEST(expression, names_round_trip) {
  std::set<std::string_view> seen;
  for (int e = 0; e < k_expression_count; ++e) {
    const std::string_view n = expression_name(expression(e));
    EXPECT_TRUE(seen.insert(n).second) << n;
    EXPECT_EQ(expression_from_name(n), expression(e));
  }
  EXPECT_EQ(expression_name(expression::blink_left), "blinkLeft");
  EXPECT_EQ(expression_name(expression::aa), "aa");
  EXPECT_EQ(expression_name(expression::look_right), "lookRight");
  EXPECT_FALSE(expression_from_name("blink_l").has_value());  // VRM 0.x spelling
  EXPECT_FALSE(expression_from_name("Blink").has_value());
}

}  // namespace
}  // namespace avatarmap
