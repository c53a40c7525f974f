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

/// How one_euro_filter_quat measures the angular speed that raises its cutoff.
enum class one_euro_speed : unsigned char {
  /// The angle from the previous output to the new sample per second (what the scalar and
  /// vec3 filters do). It includes the filter's own lag: at a steady v it reads
  /// v (1 + lag / dt), and noise of a still input reads as its full per-frame size.
  output_change,
  /// The input's angular velocity vector (the rotation from the previous sample to this one,
  /// as axis * angle, per second; in the parent's frame), low-passed at d_cutoff, then its
  /// length: the reference implementations' derivative (Casiez et al.'s, MediaPipe's). At a
  /// steady v it reads v; noise of a still input averages out in the vector, so a still
  /// noisy bone keeps a cutoff near min_cutoff.
  input_velocity,
};

/// Which angular velocity one_euro_filter_quat extrapolates along.
enum class one_euro_velocity : unsigned char {
  /// The low-passed rotation's own angular velocity, low-passed again at d_cutoff: at a steady
  /// turn it equals the input's, and of a still noisy input the low-pass has already removed
  /// most of the noise (so the extrapolation adds little jitter).
  filtered,
  /// The input's angular velocity low-passed at d_cutoff (as one_euro_speed::input_velocity):
  /// reacts sooner when a turn starts, but carries the input's noise.
  input,
};

/// Rotation-only options of one_euro_filter_quat (beside one_euro_params).
struct one_euro_quat_options {
  one_euro_speed speed = one_euro_speed::output_change;
  /// Constant-velocity extrapolation: the output is the low-passed rotation turned further
  /// along the `velocity` below by prediction * (the low-pass's own lag at the current cutoff,
  /// 1 / (2 pi cutoff)), at most max_prediction_seconds. 0 = none; 1 cancels the lag of a
  /// steady turn (and overshoots where the turn stops). Clamped to [0, 1]; not a number
  /// counts as 0.
  float prediction = 0.f;
  float max_prediction_seconds = 0.1f;  // clamped to [0, 0.5]
  one_euro_velocity velocity = one_euro_velocity::filtered;
};

/// One Euro filter of a rotation, in the tangent space: the sample's angle from the previous
/// output (radians) is what the low-pass shrinks, and the output moves from the previous
/// output toward the sample along the shortest arc, output = slerp_shortest(q_hat_prev, q,
/// alpha). The speed that sets the cutoff is measured as options.speed says (rad/s). q and -q
/// are the same rotation: the sample is brought into the previous output's hemisphere first,
/// so sign flips of the input neither count as motion nor flip the output (the output's sign
/// is continuous; compare outputs as rotations). Input need not be unit length; it is
/// normalised. beta is in seconds per radian. With options.prediction > 0 the output leads
/// the low-passed rotation (see one_euro_quat_options); value() is the output.
class one_euro_filter_quat {
 public:
  explicit one_euro_filter_quat(const one_euro_params& params = {},
                                const one_euro_quat_options& options = {}) noexcept
      : params_(params) {
    set_options(options);
  }

  glm::quat operator()(glm::quat q, float dt) noexcept {
    const float n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
    if (!(n2 > 1e-12f) || !std::isfinite(n2)) {
      // A missing sample: the next one's motion spans this step too.
      if (initialized_ && detail::valid_dt(dt)) missed_seconds_ += dt;
      return out_;
    }
    q = q * (1.f / std::sqrt(n2));
    if (!initialized_) {
      q_hat_ = out_ = last_in_ = q;
      missed_seconds_ = 0.f;
      speed_hat_ = 0.f;
      velocity_hat_ = trend_hat_ = glm::vec3(0.f);
      initialized_ = true;
      return out_;
    }
    if (!detail::valid_dt(dt)) return out_;
    if (glm::dot(q, q_hat_) < 0.f) q = -q;
    const float a_d = one_euro_alpha(params_.d_cutoff, dt);
    // The step's quaternion q_hat^-1 q; its vector part has length sin(angle / 2).
    const glm::quat step = glm::conjugate(q_hat_) * q;
    const float vn = std::sqrt(step.x * step.x + step.y * step.y + step.z * step.z);
    const float span = dt + missed_seconds_;  // the time the input's step took
    missed_seconds_ = 0.f;
    if (track_input_) {
      velocity_hat_ += a_d * (angular_velocity(last_in_, q, span) - velocity_hat_);
      last_in_ = q;
    }
    if (options_.speed == one_euro_speed::input_velocity) {
      speed_hat_ = std::sqrt(glm::dot(velocity_hat_, velocity_hat_));
    } else {
      // The chord 2 |v| (= 2 sin(angle / 2)) for the angle: within 1.2% of it up to 30
      // degrees per sample, and it only tunes the cutoff.
      speed_hat_ += a_d * (2.f * vn / dt - speed_hat_);
    }
    const float cutoff = params_.min_cutoff + params_.beta * speed_hat_;
    glm::vec3 turned(0.f);  // q_hat's turn this step: axis * angle, parent's frame
    if (vn >= 1e-7f) {
      // slerp(q_hat, q, alpha) = q_hat * step^alpha: turn the fraction alpha of the step's
      // angle about its axis (one atan2 and one sincos instead of slerp's four calls).
      const float half = std::atan2(vn, step.w) * one_euro_alpha(cutoff, dt);
      const float s = std::sin(half) / vn;
      // The step's axis is in q_hat's own frame; q_hat turns it into the parent's.
      if (prediction_ > 0.f)
        turned = q_hat_ * (glm::vec3(step.x, step.y, step.z) * (2.f * half / vn));
      q_hat_ = normalized(q_hat_ * glm::quat(std::cos(half), step.x * s, step.y * s, step.z * s));
    }
    out_ = q_hat_;
    if (prediction_ > 0.f) {
      if (options_.velocity == one_euro_velocity::filtered)
        trend_hat_ += a_d * (turned * (1.f / span) - trend_hat_);
      // A first-order low-pass trails a steady turn by exactly its time constant (for this
      // discretisation at any dt): turn ahead by the velocity times that lag.
      const float c = cutoff > 1e-6f ? cutoff : 1e-6f;
      float lead = prediction_ / (2.f * k_pi * c);
      if (lead > max_prediction_) lead = max_prediction_;
      const glm::vec3& w =
          options_.velocity == one_euro_velocity::filtered ? trend_hat_ : velocity_hat_;
      const glm::vec3 r = w * (0.5f * lead);  // half the rotation vector
      const float rn = std::sqrt(glm::dot(r, r));
      if (rn > 1e-9f) {
        const float s = std::sin(rn) / rn;
        out_ = normalized(glm::quat(std::cos(rn), r.x * s, r.y * s, r.z * s) * q_hat_);
      }
    }
    return out_;
  }

