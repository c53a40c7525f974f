// The rest skeleton a VMC stream describes (docs/vmc.md, "Rest positions"): which humanoid bones
// are sent and where each bone's joint sits at rest relative to its parent's, so that a
// receiver gets the model's real proportions rather than zeros. Built once, from the proxy
// skeleton (no avatar given) or from an avatar's rig and its humanoid binding; read per frame by
// write_vmc_bundle (stream/vmc_bundle.hpp). Plain data, no allocation.
//
// Space: VRM (metres, Y up, the avatar faces +Z, its left is +X), rest = T-pose. Rotations are
// the proxy's normalised ones, so a bone's rest offset is the same in its parent's frame and
// in the model's: offsets are world differences of rest joint positions.
#pragma once

#include <array>
#include <glm/glm.hpp>

#include "avatarmap/core/status.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/skeleton/bone.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"

namespace avatarmap {

struct vmc_skeleton {
  /// Bones that get a /VMC/Ext/Bone/Pos message; the hips always.
  std::array<bool, k_bone_count> sent{};
  /// Rest offset of each sent bone's joint from the joint of its nearest sent ancestor (VRM,
  /// metres). Unused for the hips, whose position is the pose's (below).
  std::array<glm::vec3, k_bone_count> offsets{};
  /// The proxy's hips_position h becomes the model's hips joint
  /// (hips_rest.x + s h.x, floor + s h.y, hips_rest.z + s h.z), s = hips_scale: the rule of
  /// rig/retarget.hpp, so a performer standing puts the model's hips at their rest height.
  glm::vec3 hips_rest{0.f};
  float floor = 0.f;
  float hips_scale = 1.f;
  int sent_count = 0;  // bones with sent[b]
};

/// Every bone of the proxy skeleton `s` (make_proxy_skeleton: 1.70 m unless scaled), the hips
/// moved as measured (floor 0, scale 1, hips_rest 0).
vmc_skeleton make_vmc_skeleton(const proxy_skeleton& s);

/// The bones `binding` binds in rig `r` (an avatar: avatar_loader + build_rig, bound with
/// select_binding), offsets from the rig's rest world positions turned into VRM space (VRM 0.x
/// rigs face -Z: a half turn about Y, as rig/retarget.hpp does). The floor is the lowest bound
/// foot or toe joint at rest (0 without feet); hips_scale = (rest hips height above it) /
/// `performer_hips_height` (metres, > 0). Fails when the hips are unbound or
/// performer_hips_height is not positive and finite; the message names the rig's file.
status make_vmc_skeleton(const rig& r, const bone_binding& binding, float performer_hips_height,
                         vmc_skeleton& out);

}  // namespace avatarmap
