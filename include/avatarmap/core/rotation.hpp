// Rotation helpers on GLM quaternions: shortest-arc slerp, swing-twist, the rotation between
// two directions and frames from two vectors. Conventions: docs/conventions.md.
// All functions are allocation-free and never return a non-finite quaternion for finite
// input; degenerate input (zero-length vectors) falls back as each comment says.
#pragma once

#include <cmath>

#if defined(__SSE__) || defined(_M_X64)
#include <xmmintrin.h>
#endif

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace avatarmap {

inline constexpr float k_pi = 3.14159265358979323846f;

inline glm::quat identity_quat() { return glm::quat(1.f, 0.f, 0.f, 0.f); }

/// 1 / sqrt(x) for x > 0, to about 2 ulp (hardware estimate refined by one Newton step where
/// SSE is available, which avoids the long latency of a square root followed by a division).
/// Results may differ in the last bits between processors.
inline float inv_sqrt(float x) {
#if defined(__SSE__) || defined(_M_X64)
  const float y = _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(x)));
  return y * (1.5f - 0.5f * x * y * y);
#else
  return 1.f / std::sqrt(x);
#endif
}

/// q scaled to unit length (q must not be zero).
inline glm::quat normalized(const glm::quat& q) {
  return q * inv_sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
}

inline bool is_finite(float v) { return std::isfinite(v); }
inline bool is_finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
inline bool is_finite(const glm::quat& q) {
  return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w);
}

/// `v` scaled to unit length, or `fallback` when |v| is below `eps` or not finite.
inline glm::vec3 normalize_or(const glm::vec3& v, const glm::vec3& fallback, float eps = 1e-12f) {
  float l2 = glm::dot(v, v);
  if (!(l2 > eps * eps) || !std::isfinite(l2)) return fallback;
  return v * inv_sqrt(l2);
}

/// Angle of a unit quaternion's rotation in [0, pi] (radians); robust near 0 and pi.
inline float rotation_angle(const glm::quat& q) {
  float v = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z);
  return 2.f * std::atan2(v, std::abs(q.w));
}

/// Angle in [0, pi] between two rotations (of a relative to b).
inline float angle_between(const glm::quat& a, const glm::quat& b) {
  return rotation_angle(glm::inverse(b) * a);
}

/// Unit-quaternion rotation about unit `axis` by `angle` radians.
inline glm::quat axis_angle(const glm::vec3& axis, float angle) {
  float s = std::sin(0.5f * angle);
  return glm::quat(std::cos(0.5f * angle), axis.x * s, axis.y * s, axis.z * s);
}

/// Spherical interpolation along the shortest arc (b is negated when a.b < 0). t = 0 gives a,
/// t = 1 gives b (or -b); t outside [0, 1] extrapolates along the same great circle. Near
/// identical inputs it falls back to normalised lerp, so it is safe at and near identity.
inline glm::quat slerp_shortest(const glm::quat& a, glm::quat b, float t) {
  float d = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
  if (d < 0.f) {
    b = -b;
    d = -d;
  }
  if (d > 0.9995f) {
    glm::quat r(a.w + t * (b.w - a.w), a.x + t * (b.x - a.x), a.y + t * (b.y - a.y),
                a.z + t * (b.z - a.z));
    return normalized(r);
  }
  float theta = std::acos(glm::min(d, 1.f));
  float s = std::sin(theta);
  float wa = std::sin((1.f - t) * theta) / s;
  float wb = std::sin(t * theta) / s;
  return glm::quat(wa * a.w + wb * b.w, wa * a.x + wb * b.x, wa * a.y + wb * b.y,
                   wa * a.z + wb * b.z);
}

/// Normalised linear interpolation along the shorter arc: the same path as slerp_shortest
/// with a slightly uneven speed (exact at t = 0, 1/2 and 1; within 0.6 degrees of slerp for
/// rotations up to 90 degrees apart). No trigonometry: use it where the fraction is a
/// heuristic share, not a measurement.
inline glm::quat nlerp_shortest(const glm::quat& a, glm::quat b, float t) {
  if (a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w < 0.f) b = -b;
  return normalized(glm::quat(a.w + t * (b.w - a.w), a.x + t * (b.x - a.x), a.y + t * (b.y - a.y),
                              a.z + t * (b.z - a.z)));
}

/// q^t along the shortest arc from identity (t in [0, 1] takes a fraction of the rotation).
inline glm::quat quat_fraction(const glm::quat& q, float t) {
  if (t == 0.5f) {
    // Half the rotation exactly: the bisector of identity and q (shortest arc), no trig.
    glm::quat h = q.w < 0.f ? -q : q;
    h.w += 1.f;
    float n2 = h.w * h.w + h.x * h.x + h.y * h.y + h.z * h.z;
    if (n2 > 1e-12f) return h * inv_sqrt(n2);
  }
  return slerp_shortest(identity_quat(), q, t);
}

/// The shortest rotation taking unit vector `from` onto unit vector `to`. For opposite
/// vectors it turns by pi about an axis perpendicular to `from` (deterministic choice).
inline glm::quat rotation_between(const glm::vec3& from, const glm::vec3& to) {
  float d = glm::dot(from, to);
  if (d < -0.999999f) {
    glm::vec3 axis = glm::cross(glm::vec3(1.f, 0.f, 0.f), from);
    if (glm::dot(axis, axis) < 1e-6f) axis = glm::cross(glm::vec3(0.f, 1.f, 0.f), from);
    axis = glm::normalize(axis);
    return glm::quat(0.f, axis.x, axis.y, axis.z);
  }
  glm::vec3 c = glm::cross(from, to);
  return normalized(glm::quat(1.f + d, c.x, c.y, c.z));
}

