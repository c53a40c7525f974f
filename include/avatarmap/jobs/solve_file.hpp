// The landmarks-file -> proxy-poses workflow, written once for the CLI (`solve`, `demo`,
// `convert` of a landmark file) and the C API (avm_solve_file): read a *.landmarks.jsonl,
// solve every frame, filter and optionally resample at a fixed rate (solve/pose_stream.hpp:
// landmark_filter before solving, offline_smoother or pose_filter after, by the filter rules
// of time/filter_rules.hpp), and write a *.pose.jsonl or hand each pose to a sink.
//
// Memory: one frame in flight (or a ring of 64 parsed frames with threads = 2) and, with the
// offline filter, its window of poses (offline_smoother_options::capacity_frames, ~300 kB by
// default); the poses are streamed, never held all. Per-frame state lives in the pose stream
// the job creates for one run.
//
// The face: before solving, the job calibrates the face's neutral over the take
// (frame_solver::calibrate_face; docs/expressions.md, "Calibration over a take"): a regular
// file is read once beforehand for it (whatever the filter); a source callback, a pipe or
// standard input is calibrated over its first 300 frames, held back until then (so a take of
// 300 frames or fewer gives the same poses either way).
#pragma once

#include <functional>
#include <limits>
#include <string>

#include "avatarmap/core/limits.hpp"
#include "avatarmap/core/option_table.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/body_plausibility.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "avatarmap/time/filter_rules.hpp"  // pose_filter_mode, pose_filter_channels
#include "avatarmap/time/offline_smoother.hpp"
#include "avatarmap/time/pose_filter.hpp"

namespace avatarmap {

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
  /// The input was opened and its header read: a parse error after it is a malformed line
  /// (which skip_bad_lines would skip), not a malformed header.
  bool input_opened = false;
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
  /// The camera's pitch (degrees, + = looking down) and roll relative to gravity learnt from
  /// the standing body and the floor (frame_solver::camera_pitch_degrees()), from
  /// gravity_evidence_frames standing frames and floor_evidence_points resting points (both
  /// 0: a level camera was assumed, or the body was not fitted to the image).
  float camera_pitch_degrees = 0.f;
  float camera_roll_degrees = 0.f;
  long gravity_evidence_frames = 0;
  long floor_evidence_points = 0;  // the feet's resting points, when the floor decided
  /// Frames whose lower body was held at rest (solver_options::lower_body_rest; the body's
  /// points not a person's, or the legs not seen), among body_frames frames with a body; of
  /// them, those whose spine and arms were not followed either, and how many had each doubt
  /// (solve/body_plausibility.hpp, bit index order). A warning says it when any was held.
  body_hold_stats body_hold{};
  /// The point of the solver's ground space the root was measured from (where the person, or
  /// origin_person, was first seen); has_ground_origin false when no frame had a body.
  bool has_ground_origin = false;
  float ground_origin[2] = {0.f, 0.f};
};

