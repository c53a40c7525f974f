// Percentiles of eval-pose's head figure (angle_histogram in pose_accuracy.hpp) against the
// exact order statistic of the same samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "avatarmap/synth/pose_accuracy.hpp"

namespace avatarmap {
namespace {

TEST(AngleHistogram, QuantileIsWithinOneBinAboveTheExactPercentile) {
  std::mt19937 rng(5);
  std::exponential_distribution<double> d(0.7);
  angle_histogram h;
  std::vector<double> v;
  for (int i = 0; i < 5000; ++i) {
    const double a = d(rng);
    h.add(a);
    v.push_back(a);
  }
  std::sort(v.begin(), v.end());
  for (double q : {0.5, 0.9, 0.95, 0.99}) {
    const double exact = v[size_t(std::ceil(q * v.size())) - 1];
    EXPECT_GE(h.quantile(q), exact) << q;
    EXPECT_LE(h.quantile(q), exact + angle_histogram::k_bin_degrees + 1e-9) << q;
  }
}

TEST(AngleHistogram, EmptyOutOfRangeAndNaN) {
  angle_histogram h;
  EXPECT_EQ(h.quantile(0.95), 0.0);
  h.add(200.0);
  h.add(std::nan(""));
  h.add(-1.0);
  EXPECT_EQ(h.count, 3);
  EXPECT_NEAR(h.quantile(0.3), angle_histogram::k_bin_degrees, 1e-12);  // -1 counts as 0
  EXPECT_NEAR(h.quantile(1.0), 180.0, 1e-9);  // 200 and NaN in the last bin
}

// The head's histogram is filled alongside its mean.
TEST(AngleHistogram, PoseAccuracyFillsTheHeadHistogram) {
  proxy_pose truth, solved;
  truth.set_rest();
  solved.set_rest();
  solved.rotations[idx(bone::head)] = glm::quat(std::cos(0.05f), std::sin(0.05f), 0.f, 0.f);
  pose_accuracy acc;
  accumulate_pose_accuracy(truth, solved, acc);
  EXPECT_EQ(acc.all.head_histogram.count, 1);
  const double deg = 0.1 * 180.0 / 3.14159265358979;  // 5.73 degrees
  EXPECT_NEAR(acc.all.head_histogram.quantile(0.95), deg, angle_histogram::k_bin_degrees);
}

}  // namespace
}  // namespace avatarmap
