// The proxy skeleton's proportions (a 1.70 m person, scalable) and its forward kinematics: the
// rest offsets of the VRM 1.0 humanoid bones that the proxy pose's rotations act on. Exports
// that write proxy poses without an avatar (.vrma, proxy .bvh) take their rest translations
// from it; the synthetic ground truth (synth/) turns a proxy_pose (local rotations in VRM
// normalised space + hips_position) into joint positions here, then into landmarks.
//
// Space: VRM (metres, Y up, the avatar faces +Z, avatar's left = +X); rest = VRM T-pose.
// For every bone, offsets[primary child] == lengths[bone] * bone_rest_direction(bone), so a
// bone's rest direction (docs/conventions.md) is exactly the direction from its joint to its
// primary child's joint (leaves: to their tip). Everything here is allocation-free.
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "avatarmap/skeleton/bone.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

/// Height of the reference person the proportion table is written for (metres).
inline constexpr float k_proxy_reference_height = 1.70f;

/// Rest skeleton of a synthetic person. Build with make_proxy_skeleton(); the fields are
/// plain data so that tests can inspect (or deliberately break) them.
struct proxy_skeleton {
  float height = k_proxy_reference_height;  // metres, top of the head above the soles
  float scale = 1.f;                        // height / k_proxy_reference_height
  /// Rest offset of each bone's joint from its parent's joint (VRM, metres). hips: zero.
  std::array<glm::vec3, k_bone_count> offsets{};
  /// Length of each bone along bone_rest_direction(): to its primary child's joint, or to its
  /// tip for leaves (head, eyes, jaw, distal finger bones, toes). Metres, > 0.
  std::array<float, k_bone_count> lengths{};
  /// Heel point in the foot's frame (rest VRM axes, metres from the foot joint), both feet.
  glm::vec3 heel_offset{0.f, -0.07f, -0.06f};
};

/// Rest skeleton of a person `height` metres tall (every length of the 1.70 m table scaled
/// by height / 1.70). `height` must be positive and finite (asserted); 1.70 by default.
proxy_skeleton make_proxy_skeleton(float height = k_proxy_reference_height);

/// Forward kinematics of one pose: world rotations, joint positions and bone tips (VRM space,
/// metres). joints[hips] = pose.hips_position; joints[b] = joints[parent] +
/// world[parent] * offsets[b]; tips[b] = joints[b] + world[b] * (lengths[b] * rest_dir(b)).
struct proxy_fk {
  std::array<glm::quat, k_bone_count> world{};
  std::array<glm::vec3, k_bone_count> joints{};
  std::array<glm::vec3, k_bone_count> tips{};
  glm::vec3 heels[2]{};  // [0] left, [1] right: foot joint + foot world * heel_offset
};

/// Fills `out` for `pose` (rotations need not be normalised: they are used as given, so pass
/// unit quaternions).
void compute_proxy_fk(const proxy_skeleton& skeleton, const proxy_pose& pose, proxy_fk& out);

/// The feet's points alone ([0] left, [1] right): what proxy_fk::heels and
/// proxy_fk::tips[left_toes / right_toes] hold, with the same arithmetic on the legs' bones
/// only (hips to toes: 9 of the 55 bones), for per-frame foot measurements.
struct proxy_feet {
  glm::vec3 heels[2]{};
  glm::vec3 toe_tips[2]{};
};

/// Fills `out` for `pose`, bit for bit as compute_proxy_fk would.
void compute_proxy_feet(const proxy_skeleton& skeleton, const proxy_pose& pose, proxy_feet& out);

/// Joint positions only (VRM, metres), as in proxy_fk::joints.
void joint_world_positions(const proxy_skeleton& skeleton, const proxy_pose& pose,
                           std::array<glm::vec3, k_bone_count>& out_joints);

/// Height of the hips joint above the soles in the rest pose (metres); the sole is the lowest
/// of the heel and toe-tip points.
float standing_hips_height(const proxy_skeleton& skeleton);

/// Y (VRM, metres) of the lowest heel or toe-tip point of `pose`.
float lowest_foot_point(const proxy_skeleton& skeleton, const proxy_pose& pose);

/// Moves pose.hips_position.y so that the lowest heel or toe-tip point lies at Y = 0.
void ground_pose(const proxy_skeleton& skeleton, proxy_pose& pose);

}  // namespace avatarmap
