// The landmarks-file -> proxy-poses workflow, written once for the CLI (`solve`, `demo`,
// `convert` of a landmark file) and the C API (avm_solve_file): read a *.landmarks.jsonl,
// solve every frame (frame_solver), filter (landmark_filter before; offline_smoother or
// pose_filter after), optionally resample at a fixed rate (after the filter), and write a
// *.pose.jsonl or hand each pose to a sink.
//
// Memory: one frame in flight (or a ring of 64 parsed frames with threads = 2) and, with the
// offline filter, its window of poses (offline_smoother_options::capacity_frames, ~300 kB by
// default); the poses are streamed, never held all. Per-frame state lives in the solver, the
// filters and the resampler the job creates for one run.
#pragma once

#include <functional>
#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/jobs/job_failure.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "avatarmap/time/offline_smoother.hpp"
#include "avatarmap/time/pose_filter.hpp"

namespace avatarmap {

/// Which channels of a solved pose take pose_filter's output; a channel that is off keeps the
/// solver's value (pose_filter itself filters all channels or none).
struct pose_filter_channels {
  bool rotations = true;
  bool position = true;
  bool expressions = true;
};

/// Filters `raw` into `out` with `filter`, then puts back the channels of `raw` whose
/// filtering `channels` turns off. Allocates nothing.
inline void filter_pose_channels(pose_filter& filter, const pose_filter_channels& channels,
                                 const proxy_pose& raw, proxy_pose& out) {
  filter.apply(raw, out);
  if (!channels.rotations) out.rotations = raw.rotations;
  if (!channels.position) out.hips_position = raw.hips_position;
  if (!channels.expressions) out.expressions = raw.expressions;
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

/// What a solve_file_job reports to its progress callback.
struct solve_file_progress {
  long frames = 0;               // frames solved so far
  double capture_seconds = 0.0;  // their time span (last t - first t)
  double elapsed_seconds = 0.0;  // wall-clock time since the job started
};

/// What a run did.
struct solve_file_summary {
  long frames = 0;         // frames solved
  long poses_written = 0;  // poses written (or handed to the sink)
  long bad_lines = 0;      // malformed lines skipped (skip_bad_lines)
  /// With output_fps > 0: frames left out because their time was earlier than the frame before.
  long out_of_order = 0;
  long part_frames[k_frame_part_count] = {};  // frames that had each part
  long face_iris_frames = 0;                  // frames with a 478-point face
  double t_first = 0.0;                       // first and last solved frame's time (seconds)
  double t_last = 0.0;
  double seconds = 0.0;  // wall-clock time of the run
  double fps = 0.0;  // the nominal rate of the output (its header's): output_fps, else the input's
  float image_width = 0.f;  // the image size solved with (pixels; 0 = unknown)
  float image_height = 0.f;
  bool image_size_assumed = false;  // neither the job nor the file gave one: square pixels
  float hips_height_min = 0.f;      // range of the filtered hips_position.y (metres)
  float hips_height_max = 0.f;
  /// The camera's horizontal field of view solved with (degrees): the option when given, else
  /// the solver's estimate from the pose at the end of the run (fov_estimated), from
  /// fov_evidence_frames frames (0: the pose told nothing and 60 degrees was assumed).
  float horizontal_fov_degrees = 0.f;
  bool fov_estimated = false;
  long fov_evidence_frames = 0;
  /// Why the run failed (none on success).
  job_failure failure = job_failure::none;
};

/// The job. Fill the inputs, call run(). Thread-safety: a job may be run from any thread; the
/// callbacks are called on the thread that called run().
struct solve_file_job {
  /// *.landmarks.jsonl to read ("-" = standard input). With `source` set: only the name that
  /// messages give the frames (e.g. "frames"; empty = "frames").
  std::string input;
  /// When set, frames come from here instead of a file (frames held in memory, e.g. the C
  /// API's avm_solve_frames): each call fills `out` with the next frame and returns ok, or
  /// sets `end` = true when there are no more; an error it returns ends the run with that
  /// error (failure invalid_argument: the caller's frames are its arguments). Pulled on the
  /// thread that calls run() (`threads` does not apply); no header: the image size is
  /// image_width/height or options.image_width/height, the output's fps 0.
  std::function<status(landmark_frame& out, bool& end)> source;
  /// *.pose.jsonl to write ("-" = standard output), atomically: on failure an existing file is
  /// left as it was. Ignored when `sink` is set.
  std::string output;
  /// When set, every output pose goes here instead of a file; an error it returns ends the
  /// run with that error (failure output_io).
  std::function<status(const proxy_pose&)> sink;
  solver_options options{};
  /// Image size in pixels; 0 = the file's header's, else options.image_width/height (when
  /// those are 0 too, square pixels are assumed and the summary says so).
  float image_width = 0.f;
  float image_height = 0.f;
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
  /// 0 = one pose per input frame, in the file's order. > 0: poses at t_first + j / fps; a frame
  /// earlier than the one before it is skipped with a warning (counted in out_of_order), and a
  /// frame more than k_max_clip_seconds after the first, or more than k_max_resampled_frames
  /// poses in all, fail the run (avatarmap/time/resample_clip.hpp). At most 1000.
  double output_fps = 0.0;
  /// What messages call output_fps (the CLI says "--fps").
  std::string output_fps_name = "output_fps";
  /// Report malformed lines as warnings and go on; otherwise the first one fails the run
  /// (failure input_parse, the message naming the file and line).
  bool skip_bad_lines = false;
  /// Also write per-bone confidence.
  bool write_confidence = false;
  /// 2 parses on a second thread while solving and writing on this one; 1 does it all here.
  int threads = 2;
  /// Optional: called about every 256 frames, at most four times a second.
  std::function<void(const solve_file_progress&)> progress;
  /// Optional: what was skipped (the first five malformed lines and the first five frames out
  /// of order), one sentence each without a "warning:" prefix.
  std::function<void(const std::string&)> warning;

  /// Checks the fields that do not need the file: input or source set, output or sink set, options
  /// valid, image size finite and >= 0 (both or neither), output_fps finite in [0, 1000],
  /// threads 1 or 2, filter_mode known, filter parameters positive, offline options valid
  /// (offline_smoother_options::validate). The message names the field.
  status validate() const;
  /// validate(), then the whole run into `out` (replaced). Fails with a message naming the
  /// file (and line or frame) and out.failure set. Never throws but for std::bad_alloc.
  status run(solve_file_summary& out) const;
};

}  // namespace avatarmap
