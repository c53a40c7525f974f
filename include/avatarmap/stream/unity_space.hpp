// VRM space (the proxy's: right-handed, Y up, the avatar faces +Z, its left is +X;
// docs/conventions.md) to Unity space (left-handed, Y up, a character faces +Z, its left is
// -X), as the VMC protocol's receivers expect it (docs/vmc.md, "Unity space").
//
// Both spaces put the avatar facing +Z, so the change of handedness is the mirror X -> -X:
// positions (x, y, z) -> (-x, y, z), rotations {x, y, z, w} -> {x, -y, -z, w} (a rotation
// about X keeps its sense, rotations about Y and Z reverse). This is the conversion UniVRM
// applies to VRM 1.0 files (which face +Z); the (x, y, -z) of glTF importers is for data that
// faces -Z (VRM 0.x files) and would turn a +Z-facing avatar around.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace avatarmap {

/// A position or offset in VRM space (metres) as Unity's (metres).
inline glm::vec3 vrm_to_unity_position(const glm::vec3& p) { return {-p.x, p.y, p.z}; }

/// A rotation in VRM space as the same motion in Unity space (glm::quat takes w first).
inline glm::quat vrm_to_unity_rotation(const glm::quat& q) {
  return glm::quat(q.w, q.x, -q.y, -q.z);
}

}  // namespace avatarmap
