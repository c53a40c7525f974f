// Writing a clip of proxy poses to a file whose format is chosen by its extension, written once
// for the CLI (`convert`, `animate`) and the C API (avm_clip_write): one table of formats
// (case-insensitive extensions, what each needs), one check of the clip before any work, one
// writer call per format (resampling bounded by avatarmap/time/resample_clip.hpp; rig outputs
// retargeted by retarget_clip_job).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "avatarmap/core/limits.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/foot_lock.hpp"
#include "avatarmap/rig/mapping.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

enum class clip_format : std::uint8_t { vrma, glb, bvh, pose_jsonl };

/// One output format.
struct clip_format_info {
  clip_format format;
  std::string_view extension;    // lower case, with the dot: ".vrma"
  std::string_view description;  // for help texts
  bool needs_avatar;             // cannot be written without one (.glb: the avatar with the motion)
  bool uses_avatar;              // written on the avatar's rig when one is given (.glb, .bvh)
};

/// Every output format, in the order messages list them.
inline constexpr std::array<clip_format_info, 4> k_clip_formats = {{
    {clip_format::vrma, ".vrma", "VRM Animation", false, false},
    {clip_format::glb, ".glb", "the avatar with the motion (binary glTF)", true, true},
    {clip_format::bvh, ".bvh", "Biovision Hierarchy: the avatar's rig, else the proxy skeleton",
     false, true},
    {clip_format::pose_jsonl, ".pose.jsonl", "proxy poses, one JSON line per frame", false, false},
}};

/// Frame rate of avatar outputs (.glb, rig .bvh) when the job's fps is 0: they need a fixed rate.
inline constexpr double k_default_rig_fps = 30.0;
/// Highest output frame rate accepted: the one frame-rate limit (core/limits.hpp).
inline constexpr double k_max_output_fps = k_max_fps;

/// The format whose extension ends `path`, compared without regard to ASCII case ("X.VRMA" is
/// a .vrma); null when none does.
const clip_format_info* find_clip_format(std::string_view path);

/// The supported extensions as a phrase: ".vrma, .glb, .bvh or .pose.jsonl".
std::string clip_format_list();

/// find_clip_format, or an error "PATH: unknown output format; the name must end in <list>
/// (any case)" when `path` has none of the extensions.
status clip_format_for(const std::string& path, const clip_format_info*& out);

/// What a run wrote.
struct clip_output_summary {
  const clip_format_info* format = nullptr;
  std::size_t frames_written = 0;
  double fps = 0.0;                  // the rate written (0: the frames' own times)
  float standing_hips_height = 0.f;  // rig outputs with root motion (metres)
  /// "" or why foot locking is off for a leg of the avatar (foot_lock::warning()).
  std::string foot_lock_warning;
};

/// The job. The caller keeps `frames`, `avatar_rig` and `avatar_table` alive during run().
struct clip_output_job {
  /// The file to write; its extension chooses the format (k_clip_formats). Written atomically:
  /// on failure an existing file is left as it was.
  std::string path;
  /// The clip. Times must be finite; with fps > 0 (and for avatar outputs) they must not
  /// decrease (sort_clip_by_time); with fps 0, .vrma and .bvh need them strictly increasing.
  const std::vector<proxy_pose>* frames = nullptr;
  /// 0: the frames' own times (avatar outputs: k_default_rig_fps); > 0: resampled at
  /// t_first + k / fps, times from 0. At most k_max_output_fps.
  double fps = 0.0;
  /// The header fps of a .pose.jsonl written at fps 0 (0 = not given).
  double source_fps = 0.0;
  /// Names the clip in messages about its times (a file name; default: path).
  std::string what;
  /// The avatar file, "" for none. Needed by .glb; turns .bvh into the avatar's rig; ignored by
  /// .vrma and .pose.jsonl. When it is used, avatar_rig must be the rig built from it.
  std::string avatar_path;
  const rig* avatar_rig = nullptr;
  bone_binding avatar_binding{};
  const mapping_table* avatar_table = nullptr;  // formulas (rig_binding_choice::table_or_null())
  bool keep_feet_on_ground = false;             // see retarget_clip_job
  bool root_motion = true;
  /// Foot locking (docs/foot-locking.md): on the avatar's rig for avatar outputs
  /// (retarget_clip_job::foot_lock), on the proxy skeleton for .vrma and proxy .bvh when a
  /// frame has a foot contact (lock_feet); .pose.jsonl is written as given. Default on.
  foot_lock_options foot_lock{};
  /// Optional, for diagnostics: the proxy frames that were written (resampled as written) and,
  /// for avatar outputs, the rig poses.
  std::vector<proxy_pose>* out_frames = nullptr;
  std::vector<rig_pose>* out_rig_poses = nullptr;

  /// Everything that needs no avatar file, so that a caller can check before loading one:
  /// the extension, fps, frames set and not empty, every time finite, an avatar given where
  /// the format needs one, and the clip's span and output size (resampled_frame_count, at fps,
  /// or k_default_rig_fps for avatar outputs at 0, or 1 fps for the span alone). Messages name
  /// the path (times: `what`).
  status validate() const;
  /// validate(), then the write; `out` is replaced. Fails with a message naming the file and
  /// the code of the step that failed: invalid_argument (validate, the clip's hips heights, a
  /// clip a writer refuses), parse (a binding the retargeter refuses; the avatar re-read by
  /// .glb is malformed), io (the file cannot be written, the avatar cannot be re-read),
  /// out_of_memory. Never throws but for std::bad_alloc.
  status run(clip_output_summary& out) const;
};

}  // namespace avatarmap
