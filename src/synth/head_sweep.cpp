// Seeded head sweep. See include/avatarmap/synth/head_sweep.hpp.
#include "avatarmap/synth/head_sweep.hpp"

#include <algorithm>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {

namespace {

constexpr float k_deg = k_pi / 180.f;
constexpr float k_return_probability = 0.25f;
constexpr float k_look_down_probability = 0.2f;
constexpr float k_front_degrees = 5.f;    // a return: each angle within +-5 degrees
constexpr float k_look_down_band = 15.f;  // a deep look down: pitch within 15 of pitch_min

float min_jerk(float s) {
  s = std::min(1.f, std::max(0.f, s));
  return s * s * s * (10.f + s * (-15.f + 6.f * s));
}

}  // namespace

glm::quat head_turn(const head_angles& a) {
  return axis_angle(glm::vec3(0.f, 1.f, 0.f), a.yaw * k_deg) *
         axis_angle(glm::vec3(1.f, 0.f, 0.f), -a.pitch * k_deg) *
         axis_angle(glm::vec3(0.f, 0.f, 1.f), a.roll * k_deg);
}

head_sweep::head_sweep(std::uint32_t seed, const head_sweep_options& options)
    : seed_(seed), options_(options) {
  restart();
}

void head_sweep::restart() {
  rng_.seed(seed_ ^ 0x6ead5eedu);
  a_ = b_ = head_angles{};
  t0_ = t1_ = t2_ = 0.0;
}

head_angles head_sweep::draw_key() {
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const head_sweep_options& o = options_;
  auto in = [&](float lo, float hi) { return lo + (hi - lo) * u(rng_); };
  const float kind = u(rng_);
  head_angles k;
  if (kind < k_return_probability) {
    k.yaw = in(-k_front_degrees, k_front_degrees);
    k.pitch = in(-k_front_degrees, k_front_degrees);
    k.roll = in(-k_front_degrees, k_front_degrees);
  } else if (kind < k_return_probability + k_look_down_probability) {
    k.pitch = in(o.pitch_min, std::min(o.pitch_max, o.pitch_min + k_look_down_band));
    k.yaw = in(-o.yaw_max, o.yaw_max);
    k.roll = in(-o.roll_max, o.roll_max);
  } else {
    k.pitch = in(o.pitch_min, o.pitch_max);
    k.yaw = in(-o.yaw_max, o.yaw_max);
    k.roll = in(-o.roll_max, o.roll_max);
  }
  return k;
}

void head_sweep::advance() {
  std::uniform_real_distribution<float> u(0.f, 1.f);
  a_ = b_;
  b_ = draw_key();
  t0_ = t2_;
  t1_ = t0_ + options_.move_min + (options_.move_max - options_.move_min) * u(rng_);
  t2_ = t1_ + options_.dwell_max * u(rng_);
}

head_angles head_sweep::at(double t) {
  if (!(t > 0.0)) t = 0.0;  // NaN too
  if (t < t0_) restart();
  while (t >= t2_) advance();
  const float w = t >= t1_ ? 1.f : min_jerk(static_cast<float>((t - t0_) / (t1_ - t0_)));
  head_angles h;
  h.yaw = a_.yaw + w * (b_.yaw - a_.yaw);
  h.pitch = a_.pitch + w * (b_.pitch - a_.pitch);
  h.roll = a_.roll + w * (b_.roll - a_.roll);
  return h;
}

}  // namespace avatarmap
