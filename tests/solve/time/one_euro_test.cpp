// Known behaviour of the One Euro filters (avatarmap/time/one_euro.hpp).
#include "avatarmap/time/one_euro.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <limits>
#include <random>
#include <vector>

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

// Every variant: the plain filter, the input's velocity as the speed, extrapolation along
// either velocity (with a long horizon, so that it is exercised hard).
std::vector<one_euro_quat_options> quat_variants() {
  one_euro_quat_options input_speed;
  input_speed.speed = one_euro_speed::input_velocity;
  one_euro_quat_options predict_filtered;
  predict_filtered.prediction = 1.f;
  predict_filtered.max_prediction_seconds = 0.5f;
  one_euro_quat_options predict_input = predict_filtered;
  predict_input.velocity = one_euro_velocity::input;
  predict_input.speed = one_euro_speed::input_velocity;
  return {one_euro_quat_options{}, input_speed, predict_filtered, predict_input};
}

TEST(one_euro_filter_quat, never_produces_non_finite_output) {
  for (const one_euro_quat_options& o : quat_variants()) {
    one_euro_filter_quat f({1.f, 2.f, 1.f}, o);
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

// A bone turning about `axis` at `omega` rad/s from `base`, sampled every `dt` for `seconds`:
// the last output's signed angle behind the input about the axis (radians; negative = ahead).
float trail_of_turn(one_euro_filter_quat& f, float omega, float dt, double seconds) {
  const glm::vec3 axis = glm::normalize(glm::vec3(1.f, 2.f, -1.f));
  const glm::quat base = axis_angle(glm::vec3(0.f, 0.f, 1.f), 0.6f);
  glm::quat in, out;
  for (int i = 0; i <= static_cast<int>(std::lround(seconds / dt)); ++i) {
    in = axis_angle(axis, omega * dt * static_cast<float>(i)) * base;
    out = f(in, dt);
  }
  glm::quat d = out * glm::conjugate(in);
  if (d.w < 0.f) d = -d;
  return -2.f * std::atan2(glm::dot(glm::vec3(d.x, d.y, d.z), axis), d.w);
}

// Known answer: a first-order low-pass (beta = 0) trails a steady turn by exactly its time
// constant tau = 1 / (2 pi cutoff) in this discretisation (the error e obeys e = (1 - alpha)
// (e + v dt), so e = v dt (1 - alpha) / alpha = v tau), at any sample rate.
TEST(one_euro_filter_quat, low_pass_trails_a_steady_turn_by_its_time_constant) {
  for (float dt : {1.f / 25.f, 1.f / 30.f, 1.f / 60.f}) {
    one_euro_filter_quat f({2.f, 0.f, 1.f});
    EXPECT_NEAR(trail_of_turn(f, 3.f, dt, 3.0), 3.0 * tau_of(2.0), 1e-3) << dt;
  }
}

// The two speed estimates at a steady turn of v: the input's velocity reads v; the change from
// the last output reads v (tau + dt) / dt (chord for angle: within 1 % here), which is why the
// output_change filter's cutoff at a steady turn sits higher than min_cutoff + beta v.
TEST(one_euro_filter_quat, speed_estimates_of_a_steady_turn) {
  const float dt = 1.f / 30.f, v = 3.f;
  one_euro_quat_options input;
  input.speed = one_euro_speed::input_velocity;
  one_euro_filter_quat a({2.f, 0.f, 1.f}, input), b({2.f, 0.f, 1.f});
  trail_of_turn(a, v, dt, 3.0);
  trail_of_turn(b, v, dt, 3.0);
  EXPECT_NEAR(a.speed(), v, 1e-3f * v);
  EXPECT_NEAR(b.speed(), v * (tau_of(2.0) + dt) / dt, 0.01 * v * (tau_of(2.0) + dt) / dt);
}

// Noise of a still rotation averages out in the input's velocity vector, but reads as its full
// size in the distance from the last output.
TEST(one_euro_filter_quat, input_velocity_speed_of_still_noise_stays_low) {
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.f, 0.02f);
  one_euro_quat_options input;
  input.speed = one_euro_speed::input_velocity;
  one_euro_filter_quat a({1.f, 0.f, 1.f}, input), b({1.f, 0.f, 1.f});
  double sa = 0.0, sb = 0.0;
  for (int i = 0; i < 600; ++i) {
    const glm::vec3 w(noise(rng), noise(rng), noise(rng));
    const glm::quat q = axis_angle(glm::normalize(w), glm::length(w));
    a(q, 1.f / 30.f);
    b(q, 1.f / 30.f);
    if (i >= 60) {
      sa += a.speed();
      sb += b.speed();
    }
  }
  EXPECT_LT(sa, 0.4 * sb);
}

// Extrapolation by the filter's own lag cancels the trail of a steady turn (prediction 1);
// prediction p leaves (1 - p) of it; max_prediction_seconds caps the lead; either velocity.
TEST(one_euro_filter_quat, prediction_cancels_the_lag_of_a_steady_turn) {
  const double tau = tau_of(2.0);
  for (one_euro_velocity from : {one_euro_velocity::filtered, one_euro_velocity::input}) {
    for (float dt : {1.f / 25.f, 1.f / 60.f}) {
      for (float p : {1.f, 0.5f}) {
        one_euro_quat_options o;
        o.prediction = p;
        o.max_prediction_seconds = 0.5f;
        o.velocity = from;
        one_euro_filter_quat f({2.f, 0.f, 1.f}, o);
        EXPECT_NEAR(trail_of_turn(f, 3.f, dt, 4.0), 3.0 * (1.0 - p) * tau, 2e-3) << dt << " " << p;
      }
      one_euro_quat_options capped;
      capped.prediction = 1.f;
      capped.max_prediction_seconds = 0.03f;
      capped.velocity = from;
      one_euro_filter_quat g({2.f, 0.f, 1.f}, capped);
      EXPECT_NEAR(trail_of_turn(g, 3.f, dt, 4.0), 3.0 * (tau - 0.03), 2e-3) << dt;
    }
  }
}

// A turn that stops: the extrapolated output runs past the stop by a bounded angle and comes
// back to the final rotation; the plain filter never runs past it.
TEST(one_euro_filter_quat, prediction_overshoots_a_stop_boundedly_and_settles) {
  const float dt = 1.f / 30.f, v = 3.f;
  const glm::vec3 axis(0.f, 1.f, 0.f);
  one_euro_quat_options o;
  o.prediction = 1.f;
  o.max_prediction_seconds = 0.05f;
  one_euro_filter_quat f({0.7f, 0.3f, 1.f}, o), plain({0.7f, 0.3f, 1.f});
  float lead = 0.f, plain_lead = 0.f;
  glm::quat in, y;
  for (int i = 0; i <= 150; ++i) {  // 2 s turning, 3 s still
    const float t = std::min(i * dt, 2.f);
    in = axis_angle(axis, v * t);
    y = f(in, dt);
    const glm::quat z = plain(in, dt);
    if (i * dt > 2.f) {
      lead =
          std::max(lead, 2.f * std::atan2(glm::dot(glm::vec3(y.x, y.y, y.z), axis), y.w) - v * 2.f);
      plain_lead = std::max(
          plain_lead, 2.f * std::atan2(glm::dot(glm::vec3(z.x, z.y, z.z), axis), z.w) - v * 2.f);
    }
  }
  EXPECT_GT(lead, 0.f);
  EXPECT_LT(lead, v * 0.05f);  // at most the speed times the horizon
  EXPECT_LE(plain_lead, 1e-5f);
  EXPECT_LT(angle_between(y, in), 1e-3f);
}

// prediction is clamped to [0, 1] (not a number: 0) and max_prediction_seconds to [0, 0.5].
TEST(one_euro_filter_quat, prediction_options_are_clamped) {
  const float dt = 1.f / 30.f;
  auto trail = [&](float p, float m) {
    one_euro_quat_options o;
    o.prediction = p;
    o.max_prediction_seconds = m;
    one_euro_filter_quat f({2.f, 0.f, 1.f}, o);
    return trail_of_turn(f, 3.f, dt, 3.0);
  };
  EXPECT_NEAR(trail(k_nan, 0.5f), trail(0.f, 0.5f), 1e-6f);
  EXPECT_NEAR(trail(-1.f, 0.5f), trail(0.f, 0.5f), 1e-6f);
  EXPECT_NEAR(trail(7.f, 0.5f), trail(1.f, 0.5f), 1e-6f);
  EXPECT_NEAR(trail(1.f, k_nan), trail(0.f, 0.5f), 1e-6f);  // no horizon: no lead
  EXPECT_NEAR(trail(1.f, 9.f), trail(1.f, 0.5f), 1e-6f);
}

// A missing sample in a steady turn does not read as a jump: the input's velocity spans it.
TEST(one_euro_filter_quat, missing_samples_do_not_spike_the_input_velocity) {
  const float dt = 1.f / 30.f, v = 2.f;
  one_euro_quat_options input;
  input.speed = one_euro_speed::input_velocity;
  one_euro_filter_quat f({1.f, 0.f, 1.f}, input);
  const glm::vec3 axis(0.f, 0.f, 1.f);
  for (int i = 0; i <= 90; ++i) {
    const glm::quat q =
        i % 10 == 5 ? glm::quat(k_nan, 0.f, 0.f, 0.f) : axis_angle(axis, v * dt * i);
    f(q, dt);
    if (i > 60) {
      EXPECT_NEAR(f.speed(), v, 0.01f * v) << i;
    }
  }
}

TEST(one_euro_filter_quat, input_velocity_sign_flips_are_not_motion) {
  one_euro_quat_options o;
  o.speed = one_euro_speed::input_velocity;
  o.prediction = 1.f;
  o.velocity = one_euro_velocity::input;
  one_euro_filter_quat f({1.f, 5.f, 1.f}, o);
  const glm::quat q = glm::normalize(glm::quat(0.3f, 0.6f, -0.2f, 0.7f));
  for (int i = 0; i < 60; ++i) {
    const glm::quat y = f(i % 2 ? q : -q, 1.f / 30.f);
    EXPECT_LT(angle_between(y, q), 1e-5f);
  }
  EXPECT_LT(f.speed(), 1e-3f);
}

}  // namespace
}  // namespace avatarmap
