// Known-answer tests of avatarmap/core/rotation.hpp, checked against Eigen where it has the
// same operation. Quaternions q and -q are the same rotation: results are compared as
// rotations (angle of the relative rotation, or matrices), never as raw components.
#include "avatarmap/core/rotation.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

namespace avatarmap {
namespace {

Eigen::Quaterniond to_eigen(const glm::quat& q) { return Eigen::Quaterniond(q.w, q.x, q.y, q.z); }
Eigen::Vector3d to_eigen(const glm::vec3& v) { return Eigen::Vector3d(v.x, v.y, v.z); }

// Angle between two rotations (radians), in double.
double rot_distance(const glm::quat& a, const Eigen::Quaterniond& b) {
  return to_eigen(a).normalized().angularDistance(b.normalized());
}

struct random_source {
  std::mt19937 rng;
  std::uniform_real_distribution<float> u{-1.f, 1.f};
  explicit random_source(unsigned seed) : rng(seed) {}
  glm::quat quat() { return glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng))); }
  glm::vec3 unit() {
    for (;;) {
      glm::vec3 v(u(rng), u(rng), u(rng));
      float l = glm::length(v);
      if (l > 0.1f && l <= 1.f) return v / l;
    }
  }
  float uniform(float lo, float hi) { return lo + (hi - lo) * 0.5f * (u(rng) + 1.f); }
};

// ---- rotation_angle / angle_between / axis_angle ----------------------------------------------

TEST(rotation_angle, known_answers) {
  EXPECT_EQ(rotation_angle(identity_quat()), 0.f);
  EXPECT_NEAR(rotation_angle(axis_angle({0.f, 1.f, 0.f}, 0.5f)), 0.5f, 1e-6f);
  EXPECT_NEAR(rotation_angle(axis_angle({1.f, 0.f, 0.f}, k_pi)), k_pi, 1e-6f);
  // q and -q: same angle, in [0, pi].
  const glm::quat q = axis_angle(glm::normalize(glm::vec3(1.f, 2.f, 3.f)), 2.5f);
  EXPECT_NEAR(rotation_angle(-q), 2.5f, 1e-6f);
  // A turn of 3*pi/2 is a turn of pi/2 the other way.
  EXPECT_NEAR(rotation_angle(axis_angle({0.f, 0.f, 1.f}, 1.5f * k_pi)), 0.5f * k_pi, 1e-5f);
  // Precise near 0 (acos-based formulas lose it there).
  EXPECT_NEAR(rotation_angle(axis_angle({0.f, 0.f, 1.f}, 1e-5f)), 1e-5f, 1e-9f);
}

TEST(rotation_angle, matches_eigen_angular_distance) {
  random_source r(1);
  for (int i = 0; i < 2000; ++i) {
    const glm::quat a = r.quat(), b = r.quat();
    EXPECT_NEAR(angle_between(a, b), to_eigen(a).angularDistance(to_eigen(b)), 2e-5);
    const glm::vec3 axis = r.unit();
    const float angle = r.uniform(-3.f, 3.f);
    const glm::quat q = axis_angle(axis, angle);
    EXPECT_LT(rot_distance(q, Eigen::Quaterniond(Eigen::AngleAxisd(angle, to_eigen(axis)))), 2e-6);
  }
}

// ---- slerp_shortest -------------------------------------------------------------------------

TEST(slerp_shortest, endpoints_and_halfway) {
  random_source r(2);
  for (int i = 0; i < 1000; ++i) {
    const glm::quat a = r.quat(), b = r.quat();
    EXPECT_LT(angle_between(slerp_shortest(a, b, 0.f), a), 1e-5f);
    EXPECT_LT(angle_between(slerp_shortest(a, b, 1.f), b), 1e-5f);
    const float full = angle_between(a, b);
    const glm::quat h = slerp_shortest(a, b, 0.5f);
    EXPECT_NEAR(angle_between(h, a), 0.5f * full, 2e-5f);
    EXPECT_NEAR(angle_between(h, b), 0.5f * full, 2e-5f);
    for (float t : {0.1f, 0.37f, 0.5f, 0.9f}) {
      const Eigen::Quaterniond e = to_eigen(a).slerp(t, to_eigen(b));  // Eigen: shortest arc too
      EXPECT_LT(rot_distance(slerp_shortest(a, b, t), e), 2e-5) << t;
    }
  }
}

TEST(slerp_shortest, takes_the_shortest_arc_when_dot_is_negative) {
  const glm::quat a = identity_quat();
  const glm::quat b = -axis_angle({0.f, 1.f, 0.f}, 0.4f);  // w < 0: naive slerp goes the long way
  ASSERT_LT(glm::dot(a, b), 0.f);
  const glm::quat h = slerp_shortest(a, b, 0.5f);
  EXPECT_LT(angle_between(h, axis_angle({0.f, 1.f, 0.f}, 0.2f)), 1e-6f);
  EXPECT_GT(glm::dot(h, a), 0.f);  // stays in a's hemisphere
}

