// pose_resampler's promise that sample() never produces non-finite values, whatever was pushed
// (cases found by tools/fuzz/fuzz_resample; inputs in tools/fuzz/regressions/resample/).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/time/pose_resampler.hpp"

namespace avatarmap {
namespace {

constexpr float k_float_max = std::numeric_limits<float>::max();

proxy_pose frame_at(double t) {
  proxy_pose p;
  p.t = t;
  return p;
}

// Every value of `p` finite, rotations unit, expressions and confidence in [0, 1].
void expect_sane(const proxy_pose& p) {
  for (int b = 0; b < k_bone_count; ++b) {
    const glm::quat& q = p.rotations[b];
    const float n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    ASSERT_TRUE(std::isfinite(n2)) << "bone " << b;
    EXPECT_NEAR(n2, 1.f, 1e-4f) << "bone " << b;
    EXPECT_GE(p.confidence[b], 0.f);
    EXPECT_LE(p.confidence[b], 1.f);
  }
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(p.hips_position[k])) << "axis " << k;
  for (float e : p.expressions) {
    EXPECT_GE(e, 0.f);
    EXPECT_LE(e, 1.f);
  }
}

TEST(pose_resampler_hostile, hips_at_opposite_ends_of_the_float_range_interpolate_finite) {
  pose_resampler r;
  proxy_pose a = frame_at(0.0), b = frame_at(1.0);
  a.hips_position = glm::vec3(-k_float_max, k_float_max, -k_float_max);
  b.hips_position = glm::vec3(k_float_max, -k_float_max, k_float_max);
  ASSERT_TRUE(r.push(a));
  ASSERT_TRUE(r.push(b));
  proxy_pose out;
  ASSERT_TRUE(r.sample(0.5, out));  // midway: 0 on every axis, not inf - inf
  expect_sane(out);
  EXPECT_NEAR(out.hips_position.x, 0.f, 1e32f);
  ASSERT_TRUE(r.sample(0.25, out));  // a quarter of the way: -max/2 exactly
  expect_sane(out);
  EXPECT_FLOAT_EQ(out.hips_position.x, -0.5f * k_float_max);
  ASSERT_TRUE(r.sample(1.05, out));  // extrapolation past the float range holds the newest
  expect_sane(out);
}

TEST(pose_resampler_hostile, frames_a_denormal_apart_extrapolate_finite) {
  pose_resampler r;
  proxy_pose a = frame_at(0.0), b = frame_at(std::numeric_limits<double>::denorm_min());
  b.rotations[idx(bone::head)] = glm::angleAxis(1.f, glm::vec3(0.f, 1.f, 0.f));
  b.hips_position.x = 1.f;
  b.expressions[0] = 0.5f;
  ASSERT_TRUE(r.push(a));
  ASSERT_TRUE(r.push(b));
  proxy_pose out;
  ASSERT_TRUE(r.sample(0.05, out));  // 0.05 / 5e-324 = inf: the newest frame holds
  expect_sane(out);
  EXPECT_FLOAT_EQ(out.hips_position.x, 1.f);
  EXPECT_FLOAT_EQ(out.expressions[0], 0.5f);
  const glm::quat& q = out.rotations[idx(bone::head)];
  EXPECT_NEAR(std::abs(glm::dot(q, b.rotations[idx(bone::head)])), 1.f, 1e-5f);
}

TEST(pose_resampler_hostile, far_extrapolation_keeps_rotations_unit) {
  pose_resampler_options options;
  options.max_extrapolation_seconds = 1e6;  // far more than sensible, still a valid option
  pose_resampler r(options);
  proxy_pose a = frame_at(0.0), b = frame_at(0.04);
  for (int i = 0; i < k_bone_count; ++i)
    b.rotations[i] = glm::angleAxis(0.01f * static_cast<float>(i + 1), glm::vec3(0.f, 0.f, 1.f));
  ASSERT_TRUE(r.push(a));
  ASSERT_TRUE(r.push(b));
  proxy_pose out;
  for (double t : {1.0, 1e3, 1e5, 1e6}) {
    ASSERT_TRUE(r.sample(t, out)) << t;
    expect_sane(out);
  }
}

TEST(pose_resampler_hostile, an_infinite_extrapolation_limit_holds_instead_of_nan) {
  pose_resampler_options options;
  options.max_extrapolation_seconds = std::numeric_limits<double>::infinity();
  pose_resampler r(options);
  ASSERT_TRUE(r.push(frame_at(0.0)));
  ASSERT_TRUE(r.push(frame_at(0.04)));
  proxy_pose out;
  ASSERT_TRUE(r.sample(std::numeric_limits<double>::max(), out));
  expect_sane(out);
}

}  // namespace
}  // namespace avatarmap
