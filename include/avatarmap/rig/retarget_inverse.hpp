// The inverse of the retargeter (rig/retarget.hpp): a rig pose of a bound rig -> the proxy pose
// that retargeter::apply turns into it. Reads motion made on a real skeleton (a BVH file, the
// performer's own mocap) as proxy poses.
//
// The retargeter sets, for a joint j bound to proxy bone b,  world_j = C⁻¹ · Q_b · C · T_j · W_j.
// With every proxy rotation identity it sets world_j = C⁻¹ · C · T_j · W_j =: R_j (the joint's
// "proxy rest" world rotation), so  Q_b = C · world_j · R_j⁻¹ · C⁻¹.  R_j is taken from the
// retargeter itself (apply on the identity pose, then the rig's forward kinematics), so the
// inverse follows the retargeter whatever its rest alignment does. The hips: the retargeter's
// hips translation is affine in hips_position (rest position + scale × position, in the hips'
// parent's space); the inverse probes that map with four poses and inverts it.
//
// proxy → rig → proxy is the identity on bound bones (their world rotations; their local
// rotations when every unbound proxy bone is identity) and on hips_position. Bones whose joint
// the rig lacks get identity (their rotation lands in their nearest bound descendant, as the
// retargeter folds it). Joints driven by a table's formulas (SysMocap) are read by the same
// rest-aware rule, which does not invert the formulas exactly.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

class inverse_retargeter {
 public:
  /// Precomputes the inverse of `forward` (built; its rig must outlive this object). `options`
  /// must be the ones `forward` was built with (their basis C: auto_basis picks it from the
  /// rig's source as retargeter::build does). The hips are inverted when the retargeter moves
  /// them (root_motion on, keep_feet_on_ground off); else apply gives hips_position 0. Fails
  /// (invalid_argument) when `forward` was not built. Allocates; call once. Not thread-safe
  /// (scratch space): one inverse per thread.
  status build(const retargeter& forward, const retarget_options& options = {});

  /// The proxy pose of `in` (a rig_pose of the forward's rig: one local rotation per joint and
  /// the hips joint's local translation) into `out`: rotations of bound bones from their
  /// joints' posed world rotations, identity for the others; confidence 1 for bound bones, 0
  /// for the others; hips_position by the inverted affine map (0 when the forward does not
  /// move the hips). `out.t`, expressions and foot_contact are left as they are. Non-finite
  /// or zero rotations in `in` are taken as the joint's rest rotation; a non-finite hips
  /// translation as the rest translation. Allocation-free once built.
  void apply(const rig_pose& in, proxy_pose& out) const;

  /// As apply, from posed world rotations (one per rig joint, rig order) and the hips joint's
  /// posed world position (rig world units; taken into the hips parent's rest space, as the
  /// retargeter places the hips). Allocates (a tool's entry, not the per-frame path).
  void apply_world(const std::vector<glm::quat>& world, const glm::vec3& hips_world,
                   proxy_pose& out) const;

  const rig& target() const { return *rig_; }

 private:
  const rig* rig_ = nullptr;
  bone_binding binding_{};
  glm::quat basis_{1.f, 0.f, 0.f, 0.f};
  std::vector<glm::quat> rest_inverse_;  // R_j⁻¹ · C⁻¹ for bound joints
  int hips_ = -1;
  // hips_position = hips_linear_inverse_ · (hips_local - hips_offset_); valid when
  // hips_invertible_.
  glm::mat3 hips_linear_inverse_{1.f};
  glm::vec3 hips_offset_{0.f};
  bool hips_invertible_ = false;
  glm::mat4 hips_parent_rest_inverse_{1.f};  // world -> hips parent's rest space
  mutable std::vector<glm::quat> world_;     // scratch: posed world rotations
};

}  // namespace avatarmap
