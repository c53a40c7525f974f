// pose_resampler (avatarmap/time/pose_resampler.hpp): capture at ~25 fps, render at 60 fps.
#include "avatarmap/time/pose_resampler.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {
namespace {

constexpr double k_rad_to_deg = 180.0 / 3.14159265358979323846;

Eigen::Quaterniond to_eigen(const glm::quat& q) { return Eigen::Quaterniond(q.w, q.x, q.y, q.z); }

// Angle (radians) between two rotations, computed in double with Eigen.
double eigen_angle(const glm::quat& a, const Eigen::Quaterniond& b) {
  return to_eigen(a).normalized().angularDistance(b.normalized());
}

// Ground truth: each bone turns at a constant angular velocity (world-frame, about its own
// axis) from its own start orientation; hips move at constant velocity; expressions ramp.
struct motion {
  Eigen::Vector3d axis[k_bone_count];
  double speed[k_bone_count];
  Eigen::Quaterniond start[k_bone_count];

  explicit motion(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int b = 0; b < k_bone_count; ++b) {
      axis[b] = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
      speed[b] = 4.0 * u(rng);  // up to 4 rad/s, either way
      start[b] = Eigen::Quaterniond(u(rng) + 1.5, u(rng), u(rng), u(rng)).normalized();
    }
  }
  Eigen::Quaterniond rotation(int b, double t) const {
    return Eigen::Quaterniond(Eigen::AngleAxisd(speed[b] * t, axis[b])) * start[b];
  }
  proxy_pose pose(double t) const {
    proxy_pose p;
    p.t = t;
    for (int b = 0; b < k_bone_count; ++b) {
      const Eigen::Quaterniond q = rotation(b, t);
      p.rotations[b] = glm::quat(float(q.w()), float(q.x()), float(q.y()), float(q.z()));
      p.confidence[b] = 1.f;
    }
    p.hips_position = glm::vec3(0.5f * float(t), 0.9f, -0.25f * float(t));
    for (int e = 0; e < k_expression_count; ++e) p.expressions[e] = float(0.5 + 0.1 * std::sin(t));
    return p;
  }
};

TEST(pose_resampler, empty_returns_false) {
  pose_resampler r;
  proxy_pose out;
  out.hips_position.x = 42.f;
  EXPECT_TRUE(r.empty());
  EXPECT_FALSE(r.sample(0.0, out));
  EXPECT_EQ(out.hips_position.x, 42.f);  // untouched
  proxy_pose p;
  p.t = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(r.push(p));
  EXPECT_TRUE(r.empty());
  p.t = 1.0;
  EXPECT_TRUE(r.push(p));
  EXPECT_FALSE(r.sample(std::numeric_limits<double>::infinity(), out));
}

TEST(pose_resampler, exact_at_capture_times) {
  const motion m(1);
  pose_resampler r;
  for (int i = 0; i < 4; ++i) r.push(m.pose(0.04 * i + 0.003 * (i % 2)));
  proxy_pose out;
  for (int i = 0; i < 4; ++i) {
    const proxy_pose expected = m.pose(0.04 * i + 0.003 * (i % 2));
    ASSERT_TRUE(r.sample(expected.t, out));
    EXPECT_EQ(out.t, expected.t);
    for (int b = 0; b < k_bone_count; ++b) {
      EXPECT_LT(angle_between(out.rotations[b], expected.rotations[b]), 1e-6f);
      EXPECT_GT(glm::dot(out.rotations[b], expected.rotations[b]), 0.f);  // same sign
    }
    EXPECT_EQ(out.hips_position, expected.hips_position);
    EXPECT_EQ(out.expressions, expected.expressions);
  }
}

