// `avatarmap live --vmc HOST[:PORT] [--vmc HOST[:PORT] ...] [--avatar FILE] [--vmc-blendshapes
// SET]`: the live loop's VMC protocol output (stream/vmc_stream.hpp, docs/vmc.md), one
// destination per person. The live command reads the options through it and makes send() one of
// the live session's outputs (live/live_session.hpp): the session's output thread sends each
// sampled pose through it, once per person, and the k-th --vmc receives the person in slot k
// (live_output_report::slot). It measures, per destination, the latency from a frame's arrival
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

  /// Takes every --vmc (repeatable: the k-th is slot k's destination), --avatar and
  /// --vmc-blendshapes out of `a`. Returns 0, or 2 after printing a usage error.
  int read_options(args& a);
  /// Parses each destination (2 when one is malformed), loads the avatar once and resolves
  /// each host (1 when that fails), printing the message. A no-op returning 0 without --vmc.
  int open();
  bool enabled() const { return !destinations_.empty(); }
  /// The destinations opened (the number of --vmc given once open() succeeded; else 0).
  int destination_count() const { return static_cast<int>(destinations_.size()); }

  /// The session's output: sends the sampled pose to the destination of report.slot (0 in a
  /// single-person session) and, when it is the first to carry a newly processed frame,
  /// records that frame's push -> packet latency for that destination. A slot without a
  /// destination (more people than --vmc) is not sent: counted, and said once on stderr. Called
  /// from one thread (the session's output thread). Never blocks, never allocates.
  void send(const proxy_pose& pose, const live_output_report& report);

  /// The summary lines of `live`: one per destination (nothing without --vmc).
  void print_summary(std::FILE* out) const;

 private:
  struct destination {
    std::unique_ptr<vmc_stream> stream;
    latency_stats latencies{1 << 16};
  };

  std::vector<std::string> given_;  // the --vmc values, in order (perhaps empty: a usage error)
  std::string avatar_path_;
  vmc_blend_set blends_ = vmc_blend_set::vrm0;  // --vmc-blendshapes
  std::string rest_source_;  // where the rest positions come from, for the summary
  // Fixed once open() returns: destinations_[k] receives the person in slot k.
  std::vector<std::unique_ptr<destination>> destinations_;
  long unsent_ = 0;           // poses of slots without a destination
  int unsent_people_ = 0;     // the highest such slot + 1 - destinations (for the summary)
  bool unsent_said_ = false;  // the one stderr line about them was printed
};

}  // namespace avatarmap::cli
