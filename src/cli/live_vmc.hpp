// `avatarmap live --vmc HOST[:PORT] [--avatar FILE] [--vmc-blendshapes SET]`: the live loop's VMC
// protocol output (stream/vmc_stream.hpp, docs/vmc.md). The live command reads the options through
// it and makes send() one of the live session's outputs (live/live_session.hpp): the session's
// output thread sends each sampled pose through it. It measures the latency from a frame's arrival
// to the first packet whose pose includes it (time/latency_stats.hpp).
#pragma once

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/live/live_session.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/stream/vmc_stream.hpp"
#include "avatarmap/time/latency_stats.hpp"
#include "cli/cli_args.hpp"

namespace avatarmap::cli {

/// The --vmc, --avatar and --vmc-blendshapes lines of `live --help`.
extern const char* const k_live_vmc_help;

class live_vmc {
 public:
  using clock_type = std::chrono::steady_clock;

  /// Takes --vmc, --avatar and --vmc-blendshapes out of `a`. Returns 0, or 2 after printing a usage
  /// error.
  int read_options(args& a);
  /// Parses the destination (2 when malformed), loads the avatar and resolves the host (1 when
  /// that fails), printing the message. A no-op returning 0 without --vmc.
  int open();
  bool enabled() const { return stream_ != nullptr; }

  /// The session's output: sends the sampled pose and, when it is the first to carry a newly
  /// processed frame, records that frame's push -> packet latency. Never blocks, never
  /// allocates.
  void send(const proxy_pose& pose, const live_output_report& report);

  /// The summary lines of `live` (nothing without --vmc).
  void print_summary(std::FILE* out) const;

 private:
  bool given_ = false;  // --vmc was given (perhaps empty: a usage error)
  std::string destination_;
  std::string avatar_path_;
  vmc_blend_set blends_ = vmc_blend_set::vrm0;  // --vmc-blendshapes
  std::string rest_source_;  // where the rest positions come from, for the summary
  std::unique_ptr<vmc_stream> stream_;
  latency_stats latencies_{1 << 16};
};

}  // namespace avatarmap::cli
