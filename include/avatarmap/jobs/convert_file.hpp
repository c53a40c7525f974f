// The convert workflow, written once for the CLI (`convert`, and `animate` through it), the C
// API (avm_convert_file; avm_clip_read reads with the same reader) and Python
// (avatarmap.convert_file and the Dask batch): read a motion file of any kind (landmarks,
// proxy poses, VRM Animation) into proxy poses, put them in time order by the one rule below,
// bind the avatar when the output uses one (bind_avatar), and write the output with
// clip_output_job.
//
// The one rule for frame times, for every input and every output: the frames are sorted by
// time, stably (at equal times the frame read later stays later, so it wins where resampling
// keeps one frame per time), and the number of frames that were earlier than the frame before
// them is counted (summary out_of_order) and told once through the warning callback. A
// landmark file is solved in its own order first (the solver starts again where time goes
// back), then its poses are sorted like any other input's.
//
// Memory: the whole clip is held (~1.2 kB per frame), plus the resampled copy the output needs.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/jobs/clip_output.hpp"
#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/rig/bound_avatar.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

enum class motion_input : std::uint8_t { landmarks, poses, vrma, bvh };

/// One kind of motion input.
struct motion_input_info {
  motion_input kind;
  std::string_view extension;    // lower case, with the dot: ".pose.jsonl"
  std::string_view description;  // for help texts and messages
};

/// Every motion input, in the order messages list them.
inline constexpr std::array<motion_input_info, 4> k_motion_inputs = {{
    {motion_input::landmarks, ".landmarks.jsonl", "landmarks (solved as `avatarmap solve` does)"},
    {motion_input::poses, ".pose.jsonl", "proxy poses"},
    {motion_input::vrma, ".vrma", "VRM Animation"},
    {motion_input::bvh, ".bvh", "BVH motion (read on its own skeleton, rig/bvh_rig.hpp)"},
}};

/// The inputs as a phrase: "*.landmarks.jsonl, *.pose.jsonl, *.vrma or *.bvh".
std::string motion_input_list();

/// The kind of motion input at `path`, by one rule:
///  1. the name's extension, compared without regard to ASCII case: k_motion_inputs;
///  2. "-" (standard input): landmarks;
///  3. a regular file (not a FIFO or a device, which could be read only once): its first
///     bytes: "glTF" is a .vrma; a first line that is a JSON header whose "format" is
///     "avatarmap.pose" or "avatarmap.landmarks" is that;
///  4. another name ending in .jsonl (any case): landmarks (a landmark file need not start
///     with a header).
/// Fails (invalid_argument) naming the path and the inputs when none applies. `out_stem` (optional)
/// gets the path without the extension that decided (rule 3: without the last extension, if any).
/// Never throws but for std::bad_alloc.
status find_motion_input(const std::string& path, const motion_input_info*& out,
                         std::string* out_stem = nullptr);

/// A motion file read into proxy poses.
struct motion_clip {
  const motion_input_info* input = nullptr;
  /// The poses in time order (the rule above). Times are finite.
  std::vector<proxy_pose> frames;
  /// The input's nominal rate: a pose file's header fps, a landmark file's (as `avatarmap
  /// solve` would write it: solve_file_summary::fps), a BVH's 1 / Frame Time; 0 for a .vrma or
  /// when not given.
  double source_fps = 0.0;
  /// Frames that were earlier than the frame before them (0: read in order; nothing moved).
  std::size_t out_of_order = 0;
  /// The landmark solve's summary (landmark input only).
  solve_file_summary solve;
};

/// Reads `path` (find_motion_input) into `out` (replaced): a pose file as written, a .vrma at
/// its key times (read_vrma), a .bvh at i × Frame Time through its own skeleton
/// (read_bvh_motion: bound by the tables' "auto", units detected), a landmark file solved by
/// `solve` (a copy of it with `input` and a sink set: its options, filters, threads, progress and
/// warnings apply) — or refused (invalid_argument) when `solve` is null; then the frames put in
/// time order. Fails with the reader's status (io: cannot be read; parse: a malformed line, naming
/// the file and line, or a malformed .vrma), or the solve's. An empty file is no error (no frames).
/// Never throws but for std::bad_alloc.
status read_motion(const std::string& path, const solve_file_job* solve, motion_clip& out);