TEST(slerp_shortest, near_identical_inputs_are_finite_and_normalised) {
  random_source r(3);
  for (int i = 0; i < 1000; ++i) {
    const glm::quat a = r.quat();
    const float tiny = r.uniform(0.f, 1e-3f);
    const glm::quat b = a * axis_angle(r.unit(), tiny);
    for (float t : {0.f, 0.3f, 0.5f, 1.f, 2.f}) {
      const glm::quat q = slerp_shortest(a, b, t);
      ASSERT_TRUE(is_finite(q));
      EXPECT_NEAR(glm::length(q), 1.f, 1e-6f);
      EXPECT_NEAR(angle_between(q, a), t * angle_between(b, a), 1e-5f);
    }
    const glm::quat same = slerp_shortest(a, a, 0.5f);
    ASSERT_TRUE(is_finite(same));
    EXPECT_LT(angle_between(same, a), 1e-6f);
    const glm::quat flipped = slerp_shortest(a, -a, 0.5f);
    ASSERT_TRUE(is_finite(flipped));
    EXPECT_LT(angle_between(flipped, a), 1e-6f);
  }
}

TEST(slerp_shortest, extrapolates_along_the_same_great_circle) {
  const glm::vec3 axis = glm::normalize(glm::vec3(1.f, -1.f, 2.f));
  const glm::quat a = axis_angle(axis, 0.2f), b = axis_angle(axis, 0.5f);
  EXPECT_LT(angle_between(slerp_shortest(a, b, 2.f), axis_angle(axis, 0.8f)), 1e-5f);
  EXPECT_LT(angle_between(slerp_shortest(a, b, -1.f), axis_angle(axis, -0.1f)), 1e-5f);
  // Small angles take the nlerp branch; its extrapolation error stays small.
  const glm::quat c = axis_angle(axis, 0.2f + 0.02f);
  EXPECT_LT(angle_between(slerp_shortest(a, c, 3.f), axis_angle(axis, 0.26f)), 1e-4f);
}

// ---- rotation_between -----------------------------------------------------------------------

TEST(rotation_between, random_pairs_match_eigen) {
  random_source r(4);
  for (int i = 0; i < 5000; ++i) {
    const glm::vec3 from = r.unit(), to = r.unit();
    const glm::quat q = rotation_between(from, to);
    EXPECT_NEAR(glm::length(q), 1.f, 1e-5f);
    EXPECT_LT(glm::length(q * from - to), 1e-5f);
    // Shortest: the angle is the angle between the vectors, as Eigen's FromTwoVectors.
    const Eigen::Quaterniond e = Eigen::Quaterniond::FromTwoVectors(to_eigen(from), to_eigen(to));
    EXPECT_LT(rot_distance(q, e), 2e-4) << i;
  }
}

TEST(rotation_between, identical_and_antiparallel) {
  random_source r(5);
  for (int i = 0; i < 500; ++i) {
    const glm::vec3 v = r.unit();
    EXPECT_LT(rotation_angle(rotation_between(v, v)), 1e-3f);
    const glm::quat q = rotation_between(v, -v);
    ASSERT_TRUE(is_finite(q));
    EXPECT_NEAR(rotation_angle(q), k_pi, 1e-5f);
    EXPECT_LT(glm::length(q * v + v), 1e-5f);
  }
  for (glm::vec3 v : {glm::vec3(1.f, 0.f, 0.f), glm::vec3(-1.f, 0.f, 0.f), glm::vec3(0.f, 1.f, 0.f),
                      glm::vec3(0.f, 0.f, -1.f)}) {
    const glm::quat q = rotation_between(v, -v);
    EXPECT_LT(glm::length(q * v + v), 1e-6f);
    const glm::vec3 axis(q.x, q.y, q.z);
    EXPECT_NEAR(glm::dot(axis, v), 0.f, 1e-6f);  // about an axis perpendicular to v
  }
  // Nearly antiparallel: still maps from onto to.
  const glm::vec3 from(0.f, 0.f, 1.f);
  for (float eps : {1e-2f, 1e-3f, 3e-3f}) {
    const glm::vec3 to = glm::normalize(glm::vec3(eps, 0.f, -1.f));
    EXPECT_LT(glm::length(rotation_between(from, to) * from - to), 2e-3f) << eps;
  }
}

// ---- swing_twist ----------------------------------------------------------------------------

