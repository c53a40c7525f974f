// Tests of landmark_smoothing.hpp: MediaPipe's One Euro variant against hand-computed first
// order low-pass answers, its scale invariance (value scaling by the object size), resets and
// bad input.
#include "avatarmap/capture/landmark_smoothing.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace avatarmap {
namespace {

TEST(mediapipe_one_euro, beta_zero_is_a_first_order_low_pass_at_the_sample_rate) {
  mediapipe_one_euro f;
  f.set_params({1.f, 0.f, 1.f, false});
  // 10 Hz samples, 1 Hz cutoff: alpha = 1 / (1 + tau / te), tau = 1 / (2 pi), te = 0.1.
  const double a = 1.0 / (1.0 + (1.0 / (2.0 * 3.14159265358979)) / 0.1);
  EXPECT_DOUBLE_EQ(f.apply(0.0, 1.0, 0.0), 0.0);  // the first sample passes through
  double want = 0.0;
  for (int i = 1; i <= 5; ++i) {
    want += a * (1.0 - want);
    EXPECT_NEAR(f.apply(0.1 * i, 1.0, 1.0), want, 1e-12) << i;
  }
  // A timestamp that does not advance returns the sample unfiltered, state unchanged.
  EXPECT_DOUBLE_EQ(f.apply(0.5, 1.0, 7.0), 7.0);
  want += a * (1.0 - want);
  EXPECT_NEAR(f.apply(0.6, 1.0, 1.0), want, 1e-12);
}

TEST(mediapipe_one_euro, speed_raises_the_cutoff) {
  mediapipe_one_euro slow, fast;
  slow.set_params({0.05f, 0.f, 1.f, false});
  fast.set_params({0.05f, 80.f, 1.f, false});
  slow.apply(0.0, 1.0, 0.0);
  fast.apply(0.0, 1.0, 0.0);
  const double ys = slow.apply(0.2, 1.0, 1.0), yf = fast.apply(0.2, 1.0, 1.0);
  EXPECT_LT(ys, 0.1);  // a 0.05 Hz low-pass barely moves in 0.2 s
  EXPECT_GT(yf, 0.9);  // a fast move lifts the cutoff: little lag
}

TEST(mediapipe_velocity_filter, weight_follows_the_windowed_speed) {
  mediapipe_velocity_filter f;
  f.set_params({5, 10.f});
  EXPECT_DOUBLE_EQ(f.apply(0.0, 1.0, 0.0), 0.0);  // the first value passes through
  // Step to 1 in 1/30 s: speed 30 /s, weight 1 - 1 / (1 + 10 * 30) = 300 / 301.
  const double y1 = 300.0 / 301.0;
  EXPECT_NEAR(f.apply(1.0 / 30, 1.0, 1.0), y1, 1e-12);
  // Still at 1: the window (2/30 s) holds both steps: speed 1 / (2/30) = 15 /s.
  const double a2 = 1.0 - 1.0 / (1.0 + 10.0 * 15.0);
  EXPECT_NEAR(f.apply(2.0 / 30, 1.0, 1.0), a2 + (1 - a2) * y1, 1e-12);
  // A time that does not advance returns the value unfiltered.
  EXPECT_DOUBLE_EQ(f.apply(2.0 / 30, 1.0, 5.0), 5.0);
}

TEST(mediapipe_velocity_filter, slow_frames_use_only_the_last_step_and_scale_matters) {
  // At 5 frames/s a step (0.2 s) already fills the window's 1/30 s per element: only the
  // newest step counts. value_scale divides the speed by the object's size.
  mediapipe_velocity_filter f;
  f.set_params({5, 10.f});
  f.apply(0.0, 0.01, 0.0);
  const double a1 = 1.0 - 1.0 / (1.0 + 10.0 * (100.0 * 0.01 / 0.2));
  EXPECT_NEAR(f.apply(0.2, 0.01, 100.0), a1 * 100.0, 1e-9);
  const double y1 = a1 * 100.0;
  const double a2 = 1.0 - 1.0 / (1.0 + 10.0 * (0.0 / 0.2));  // no motion: holds
  EXPECT_NEAR(f.apply(0.4, 0.01, 100.0), a2 * 100.0 + (1 - a2) * y1, 1e-9);
}

std::vector<landmark> points(float scale, float shift) {
  std::vector<landmark> p(5);
  for (int i = 0; i < 5; ++i) {
    p[i].x = scale * (0.1f * i + shift);
    p[i].y = scale * (0.05f * i * i - shift);
    p[i].z = scale * (0.02f * i + shift * 0.5f);
  }
  return p;
}

TEST(landmark_smoother, output_scales_with_the_object) {
  // Value scaling divides speeds by the object's size: the same motion at twice the size is
  // filtered to exactly twice the output, with either filter.
  const mediapipe_one_euro_params prm{0.05f, 80.f, 1.f, false};
  landmark_smoother a(prm), b(prm);
  landmark_smoother va(mediapipe_velocity_params{5, 10.f}), vb(mediapipe_velocity_params{5, 10.f});
  for (int k = 0; k < 6; ++k) {
    std::vector<landmark> p = points(1.f, 0.03f * k * k), q = points(2.f, 0.03f * k * k);
    va.apply(0.2 * k, p.data(), 5, false, 0, 0);
    vb.apply(0.2 * k, q.data(), 5, false, 0, 0);
    for (int i = 0; i < 5; ++i) EXPECT_NEAR(q[i].y, 2 * p[i].y, 1e-5f);
  }
  for (int k = 0; k < 6; ++k) {
    std::vector<landmark> p = points(1.f, 0.03f * k * k), q = points(2.f, 0.03f * k * k);
    a.apply(0.2 * k, p.data(), 5, false, 0, 0);
    b.apply(0.2 * k, q.data(), 5, false, 0, 0);
    for (int i = 0; i < 5; ++i) {
      EXPECT_NEAR(q[i].x, 2 * p[i].x, 1e-5f);
      EXPECT_NEAR(q[i].y, 2 * p[i].y, 1e-5f);
      EXPECT_NEAR(q[i].z, 2 * p[i].z, 1e-5f);
    }
  }
}

TEST(landmark_smoother, normalised_points_are_filtered_in_pixels) {
  // A normalised point set on a 200 x 100 image behaves as the pixel set filtered metric.
  const mediapipe_one_euro_params prm{0.05f, 80.f, 1.f, false};
  landmark_smoother n(prm), m(prm);
  for (int k = 0; k < 5; ++k) {
    std::vector<landmark> p = points(1.f, 0.02f * k), q = p;
    for (landmark& l : q) {
      l.x *= 200.f;
      l.y *= 100.f;
      l.z *= 200.f;
    }
    n.apply(0.1 * k, p.data(), 5, true, 200, 100);
    m.apply(0.1 * k, q.data(), 5, false, 0, 0);
    for (int i = 0; i < 5; ++i) {
      EXPECT_NEAR(p[i].x * 200.f, q[i].x, 1e-3f);
      EXPECT_NEAR(p[i].y * 100.f, q[i].y, 1e-3f);
      EXPECT_NEAR(p[i].z * 200.f, q[i].z, 1e-3f);
    }
  }
}

TEST(landmark_smoother, non_finite_input_resets_and_passes_through) {
  landmark_smoother s({0.05f, 0.f, 1.f, false});
  std::vector<landmark> p = points(1.f, 0.f);
  s.apply(0.0, p.data(), 5, false, 0, 0);
  std::vector<landmark> q = points(1.f, 0.5f);
  q[2].x = std::numeric_limits<float>::quiet_NaN();
  s.apply(0.1, q.data(), 5, false, 0, 0);
  EXPECT_TRUE(std::isnan(q[2].x));
  EXPECT_EQ(q[0].x, points(1.f, 0.5f)[0].x);
  // After the reset the next set passes through unchanged.
  std::vector<landmark> r = points(1.f, 0.7f);
  s.apply(0.2, r.data(), 5, false, 0, 0);
  EXPECT_EQ(r[4].y, points(1.f, 0.7f)[4].y);
}

TEST(visibility_smoother, low_pass_with_alpha) {
  visibility_smoother v(0.1f);
  landmark l;
  l.visibility = 1.f;
  v.apply(&l, 1);
  EXPECT_FLOAT_EQ(l.visibility, 1.f);
  l.visibility = 0.f;
  v.apply(&l, 1);
  EXPECT_FLOAT_EQ(l.visibility, 0.9f);
  l.visibility = 0.f;
  v.apply(&l, 1);
  EXPECT_FLOAT_EQ(l.visibility, 0.81f);
}

}  // namespace
}  // namespace avatarmap
