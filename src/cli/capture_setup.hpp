// What `capture`, `live` and `animate` share: the estimator options on the command line, the
// ONNX estimator they make, and the per-stage timing summary.
#pragma once

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/live/live_session.hpp"
#include "avatarmap/media/video_source.hpp"
#include "cli/cli_args.hpp"
#include "cli/option_flags.hpp"

namespace avatarmap::cli {

/// The estimator options' help lines (k_estimator_option_table's flags, with the command's
/// defaults: `hands_face_default` is what --hands/--face default to).
std::string estimator_options_help(bool hands_face_default);

/// Reads the flags of k_estimator_option_table (--model, --hands/--no-hands, --models, ...)
/// over the table's defaults; `hands_face_default` is what --hands/--face default to (capture
/// and live: off, animate: on). The models folder is find_resource()'s (io/resources.hpp) with
/// --models as its explicit folder. Returns false with a message for a bad value.
bool parse_estimator_options(args& a, bool hands_face_default, estimator_options& out,
                             std::string& error);

/// The input options' help lines: what INPUT may be, and the device and live-input options
/// (k_video_source_option_table's flags).
std::string input_options_help();

/// Reads the flags of k_video_source_option_table (--video-size, --framerate, --input-format,
/// --open-seconds, --stall-seconds) into `out`. False with a message for a malformed or
/// out-of-range value.
bool parse_input_options(args& a, video_source_options& out, std::string& error);

/// Appends the input and estimator flags (for animate, which hands them to capture), with the
/// hands and face defaulting to `hands_face_default` in their help.
void add_capture_flag_specs(bool hands_face_default, std::vector<flag_spec>& out);

/// Creates the ONNX estimator; the error says how to get the models.
status make_estimator(const estimator_options& options, std::unique_ptr<estimator>& out);
/// The same for a live session (its capture pipeline's estimator), with the same hint.
status make_live_session(const live_session_options& options, std::unique_ptr<live_session>& out);

/// Sums of estimator_timings over frames, for the summary line.
struct timing_totals {
  estimator_timings sum{};
  long frames = 0;
  long pose_detector_frames = 0, palm_frames = 0, face_detector_frames = 0;
  double startup_ms = 0;  // creating the estimator (loading the models); 0 = not measured
  void add(const estimator_timings& t);
  /// Prints "start-up: N ms (models)" when measured, then mean milliseconds per frame for
  /// each stage that ran.
  void print(std::FILE* to) const;
};

/// Resident memory of this process in KiB (from /proc/self/status; 0 when unknown).
long resident_kib();

}  // namespace avatarmap::cli