/// Swing-twist decomposition about unit `axis`: q = swing * twist, twist a rotation about
/// `axis`, swing a rotation about an axis perpendicular to it. When q turns `axis` by pi
/// the twist is undefined and identity is returned as the twist.
struct swing_twist_result {
  glm::quat swing;
  glm::quat twist;
};
inline swing_twist_result swing_twist(const glm::quat& q, const glm::vec3& axis) {
  glm::vec3 v(q.x, q.y, q.z);
  glm::vec3 p = glm::dot(v, axis) * axis;
  glm::quat twist(q.w, p.x, p.y, p.z);
  float n2 = twist.w * twist.w + glm::dot(p, p);
  if (n2 < 1e-12f) {
    twist = identity_quat();
  } else {
    twist = twist * inv_sqrt(n2);
  }
  return {q * glm::inverse(twist), twist};
}

/// Signed twist angle (radians, in (-pi, pi]) of q about unit `axis`.
inline float twist_angle(const glm::quat& q, const glm::vec3& axis) {
  glm::quat t = swing_twist(q, axis).twist;
  float s = glm::dot(glm::vec3(t.x, t.y, t.z), axis);
  // q and -q are the same rotation: fold into w >= 0 so the angle lands in (-pi, pi].
  if (t.w < 0.f || (t.w == 0.f && s < 0.f)) {
    s = -s;
    t.w = -t.w;
  }
  return 2.f * std::atan2(s, t.w);
}

/// The unit quaternion of the rotation matrix whose columns are the orthonormal, right-handed
/// vectors x, y, z (the images of the X, Y and Z axes). Shepperd's method: divides by the
/// largest component, so it is accurate for every rotation.
inline glm::quat quat_from_basis(const glm::vec3& x, const glm::vec3& y, const glm::vec3& z) {
  const float tr = x.x + y.y + z.z;
  if (tr > 0.f) {
    const float r = inv_sqrt(1.f + tr);
    const float h = 0.5f * r;
    return glm::quat(0.5f * (1.f + tr) * r, (y.z - z.y) * h, (z.x - x.z) * h, (x.y - y.x) * h);
  }
  if (x.x >= y.y && x.x >= z.z) {
    const float t = 1.f + x.x - y.y - z.z;
    const float r = inv_sqrt(t);
    const float h = 0.5f * r;
    return glm::quat((y.z - z.y) * h, 0.5f * t * r, (y.x + x.y) * h, (z.x + x.z) * h);
  }
  if (y.y >= z.z) {
    const float t = 1.f - x.x + y.y - z.z;
    const float r = inv_sqrt(t);
    const float h = 0.5f * r;
    return glm::quat((z.x - x.z) * h, (y.x + x.y) * h, 0.5f * t * r, (z.y + y.z) * h);
  }
  const float t = 1.f - x.x - y.y + z.z;
  const float r = inv_sqrt(t);
  const float h = 0.5f * r;
  return glm::quat((x.y - y.x) * h, (z.x + x.z) * h, (z.y + y.z) * h, 0.5f * t * r);
}

/// The rotation R with R * rest_primary = primary exactly and R * rest_secondary in the
/// half-plane spanned by `primary` and `secondary` (secondary is orthogonalised against
/// primary). Inputs need not be unit length. When `secondary` is (nearly) parallel to
/// `primary` or zero, the result is rotation_between(rest_primary, primary). rest_primary
/// and rest_secondary must not be parallel.
inline glm::quat frame_from_two_vectors(const glm::vec3& rest_primary,
                                        const glm::vec3& rest_secondary, const glm::vec3& primary,
                                        const glm::vec3& secondary) {
  // R = [p s t] * [a b c]^T for the orthonormal rest frame (a, b, c) and target frame (p, s, t).
  const glm::vec3 a = rest_primary * inv_sqrt(glm::dot(rest_primary, rest_primary));
  const glm::vec3 p = normalize_or(primary, a);
  glm::vec3 s = secondary - glm::dot(secondary, p) * p;
  const float s2 = glm::dot(s, s);
  const float sec2 = glm::dot(secondary, secondary);
  if (!(s2 > 1e-10f * (sec2 > 1e-20f ? sec2 : 1e-20f)) || !std::isfinite(s2))
    return rotation_between(a, p);
  s *= inv_sqrt(s2);
  glm::vec3 b = rest_secondary - glm::dot(rest_secondary, a) * a;
  b *= inv_sqrt(glm::dot(b, b));
  const glm::vec3 c = glm::cross(a, b);
  const glm::vec3 t = glm::cross(p, s);
  return quat_from_basis(p * a.x + s * b.x + t * c.x, p * a.y + s * b.y + t * c.y,
                         p * a.z + s * b.z + t * c.z);
}

/// Mirror of a rotation through the YZ plane (x -> -x): the rotation that the mirror image of
/// a body performs. {x, y, z, w} -> {x, -y, -z, w}.
inline glm::quat mirror_x(const glm::quat& q) { return glm::quat(q.w, q.x, -q.y, -q.z); }
inline glm::vec3 mirror_x(const glm::vec3& v) { return glm::vec3(-v.x, v.y, v.z); }

/// Writes q as {x, y, z, w}; the only memory order used at the library's boundaries.
inline void store_xyzw(const glm::quat& q, float* out) {
  out[0] = q.x;
  out[1] = q.y;
  out[2] = q.z;
  out[3] = q.w;
}
/// Reads {x, y, z, w}.
inline glm::quat load_xyzw(const float* in) { return glm::quat(in[3], in[0], in[1], in[2]); }

}  // namespace avatarmap