TEST(swing_twist, reconstructs_and_splits_correctly) {
  random_source r(6);
  for (int i = 0; i < 5000; ++i) {
    const glm::quat q = r.quat();
    const glm::vec3 axis = r.unit();
    const swing_twist_result st = swing_twist(q, axis);
    EXPECT_LT(angle_between(st.swing * st.twist, q), 2e-5f);
    EXPECT_NEAR(glm::length(st.twist), 1.f, 1e-5f);
    EXPECT_NEAR(glm::length(st.swing), 1.f, 1e-5f);
    // Twist: about the axis (its vector part is parallel to it); it leaves the axis in place.
    const glm::vec3 tv(st.twist.x, st.twist.y, st.twist.z);
    EXPECT_LT(glm::length(glm::cross(tv, axis)), 1e-5f);
    EXPECT_LT(glm::length(st.twist * axis - axis), 1e-5f);
    // Swing: about an axis perpendicular to it, and it moves the axis exactly as q does.
    const glm::vec3 sv(st.swing.x, st.swing.y, st.swing.z);
    EXPECT_NEAR(glm::dot(sv, axis), 0.f, 1e-5f);
    EXPECT_LT(glm::length(st.swing * axis - q * axis), 1e-5f);
    // The twist angle agrees with twist_angle().
    const float ta = twist_angle(q, axis);
    EXPECT_GT(ta, -k_pi - 1e-6f);
    EXPECT_LE(ta, k_pi + 1e-6f);
    EXPECT_NEAR(twist_angle(-q, axis), ta, 1e-5f);  // documented range (-pi, pi] for q and -q
    EXPECT_LT(angle_between(axis_angle(axis, ta), st.twist), 1e-5f);
  }
}

TEST(swing_twist, pure_twist_pure_swing_and_180_degree_cases) {
  const glm::vec3 y(0.f, 1.f, 0.f);
  const glm::quat twist = axis_angle(y, 0.7f);
  swing_twist_result st = swing_twist(twist, y);
  EXPECT_LT(rotation_angle(st.swing), 1e-6f);
  EXPECT_NEAR(twist_angle(twist, y), 0.7f, 1e-6f);
  const glm::quat swing = axis_angle({1.f, 0.f, 0.f}, 0.9f);
  st = swing_twist(swing, y);
  EXPECT_LT(rotation_angle(st.twist), 1e-6f);
  // Twist of 180 degrees about the axis: the whole rotation is twist.
  const glm::quat half_turn = axis_angle(y, k_pi);
  st = swing_twist(half_turn, y);
  EXPECT_LT(rotation_angle(st.swing), 1e-5f);
  EXPECT_NEAR(rotation_angle(st.twist), k_pi, 1e-5f);
  // Swing of 180 degrees (the axis is turned onto its opposite): twist undefined -> identity,
  // and the decomposition still reconstructs q.
  const glm::quat flip = axis_angle({0.f, 0.f, 1.f}, k_pi);
  st = swing_twist(flip, y);
  EXPECT_TRUE(is_finite(st.swing) && is_finite(st.twist));
  EXPECT_EQ(st.twist, identity_quat());
  EXPECT_LT(angle_between(st.swing * st.twist, flip), 1e-6f);
  // Twist sign: positive about +axis, negative about -axis.
  EXPECT_NEAR(twist_angle(axis_angle(y, -0.3f), y), -0.3f, 1e-6f);
  EXPECT_NEAR(twist_angle(-axis_angle(y, 0.3f), y), 0.3f, 1e-6f);
}

// ---- frame_from_two_vectors -----------------------------------------------------------------

TEST(frame_from_two_vectors, maps_primary_exactly_and_secondary_into_the_half_plane) {
  random_source r(7);
  for (int i = 0; i < 3000; ++i) {
    const glm::vec3 rest_p = r.unit();
    glm::vec3 rest_s = r.unit();
    if (std::abs(glm::dot(rest_p, rest_s)) > 0.95f) continue;
    const glm::vec3 p = r.unit() * r.uniform(0.1f, 10.f);  // not unit length
    const glm::vec3 s = r.unit() * r.uniform(0.1f, 10.f);
    if (std::abs(glm::dot(glm::normalize(p), glm::normalize(s))) > 0.99f) continue;
    const glm::quat q = frame_from_two_vectors(rest_p, rest_s, p, s);
    EXPECT_NEAR(glm::length(q), 1.f, 1e-5f);
    EXPECT_LT(glm::length(q * rest_p - glm::normalize(p)), 2e-5f) << i;
    // q * rest_s lies in the plane of p and s, on s's side of p.
    const glm::vec3 qs = q * rest_s;
    const glm::vec3 n = glm::normalize(glm::cross(p, s));
    EXPECT_NEAR(glm::dot(qs, n), 0.f, 2e-5f);
    const glm::vec3 pn = glm::normalize(p);
    const glm::vec3 s_perp = glm::normalize(s - glm::dot(s, pn) * pn);
    const glm::vec3 rest_perp =
        glm::normalize(rest_s - glm::dot(rest_s, glm::normalize(rest_p)) * glm::normalize(rest_p));
    EXPECT_GT(glm::dot(qs, s_perp), 0.f);
    EXPECT_LT(glm::length(q * rest_perp - s_perp), 2e-5f);
  }
}

