// The CLI's --filter option, shared by `solve` and `convert` (and through
// convert by `animate`): one table of names, one message.
#pragma once

#include <string>

#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/time/filter_rules.hpp"

namespace avatarmap::cli {

/// The --filter values, for help texts and messages.
inline constexpr const char* k_filter_names = "offline, live or none (or euro, landmarks, both)";

/// Sets `job`'s filters from a --filter value: offline (zero-phase smoothing and gap filling,
/// the default), live (pose_filter, the causal filter on the solved poses: One Euro plus a
/// short constant-velocity extrapolation of the rotations, with pose_filter_options'
/// defaults unless --min-cutoff / --beta change them), none; and the older
/// names: euro = live, landmarks = One Euro on the landmarks before solving and nothing
/// after, both = landmarks and live. False (job unchanged) for any other value.
inline bool apply_filter_option(const std::string& value, solve_file_job& job) {
  pose_filter_mode mode = pose_filter_mode::offline;
  bool points = false;
  if (value == "offline") {
    mode = pose_filter_mode::offline;
  } else if (value == "live" || value == "euro") {
    mode = pose_filter_mode::live;
  } else if (value == "none") {
    mode = pose_filter_mode::none;
  } else if (value == "landmarks") {
    mode = pose_filter_mode::none;
    points = true;
  } else if (value == "both") {
    mode = pose_filter_mode::live;
    points = true;
  } else {
    return false;
  }
  job.filter_mode = mode;
  job.filter.enabled = mode == pose_filter_mode::live;
  job.landmark_filter.enabled = points;
  return true;
}

}  // namespace avatarmap::cli
