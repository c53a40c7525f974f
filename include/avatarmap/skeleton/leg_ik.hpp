// Two-bone inverse kinematics for a leg (hip -> knee -> ankle), written once for every skeleton
// that locks feet: the target rig (rig/foot_lock.hpp) and the proxy skeleton. Pure geometry on
// points in any right-handed space and unit (metres, centimetres: the caller's); no state, no
// allocation, never NaN for finite input.
#pragma once

#include <glm/glm.hpp>

namespace avatarmap {

/// Where the knee and the ankle go.
struct two_bone_ik_result {
  glm::vec3 knee{0.f};
  glm::vec3 ankle{0.f};
  /// True when the target lies within reach (|upper - lower| <= distance <= upper + lower);
  /// false: the leg points straight at the target (too far) or folds as far as it can along
  /// the line to it (too near), and `ankle` is the nearest point the leg reaches.
  bool reached = false;
};

/// Places a chain of two bones of lengths `upper` (hip -> knee) and `lower` (knee -> ankle),
/// both > 0, from `hip` so that the ankle lies on `target`. The knee bends towards `pole`: a
/// point (e.g. the knee before the IK) whose offset from the hip-target line, projected
/// perpendicular to it, gives the bend direction, so the knee stays in the plane through hip,
/// target and pole. When the pole lies on that line (a straight leg), `fallback_bend` (a
/// direction, e.g. the body's forward) takes its place, and failing that any perpendicular.
/// The bone lengths are kept exactly (to float precision) in every case. Non-finite input
/// gives the hip for both points and reached = false.
two_bone_ik_result solve_two_bone_ik(const glm::vec3& hip, float upper, float lower,
                                     const glm::vec3& target, const glm::vec3& pole,
                                     const glm::vec3& fallback_bend = glm::vec3(0.f, 0.f, 1.f));

/// How far (>= 0, along -`up`, a unit vector) the hip must move down so that `target` is
/// within `reach` of it: 0 when it already is; when the target's horizontal distance (across
/// `up`) is at least `reach`, the drop that brings the hip level with the target (the nearest
/// the leg can get by lowering alone). Non-finite input gives 0.
float hip_drop_to_reach(const glm::vec3& hip, const glm::vec3& target, float reach,
                        const glm::vec3& up = glm::vec3(0.f, 1.f, 0.f));

}  // namespace avatarmap
