// Internal building blocks of the solver: bone frames from landmark geometry. All inputs
// and outputs are in VRM space (metres or VRM-oriented pixels: only directions matter here).
// Limb functions work on the avatar's LEFT side; the right side is solved by mirroring its
// points through X (mirror_x) and mirroring the resulting rotations back.
#pragma once

#include <cmath>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap::solve_detail {

inline constexpr glm::vec3 k_x{1.f, 0.f, 0.f};
inline constexpr glm::vec3 k_y{0.f, 1.f, 0.f};
inline constexpr glm::vec3 k_z{0.f, 0.f, 1.f};
inline constexpr float k_deg = k_pi / 180.f;

inline float smoothstep(float e0, float e1, float x) {
  float t = glm::clamp((x - e0) / (e1 - e0), 0.f, 1.f);
  return t * t * (3.f - 2.f * t);
}

inline float angle_of(const glm::vec3& a, const glm::vec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

/// Component of v orthogonal to unit u.
inline glm::vec3 orth(const glm::vec3& v, const glm::vec3& u) { return v - glm::dot(v, u) * u; }

/// World rotation of a bone that points along `dir` (rest direction `rest_dir`), whose twist is
/// set by `bend_target` (the next segment's direction, which should lie on the side of the
/// bone's local axis `rest_bend`) when the joint below is bent more than ~30 degrees, and
/// otherwise by the minimal twist from `parent_world` (no defined bend plane).
/// `fallback_secondary`, when non-zero, replaces the parent's minimal twist as the reference
/// for straight limbs (e.g. the foot's forward direction for the knee).
inline glm::quat aim_with_bend(const glm::quat& parent_world, const glm::vec3& rest_dir,
                               const glm::vec3& rest_bend, const glm::vec3& dir,
                               const glm::vec3& bend_target, const glm::vec3& fallback_secondary) {
  glm::vec3 d = normalize_or(dir, parent_world * rest_dir);
  // Minimal-twist frame: the parent's frame swung onto d.
  glm::quat swing = rotation_between(glm::normalize(parent_world * rest_dir), d) * parent_world;
  glm::vec3 ref = orth(swing * rest_bend, d);
  glm::vec3 fb = orth(fallback_secondary, d);
  if (glm::dot(fb, fb) > 1e-8f * glm::max(1e-20f, glm::dot(fallback_secondary, fallback_secondary)))
    ref = fb;
  ref = normalize_or(ref, swing * rest_bend);
  glm::vec3 b = orth(bend_target, d);
  float bend = angle_of(d, bend_target);
  float w = smoothstep(15.f * k_deg, 40.f * k_deg, bend);
  glm::vec3 secondary = ref;
  if (w > 0.f) {
    glm::vec3 bn = normalize_or(b, ref);
    secondary = w * bn + (1.f - w) * ref;
    if (glm::dot(secondary, secondary) < 1e-6f) secondary = bn;
  }
  return frame_from_two_vectors(rest_dir, rest_bend, d, secondary);
}

/// Local rotation of a child bone relative to `parent_world` that points the child's rest
/// direction along `dir` by the shortest arc (a pure hinge when dir lies in the bend plane).
inline glm::quat swing_local(const glm::quat& parent_world, const glm::vec3& rest_dir,
                             const glm::vec3& dir) {
  glm::vec3 v = normalize_or(glm::inverse(parent_world) * dir, rest_dir);
  return rotation_between(rest_dir, v);
}

/// Hinge rotation about the local axis that turns +X toward -Y (rotation about Z by -theta),
/// with theta = atan2(-v.y, v.x) taken from the child's direction v in the parent's frame:
/// fingers flex past 90 degrees without folding back.
inline glm::quat finger_hinge(const glm::vec3& v_local) {
  float theta = std::atan2(-v_local.y, v_local.x);
  return axis_angle(k_z, -theta);
}

}  // namespace avatarmap::solve_detail
