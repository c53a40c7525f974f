// Retargeting a whole clip of proxy poses onto a built rig, written once for the CLI
// (`convert`, and `animate` through it) and the C API (avm_clip_write): the performer's
// standing hips height is taken from the clip (one rule, below), a retargeter is built for the
// rig and its binding, and every frame is applied.
#pragma once

#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/foot_lock.hpp"
#include "avatarmap/rig/mapping.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

/// The share of a clip's frames whose hips are at or below the standing height: the
/// performer stands for most of a capture, and squats, jumps and solver outliers are the rest.
inline constexpr int k_standing_hips_percentile = 90;

/// The performer's standing hips height (metres above the floor) from a clip: the
/// k_standing_hips_percentile-th percentile of the frames' hips_position.y (the value at index
/// n * 9 / 10 of the sorted heights; non-finite heights sort last). Fails, with a message that
/// starts with `what` and says what to do, when `frames` is empty or the percentile is not a
/// finite height > 0 (hips at or below the floor: the poses carry no root motion to scale).
/// `out_height` is 0 on failure.
status standing_hips_height(const std::vector<proxy_pose>& frames, const std::string& what,
                            float& out_height);

/// The job. The caller keeps `rig`, `binding`'s rig and `table` alive during run().
struct retarget_clip_job {
  /// The clip (times are not used: one rig pose per frame, in order).
  const std::vector<proxy_pose>* frames = nullptr;
  /// The built rig to drive and its binding (select_binding, or the CLI's --rig/--bind).
  const rig* target = nullptr;
  bone_binding binding{};
  /// The mapping table whose formulas apply (rig_binding_choice::table_or_null()); may be null.
  const mapping_table* table = nullptr;
  /// Move the hips each frame so that the lowest foot touches the floor.
  bool keep_feet_on_ground = false;
  /// Apply the clip's hips position (scaled by the rig's over the performer's standing hips
  /// height, see standing_hips_height()); false: the hips keep their rest translation and the
  /// standing height is neither needed nor checked.
  bool root_motion = true;
  /// Foot locking after the retarget, frame by frame in order (rig/foot_lock.hpp,
  /// docs/foot-locking.md): the feet planted by the frames' foot_contact stay put on the rig.
  /// foot_lock.enabled = false turns it off.
  foot_lock_options foot_lock{};
  /// Names the clip in messages (a file name, or the C function).
  std::string what = "clip";

  /// Checks frames (set, not empty), target (set), binding (every joint index -1 or within
  /// the rig) and foot_lock (foot_lock_options::validate). The message names the field.
  status validate() const;
  /// validate(), the standing height (root_motion only), retargeter::build, then one rig pose
  /// per frame into `out_poses` (replaced). On failure `out_poses` is empty and the status's
  /// code says why: invalid_argument for the fields and the clip's heights, parse for a
  /// binding the retargeter refuses. `out_warning`, when given, gets foot_lock::warning() (""
  /// when both legs can be locked or locking is off). Never throws but for std::bad_alloc.
  status run(std::vector<rig_pose>& out_poses, float* out_standing_height = nullptr,
             std::string* out_warning = nullptr) const;
};

}  // namespace avatarmap
