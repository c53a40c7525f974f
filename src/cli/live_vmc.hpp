// `avatarmap live --vmc HOST[:PORT] [--avatar FILE]`: the live loop's VMC protocol output
// (stream/vmc_stream.hpp, docs/vmc.md). The live command reads the options through it, tells it
// when a frame's pose reaches the resampler and when the output thread samples, and the output
// thread sends each sampled pose through it. It measures the latency from a frame's arrival to
// the first packet whose pose includes it.
#pragma once

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/stream/vmc_stream.hpp"
#include "cli/cli_args.hpp"

namespace avatarmap::cli {

/// The --vmc and --avatar lines of `live --help`.
extern const char* const k_live_vmc_help;

class live_vmc {
 public:
  using clock_type = std::chrono::steady_clock;

  /// Takes --vmc and --avatar out of `a`. Returns 0, or 2 after printing a usage error.
  int read_options(args& a);
  /// Parses the destination (2 when malformed), loads the avatar and resolves the host (1 when
  /// that fails), printing the message. A no-op returning 0 without --vmc.
  int open();
  bool enabled() const { return stream_ != nullptr; }

  /// A frame that arrived at `arrived` has reached the resampler (call under the loop's lock).
  void frame_pushed(clock_type::time_point arrived) {
    pending_ = true;
    pending_arrival_ = arrived;
  }
  /// The output thread sampled a pose, which includes every frame pushed so far (call under the
  /// loop's lock, before send()).
  void pose_sampled() {
    carrying_ = pending_;
    carrying_arrival_ = pending_arrival_;
    pending_ = false;
  }
  /// Sends the sampled pose (output thread, outside the lock). Never blocks, never allocates.
  void send(const proxy_pose& pose);

  /// The summary lines of `live` (nothing without --vmc).
  void print_summary(std::FILE* out) const;

 private:
  bool given_ = false;  // --vmc was given (perhaps empty: a usage error)
  std::string destination_;
  std::string avatar_path_;
  std::string rest_source_;  // where the rest positions come from, for the summary
  std::unique_ptr<vmc_stream> stream_;
  bool pending_ = false;
  clock_type::time_point pending_arrival_{};
  bool carrying_ = false;
  clock_type::time_point carrying_arrival_{};
  std::vector<double> latencies_ms_;  // a ring, allocated by open()
  long latency_count_ = 0;
};

}  // namespace avatarmap::cli