TEST(pose_resampler, halfway_matches_eigen_slerp) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  for (int trial = 0; trial < 200; ++trial) {
    proxy_pose a, b;
    a.t = 1.0;
    b.t = 1.04;
    for (int i = 0; i < k_bone_count; ++i) {
      a.rotations[i] = glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng)));
      b.rotations[i] = glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng)));
    }
    pose_resampler r;
    r.push(a);
    r.push(b);
    proxy_pose out;
    for (double s : {0.25, 0.5, 0.8}) {
      ASSERT_TRUE(r.sample(1.0 + 0.04 * s, out));
      for (int i = 0; i < k_bone_count; ++i) {
        // Eigen's slerp also takes the shortest arc.
        const Eigen::Quaterniond expected =
            to_eigen(a.rotations[i]).slerp(s, to_eigen(b.rotations[i]));
        EXPECT_LT(eigen_angle(out.rotations[i], expected), 2e-5) << trial << " " << s;
        EXPECT_NEAR(glm::length(out.rotations[i]), 1.f, 1e-5f);
      }
    }
  }
}

TEST(pose_resampler, lerps_position_expressions_and_takes_lower_confidence) {
  proxy_pose a, b;
  a.t = 0.0;
  b.t = 0.1;
  a.hips_position = glm::vec3(0.f, 1.f, 2.f);
  b.hips_position = glm::vec3(1.f, 0.f, 4.f);
  a[expression::aa] = 0.2f;
  b[expression::aa] = 0.6f;
  a[blendshape::mouth_pucker] = 0.8f;
  b[blendshape::mouth_pucker] = 0.4f;
  a.confidence[3] = 0.9f;
  b.confidence[3] = 0.4f;
  a.confidence[4] = 0.1f;
  b.confidence[4] = 0.7f;
  pose_resampler r;
  r.push(a);
  r.push(b);
  proxy_pose out;
  ASSERT_TRUE(r.sample(0.025, out));
  EXPECT_NEAR(out.hips_position.x, 0.25f, 1e-6f);
  EXPECT_NEAR(out.hips_position.y, 0.75f, 1e-6f);
  EXPECT_NEAR(out.hips_position.z, 2.5f, 1e-6f);
  EXPECT_NEAR(out[expression::aa], 0.3f, 1e-6f);
  EXPECT_NEAR(out[blendshape::mouth_pucker], 0.7f, 1e-6f);
  EXPECT_EQ(out[blendshape::mouth_funnel], 0.f);
  EXPECT_EQ(out.confidence[3], 0.4f);
  EXPECT_EQ(out.confidence[4], 0.1f);
}

TEST(pose_resampler, lerps_foot_contact_clamped_and_never_nan) {
  proxy_pose a, b;
  a.t = 0.0;
  b.t = 0.1;
  a.foot_contact = {0.f, 1.f};
  b.foot_contact = {1.f, 7.f};  // clamped to 1 when pushed
  pose_resampler r;
  r.push(a);
  r.push(b);
  proxy_pose out;
  ASSERT_TRUE(r.sample(0.025, out));
  EXPECT_NEAR(out.foot_contact[0], 0.25f, 1e-6f);
  EXPECT_EQ(out.foot_contact[1], 1.f);
  ASSERT_TRUE(r.sample(0.15, out));  // extrapolated past 1: clamped
  EXPECT_EQ(out.foot_contact[0], 1.f);
  proxy_pose c = b;
  c.t = 0.2;
  c.foot_contact[0] = std::numeric_limits<float>::quiet_NaN();
  r.push(c);
  ASSERT_TRUE(r.sample(0.2, out));
  EXPECT_EQ(out.foot_contact[0], 0.f);
}

