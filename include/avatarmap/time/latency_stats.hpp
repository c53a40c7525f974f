// The one latency statistic of every live report (the live session's stats, so avm_live_stats
// and Python's Live.stats(); the CLI's `live` summary and its VMC line): a ring of the last
// samples for the percentiles, a running mean and maximum over all, and one percentile
// definition, the nearest rank.
//
// Memory: the ring is allocated at construction; add() never allocates, summary() copies the
// kept samples to sort them. Thread-safety: none; the owner locks.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace avatarmap {

/// The p-th percentile (p in [0, 100]) of `n` samples sorted in ascending order, by nearest
/// rank: the smallest sample such that at least p % of the samples are at or below it, i.e.
/// sorted[ceil(p / 100 x n) - 1], and the smallest sample for p = 0. Always one of the
/// samples (no interpolation). With 20 samples the median is the 10th, p95 the 19th. `n`
/// must be >= 1.
inline double nearest_rank_percentile(const double* sorted, std::size_t n, double p) {
  // A hair below the product so that p x n landing on an integer is not pushed one rank up by
  // the rounding of p / 100.
  const double rank = std::ceil(p / 100.0 * static_cast<double>(n) - 1e-9);
  const std::size_t r =
      rank < 1.0 ? 1 : (rank > static_cast<double>(n) ? n : static_cast<std::size_t>(rank));
  return sorted[r - 1];
}

/// What a latency_stats reports. Milliseconds; all 0 before the first sample.
struct latency_summary {
  long samples = 0;      // samples added in all
  long kept = 0;         // the last ones, of which the percentiles are taken
  double mean_ms = 0.0;  // over all samples
  double p50_ms = 0.0;   // nearest-rank median of the kept samples
  double p95_ms = 0.0;   // nearest-rank 95th percentile of the kept samples
  double max_ms = 0.0;   // over all samples
};

/// Latency samples of a stream (any unit; the live reports use milliseconds).
class latency_stats {
 public:
  /// Keeps the last `capacity` samples (>= 1; less is taken as 1) for the percentiles.
  explicit latency_stats(int capacity = 4096)
      : ring_(static_cast<std::size_t>(capacity < 1 ? 1 : capacity), 0.0) {}

  /// Adds a sample. Never allocates; a sample that is not finite is ignored.
  void add(double v) noexcept {
    if (!std::isfinite(v)) return;
    ring_[static_cast<std::size_t>(count_ % static_cast<long>(ring_.size()))] = v;
    ++count_;
    sum_ += v;
    max_ = count_ == 1 ? v : std::max(max_, v);
  }
  long count() const noexcept { return count_; }
  int capacity() const noexcept { return static_cast<int>(ring_.size()); }
  void clear() noexcept {
    count_ = 0;
    sum_ = max_ = 0.0;
  }

  /// Mean and maximum over every sample, median and p95 (nearest_rank_percentile) over the
  /// kept ones. Allocates a sorted copy of the kept samples.
  latency_summary summary() const {
    latency_summary s;
    if (count_ == 0) return s;
    const std::size_t n = static_cast<std::size_t>(std::min<long>(count_, capacity()));
    std::vector<double> sorted(ring_.begin(), ring_.begin() + static_cast<std::ptrdiff_t>(n));
    std::sort(sorted.begin(), sorted.end());
    s.samples = count_;
    s.kept = static_cast<long>(n);
    s.mean_ms = sum_ / static_cast<double>(count_);
    s.p50_ms = nearest_rank_percentile(sorted.data(), n, 50.0);
    s.p95_ms = nearest_rank_percentile(sorted.data(), n, 95.0);
    s.max_ms = max_;
    return s;
  }

 private:
  std::vector<double> ring_;
  long count_ = 0;
  double sum_ = 0.0;
  double max_ = 0.0;
};

}  // namespace avatarmap
