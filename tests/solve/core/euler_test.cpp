// Known-answer tests of avatarmap/core/euler.hpp against Eigen and hand-computed matrices.
#include "avatarmap/core/euler.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <random>
#include <string>

namespace avatarmap {
namespace {

constexpr double k_pi_d = 3.14159265358979323846;
constexpr float k_pi = static_cast<float>(k_pi_d);

Eigen::Vector3d unit_axis(char c) {
  return c == 'X'   ? Eigen::Vector3d::UnitX()
         : c == 'Y' ? Eigen::Vector3d::UnitY()
                    : Eigen::Vector3d::UnitZ();
}
int axis_index(char c) { return c - 'X'; }

// R_A(a) R_B(b) R_C(c) with Eigen, in double: the intrinsic sequence the header documents.
Eigen::Matrix3d eigen_euler(const glm::vec3& xyz, euler_order order) {
  const std::string_view n = euler_order_name(order);
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  for (char c : n) m = m * Eigen::AngleAxisd(xyz[axis_index(c)], unit_axis(c)).toRotationMatrix();
  return m;
}

Eigen::Matrix3d to_eigen(const glm::mat3& m) {
  Eigen::Matrix3d e;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) e(r, c) = m[c][r];
  return e;
}
Eigen::Matrix3d to_eigen(const glm::quat& q) { return to_eigen(glm::mat3_cast(q)); }

double max_abs_diff(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

TEST(euler, order_names_round_trip) {
  for (euler_order o : k_all_euler_orders) {
    const std::string_view name = euler_order_name(o);
    ASSERT_EQ(name.size(), 3u);
    EXPECT_EQ(euler_order_from_name(name), o);
    std::string lower(name);
    for (char& c : lower) c = static_cast<char>(c - 'A' + 'a');
    EXPECT_EQ(euler_order_from_name(lower), o);
  }
  EXPECT_EQ(euler_order_name(euler_order::zxy), "ZXY");
  EXPECT_FALSE(euler_order_from_name("XYX").has_value());
  EXPECT_FALSE(euler_order_from_name("XY").has_value());
  EXPECT_FALSE(euler_order_from_name("XYZW").has_value());
  EXPECT_FALSE(euler_order_from_name("").has_value());
  EXPECT_FALSE(euler_order_from_name("ABC").has_value());
}

TEST(euler, quarter_turn_about_x_takes_y_to_z) {
  const float q90 = 0.5f * k_pi;
  for (euler_order o : k_all_euler_orders) {
    const glm::quat q = quat_from_euler({q90, 0.f, 0.f}, o);
    const glm::vec3 v = q * glm::vec3(0.f, 1.f, 0.f);
    EXPECT_NEAR(v.x, 0.f, 1e-6f);
    EXPECT_NEAR(v.y, 0.f, 1e-6f);
    EXPECT_NEAR(v.z, 1.f, 1e-6f);
  }
  // About Y: +Z -> +X; about Z: +X -> +Y (right-handed).
  glm::vec3 v = quat_from_euler({0.f, q90, 0.f}, euler_order::xyz) * glm::vec3(0.f, 0.f, 1.f);
  EXPECT_NEAR(v.x, 1.f, 1e-6f);
  v = quat_from_euler({0.f, 0.f, q90}, euler_order::xyz) * glm::vec3(1.f, 0.f, 0.f);
  EXPECT_NEAR(v.y, 1.f, 1e-6f);
}

// XYZ (a, b, c): R = Rx(a) Ry(b) Rz(c), elements written out by hand.
TEST(euler, xyz_matrix_elements) {
  const float a = 0.3f, b = -0.7f, c = 1.1f;
  const glm::mat3 m = glm::mat3_cast(quat_from_euler({a, b, c}, euler_order::xyz));
  auto at = [&](int r, int col) { return m[col][r]; };
  const float ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b),
              cc = std::cos(c), sc = std::sin(c);
  EXPECT_NEAR(at(0, 0), cb * cc, 1e-6f);
  EXPECT_NEAR(at(0, 1), -cb * sc, 1e-6f);
  EXPECT_NEAR(at(0, 2), sb, 1e-6f);
  EXPECT_NEAR(at(1, 0), ca * sc + sa * sb * cc, 1e-6f);
  EXPECT_NEAR(at(1, 1), ca * cc - sa * sb * sc, 1e-6f);
  EXPECT_NEAR(at(1, 2), -sa * cb, 1e-6f);
  EXPECT_NEAR(at(2, 0), sa * sc - ca * sb * cc, 1e-6f);
  EXPECT_NEAR(at(2, 1), sa * cc + ca * sb * sc, 1e-6f);
  EXPECT_NEAR(at(2, 2), ca * cb, 1e-6f);
  // ZYX (the aerospace yaw-pitch-roll): R = Rz Ry Rx; element (2, 0) = -sin(y).
  const glm::mat3 z = glm::mat3_cast(quat_from_euler({a, b, c}, euler_order::zyx));
  EXPECT_NEAR(z[0][2], -sb, 1e-6f);
  EXPECT_NEAR(z[0][0], cc * cb, 1e-6f);
  EXPECT_NEAR(z[2][2], cb * ca, 1e-6f);
}

TEST(euler, quat_from_euler_matches_eigen_for_all_orders) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(-k_pi, k_pi);
  for (euler_order o : k_all_euler_orders) {
    for (int i = 0; i < 2000; ++i) {
      const glm::vec3 e(u(rng), u(rng), u(rng));
      const glm::quat q = quat_from_euler(e, o);
      EXPECT_NEAR(glm::length(q), 1.f, 1e-5f);
      ASSERT_LT(max_abs_diff(to_eigen(q), eigen_euler(e, o)), 2e-6)
          << euler_order_name(o) << " " << e.x << " " << e.y << " " << e.z;
    }
  }
}