TEST(pose_resampler, before_first_gives_first_and_extrapolation_is_bounded) {
  const motion m(3);
  pose_resampler r;  // default 0.1 s
  EXPECT_EQ(r.options().max_extrapolation_seconds, 0.1);
  r.push(m.pose(1.00));
  r.push(m.pose(1.04));
  proxy_pose out;
  ASSERT_TRUE(r.sample(0.5, out));
  EXPECT_EQ(out.t, 0.5);
  for (int b = 0; b < k_bone_count; ++b)
    EXPECT_LT(angle_between(out.rotations[b], m.pose(1.0).rotations[b]), 1e-6f);

  // Within the horizon: constant angular velocity continues (slerp at small angles falls back
  // to nlerp, hence the looser bound than for interpolation).
  for (double h : {0.01, 0.05, 0.1}) {
    ASSERT_TRUE(r.sample(1.04 + h, out));
    for (int b = 0; b < k_bone_count; ++b)
      EXPECT_LT(eigen_angle(out.rotations[b], m.rotation(b, 1.04 + h)) * k_rad_to_deg, 0.05) << h;
    EXPECT_NEAR(out.hips_position.x, 0.5f * float(1.04 + h), 1e-5f);
  }
  // Beyond it: held at the horizon.
  proxy_pose at_horizon;
  r.sample(1.14, at_horizon);
  for (double t : {1.2, 2.0, 100.0}) {
    ASSERT_TRUE(r.sample(t, out));
    EXPECT_EQ(out.t, t);
    for (int b = 0; b < k_bone_count; ++b)
      EXPECT_LT(angle_between(out.rotations[b], at_horizon.rotations[b]), 1e-6f);
    EXPECT_EQ(out.hips_position, at_horizon.hips_position);
  }
  // A horizon of 0 holds the newest frame.
  r.set_options({0.0});
  ASSERT_TRUE(r.sample(1.5, out));
  for (int b = 0; b < k_bone_count; ++b)
    EXPECT_LT(angle_between(out.rotations[b], m.pose(1.04).rotations[b]), 1e-6f);
}

TEST(pose_resampler, extrapolated_expressions_stay_in_range_and_single_frame_holds) {
  proxy_pose a, b;
  a.t = 0.0;
  b.t = 0.04;
  a[expression::blink] = 0.2f;
  b[expression::blink] = 0.95f;
  pose_resampler r;
  r.push(a);
  proxy_pose out;
  ASSERT_TRUE(r.sample(0.09, out));  // one frame: hold
  EXPECT_EQ(out[expression::blink], 0.2f);
  r.push(b);
  ASSERT_TRUE(r.sample(0.1, out));
  EXPECT_EQ(out[expression::blink], 1.f);
}

TEST(pose_resampler, capture_25fps_render_60fps_reproduces_constant_angular_velocity) {
  const motion m(4);
  pose_resampler r;
  const double capture_dt = 1.0 / 25.0, render_dt = 1.0 / 60.0;
  int next_capture = 0;
  double worst = 0.0;
  proxy_pose out;
  for (int k = 0; k < 180; ++k) {  // 3 s of rendering
    const double t = 0.2 + k * render_dt;
    // The renderer runs one capture interval behind, so every render time is bracketed.
    while (next_capture * capture_dt <= t + capture_dt) r.push(m.pose(next_capture++ * capture_dt));
    ASSERT_TRUE(r.sample(t, out));
    for (int b = 0; b < k_bone_count; ++b)
      worst = std::max(worst, eigen_angle(out.rotations[b], m.rotation(b, t)) * k_rad_to_deg);
    EXPECT_NEAR(out.hips_position.x, 0.5f * float(t), 1e-5f);
  }
  EXPECT_LT(worst, 0.01) << "degrees";
}

TEST(pose_resampler, irregular_timestamps) {
  const motion m(5);
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> jitter(0.02, 0.07);
  pose_resampler r;
  double t_capture = 0.0;
  r.push(m.pose(t_capture));
  double worst = 0.0;
  proxy_pose out;
  for (int i = 0; i < 100; ++i) {
    const double prev = t_capture;
    t_capture += jitter(rng);
    r.push(m.pose(t_capture));
    for (double s : {0.1, 0.5, 0.9}) {
      const double t = prev + s * (t_capture - prev);
      ASSERT_TRUE(r.sample(t, out));
      for (int b = 0; b < k_bone_count; ++b)
        worst = std::max(worst, eigen_angle(out.rotations[b], m.rotation(b, t)) * k_rad_to_deg);
    }
  }
  EXPECT_LT(worst, 0.01) << "degrees";
}

