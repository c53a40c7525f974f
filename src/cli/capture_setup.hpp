// What `capture`, `live` and `animate` share: the estimator options on the command line, the
// ONNX estimator they make, and the per-stage timing summary.
#pragma once

#include <cstdio>
#include <memory>
#include <string>

#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/media/video_source.hpp"
#include "cli/cli_args.hpp"

namespace avatarmap::cli {

/// The options' help lines (for the commands' --help texts).
extern const char* const k_estimator_options_help;

/// Reads --model, --hand-model, --threads, --models, --static, --hands, --face, --body-only,
/// --mirrored. `hands_face_default` is what --hands/--face default to (animate: on). Returns
/// false with a message for a bad value.
bool parse_estimator_options(args& a, bool hands_face_default, estimator_options& out,
                             std::string& error);

/// The input options' help lines: what INPUT may be, and the device and live-input options.
extern const char* const k_input_options_help;

/// Reads --video-size, --framerate, --input-format, --open-seconds and --stall-seconds into
/// `out` (checked by video_source::open). False with a message for a value that is not a
/// number.
bool parse_input_options(args& a, video_source_options& out, std::string& error);

/// Creates the ONNX estimator; the error says how to get the models.
status make_estimator(const estimator_options& options, std::unique_ptr<estimator>& out);
/// The same for a capture pipeline (estimator + solver + live filter), with the same hint.
status make_capture_pipeline(const capture_pipeline_options& options,
                             std::unique_ptr<capture_pipeline>& out);

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
