// Coordinate spaces and the conversions between them. Conventions: docs/conventions.md.
//
// - MediaPipe world space (pose_world, *_hand_world): metres, x toward image right, y down,
//   z away from the camera; right-handed. Pose origin: hip midpoint.
// - MediaPipe image space (pose, *_hand, face): x, y normalised to [0, 1] of the image's
//   width and height, y down, z relative depth at roughly x's scale (smaller = closer).
// - Pixel space: image space times (W, H, W): isotropic, so angles and ratios are right for
//   any aspect ratio.
// - VRM space (the proxy's): Y up, the avatar faces +Z (toward the camera), avatar's left is
//   +X; right-handed; metres. From a camera-aligned space (world or pixel): X = x, Y = -y,
//   Z = -z.
#pragma once

#include <glm/glm.hpp>

namespace avatarmap {

/// MediaPipe world point (metres) -> VRM space (metres).
inline glm::vec3 world_to_vrm(const glm::vec3& p) { return glm::vec3(p.x, -p.y, -p.z); }

/// MediaPipe normalised image point -> VRM-oriented pixel space (x * W, -(y * H), -(z * W)).
/// Pixel units; use it for directions, angles and ratios, never as metres.
inline glm::vec3 image_to_vrm_pixels(const glm::vec3& p, float width, float height) {
  return glm::vec3(p.x * width, -p.y * height, -p.z * width);
}

}  // namespace avatarmap