/// The job. Fill the inputs, call run(). Thread-safety: a job may be run from any thread; the
/// callbacks are called on the thread that called run(). Its filter fields (filter_mode,
/// offline, filter, filter_channels, landmark_filter) are the pose stream's, inherited from
/// pose_stream_filters (time/filter_rules.hpp), which owns their rules.
struct solve_file_job : pose_stream_filters {
  /// *.landmarks.jsonl to read ("-" = standard input). With `source` set: only the name that
  /// messages give the frames (e.g. "frames"; empty = "frames").
  std::string input;
  /// When set, frames come from here instead of a file (frames held in memory, e.g. the C
  /// API's avm_solve_frames): each call fills `out` with the next frame and returns ok, or
  /// sets `end` = true when there are no more; an error it returns ends the run with that
  /// error, its code kept (invalid_argument: the caller's frames are its arguments). Pulled on the
  /// thread that calls run() (`threads` does not apply); no header: the image size is
  /// image_width/height or options.image_width/height, the output's fps 0.
  std::function<status(landmark_frame& out, bool& end)> source;
  /// Which person of a file of several (docs/file-formats.md, version 2) is solved; -1: the
  /// file's only person (a file of several people is then refused: jobs/people.hpp plans one
  /// run per person). Not used with `source`.
  int person = -1;
  /// Of a file of several people: measure the root (hips_position X/Z) from where person
  /// `origin_person` was first seen (that person's own solve of this file gives the point)
  /// instead of where `person` was, so that people stand apart as in the video, as live places
  /// them. -1: the file's lowest id when the file (a regular, version-2 one) holds several
  /// people, else `person` itself. Costs a solve of that person first (when it is not
  /// `person`). Give `person` itself to measure from its own first place. Not used with
  /// `source`.
  int origin_person = -1;
  /// *.pose.jsonl to write ("-" = standard output), atomically: on failure an existing file is
  /// left as it was. Ignored when `sink` is set.
  std::string output;
  /// When set, every output pose goes here instead of a file; an error it returns ends the
  /// run with that error, its code kept.
  std::function<status(const proxy_pose&)> sink;
  solver_options options{};
  /// Image size in pixels; 0 = the file's header's, else options.image_width/height (when
  /// those are 0 too, square pixels are assumed and the summary says so).
  float image_width = 0.f;
  float image_height = 0.f;
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
  /// valid, image size finite and >= 0 (both or neither), output_fps finite in [0, k_max_fps],
  /// threads 1 or 2, and the filter fields by the filter rules (pose_stream_filters::validate:
  /// filter_mode known, filter parameters positive, offline options valid). The message names
  /// the field.
  status validate() const;
  /// validate(), then the whole run into `out` (replaced). Fails with a message naming the
  /// file (and line or frame) and the code of the step that failed: invalid_argument (the
  /// fields, a source's frame, times too far apart for output_fps), io (the input cannot be
  /// opened or read, the output cannot be written), parse (a malformed header or line),
  /// out_of_memory; a sink's error keeps its own code. Never throws but for std::bad_alloc.
  status run(solve_file_summary& out) const;
};

