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

/// Component of v orthogonal to unit u.
inline glm::vec3 orth(const glm::vec3& v, const glm::vec3& u) { return v - glm::dot(v, u) * u; }

/// A signed coordinate axis of a bone's local frame as a compile-time type: I = 0 (X), 1 (Y),
/// 2 (Z); S = +1 or -1.
template <int I, int S>
struct axis {
  static constexpr int index = I;
  static constexpr float sign = static_cast<float>(S);
  static glm::vec3 vec() {
    glm::vec3 v(0.f);
    v[I] = sign;
    return v;
  }
  /// Image of this axis under the rotation q: a signed column of q's matrix.
  static glm::vec3 rotated(const glm::quat& q) {
    const float x = q.x, y = q.y, z = q.z, w = q.w;
    glm::vec3 c;
    if constexpr (I == 0)
      c = glm::vec3(1.f - 2.f * (y * y + z * z), 2.f * (x * y + w * z), 2.f * (x * z - w * y));
    else if constexpr (I == 1)
      c = glm::vec3(2.f * (x * y - w * z), 1.f - 2.f * (x * x + z * z), 2.f * (y * z + w * x));
    else
      c = glm::vec3(2.f * (x * z + w * y), 2.f * (y * z - w * x), 1.f - 2.f * (x * x + y * y));
    return sign * c;
  }
};
using k_px = axis<0, 1>;
using k_nx = axis<0, -1>;
using k_py = axis<1, 1>;
using k_ny = axis<1, -1>;
using k_pz = axis<2, 1>;
using k_nz = axis<2, -1>;

/// The rotation that maps local axis A onto the unit vector `p` exactly and local axis B
/// (a different axis) into the half-plane of `hint` (orthogonalised against p). When hint is
/// parallel to p or zero: the shortest rotation of axis A onto p.
template <class A, class B>
inline glm::quat frame_from_axes(const glm::vec3& p, const glm::vec3& hint) {
  static_assert(A::index != B::index, "two different axes");
  glm::vec3 s = hint - glm::dot(hint, p) * p;
  const float s2 = glm::dot(s, s);
  const float h2 = glm::dot(hint, hint);
  if (!(s2 > 1e-10f * (h2 > 1e-20f ? h2 : 1e-20f)) || !std::isfinite(s2))
    return rotation_between(A::vec(), p);
  s *= inv_sqrt(s2);
  glm::vec3 col[3];
  col[A::index] = A::sign * p;
  col[B::index] = B::sign * s;
  constexpr int c = 3 - A::index - B::index;
  col[c] = glm::cross(col[(c + 1) % 3], col[(c + 2) % 3]);
  return quat_from_basis(col[0], col[1], col[2]);
}

/// World rotation of a bone whose local axis `Along` points along `dir`, and whose twist is
/// set by `bend_target` (the next segment's direction, which leaves toward the bone's local
/// axis `Bend`) when the joint below is bent more than ~30 degrees, and otherwise by the
/// minimal twist from `reference` (a world rotation whose Along/Bend axes are the reference
/// directions). `fallback_secondary`, when non-zero, replaces that minimal-twist reference as
/// where Bend points for straight limbs (e.g. the foot's forward direction for the knee).
template <class Along, class Bend>
inline glm::quat aim_with_bend(const glm::quat& reference, const glm::vec3& dir,
                               const glm::vec3& bend_target, const glm::vec3& fallback_secondary) {
  const glm::vec3 ref_dir = Along::rotated(reference);
  const glm::vec3 ref_bend = Bend::rotated(reference);
  const glm::vec3 d = normalize_or(dir, ref_dir);
  glm::vec3 ref;
  const float fb2 = glm::dot(fallback_secondary, fallback_secondary);
  const glm::vec3 fb = fb2 > 0.f ? orth(fallback_secondary, d) : glm::vec3(0.f);
  if (fb2 > 0.f && glm::dot(fb, fb) > 1e-8f * (fb2 > 1e-20f ? fb2 : 1e-20f)) {
    ref = fb;
  } else {
    // ref_bend carried by the shortest rotation taking ref_dir onto d:
    // R v = c v + k x v + k (k . v) / (1 + c), with c = ref_dir . d, k = ref_dir x d.
    const float c = glm::dot(ref_dir, d);
    if (c > -0.999f) {
      const glm::vec3 k = glm::cross(ref_dir, d);
      ref = c * ref_bend + glm::cross(k, ref_bend) + k * (glm::dot(k, ref_bend) / (1.f + c));
    } else {
      ref = ref_bend;
    }
    ref = orth(ref, d);
  }
  // Bend weight: 0 below 15 degrees of bend, 1 above 40, smooth between (on the cosine, which
  // is monotonic in the angle and needs no atan2).
  constexpr float k_cos15 = 0.96592583f, k_cos40 = 0.76604444f;
  const float tl2 = glm::dot(bend_target, bend_target);
  const float cos_bend = tl2 > 0.f ? glm::dot(d, bend_target) * inv_sqrt(tl2) : 1.f;
  constexpr float k_inv_range = 1.f / (k_cos40 - k_cos15);
  const float tw = glm::clamp((cos_bend - k_cos15) * k_inv_range, 0.f, 1.f);
  const float w = tw * tw * (3.f - 2.f * tw);
  glm::vec3 secondary = normalize_or(ref, ref_bend);
  if (w > 0.f) {
    const glm::vec3 bn = normalize_or(orth(bend_target, d), secondary);
    const glm::vec3 mixed = w * bn + (1.f - w) * secondary;
    secondary = glm::dot(mixed, mixed) < 1e-6f ? bn : mixed;
  }
  return frame_from_axes<Along, Bend>(d, secondary);
}

/// Local rotation of a child bone relative to `parent_world` that points the child's rest
/// direction along `dir` by the shortest arc (a pure hinge when dir lies in the bend plane).
inline glm::quat swing_local(const glm::quat& parent_world, const glm::vec3& rest_dir,
                             const glm::vec3& dir) {
  glm::vec3 v = normalize_or(glm::conjugate(parent_world) * dir, rest_dir);
  return rotation_between(rest_dir, v);
}

/// Rotation about the unit axis `k` by the angle whose cosine and sine are c and s (c^2 + s^2
/// = 1), without trigonometric calls: q ~ (1 + c, s k) normalised (half-angle identity). At
/// c = -1 (a half turn) it returns (0, k).
inline glm::quat axis_cos_sin(const glm::vec3& k, float c, float s) {
  float w = 1.f + c;
  if (w < 1e-7f) return glm::quat(0.f, k.x, k.y, k.z);
  float n = inv_sqrt(w * w + s * s);
  return glm::quat(w * n, k.x * s * n, k.y * s * n, k.z * s * n);
}

}  // namespace avatarmap::solve_detail
