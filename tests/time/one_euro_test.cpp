// Known behaviour of the One Euro filters (avatarmap/time/one_euro.hpp).
#include "avatarmap/time/one_euro.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <limits>
#include <random>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {
namespace {

constexpr float k_nan = std::numeric_limits<float>::quiet_NaN();
constexpr float k_inf = std::numeric_limits<float>::infinity();

double tau_of(double cutoff_hz) { return 1.0 / (2.0 * 3.14159265358979323846 * cutoff_hz); }

// Step response at time `t_end` of a scalar filter sampled every `dt` seconds.
float step_response(const one_euro_params& p, float dt, double t_end) {
  one_euro_filter f(p);
  f(0.f, dt);
  float y = 0.f;
  const int n = static_cast<int>(std::lround(t_end / dt));
  for (int i = 0; i < n; ++i) y = f(1.f, dt);
  return y;
}

TEST(one_euro_alpha, matches_paper_formula) {
  const float dt = 1.f / 30.f;
  for (float cutoff : {0.1f, 1.f, 2.5f, 10.f}) {
    const double tau = tau_of(cutoff);
    EXPECT_NEAR(one_euro_alpha(cutoff, dt), 1.0 / (1.0 + tau / dt), 1e-6);
  }
  EXPECT_GT(one_euro_alpha(0.f, dt), 0.f);  // clamped, not a division by zero
  EXPECT_LT(one_euro_alpha(0.f, dt), 1e-4f);
}

TEST(one_euro_filter, first_sample_passes_through) {
  one_euro_filter f({1.f, 0.5f, 1.f});
  EXPECT_FALSE(f.initialized());
  EXPECT_EQ(f(3.25f, 0.f), 3.25f);  // even with no valid dt
  EXPECT_TRUE(f.initialized());
  EXPECT_EQ(f.value(), 3.25f);
}

TEST(one_euro_filter, constant_input_gives_constant_output) {
  one_euro_filter f({1.f, 0.7f, 1.f});
  for (int i = 0; i < 200; ++i) EXPECT_EQ(f(-1.5f, 1.f / 30.f), -1.5f);
}

// With beta = 0 the filter is a first-order low-pass: for a fixed dt the step response after n
// samples is exactly 1 - (1 - alpha)^n with alpha = 1 / (1 + tau / dt).
TEST(one_euro_filter, step_matches_closed_form_first_order_lowpass) {
  const one_euro_params p{2.f, 0.f, 1.f};
  for (float dt : {1.f / 25.f, 1.f / 30.f, 1.f / 60.f, 1.f / 240.f}) {
    one_euro_filter f(p);
    f(0.f, dt);
    const double alpha = 1.0 / (1.0 + tau_of(2.0) / dt);
    for (int n = 1; n <= 100; ++n) {
      const float y = f(1.f, dt);
      EXPECT_NEAR(y, 1.0 - std::pow(1.0 - alpha, n), 2e-6) << "dt " << dt << " n " << n;
    }
  }
}

// As dt -> 0 the discrete response tends to the continuous 1 - exp(-t / tau): at one time
// constant it reaches 63.2 %.
TEST(one_euro_filter, step_has_documented_time_constant) {
  const float cutoff = 1.f;
  const double tau = tau_of(cutoff);
  const float dt = 1e-4f;
  const one_euro_params p{cutoff, 0.f, 1.f};
  for (double k : {0.5, 1.0, 2.0, 3.0}) {
    EXPECT_NEAR(step_response(p, dt, k * tau), 1.0 - std::exp(-k), 2e-3) << k << " tau";
  }
}

// dt-aware: the response depends on elapsed time, not on the number of samples.
TEST(one_euro_filter, two_sample_rates_give_the_same_time_response) {
  const one_euro_params p{1.f, 0.f, 1.f};
  for (double t : {0.1, 0.2, 0.5, 1.0}) {
    const float y30 = step_response(p, 1.f / 30.f, t);
    const float y120 = step_response(p, 1.f / 120.f, t);
    const double exact = 1.0 - std::exp(-t / tau_of(1.0));
    EXPECT_NEAR(y30, y120, 0.03) << t;
    EXPECT_NEAR(y120, exact, 0.012) << t;
    // A filter with a fixed per-sample factor (SysMocap's "slerp 0.3 per frame") differs a lot.
    const int n30 = static_cast<int>(std::lround(t * 30)),
              n120 = static_cast<int>(std::lround(t * 120));
    if (t <= 0.2) {
      EXPECT_GT(std::pow(0.7, n30) - std::pow(0.7, n120), 0.1) << t;
    }
  }
}

TEST(one_euro_filter, higher_speed_gives_higher_cutoff) {
  const one_euro_params p{1.f, 2.f, 1.f};
  const float dt = 1.f / 30.f;
  const float base_alpha = one_euro_alpha(p.min_cutoff, dt);
  float previous_fraction = base_alpha;
  for (float jump : {0.01f, 0.1f, 1.f, 10.f}) {
    one_euro_filter f(p);
    f(0.f, dt);
    const float fraction = f(jump, dt) / jump;  // = alpha(cutoff(speed))
    EXPECT_GT(fraction, previous_fraction) << jump;
    previous_fraction = fraction;
  }
  // beta = 0: the same fraction whatever the speed.
  for (float jump : {0.01f, 10.f}) {
    one_euro_filter f({1.f, 0.f, 1.f});
    f(0.f, dt);
    EXPECT_NEAR(f(jump, dt) / jump, base_alpha, 1e-6f);
  }
}

TEST(one_euro_filter, speed_uses_documented_formula) {
  const one_euro_params p{1.f, 0.5f, 2.f};
  const float dt = 0.05f;
  one_euro_filter f(p);
  f(0.f, dt);
  const float x = 0.3f;
  const float speed_hat = one_euro_alpha(p.d_cutoff, dt) * (x / dt);
  const float a = one_euro_alpha(p.min_cutoff + p.beta * speed_hat, dt);
  EXPECT_NEAR(f(x, dt), a * x, 1e-6f);
}

TEST(one_euro_filter, bad_dt_and_non_finite_input_hold_previous_output) {
  one_euro_filter f({1.f, 1.f, 1.f});
  EXPECT_EQ(f(k_nan, 0.1f), 0.f);  // nothing yet: 0, and still uninitialised
  EXPECT_FALSE(f.initialized());
  f(1.f, 0.1f);
  const float y = f(2.f, 0.1f);
  EXPECT_EQ(f(5.f, 0.f), y);
  EXPECT_EQ(f(5.f, -0.1f), y);
  EXPECT_EQ(f(5.f, k_nan), y);
  EXPECT_EQ(f(5.f, k_inf), y);
  EXPECT_EQ(f(k_nan, 0.1f), y);
  EXPECT_EQ(f(k_inf, 0.1f), y);
  EXPECT_EQ(f(-k_inf, 0.1f), y);
  EXPECT_TRUE(std::isfinite(f(3.f, 0.1f)));
  f.reset();
  EXPECT_EQ(f(-7.f, 0.1f), -7.f);
}

TEST(one_euro_filter_vec3, constant_and_isotropic) {
  one_euro_filter_vec3 f({1.f, 1.f, 1.f});
  const glm::vec3 c(0.1f, -0.2f, 0.3f);
  for (int i = 0; i < 50; ++i) {
    const glm::vec3 y = f(c, 1.f / 30.f);
    EXPECT_EQ(y, c);
  }
  // A step along a direction stays on the line through the start and the target.
  one_euro_filter_vec3 g({1.f, 1.f, 1.f});
  g(glm::vec3(0.f), 0.03f);
  const glm::vec3 target(1.f, 2.f, -2.f);
  for (int i = 0; i < 20; ++i) {
    const glm::vec3 y = g(target, 0.03f);
    EXPECT_LT(glm::length(glm::cross(y, target)), 1e-5f);
    EXPECT_GT(glm::dot(y, target), 0.f);
  }
}

TEST(one_euro_filter_vec3, beta_zero_matches_scalar_per_component) {
  const one_euro_params p{1.5f, 0.f, 1.f};
  one_euro_filter_vec3 v(p);
  one_euro_filter fx(p), fy(p), fz(p);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  for (int i = 0; i < 100; ++i) {
    const glm::vec3 x(u(rng), u(rng), u(rng));
    const float dt = 0.02f + 0.02f * (u(rng) + 1.f);
    const glm::vec3 y = v(x, dt);
    EXPECT_NEAR(y.x, fx(x.x, dt), 1e-6f);
    EXPECT_NEAR(y.y, fy(x.y, dt), 1e-6f);
    EXPECT_NEAR(y.z, fz(x.z, dt), 1e-6f);
  }
}

TEST(one_euro_filter_vec3, non_finite_component_is_missing) {
  one_euro_filter_vec3 f;
  f(glm::vec3(1.f, 2.f, 3.f), 0.1f);
  const glm::vec3 y = f(glm::vec3(1.f, k_nan, 3.f), 0.1f);
  EXPECT_EQ(y, glm::vec3(1.f, 2.f, 3.f));
}

TEST(one_euro_filter_quat, constant_rotation_stays) {
  one_euro_filter_quat f({1.f, 0.5f, 1.f});
  const glm::quat q = glm::normalize(glm::quat(0.8f, 0.1f, -0.5f, 0.3f));
  for (int i = 0; i < 100; ++i) {
    const glm::quat y = f(q, 1.f / 30.f);
    EXPECT_LT(angle_between(y, q), 1e-5f);
    EXPECT_NEAR(glm::length(y), 1.f, 1e-6f);
  }
  EXPECT_LT(f.speed(), 1e-3f);
}

TEST(one_euro_filter_quat, sign_flips_of_the_input_are_not_motion) {
  one_euro_filter_quat f({1.f, 5.f, 1.f});
  const glm::quat q = glm::normalize(glm::quat(0.3f, 0.6f, -0.2f, 0.7f));
  const glm::quat first = f(q, 1.f / 30.f);
  for (int i = 0; i < 60; ++i) {
    const glm::quat y = f(i % 2 ? q : -q, 1.f / 30.f);
    EXPECT_LT(angle_between(y, q), 1e-5f);
    EXPECT_GT(glm::dot(y, first), 0.999f);  // the output's sign is continuous
  }
  EXPECT_LT(f.speed(), 1e-3f);
}

// beta = 0: each step moves the fraction alpha of the remaining angle along the great circle,
// so the remaining angle after n steps is (1 - alpha)^n times the initial one.
TEST(one_euro_filter_quat, step_follows_first_order_lowpass_along_the_arc) {
  const float dt = 1.f / 30.f;
  const one_euro_params p{1.f, 0.f, 1.f};
  one_euro_filter_quat f(p);
  const glm::vec3 axis = glm::normalize(glm::vec3(1.f, 2.f, 3.f));
  const float angle = 1.5f;
  const glm::quat target = axis_angle(axis, angle);
  f(identity_quat(), dt);
  const double alpha = one_euro_alpha(p.min_cutoff, dt);
  for (int n = 1; n <= 60; ++n) {
    const glm::quat y = f(target, dt);
    EXPECT_NEAR(angle_between(y, target), angle * std::pow(1.0 - alpha, n), 2e-5) << n;
    EXPECT_NEAR(angle_between(y, identity_quat()) + angle_between(y, target), angle, 2e-5);
  }
}

TEST(one_euro_filter_quat, angular_speed_raises_cutoff) {
  const float dt = 1.f / 30.f;
  float previous = 0.f;
  for (float angle : {0.05f, 0.3f, 1.f, 2.f}) {
    one_euro_filter_quat f({1.f, 1.f, 1.f});
    f(identity_quat(), dt);
    const glm::quat y = f(axis_angle(glm::vec3(0.f, 1.f, 0.f), angle), dt);
    const float fraction = rotation_angle(y) / angle;
    EXPECT_GT(fraction, previous) << angle;
    previous = fraction;
  }
}

TEST(one_euro_filter_quat, never_produces_non_finite_output) {
  one_euro_filter_quat f({1.f, 2.f, 1.f});
  EXPECT_EQ(f(glm::quat(k_nan, 0.f, 0.f, 0.f), 0.1f), identity_quat());
  EXPECT_EQ(f(glm::quat(0.f, 0.f, 0.f, 0.f), 0.1f), identity_quat());
  EXPECT_FALSE(f.initialized());
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  std::uniform_int_distribution<int> kind(0, 9);
  for (int i = 0; i < 20000; ++i) {
    glm::quat q(u(rng), u(rng), u(rng), u(rng));
    float dt = 0.001f + 0.05f * (u(rng) + 1.f);
    switch (kind(rng)) {
      case 0:
        q = glm::quat(k_nan, q.x, q.y, q.z);
        break;
      case 1:
        q = glm::quat(0.f, 0.f, 0.f, 0.f);
        break;
      case 2:
        q = -f.value();
        break;
      case 3:
        dt = 0.f;
        break;
      case 4:
        dt = k_inf;
        break;
      case 5:
        q = q * 1e-7f;
        break;  // tiny but not zero: normalised
      case 6:
        dt = 1e-9f;
        break;
      default:
        break;
    }
    const glm::quat y = f(q, dt);
    ASSERT_TRUE(is_finite(y)) << i;
    ASSERT_NEAR(glm::length(y), 1.f, 1e-5f) << i;
  }
}

TEST(one_euro_filter_quat, bad_dt_holds_and_input_is_normalised) {
  one_euro_filter_quat f;
  const glm::quat q = axis_angle(glm::vec3(1.f, 0.f, 0.f), 0.5f);
  const glm::quat y0 = f(q * 3.f, 0.1f);
  EXPECT_NEAR(glm::length(y0), 1.f, 1e-6f);
  EXPECT_LT(angle_between(y0, q), 1e-6f);
  const glm::quat other = axis_angle(glm::vec3(0.f, 1.f, 0.f), 1.f);
  EXPECT_EQ(f(other, 0.f), y0);
  EXPECT_EQ(f(other, -1.f), y0);
  EXPECT_EQ(f(other, k_nan), y0);
}

}  // namespace
}  // namespace avatarmap