/// What a convert did.
struct convert_file_summary {
  const motion_input_info* input = nullptr;  // the kind read
  std::size_t frames_read = 0;               // poses read or solved, before resampling
  std::size_t out_of_order = 0;              // see motion_clip::out_of_order
  double t_first = 0.0;                      // first and last time read (seconds, sorted)
  double t_last = 0.0;
  double source_fps = 0.0;     // the input's nominal rate (motion_clip::source_fps)
  solve_file_summary solve;    // landmark input only
  clip_output_summary output;  // what was written (format, frames, rate)
  /// The avatar as bound, when the output used one (null otherwise): its rig and how it was
  /// bound (bound_avatar::description), for reports and diagnostics. When binding it failed,
  /// as far as it got (bound_avatar::failed_step says where).
  std::shared_ptr<const bound_avatar> avatar;
  double seconds = 0.0;  // wall-clock time of the run
};

/// The job. Fill the inputs, call run(). Thread-safety: a job may be run from any thread; the
/// callbacks are called on the thread that called run().
struct convert_file_job {
  /// The motion file to read (find_motion_input's rule; "-" = landmarks on standard input).
  std::string input;
  /// The file to write; its extension chooses the format (k_clip_formats). Written atomically.
  std::string output;
  /// 0: the frames' own times (avatar outputs: k_default_rig_fps); > 0: resampled at that rate
  /// from the first frame, at most k_max_output_fps (clip_output_job::fps).
  double fps = 0.0;
  /// How a landmark input is solved (its options, filters, threads, progress, warnings); its
  /// input, output and sink are set by the job. Ignored for other inputs.
  solve_file_job solve{};
  /// The avatar file, "" for none. Needed by .glb; turns .bvh into the avatar's rig; not
  /// loaded for .vrma and .pose.jsonl, which do not use it.
  std::string avatar;
  /// How the avatar is bound (bind_avatar).
  bind_avatar_options binding{};
  bool keep_feet_on_ground = false;  // see retarget_clip_job
  bool root_motion = true;
  /// Foot locking on the output (clip_output_job::foot_lock); a leg of the avatar that cannot
  /// be locked is told through `warning`.
  foot_lock_options foot_lock{};
  /// What messages call the avatar when a format needs one (the CLI says "--avatar AVATAR").
  std::string avatar_name = "an avatar";
  /// Optional: what the run warns about (frames out of time order; the landmark solve's
  /// warnings unless solve.warning is set), one sentence each without a "warning:" prefix.
  std::function<void(const std::string&)> warning;
  /// Optional, for diagnostics: the proxy frames written (resampled as written) and, for
  /// avatar outputs, the rig poses (clip_output_job::out_frames, out_rig_poses).
  std::vector<proxy_pose>* out_frames = nullptr;
  std::vector<rig_pose>* out_rig_poses = nullptr;

  /// Checks what needs no file: input and output set, the output's extension known
  /// (clip_format_for), fps finite in [0, k_max_output_fps], an avatar given where the format
  /// needs one ("<ext> output needs <avatar_name> (the model to animate)") and is no .bvh
  /// skeleton there (a .glb animates a mesh), the solve's options
  /// (solve_file_job::validate). All invalid_argument.
  status validate() const;
  /// validate(), then: the input's kind (find_motion_input), the avatar bound when the output
  /// uses it (before the long work: a bad avatar fails first), the input read (read_motion;
  /// "INPUT has no frames" when it has none), the output written (clip_output_job). `out` is
  /// replaced. Fails with the failing step's status (its code kept). Never throws but for
  /// std::bad_alloc.
  status run(convert_file_summary& out) const;
};

}  // namespace avatarmap
