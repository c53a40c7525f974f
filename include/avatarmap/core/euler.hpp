// Euler angles in explicit orders. Conventions: docs/conventions.md ("Euler angles").
//
// An order names three axes A, B, C. The rotation it denotes is the intrinsic sequence
// "turn about A, then about the new B, then about the newer C", i.e. the matrix
//   R = R_A(a) * R_B(b) * R_C(c)      (column vectors, right-handed, radians)
// which equals the extrinsic sequence C, B, A about fixed axes. This is three.js's and
// SysMocap's convention (order "XYZ" -> Rx * Ry * Rz). Angles are always stored as
// (x, y, z): the angle about X in .x, about Y in .y, about Z in .z, whatever the order.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <optional>
#include <string_view>

namespace avatarmap {

/// The six Tait-Bryan orders. Each enumerator spells A, B, C of R = R_A * R_B * R_C.
enum class euler_order : std::uint8_t { xyz, xzy, yxz, yzx, zxy, zyx };

inline constexpr std::array<euler_order, 6> k_all_euler_orders = {
    euler_order::xyz, euler_order::xzy, euler_order::yxz,
    euler_order::yzx, euler_order::zxy, euler_order::zyx};

/// Upper-case name of an order ("XYZ"...), as SysMocap's binding files write it.
constexpr std::string_view euler_order_name(euler_order order) {
  constexpr std::array<std::string_view, 6> k_names = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"};
  return k_names[static_cast<int>(order)];
}

/// Parses "XYZ"/"xyz"...; nullopt for anything else.
inline std::optional<euler_order> euler_order_from_name(std::string_view name) {
  if (name.size() != 3) return std::nullopt;
  char up[3];
  for (int i = 0; i < 3; ++i) {
    char c = name[i];
    up[i] = (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c;
  }
  for (euler_order o : k_all_euler_orders) {
    std::string_view n = euler_order_name(o);
    if (n[0] == up[0] && n[1] == up[1] && n[2] == up[2]) return o;
  }
  return std::nullopt;
}

namespace detail {
// Axis indices (0 = X, 1 = Y, 2 = Z) of A, B, C and the permutation's parity sign.
struct euler_axes {
  int i, j, k;
  float parity;  // +1 for cyclic orders (XYZ, YZX, ZXY), -1 otherwise
};
constexpr euler_axes axes_of(euler_order order) {
  switch (order) {
    case euler_order::xyz:
      return {0, 1, 2, 1.f};
    case euler_order::xzy:
      return {0, 2, 1, -1.f};
    case euler_order::yxz:
      return {1, 0, 2, -1.f};
    case euler_order::yzx:
      return {1, 2, 0, 1.f};
    case euler_order::zxy:
      return {2, 0, 1, 1.f};
    case euler_order::zyx:
      return {2, 1, 0, -1.f};
  }
  return {0, 1, 2, 1.f};
}
inline glm::quat axis_quat(int axis, float angle) {
  float h = 0.5f * angle;
  float s = std::sin(h);
  glm::quat q(std::cos(h), 0.f, 0.f, 0.f);  // glm::quat(w, x, y, z)
  q[axis] = s;                              // glm::quat operator[]: 0 = x, 1 = y, 2 = z
  return q;
}
}  // namespace detail

/// Quaternion of Euler angles `xyz` (radians, see the header comment) in `order`.
inline glm::quat quat_from_euler(glm::vec3 xyz, euler_order order) {
  detail::euler_axes a = detail::axes_of(order);
  return detail::axis_quat(a.i, xyz[a.i]) * detail::axis_quat(a.j, xyz[a.j]) *
         detail::axis_quat(a.k, xyz[a.k]);
}

/// Euler angles (x, y, z) of a rotation matrix in `order`. The middle angle (about B) lies in
/// [-pi/2, pi/2], the others in (-pi, pi]. At gimbal lock (|middle| = pi/2) the angle about C
/// is set to 0 and the whole remaining rotation goes to A. `m` must be a rotation matrix.
inline glm::vec3 euler_from_matrix(const glm::mat3& m, euler_order order) {
  detail::euler_axes a = detail::axes_of(order);
  // glm is column-major: element (row r, column c) is m[c][r].
  auto at = [&](int r, int c) { return m[c][r]; };
  const float s = a.parity;
  // atan2 of sin and cos rather than asin keeps the middle angle precise near +-pi/2.
  const float sb = s * at(a.i, a.k);
  const float cb = std::sqrt(at(a.i, a.i) * at(a.i, a.i) + at(a.i, a.j) * at(a.i, a.j));
  glm::vec3 out(0.f);
  out[a.j] = std::atan2(sb, cb);
  if (cb > 1e-6f) {
    out[a.i] = std::atan2(-s * at(a.j, a.k), at(a.k, a.k));
    // Near gimbal lock the angle about A is ill-conditioned (its atan2 arguments are ~cos b);
    // taking C from R_A(a)^T * m = R_B(b) * R_C(c) (row B) makes C absorb A's error, so the
    // three angles still reproduce m. Far from the lock this equals atan2(-s m_ij, m_ii).
    const float ca = std::cos(out[a.i]), sa = std::sin(out[a.i]);
    out[a.k] = std::atan2(s * ca * at(a.j, a.i) + sa * at(a.k, a.i),
                          ca * at(a.j, a.j) + s * sa * at(a.k, a.j));
  } else {
    out[a.i] = std::atan2(s * at(a.k, a.j), at(a.j, a.j));
    out[a.k] = 0.f;
  }
  return out;
}

/// Euler angles (x, y, z) of a unit quaternion in `order`; see euler_from_matrix.
inline glm::vec3 euler_from_quat(const glm::quat& q, euler_order order) {
  return euler_from_matrix(glm::mat3_cast(q), order);
}

}  // namespace avatarmap
