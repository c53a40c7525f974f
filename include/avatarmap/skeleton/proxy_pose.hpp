// A pose of the proxy skeleton in VRM 1.0 normalised space: a local rotation per bone
// (relative to its parent; identity = VRM T-pose), the hips position in metres, expression
// weights, ARKit's 52 blendshape weights and a per-bone confidence. Fixed-size: never allocates.
#pragma once

#include <array>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "avatarmap/skeleton/blendshape.hpp"
#include "avatarmap/skeleton/bone.hpp"
#include "avatarmap/skeleton/expression.hpp"

namespace avatarmap {

/// Default hips height (metres above the soles) used when the legs were never seen.
inline constexpr float k_default_hips_height = 0.95f;

struct proxy_pose {
  double t = 0.0;  // seconds
  /// Hips joint in VRM space, metres: Y above the floor (soles at 0); X and Z from the
  /// solver's origin (see solver docs).
  glm::vec3 hips_position{0.f, k_default_hips_height, 0.f};
  std::array<glm::quat, k_bone_count> rotations;        // local, {w,x,y,z} in GLM's storage
  std::array<float, k_bone_count> confidence{};         // 0 = not observed .. 1 = observed
  std::array<float, k_expression_count> expressions{};  // 0 .. 1
  std::array<float, k_blendshape_count> blendshapes{};  // ARKit's 52, 0 .. 1
  /// Foot contact per foot ([0] left, [1] right): 0 = the foot moves freely .. 1 = planted
  /// on the floor; values between blend foot locking in and out. Set by the contact stage
  /// (time/foot_contacts.hpp); 0 when no stage ran.
  std::array<float, 2> foot_contact{};

  proxy_pose() { set_rest(); }

  /// T-pose: identity rotations, default hips height, zero expressions and confidence.
  void set_rest() {
    hips_position = glm::vec3(0.f, k_default_hips_height, 0.f);
    rotations.fill(glm::quat(1.f, 0.f, 0.f, 0.f));
    confidence.fill(0.f);
    expressions.fill(0.f);
    blendshapes.fill(0.f);
    foot_contact.fill(0.f);
  }

  glm::quat& operator[](bone b) { return rotations[idx(b)]; }
  const glm::quat& operator[](bone b) const { return rotations[idx(b)]; }
  float& operator[](expression e) { return expressions[idx(e)]; }
  float operator[](expression e) const { return expressions[idx(e)]; }
  float& operator[](blendshape s) { return blendshapes[idx(s)]; }
  float operator[](blendshape s) const { return blendshapes[idx(s)]; }
};

/// World (model-space) rotations of every bone from a pose's local rotations.
inline void compute_world_rotations(const proxy_pose& pose,
                                    std::array<glm::quat, k_bone_count>& out_world) {
  for (int b = 0; b < k_bone_count; ++b) {
    int p = bone_parent(b);
    out_world[b] = p == k_no_parent ? pose.rotations[b] : out_world[p] * pose.rotations[b];
  }
}

}  // namespace avatarmap