TEST(pose_resampler, ring_keeps_last_four_equal_time_replaces_earlier_resets) {
  const motion m(7);
  pose_resampler r;
  for (int i = 0; i < 6; ++i) r.push(m.pose(0.1 * i));
  EXPECT_EQ(r.size(), 4);
  EXPECT_DOUBLE_EQ(r.frame(0).t, 0.2);
  EXPECT_DOUBLE_EQ(r.frame(3).t, 0.5);
  proxy_pose out;
  r.sample(0.0, out);  // before the oldest kept frame: the oldest kept frame
  EXPECT_LT(angle_between(out.rotations[0], m.pose(0.2).rotations[0]), 1e-6f);

  proxy_pose replacement = m.pose(0.5);
  replacement.hips_position.x = 7.f;
  EXPECT_TRUE(r.push(replacement));
  EXPECT_EQ(r.size(), 4);
  EXPECT_EQ(r.frame(3).hips_position.x, 7.f);

  EXPECT_TRUE(r.push(m.pose(0.25)));  // back in time: restart
  EXPECT_EQ(r.size(), 1);
  EXPECT_DOUBLE_EQ(r.frame(0).t, 0.25);
  r.reset();
  EXPECT_TRUE(r.empty());
}

TEST(pose_resampler, push_sanitises_non_finite_values) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  proxy_pose a;
  a.t = 0.0;
  a[bone::spine] = axis_angle(glm::vec3(1.f, 0.f, 0.f), 0.4f);
  a.hips_position = glm::vec3(0.1f, 0.9f, 0.f);
  a[expression::oh] = 0.5f;
  a[blendshape::cheek_puff] = 0.25f;
  proxy_pose b = a;
  b.t = 0.04;
  b[bone::spine] = glm::quat(nan, 0.f, 0.f, 0.f);
  b[bone::neck] = glm::quat(0.f, 0.f, 0.f, 0.f);
  b[bone::head] = glm::quat(2.f, 0.f, 0.f, 0.f);  // not unit: normalised
  b.hips_position.z = nan;
  b[expression::oh] = nan;
  b[expression::aa] = 3.f;
  b[blendshape::cheek_puff] = nan;
  b[blendshape::tongue_out] = -2.f;
  b[blendshape::jaw_open] = std::numeric_limits<float>::infinity();
  b.confidence[0] = -1.f;
  pose_resampler r;
  r.push(a);
  r.push(b);
  for (double t : {0.0, 0.02, 0.04, 0.06, 1.0}) {
    proxy_pose out;
    ASSERT_TRUE(r.sample(t, out));
    for (const auto& q : out.rotations) {
      ASSERT_TRUE(is_finite(q));
      EXPECT_NEAR(glm::length(q), 1.f, 1e-5f);
    }
    ASSERT_TRUE(is_finite(out.hips_position));
    for (float e : out.expressions) {
      EXPECT_GE(e, 0.f);
      EXPECT_LE(e, 1.f);
    }
    EXPECT_LT(angle_between(out[bone::spine], a[bone::spine]), 1e-6f);
    for (float w : out.blendshapes) {
      EXPECT_GE(w, 0.f);
      EXPECT_LE(w, 1.f);
    }
    EXPECT_EQ(out[expression::oh], 0.5f);
    EXPECT_EQ(out[blendshape::cheek_puff], 0.25f);  // held from a
    EXPECT_EQ(out[blendshape::jaw_open], 0.f);      // held from a (0)
    EXPECT_EQ(out[blendshape::tongue_out], 0.f);    // clamped
    EXPECT_GE(out.confidence[0], 0.f);
  }
}

}  // namespace
}  // namespace avatarmap