TEST(frame_from_two_vectors, known_answer_and_degenerate_fallback) {
  const glm::vec3 x(1.f, 0.f, 0.f), y(0.f, 1.f, 0.f), z(0.f, 0.f, 1.f);
  // Rest frame (x, y) onto (y, -x): a quarter turn about +Z.
  glm::quat q = frame_from_two_vectors(x, y, y, -x);
  EXPECT_LT(angle_between(q, axis_angle(z, 0.5f * k_pi)), 1e-6f);
  // Secondary parallel to primary, zero, or non-finite: rotation_between(rest_primary, primary).
  const glm::vec3 p = glm::normalize(glm::vec3(1.f, 1.f, 0.f));
  const glm::quat expected = rotation_between(x, p);
  for (glm::vec3 s : {p * 3.f, glm::vec3(0.f), -p,
                      glm::vec3(std::numeric_limits<float>::quiet_NaN(), 0.f, 0.f)}) {
    q = frame_from_two_vectors(x, y, p, s);
    ASSERT_TRUE(is_finite(q));
    EXPECT_LT(angle_between(q, expected), 1e-6f);
  }
  // Zero primary: falls back to the rest primary (identity when the secondary agrees).
  q = frame_from_two_vectors(x, y, glm::vec3(0.f), y);
  ASSERT_TRUE(is_finite(q));
  EXPECT_LT(rotation_angle(q), 1e-6f);
}

// ---- mirror_x -------------------------------------------------------------------------------

TEST(mirror_x, equals_m_r_m_with_eigen_matrices) {
  random_source r(8);
  const Eigen::Matrix3d m = Eigen::Vector3d(-1.0, 1.0, 1.0).asDiagonal();
  for (int i = 0; i < 2000; ++i) {
    const glm::quat q = r.quat();
    const Eigen::Matrix3d expected = m * to_eigen(q).toRotationMatrix() * m;
    const Eigen::Matrix3d got = to_eigen(mirror_x(q)).toRotationMatrix();
    EXPECT_LT((expected - got).cwiseAbs().maxCoeff(), 2e-6);
    // Involution, and consistent with mirroring vectors: mirror(q) * mirror(v) = mirror(q * v).
    EXPECT_EQ(mirror_x(mirror_x(q)), q);
    const glm::vec3 v = r.unit();
    EXPECT_LT(glm::length(mirror_x(q) * mirror_x(v) - mirror_x(q * v)), 1e-5f);
  }
  // Known answers: about X unchanged; about Y and Z reversed.
  EXPECT_LT(
      angle_between(mirror_x(axis_angle({1.f, 0.f, 0.f}, 0.6f)), axis_angle({1.f, 0.f, 0.f}, 0.6f)),
      1e-6f);
  EXPECT_LT(angle_between(mirror_x(axis_angle({0.f, 1.f, 0.f}, 0.6f)),
                          axis_angle({0.f, 1.f, 0.f}, -0.6f)),
            1e-6f);
  EXPECT_EQ(mirror_x(glm::vec3(1.f, 2.f, 3.f)), glm::vec3(-1.f, 2.f, 3.f));
}

// ---- small helpers --------------------------------------------------------------------------

TEST(rotation_helpers, xyzw_order_and_normalize_or) {
  const glm::quat q(0.1f, 0.2f, 0.3f, 0.4f);  // glm::quat(w, x, y, z)
  float buf[4];
  store_xyzw(q, buf);
  EXPECT_EQ(buf[0], 0.2f);
  EXPECT_EQ(buf[1], 0.3f);
  EXPECT_EQ(buf[2], 0.4f);
  EXPECT_EQ(buf[3], 0.1f);
  EXPECT_EQ(load_xyzw(buf), q);
  const glm::vec3 fb(0.f, 1.f, 0.f);
  EXPECT_EQ(normalize_or(glm::vec3(0.f), fb), fb);
  EXPECT_EQ(normalize_or(glm::vec3(std::numeric_limits<float>::infinity(), 0.f, 0.f), fb), fb);
  EXPECT_LT(glm::length(normalize_or(glm::vec3(3.f, 0.f, 4.f), fb) - glm::vec3(0.6f, 0.f, 0.8f)),
            1e-6f);
  EXPECT_LT(angle_between(quat_fraction(axis_angle({0.f, 0.f, 1.f}, 1.f), 0.25f),
                          axis_angle({0.f, 0.f, 1.f}, 0.25f)),
            1e-6f);
}

}  // namespace
}  // namespace avatarmap