/// The solve-file job's options as the front ends take them (the CLI's solve and convert
/// flags, avm_solver_options' filter and file fields, Python's solve and Solver), one row per
/// option; the rows the C struct has come in its order, with its names (the live filter's
/// parameters serve the C solver handle too). core/option_table.hpp.
inline constexpr option_row<solve_file_job> k_solve_file_option_table[] = {
    option_row<solve_file_job>("filter_rotations",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter_channels.rotations))
        .boolean()
        .help("the live filter smooths the bone rotations"),
    option_row<solve_file_job>("rotation_min_cutoff",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter.rotation.min_cutoff))
        .number(0, std::numeric_limits<double>::infinity(), true)
        .cli("--min-cutoff", "HZ")
        .help("live: One Euro cutoff at rest for rotations"),
    option_row<solve_file_job>("rotation_beta",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter.rotation.beta))
        .number(0, std::numeric_limits<double>::infinity())
        .cli("--beta", "B")
        .help("live: One Euro speed coefficient for rotations"),
    option_row<solve_file_job>("rotation_d_cutoff",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter.rotation.d_cutoff))
        .number(0, std::numeric_limits<double>::infinity(), true)
        .help("live: cutoff of the rotations' speed estimate (Hz)"),
    option_row<solve_file_job>("filter_position",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter_channels.position))
        .boolean()
        .help("the live filter smooths the hips position"),
    option_row<solve_file_job>("position_min_cutoff",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter.position.min_cutoff))
        .number(0, std::numeric_limits<double>::infinity(), true)
        .help("live: One Euro cutoff at rest for the hips position (Hz)"),
    option_row<solve_file_job>("position_beta",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter.position.beta))
        .number(0, std::numeric_limits<double>::infinity())
        .help("live: One Euro speed coefficient for the hips position (s/m)"),
    option_row<solve_file_job>("position_d_cutoff",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter.position.d_cutoff))
        .number(0, std::numeric_limits<double>::infinity(), true)
        .help("live: cutoff of the position's speed estimate (Hz)"),
    option_row<solve_file_job>("filter_expressions",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter_channels.expressions))
        .boolean()
        .help("the live filter smooths the expressions"),
    option_row<solve_file_job>("expression_min_cutoff",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter.expression.min_cutoff))
        .number(0, std::numeric_limits<double>::infinity(), true)
        .help("live: One Euro cutoff at rest for the expressions (Hz)"),
    option_row<solve_file_job>("expression_beta",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter.expression.beta))
        .number(0, std::numeric_limits<double>::infinity())
        .help("live: One Euro speed coefficient for the expressions"),
    option_row<solve_file_job>("expression_d_cutoff",
                               AVATARMAP_OPTION_FIELD(solve_file_job, filter.expression.d_cutoff))
        .number(0, std::numeric_limits<double>::infinity(), true)
        .help("live: cutoff of the expressions' speed estimate (Hz)"),
    option_row<solve_file_job>("file_filter", AVATARMAP_OPTION_FIELD(solve_file_job, filter_mode))
        .choices("offline|live|none")
        .help("the filter after solving a file: offline (zero-lag smoothing that sees 1.5 s "
              "ahead and fills gaps), live (the causal One Euro filter) or none"),
    option_row<solve_file_job>("file_smoothing",
                               AVATARMAP_OPTION_FIELD(solve_file_job, offline.strength))
        .number(0, k_max_smoothing)
        .cli("--smoothing", "S")
        .help("scale on the offline filter's time constants (0 = fill gaps only, 2 = twice as "
              "smooth)"),
    option_row<solve_file_job>("file_threads", AVATARMAP_OPTION_FIELD(solve_file_job, threads))
        .integer(1, 2)
        .cli("--threads", "1|2")
        .help("2 parses the input on a second thread; 1 does all on one"),
    option_row<solve_file_job>("foot_contacts",
                               AVATARMAP_OPTION_FIELD(solve_file_job, foot_contacts.enabled))
        .boolean()
        .cli(nullptr, nullptr, "--no-foot-contacts")
        .help("--no-foot-contacts: no foot contact detection (foot_contact 0, the hips as "
              "filtered); default: planted feet are detected and the hips follow them "
              "(docs/contacts.md)"),
    option_row<solve_file_job>(
        "root_follows_contacts",
        AVATARMAP_OPTION_FIELD(solve_file_job, foot_contacts.root_follows_contacts))
        .boolean()
        .cli(nullptr, nullptr, "--no-root-follow")
        .help("--no-root-follow: detect foot contacts but leave the hips as filtered (default: "
              "the hips move so that a planted foot stays where it landed)"),
    option_row<solve_file_job>("person", AVATARMAP_OPTION_FIELD(solve_file_job, person))
        .integer(-1, k_max_person_id)
        .cli("--person", "ID")
        .help("of a file of several people, solve only person ID (default: each person to its "
              "own output, the id before the extension: take.p0.glb, take.p1.glb)"),
    option_row<solve_file_job>("origin_person",
                               AVATARMAP_OPTION_FIELD(solve_file_job, origin_person))
        .integer(-1, k_max_person_id)
        .cli("--origin-person", "ID")
        .not_in_c()
        .help("of a file of several people, measure every root from where person ID was first "
              "seen, so that people stand apart as in the video; -1: the file's lowest id, as "
              "live does; a person's own id: its own first place"),
    option_row<solve_file_job>("output_fps", AVATARMAP_OPTION_FIELD(solve_file_job, output_fps))
        .number(0, k_max_fps, true)
        .or_zero()
        .cli("--fps", "N")
        .not_in_c()
        .help("resample the output at N frames per second (slerp between capture frames); 0: "
              "one pose per input frame. Frames earlier than the one before are skipped (a "
              "warning); at most 24 h of capture and 4194304 poses"),
    option_row<solve_file_job>("skip_bad_lines",
                               AVATARMAP_OPTION_FIELD(solve_file_job, skip_bad_lines))
        .boolean()
        .cli("--skip-bad-lines")
        .not_in_c()
        .help("report malformed lines and go on (default: stop at the first)"),
    option_row<solve_file_job>("write_confidence",
                               AVATARMAP_OPTION_FIELD(solve_file_job, write_confidence))
        .boolean()
        .cli("--confidence")
        .not_in_c()
        .help("also write per-bone confidence"),
};

}  // namespace avatarmap
