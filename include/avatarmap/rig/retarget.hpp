// Proxy pose -> a real rig's joint rotations, rest-pose aware (docs/conventions.md): the proxy's
// normalised rotations become world orientations of the rig's bones, whatever the rig's bone
// axes and rest rotations, so a humanoid rig works from its bone names alone.
//
// For a rig joint j bound to proxy bone b:  world_j = C⁻¹ · Q_b · C · T_j · W_j
//   Q_b  the proxy bone's world rotation in VRM space (its chain of normalised locals),
//   W_j  the joint's rest world rotation, C the rotation from the rig's world axes to VRM space
//        (identity for glTF / VRM 1.0, which face +Z; 180° about Y for VRM 0.x, which faces −Z),
//   T_j  the swing that turns the joint's rest bone direction onto the proxy's rest direction
//        (identity for a T-pose rig; straightens an A-pose rig's arms). The hips' direction
//        runs from the upper legs' midpoint (the proxy's hips joint) to the spine; clavicles,
//        feet, toes, eyes and jaw keep their rest direction (anatomy, not a pose: T_j = 1).
// Unbound joints keep their rest local rotation. A proxy bone whose joint the rig lacks (no
// chest, no upperChest) folds into its children automatically: they receive world
// orientations, so the missing rotation lands in the nearest present ancestor's child.
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/mapping.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

/// Which rig joint drives each proxy bone (-1: the rig has no such bone).
using bone_binding = std::array<int, k_bone_count>;

struct retarget_options {
  /// Rotation from the rig's world axes to VRM space (see the header comment). Default:
  /// chosen from rig.source (VRM 0.x: 180° about Y; otherwise identity).
  bool auto_basis = true;
  glm::quat basis{1.f, 0.f, 0.f, 0.f};
  /// Hips translation is scaled by the rig's hips height (rig_hips_height(): above its lowest
  /// foot/toe joint, the rig's floor reference, with its legs as the proxy's rest pose turns
  /// them) over `performer_hips_height` (metres, the performer's standing hips height above the
  /// soles): a performer standing puts the rig's lowest foot/toe joint on the floor reference
  /// (the hips at their rest height for a rig whose legs are straight at rest), half that
  /// height puts the hips halfway down to the floor reference.
  float performer_hips_height = k_default_hips_height;
  /// Move the hips each frame so that the lowest foot/toe joint touches Y = 0 (ground
  /// calibration); else hips_position is applied as is (scaled).
  bool keep_feet_on_ground = false;
  /// Apply hips_position at all (else the hips keep their rest translation).
  bool root_motion = true;
};

/// Output of one retarget: a local rotation per rig joint and the hips joint's local
/// translation (in its parent's units).
struct rig_pose {
  std::vector<glm::quat> local_rotations;  // one per rig joint, rig order
  glm::vec3 hips_translation{0.f};
  int hips_joint = -1;
};

class retargeter {
 public:
  /// Binds `r` (kept by reference: it must outlive the retargeter) with `binding`. Needs at
  /// least the hips bound; the error (status_code::parse: the binding does not fit the rig)
  /// names what is missing. Precomputes every constant.
  /// `table`, when given, supplies per-bone formulas (docs/mappings.md): bones with formulas
  /// take SysMocap's conversion (rest Euler angles + f(x, y, z) in the bone's order) instead
  /// of the rest-aware one; the formulas are copied.
  status build(const rig& r, const bone_binding& binding, const retarget_options& options = {},
               const mapping_table* table = nullptr);

  /// Sizes `out` for this rig (allocates; call once).
  void prepare(rig_pose& out) const;
  /// Applies one proxy pose. Allocation-free once `out` is prepared.
  void apply(const proxy_pose& pose, rig_pose& out) const;

  const rig& target() const { return *rig_; }
  const bone_binding& binding() const { return binding_; }
  /// Height of the rig's hips joint above its lowest foot joint (above its floor, rig::floor_y,
  /// when the file tells one) in the pose the rig takes for the proxy's rest pose (its rest
  /// with the bound bones turned onto the proxy's rest directions: spread or A-posed legs
  /// straightened), in world units.
  float rig_hips_height() const { return rig_hips_height_; }
  /// The rig's floor (rig world Y): where its lowest foot or toe joint stands in the rest pose,
  /// or rig::floor_y below it when the file tells one (a BVH's toe tips); where the retargeter
  /// puts a standing performer's soles, the floor of foot locking.
  float floor_height() const { return floor_vrm_; }
  /// The direction the rig faces in its own world (VRM's +Z carried back by the basis).
  glm::vec3 forward() const { return glm::conjugate(basis_) * glm::vec3(0.f, 0.f, 1.f); }
  /// Factor from the performer's hips motion (metres) to the rig's world units: the rig's
  /// hips height over options.performer_hips_height (the ratio of the two legs' lengths).
  float translation_scale() const { return translation_scale_; }

 private:
  const rig* rig_ = nullptr;
  bone_binding binding_{};
  retarget_options options_{};
  glm::quat basis_{1.f, 0.f, 0.f, 0.f};
  bool identity_basis_ = true;
  std::vector<int> bone_of_joint_;       // proxy bone bound to each joint, or -1
  std::vector<glm::quat> rest_aligned_;  // C · T_j · W_j for bound joints
  std::vector<int> foot_joints_;         // joints whose height defines the floor
  float rig_hips_height_ = 1.f;
  float translation_scale_ = 1.f;
  glm::mat4 hips_parent_inverse_{1.f};  // world -> hips parent's space
  glm::vec3 hips_rest_world_{0.f};
  float floor_vrm_ = 0.f;  // floor_height()
  struct formula_bone {
    int joint;
    int bone;
    euler_order order;         // the proxy's angles are read in this order
    euler_order target_order;  // the rig's angles (rest + f) are composed in this order
    std::array<formula, 3> f;
    glm::vec3 rest;  // Euler angles (radians, in `order`) the results are added to
  };
  std::vector<formula_bone> formula_bones_;
  std::vector<int> formula_of_joint_;         // index into formula_bones_, or -1
  mutable std::vector<glm::quat> world_;      // scratch: posed world rotations
  mutable std::vector<glm::vec3> positions_;  // scratch: posed world positions (grounding)
};

}  // namespace avatarmap