  void reset() noexcept {
    initialized_ = false;
    q_hat_ = out_ = last_in_ = identity_quat();
    speed_hat_ = 0.f;
    velocity_hat_ = trend_hat_ = glm::vec3(0.f);
    missed_seconds_ = 0.f;
  }
  bool initialized() const noexcept { return initialized_; }
  /// Last output (identity before the first valid sample); unit length.
  const glm::quat& value() const noexcept { return out_; }
  /// Filtered angular speed (rad/s) that set the last cutoff.
  float speed() const noexcept { return speed_hat_; }
  const one_euro_params& params() const noexcept { return params_; }
  void set_params(const one_euro_params& params) noexcept { params_ = params; }
  const one_euro_quat_options& options() const noexcept { return options_; }
  /// New rotation options; the state is kept (a velocity estimate that was not kept so far
  /// starts from 0).
  void set_options(const one_euro_quat_options& options) noexcept {
    options_ = options;
    const float p = options.prediction;
    if (!(prediction_ > 0.f)) trend_hat_ = glm::vec3(0.f);  // not kept while off
    prediction_ = p > 0.f ? (p < 1.f ? p : 1.f) : 0.f;      // NaN -> 0
    const float m = options.max_prediction_seconds;
    max_prediction_ = m > 0.f ? (m < 0.5f ? m : 0.5f) : 0.f;
    const bool track = options.speed == one_euro_speed::input_velocity ||
                       (prediction_ > 0.f && options.velocity == one_euro_velocity::input);
    if (track && !track_input_) {
      velocity_hat_ = glm::vec3(0.f);
      last_in_ = q_hat_;
    }
    track_input_ = track;
  }

 private:
  // The rotation vector (axis * angle, radians; in the parent's frame) of the turn from `from`
  // to `to` (to = turn * from), divided by `seconds`. Exact angle (atan2 of the half angle).
  static glm::vec3 angular_velocity(const glm::quat& from, const glm::quat& to,
                                    float seconds) noexcept {
    glm::quat d = to * glm::conjugate(from);
    if (d.w < 0.f) d = -d;
    const glm::vec3 v(d.x, d.y, d.z);
    const float n = std::sqrt(glm::dot(v, v));
    return n > 1e-9f ? v * (2.f * std::atan2(n, d.w) / (n * seconds)) : v * (2.f / seconds);
  }

  one_euro_params params_;
  one_euro_quat_options options_;
  float prediction_ = 0.f;
  float max_prediction_ = 0.f;
  bool track_input_ = false;               // keep velocity_hat_ (and last_in_) up to date
  glm::quat q_hat_{1.f, 0.f, 0.f, 0.f};    // the low-passed rotation
  glm::quat out_{1.f, 0.f, 0.f, 0.f};      // the output (q_hat_, or led by the prediction)
  glm::quat last_in_{1.f, 0.f, 0.f, 0.f};  // the last valid sample (velocity tracking)
  glm::vec3 velocity_hat_{0.f};  // the input's low-passed angular velocity, rad/s, parent frame
  glm::vec3 trend_hat_{0.f};     // q_hat_'s low-passed angular velocity, rad/s, parent frame
  float speed_hat_ = 0.f;
  float missed_seconds_ = 0.f;  // time of missing samples since the last valid one
  bool initialized_ = false;
};

}  // namespace avatarmap
