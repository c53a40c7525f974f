// resample_clip: counts, rebasing, known answers for a constant angular velocity, and the
// tolerance for times that went through float.
#include "avatarmap/time/resample_clip.hpp"

#include <gtest/gtest.h>

namespace avatarmap {
namespace {

std::vector<proxy_pose> spin_clip(double fps, int n, double t0) {
  std::vector<proxy_pose> clip(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    clip[i].t = t0 + i / fps;
    clip[i][bone::head] = axis_angle({0, 1, 0}, static_cast<float>(0.5 * (clip[i].t - t0)));
    clip[i].hips_position = glm::vec3(static_cast<float>(clip[i].t - t0), 0.9f, 0.f);
  }
  return clip;
}

TEST(ResampleClip, TwentyFiveToSixtyFollowsAConstantSpin) {
  const std::vector<proxy_pose> clip = spin_clip(25.0, 26, 3.0);  // 1 s from t = 3
  const std::vector<proxy_pose> out = resample_clip(clip, 60.0, true);
  ASSERT_EQ(out.size(), 61u);
  for (size_t k = 0; k < out.size(); ++k) {
    const double t = k / 60.0;
    EXPECT_NEAR(out[k].t, t, 1e-12);
    const glm::quat want = axis_angle({0, 1, 0}, static_cast<float>(0.5 * t));
    EXPECT_LT(angle_between(out[k][bone::head], want), 0.01f * k_pi / 180.f) << k;
    EXPECT_NEAR(out[k].hips_position.x, t, 1e-5);
  }
  const std::vector<proxy_pose> kept = resample_clip(clip, 60.0, false);
  EXPECT_NEAR(kept.front().t, 3.0, 1e-12);
}

TEST(ResampleClip, FloatTimesDoNotLoseTheLastFrameAndEdgeCases) {
  std::vector<proxy_pose> clip = spin_clip(30.0, 300, 0.0);
  clip.back().t = static_cast<float>(clip.back().t);  // 9.9666662 instead of 9.9666667
  EXPECT_EQ(resample_clip(clip, 30.0, true).size(), 300u);
  EXPECT_TRUE(resample_clip({}, 30.0, true).empty());
  EXPECT_TRUE(resample_clip(clip, 0.0, true).empty());
  EXPECT_EQ(resample_clip(std::vector<proxy_pose>(1), 30.0, true).size(), 1u);
}

}  // namespace
}  // namespace avatarmap
