// The One Euro filter (Casiez, Roussel, Vogel, "1 Euro Filter: A Simple Speed-based Low-pass
// Filter for Noisy Input in Interactive Systems", CHI 2012), time-step aware, for a scalar, a
// glm::vec3 and a unit quaternion.
//
// Each sample is low-passed with a first-order filter whose cutoff rises with the signal's
// (separately low-passed) speed:
//   speed_hat = lowpass(d_cutoff, |x - x_hat_prev| / dt)
//   cutoff    = min_cutoff + beta * speed_hat
//   x_hat     = x_hat_prev + alpha(cutoff, dt) * (x - x_hat_prev)
//   alpha(f, dt) = 1 / (1 + tau / dt),  tau = 1 / (2 pi f)
// alpha is the paper's (backward-Euler) discretisation of the continuous first-order low-pass
// with time constant tau: for a fixed dt the step response after n samples is exactly
// 1 - (1 - alpha)^n, which tends to 1 - exp(-t / tau) as dt -> 0, so different sample rates
// give (nearly) the same response in time, not in samples. With beta = 0 the filter is a plain
// first-order low-pass at min_cutoff.
//
// Behaviour common to the three variants (all header-only, allocation-free, noexcept):
// - The first valid sample passes through unchanged (speed starts at 0).
// - dt <= 0 or non-finite dt: the sample is ignored and the previous output is returned
//   (state unchanged). Callers that know time went backwards should call reset().
// - Non-finite samples (any component NaN/inf, or a quaternion of ~zero length) are treated as
//   missing: ignored, previous output returned. Before the first valid sample the output is 0,
//   the zero vector or identity. No variant ever returns a non-finite value.
// - Parameters: min_cutoff and d_cutoff in Hz (> 0; non-positive values are clamped to a tiny
//   positive cutoff, i.e. "hold"), beta in 1 / (units of the signal): seconds per unit for a
//   scalar or a position, seconds per radian for a rotation.
#pragma once

#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {

/// Parameters of a One Euro filter (see the header comment for units).
struct one_euro_params {
  float min_cutoff = 1.0f;  // Hz: cutoff at zero speed (jitter removal at rest)
  float beta = 0.0f;        // cutoff increase per unit of speed (lag reduction when moving)
  float d_cutoff = 1.0f;    // Hz: cutoff of the speed estimate
};

/// Smoothing factor of a first-order low-pass with cutoff `cutoff_hz` for a step of `dt`
/// seconds: 1 / (1 + tau / dt), tau = 1 / (2 pi cutoff). In (0, 1) for positive finite input.
inline float one_euro_alpha(float cutoff_hz, float dt) noexcept {
  const float cutoff = cutoff_hz > 1e-6f ? cutoff_hz : 1e-6f;
  const float tau = 1.f / (2.f * k_pi * cutoff);
  return 1.f / (1.f + tau / dt);
}

namespace detail {
inline bool valid_dt(float dt) noexcept { return dt > 0.f && std::isfinite(dt); }
}  // namespace detail

/// One Euro filter of a scalar signal.
class one_euro_filter {
 public:
  explicit one_euro_filter(const one_euro_params& params = {}) noexcept : params_(params) {}

  /// Filters sample `x` taken `dt` seconds after the previous one; returns the output.
  float operator()(float x, float dt) noexcept {
    if (!std::isfinite(x)) return x_hat_;
    if (!initialized_) {
      x_hat_ = x;
      speed_hat_ = 0.f;
      initialized_ = true;
      return x_hat_;
    }
    if (!detail::valid_dt(dt)) return x_hat_;
    const float speed = std::abs(x - x_hat_) / dt;
    speed_hat_ += one_euro_alpha(params_.d_cutoff, dt) * (speed - speed_hat_);
    const float cutoff = params_.min_cutoff + params_.beta * speed_hat_;
    x_hat_ += one_euro_alpha(cutoff, dt) * (x - x_hat_);
    return x_hat_;
  }

  /// Forgets the history: the next valid sample passes through.
  void reset() noexcept {
    initialized_ = false;
    x_hat_ = 0.f;
    speed_hat_ = 0.f;
  }
  bool initialized() const noexcept { return initialized_; }
  /// Last output (0 before the first valid sample).
  float value() const noexcept { return x_hat_; }
  const one_euro_params& params() const noexcept { return params_; }
  /// New parameters; the state is kept.
  void set_params(const one_euro_params& params) noexcept { params_ = params; }

 private:
  one_euro_params params_;
  float x_hat_ = 0.f;
  float speed_hat_ = 0.f;
  bool initialized_ = false;
};

