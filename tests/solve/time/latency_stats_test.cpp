// latency_stats: the one percentile definition of every live report (nearest rank), against
// known answers worked by hand from the definition (the smallest sample with at least p % of
// the samples at or below it), including the textbook example {15, 20, 35, 40, 50}
// (5th -> 15, 30th -> 20, 40th -> 20, 50th -> 35, 100th -> 50); and the ring, mean and max.
#include "avatarmap/time/latency_stats.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace avatarmap {
namespace {

TEST(latency_stats, nearest_rank_known_answers) {
  const std::vector<double> five{15, 20, 35, 40, 50};
  auto p = [&](double q) { return nearest_rank_percentile(five.data(), five.size(), q); };
  EXPECT_EQ(p(5), 15);
  EXPECT_EQ(p(30), 20);
  EXPECT_EQ(p(40), 20);  // 40 % of 5 is exactly 2 samples: the 2nd, not the 3rd
  EXPECT_EQ(p(50), 35);
  EXPECT_EQ(p(100), 50);
  EXPECT_EQ(p(0), 15);

  std::vector<double> twenty;
  for (int i = 1; i <= 20; ++i) twenty.push_back(i);
  auto q = [&](double r) { return nearest_rank_percentile(twenty.data(), twenty.size(), r); };
  EXPECT_EQ(q(50), 10);  // the lower median of an even count
  EXPECT_EQ(q(95), 19);  // 95 % of 20 is exactly 19 samples
  EXPECT_EQ(q(96), 20);
  EXPECT_EQ(q(100), 20);

  std::vector<double> ten;
  for (int i = 1; i <= 10; ++i) ten.push_back(i * 10.0);
  EXPECT_EQ(nearest_rank_percentile(ten.data(), 10, 95), 100);  // ceil(9.5) = 10th
  EXPECT_EQ(nearest_rank_percentile(ten.data(), 10, 50), 50);
  const double one = 7.5;
  EXPECT_EQ(nearest_rank_percentile(&one, 1, 50), 7.5);
  EXPECT_EQ(nearest_rank_percentile(&one, 1, 95), 7.5);
}

TEST(latency_stats, summary_mean_max_over_all_percentiles_over_the_ring) {
  latency_stats s(4);
  EXPECT_EQ(s.summary().samples, 0);
  EXPECT_EQ(s.summary().p95_ms, 0.0);
  for (double v : {9.0, 1.0, 5.0}) s.add(v);
  latency_summary l = s.summary();
  EXPECT_EQ(l.samples, 3);
  EXPECT_EQ(l.kept, 3);
  EXPECT_DOUBLE_EQ(l.mean_ms, 5.0);
  EXPECT_EQ(l.p50_ms, 5.0);
  EXPECT_EQ(l.p95_ms, 9.0);
  EXPECT_EQ(l.max_ms, 9.0);
  // Three more: the ring keeps the last 4 (5, 2, 3, 4); mean and max keep every sample.
  for (double v : {2.0, 3.0, 4.0}) s.add(v);
  l = s.summary();
  EXPECT_EQ(l.samples, 6);
  EXPECT_EQ(l.kept, 4);
  EXPECT_DOUBLE_EQ(l.mean_ms, 24.0 / 6.0);
  EXPECT_EQ(l.p50_ms, 3.0);  // sorted 2 3 4 5: rank ceil(2) = 2
  EXPECT_EQ(l.p95_ms, 5.0);
  EXPECT_EQ(l.max_ms, 9.0);
  s.add(NAN);  // ignored
  EXPECT_EQ(s.count(), 6);
  s.clear();
  EXPECT_EQ(s.summary().samples, 0);
  latency_stats at_least_one(0);
  EXPECT_EQ(at_least_one.capacity(), 1);
}

}  // namespace
}  // namespace avatarmap
