// World joint matrices and positions of a posed rig (rest translations and scales, posed rotations,
// the hips' posed translation): the independent forward kinematics the rig tests compare with.
#pragma once

#include <glm/glm.hpp>
#include <vector>

#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"

namespace avatarmap::test {

inline std::vector<glm::mat4> posed_matrices(const rig& r, const rig_pose& pose) {
  std::vector<glm::mat4> world(static_cast<size_t>(r.joint_count()));
  for (int j = 0; j < r.joint_count(); ++j) {
    transform t = r.rest_local[j];
    t.rotation = pose.local_rotations[j];
    if (j == pose.hips_joint) t.translation = pose.hips_translation;
    glm::mat4 m = glm::mat4_cast(t.rotation);
    m[0] *= t.scale.x;
    m[1] *= t.scale.y;
    m[2] *= t.scale.z;
    m[3] = glm::vec4(t.translation, 1.f);
    world[j] = r.parents[j] < 0 ? m : world[r.parents[j]] * m;
  }
  return world;
}

inline std::vector<glm::vec3> posed_positions(const rig& r, const rig_pose& pose) {
  const std::vector<glm::mat4> world = posed_matrices(r, pose);
  std::vector<glm::vec3> out(world.size());
  for (std::size_t j = 0; j < world.size(); ++j) out[j] = glm::vec3(world[j][3]);
  return out;
}

}  // namespace avatarmap::test