/// One Euro filter of a 3-D point. The speed is the magnitude of the velocity, so one cutoff
/// applies to all three components (the filter is isotropic: it does not bend a path toward
/// the axes).
class one_euro_filter_vec3 {
 public:
  explicit one_euro_filter_vec3(const one_euro_params& params = {}) noexcept : params_(params) {}

  glm::vec3 operator()(const glm::vec3& x, float dt) noexcept {
    if (!is_finite(x)) return x_hat_;
    if (!initialized_) {
      x_hat_ = x;
      speed_hat_ = 0.f;
      initialized_ = true;
      return x_hat_;
    }
    if (!detail::valid_dt(dt)) return x_hat_;
    const glm::vec3 d = x - x_hat_;
    const float speed = std::sqrt(glm::dot(d, d)) / dt;
    speed_hat_ += one_euro_alpha(params_.d_cutoff, dt) * (speed - speed_hat_);
    const float cutoff = params_.min_cutoff + params_.beta * speed_hat_;
    x_hat_ += one_euro_alpha(cutoff, dt) * d;
    return x_hat_;
  }

  void reset() noexcept {
    initialized_ = false;
    x_hat_ = glm::vec3(0.f);
    speed_hat_ = 0.f;
  }
  bool initialized() const noexcept { return initialized_; }
  const glm::vec3& value() const noexcept { return x_hat_; }
  const one_euro_params& params() const noexcept { return params_; }
  void set_params(const one_euro_params& params) noexcept { params_ = params; }

 private:
  one_euro_params params_;
  glm::vec3 x_hat_{0.f};
  float speed_hat_ = 0.f;
  bool initialized_ = false;
};

/// One Euro filter of a rotation, in the tangent space: the speed is the angle of
/// q_hat_prev^-1 * q (radians, = 2 |log|) divided by dt, and the output moves from the previous
/// output toward the sample along the shortest arc, output = slerp_shortest(q_hat_prev, q,
/// alpha). q and -q are the same rotation: the sample is brought into the previous output's
/// hemisphere first, so sign flips of the input neither count as motion nor flip the output
/// (the output's sign is continuous; compare outputs as rotations). Input need not be unit
/// length; it is normalised. beta is in seconds per radian.
class one_euro_filter_quat {
 public:
  explicit one_euro_filter_quat(const one_euro_params& params = {}) noexcept : params_(params) {}

  glm::quat operator()(glm::quat q, float dt) noexcept {
    const float n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
    if (!(n2 > 1e-12f) || !std::isfinite(n2)) return q_hat_;
    q = q * (1.f / std::sqrt(n2));
    if (!initialized_) {
      q_hat_ = q;
      speed_hat_ = 0.f;
      initialized_ = true;
      return q_hat_;
    }
    if (!detail::valid_dt(dt)) return q_hat_;
    if (glm::dot(q, q_hat_) < 0.f) q = -q;
    // Angular speed from the chord 2 |v| of the step's quaternion q_hat^-1 q (= 2 sin(angle/2)):
    // within 1.2% of the angle up to 30 degrees per sample, and it only tunes the cutoff.
    const glm::quat step = glm::conjugate(q_hat_) * q;
    const float chord = 2.f * std::sqrt(step.x * step.x + step.y * step.y + step.z * step.z);
    const float speed = chord / dt;  // rad/s
    speed_hat_ += one_euro_alpha(params_.d_cutoff, dt) * (speed - speed_hat_);
    const float cutoff = params_.min_cutoff + params_.beta * speed_hat_;
    // slerp(q_hat, q, alpha) = q_hat * step^alpha: turn the fraction alpha of the step's angle
    // about its axis (one atan2 and one sincos instead of slerp's four calls).
    const float vn = 0.5f * chord;  // |v| = sin(angle / 2)
    if (vn < 1e-7f) return q_hat_;
    const float half = std::atan2(vn, step.w) * one_euro_alpha(cutoff, dt);
    const float s = std::sin(half) / vn;
    const glm::quat part(std::cos(half), step.x * s, step.y * s, step.z * s);
    q_hat_ = normalized(q_hat_ * part);
    return q_hat_;
  }

  void reset() noexcept {
    initialized_ = false;
    q_hat_ = identity_quat();
    speed_hat_ = 0.f;
  }
  bool initialized() const noexcept { return initialized_; }
  /// Last output (identity before the first valid sample); unit length.
  const glm::quat& value() const noexcept { return q_hat_; }
  /// Filtered angular speed (rad/s) that set the last cutoff.
  float speed() const noexcept { return speed_hat_; }
  const one_euro_params& params() const noexcept { return params_; }
  void set_params(const one_euro_params& params) noexcept { params_ = params; }

 private:
  one_euro_params params_;
  glm::quat q_hat_{1.f, 0.f, 0.f, 0.f};
  float speed_hat_ = 0.f;
  bool initialized_ = false;
};

}  // namespace avatarmap