TEST(euler, matrix_round_trip_random) {
  std::mt19937 rng(43);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  for (euler_order o : k_all_euler_orders) {
    for (int i = 0; i < 5000; ++i) {
      const glm::quat q = glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng)));
      const glm::mat3 m = glm::mat3_cast(q);
      const glm::vec3 e = euler_from_matrix(m, o);
      // Documented ranges.
      const int j = axis_index(euler_order_name(o)[1]);
      EXPECT_LE(std::abs(e[j]), 0.5f * k_pi + 1e-6f);
      for (int k = 0; k < 3; ++k) EXPECT_LE(std::abs(e[k]), k_pi + 1e-6f);
      ASSERT_LT(max_abs_diff(eigen_euler(e, o), to_eigen(m)), 1e-5)
          << euler_order_name(o) << " i=" << i;
      ASSERT_LT(max_abs_diff(to_eigen(quat_from_euler(euler_from_quat(q, o), o)), to_eigen(q)),
                1e-5);
    }
  }
}

TEST(euler, angles_inside_the_principal_range_are_recovered) {
  std::mt19937 rng(44);
  std::uniform_real_distribution<float> u(-3.f, 3.f), v(-1.5f, 1.5f);
  for (euler_order o : k_all_euler_orders) {
    const int j = axis_index(euler_order_name(o)[1]);
    for (int i = 0; i < 1000; ++i) {
      glm::vec3 e(u(rng), u(rng), u(rng));
      e[j] = v(rng);
      const glm::vec3 r = euler_from_quat(quat_from_euler(e, o), o);
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(r[k], e[k], 2e-4f) << euler_order_name(o);
    }
  }
}

// Near gimbal lock the two outer angles are ill-conditioned individually, but the recovered
// triple must still reproduce the rotation.
TEST(euler, round_trip_near_gimbal_lock) {
  std::mt19937 rng(45);
  std::uniform_real_distribution<float> u(-k_pi, k_pi);
  std::uniform_real_distribution<double> log_eps(std::log(1e-6), std::log(1e-2));
  for (euler_order o : k_all_euler_orders) {
    const int j = axis_index(euler_order_name(o)[1]);
    double worst = 0.0;
    for (int i = 0; i < 4000; ++i) {
      glm::vec3 e(u(rng), u(rng), u(rng));
      const double eps = std::exp(log_eps(rng));
      e[j] = static_cast<float>((i % 2 ? 1.0 : -1.0) * (0.5 * k_pi_d - eps));
      const glm::mat3 m = glm::mat3_cast(quat_from_euler(e, o));
      const glm::vec3 r = euler_from_matrix(m, o);
      ASSERT_TRUE(std::isfinite(r.x) && std::isfinite(r.y) && std::isfinite(r.z));
      worst = std::max(worst, max_abs_diff(eigen_euler(r, o), to_eigen(m)));
    }
    EXPECT_LT(worst, 1e-4) << euler_order_name(o);
  }
}

TEST(euler, exact_gimbal_lock) {
  for (euler_order o : k_all_euler_orders) {
    const int j = axis_index(euler_order_name(o)[1]);
    for (float sign : {-1.f, 1.f}) {
      glm::vec3 e(0.4f, -0.9f, 1.3f);
      e[j] = sign * 0.5f * k_pi;
      const glm::mat3 m = glm::mat3_cast(quat_from_euler(e, o));
      const glm::vec3 r = euler_from_matrix(m, o);
      EXPECT_LT(max_abs_diff(eigen_euler(r, o), to_eigen(m)), 1e-5) << euler_order_name(o);
      EXPECT_NEAR(std::abs(r[j]), 0.5f * k_pi, 1e-3f);
    }
  }
}

TEST(euler, identity_gives_zero_angles) {
  for (euler_order o : k_all_euler_orders) {
    const glm::vec3 e = euler_from_quat(glm::quat(1.f, 0.f, 0.f, 0.f), o);
    EXPECT_EQ(e, glm::vec3(0.f));
  }
}

}  // namespace
}  // namespace avatarmap
