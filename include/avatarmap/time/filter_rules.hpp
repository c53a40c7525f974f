// The temporal filter rules of a pose stream (solve/pose_stream.hpp), written once for every
// caller (the solve-file job, the capture pipeline, the C solver, the CLI's --filter and
// --smoothing, avm_solver_options): which filter runs after solving, which channels take its
// output, point filtering before solving, their defaults and their validation, and the range
// of the offline filter's strength (docs/smoothing.md).
#pragma once

#include <cmath>
#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/time/foot_contacts.hpp"
#include "avatarmap/time/offline_smoother.hpp"
#include "avatarmap/time/one_euro.hpp"
#include "avatarmap/time/pose_filter.hpp"

namespace avatarmap {

/// Which channels of a solved pose take pose_filter's output; a channel that is off keeps the
/// solver's value (pose_filter itself filters all channels or none).
struct pose_filter_channels {
  bool rotations = true;
  bool position = true;
  bool expressions = true;  // the expression weights and the ARKit blendshape weights
};

/// Filters `raw` into `out` with `filter`, then puts back the channels of `raw` whose
/// filtering `channels` turns off. `out` must not be `raw`. Allocates nothing.
inline void filter_pose_channels(pose_filter& filter, const pose_filter_channels& channels,
                                 const proxy_pose& raw, proxy_pose& out) {
  filter.apply(raw, out);
  if (!channels.rotations) out.rotations = raw.rotations;
  if (!channels.position) out.hips_position = raw.hips_position;
  if (!channels.expressions) {
    out.expressions = raw.expressions;
    out.blendshapes = raw.blendshapes;
  }
}

/// How solved poses are smoothed over time (docs/smoothing.md).
enum class pose_filter_mode : unsigned char {
  /// Zero-phase smoothing and gap filling with a bounded lookahead (offline_smoother): the
  /// default for files. The solver's confidence gate is opened (thresholds 0) so that every
  /// measured bone reaches the smoother, which decides what is observed with the future in
  /// view (offline_smoother_options::observed_above) and fills or eases the rest.
  offline,
  /// The causal One Euro filter (pose_filter, `filter`): what a live stream gets; the solver's
  /// gate as configured in `options`.
  live,
  /// No temporal filter after solving (the solver's gate as configured).
  none,
};

/// The filters of a pose stream: point filtering before solving, then one of the pose filters
/// after it. The field names are the solve-file job's (its messages name them).
struct pose_stream_filters {
  /// Which filter runs after solving; `offline` and `live` use the options below.
  pose_filter_mode filter_mode = pose_filter_mode::offline;
  /// Options of the offline filter (filter_mode offline).
  offline_smoother_options offline{};
  /// Options of the live filter (filter_mode live; filter.enabled = false is the same as none).
  pose_filter_options filter{};
  /// Channels that take the live filter's output (filter_mode live only).
  pose_filter_channels filter_channels{};
  /// Point filtering before solving: off unless asked for.
  landmark_filter_options landmark_filter = [] {
    landmark_filter_options o;
    o.enabled = false;
    return o;
  }();
  /// Foot contacts and root motion after the filter (time/foot_contacts.hpp): both-sided with
  /// the offline filter, causal with the others; on by default.
  foot_contact_options foot_contacts{};

  /// Checks the One Euro parameters of `filter` (min_cutoff and d_cutoff finite and > 0, beta
  /// finite and >= 0: "filter.rotation.min_cutoff must be finite and > 0"), filter_mode known,
  /// `offline` (offline_smoother_options::validate, whatever the mode) and `foot_contacts`
  /// (foot_contact_options::validate). The message names the field.
  status validate() const;
};

/// The largest strength of the offline filter (the CLI's --smoothing, avm_solver_options'
/// file_smoothing) with the default sigmas: the widest kernel, strength x the largest sigma
/// (0.3 s, the fingers'), is at most 2 s (offline_smoother_options::validate; 6.67).
inline constexpr float k_max_smoothing = offline_smoother_options{}.max_strength();

/// The one rule for a smoothing strength given by a user (--smoothing,
/// avm_solver_options.file_smoothing): offline_smoother_options::validate with `value` as the
/// strength of the default options, i.e. finite, >= 0 and at most k_max_smoothing. The error
/// names `name` and the range, rounded down: "NAME must be finite and in [0, 6.66] (1 =
/// default)".
status check_smoothing(double value, const std::string& name);

}  // namespace avatarmap
