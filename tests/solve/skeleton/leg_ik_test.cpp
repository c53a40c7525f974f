// Two-bone leg IK against answers worked by hand (a 3-4-5 triangle, a straight leg, the hip
// drop of a right triangle) and against its own invariants on random targets.
#include "avatarmap/skeleton/leg_ik.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace avatarmap {
namespace {

constexpr float k_tenth_mm = 1e-4f;  // metres

void expect_near(const glm::vec3& a, const glm::vec3& b, float tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(LegIk, ThreeFourFiveTriangle) {
  // Hip at the origin, bones 3 and 4, target 5 away along +X, pole up: the knee is the right
  // angle of the 3-4-5 triangle, 1.8 along the line and 2.4 up (3^2 = 1.8^2 + 2.4^2).
  const two_bone_ik_result r = solve_two_bone_ik({0, 0, 0}, 3.f, 4.f, {5, 0, 0}, {1, 10, 0});
  EXPECT_TRUE(r.reached);
  expect_near(r.knee, {1.8f, 2.4f, 0.f}, 1e-5f);
  expect_near(r.ankle, {5.f, 0.f, 0.f}, 1e-5f);
}

TEST(LegIk, ReachableTargetHitWithLengthsKeptAndKneeInPolePlane) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  int n = 0;
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 hip(u(rng), 1.f + u(rng), u(rng));
    const float upper = 0.3f + 0.2f * std::abs(u(rng));
    const float lower = 0.3f + 0.2f * std::abs(u(rng));
    const glm::vec3 t = hip + glm::vec3(u(rng), u(rng), u(rng)) * 0.6f;
    const float d = glm::length(t - hip);
    if (d > 0.999f * (upper + lower) || d < std::abs(upper - lower) + 1e-3f) continue;
    const glm::vec3 pole = hip + glm::vec3(u(rng), u(rng), u(rng));
    const glm::vec3 normal = glm::cross(t - hip, pole - hip);
    if (glm::length(normal) < 1e-3f) continue;
    const two_bone_ik_result r = solve_two_bone_ik(hip, upper, lower, t, pole);
    ++n;
    ASSERT_TRUE(r.reached);
    EXPECT_LT(glm::length(r.ankle - t), k_tenth_mm);
    EXPECT_NEAR(glm::length(r.knee - hip), upper, 1e-5f);
    EXPECT_NEAR(glm::length(r.ankle - r.knee), lower, 1e-5f);
    // In the plane through hip, target and pole, on the pole's side of the hip-target line.
    EXPECT_NEAR(glm::dot(r.knee - hip, glm::normalize(normal)), 0.f, 1e-5f);
    const glm::vec3 dir = glm::normalize(t - hip);
    const glm::vec3 pole_side = (pole - hip) - dir * glm::dot(pole - hip, dir);
    EXPECT_GT(glm::dot(r.knee - hip, pole_side), 0.f);
  }
  EXPECT_GT(n, 500);
}

TEST(LegIk, UnreachableTargetGivesStraightLegPointingAtIt) {
  const two_bone_ik_result r = solve_two_bone_ik({0, 1, 0}, 0.4f, 0.5f, {0, -2, 0}, {0, 0.5f, 1});
  EXPECT_FALSE(r.reached);
  expect_near(r.knee, {0.f, 0.6f, 0.f}, 1e-6f);
  expect_near(r.ankle, {0.f, 0.1f, 0.f}, 1e-6f);
}

TEST(LegIk, StraightPoleUsesFallbackBend) {
  // The pole on the hip-target line: the knee bends towards the fallback (+Z, forward).
  const two_bone_ik_result r =
      solve_two_bone_ik({0, 1, 0}, 0.5f, 0.5f, {0, 0.2f, 0}, {0, 0.5f, 0}, {0, 0, 1});
  EXPECT_TRUE(r.reached);
  // 0.4 along the line (half of 0.8), sqrt(0.25 - 0.16) = 0.3 forward.
  expect_near(r.knee, {0.f, 0.6f, 0.3f}, 1e-5f);
  expect_near(r.ankle, {0.f, 0.2f, 0.f}, 1e-5f);
}

TEST(LegIk, NonFiniteInputGivesTheHip) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const two_bone_ik_result r = solve_two_bone_ik({0, 1, 0}, 0.4f, 0.4f, {nan, 0, 0}, {0, 0, 1});
  EXPECT_FALSE(r.reached);
  expect_near(r.knee, {0, 1, 0}, 0.f);
  expect_near(r.ankle, {0, 1, 0}, 0.f);
  const two_bone_ik_result z = solve_two_bone_ik({0, 1, 0}, 0.f, 0.4f, {0, 0, 0}, {0, 0, 1});
  EXPECT_FALSE(z.reached);
  // A target on the hip: folded as far as the bones allow, still finite.
  const two_bone_ik_result f = solve_two_bone_ik({0, 1, 0}, 0.5f, 0.3f, {0, 1, 0}, {0, 1, 1});
  EXPECT_FALSE(f.reached);
  EXPECT_NEAR(glm::length(f.knee - glm::vec3(0, 1, 0)), 0.5f, 1e-5f);
  EXPECT_NEAR(glm::length(f.ankle - f.knee), 0.3f, 1e-5f);
}

TEST(LegIk, HipDropKnownAnswers) {
  // Target 0.3 across and 1.0 below, reach 0.5: the hip must end 0.4 above it (0.3-0.4-0.5).
  EXPECT_NEAR(hip_drop_to_reach({0, 1, 0}, {0.3f, 0, 0}, 0.5f), 0.6f, 1e-6f);
  EXPECT_EQ(hip_drop_to_reach({0, 1, 0}, {0.3f, 0.8f, 0}, 0.5f), 0.f);  // within reach
  // Too far across: level with the target, the nearest lowering gets.
  EXPECT_NEAR(hip_drop_to_reach({0, 1, 0}, {0.6f, 0.2f, 0}, 0.5f), 0.8f, 1e-6f);
  EXPECT_EQ(hip_drop_to_reach({0, 1, 0}, {0.6f, 1.5f, 0}, 0.5f), 0.f);  // above: never up
  EXPECT_EQ(hip_drop_to_reach({0, 1, 0}, {0, std::nanf(""), 0}, 0.5f), 0.f);
}

}  // namespace
}  // namespace avatarmap
