// Resampling a stream of proxy poses captured at an irregular, low rate (the paper: capture
// ~20-30 fps) to any render time (display 60+ fps): shortest-arc slerp of every bone rotation
// and linear interpolation of the hips position, expression and blendshape weights between the two
// captured frames around the render time, with bounded extrapolation past the newest frame.
//
// Fixed memory: the last k_pose_resampler_capacity (4) captured frames in a ring; push() and
// sample() never allocate.
#pragma once

#include <array>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <limits>

#include "avatarmap/core/option_table.hpp"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

inline constexpr int k_pose_resampler_capacity = 4;

struct pose_resampler_options {
  /// How far past the newest captured frame sample() extrapolates, in seconds (>= 0). Beyond
  /// it the pose holds. 0.1 s covers two to three missing frames at 20-30 fps (the estimator
  /// drops frames it cannot keep up with) without letting a limb fly away when capture stalls.
  double max_extrapolation_seconds = 0.1;
};

/// The resampler's options (avm_solver_options' field of the same name; core/option_table.hpp).
inline constexpr option_row<pose_resampler_options> k_pose_resampler_option_table[] = {
    option_row<pose_resampler_options>(
        "max_extrapolation_seconds",
        AVATARMAP_OPTION_FIELD(pose_resampler_options, max_extrapolation_seconds))
        .number(0, std::numeric_limits<double>::infinity())
        .help("how far past the newest frame a sample extrapolates (seconds); beyond it the "
              "pose holds"),
};

/// Thread-safety: one instance per stream; push() and sample() must not run concurrently.
class pose_resampler {
 public:
  explicit pose_resampler(const pose_resampler_options& options = {}) noexcept
      : options_(options) {}

  const pose_resampler_options& options() const noexcept { return options_; }
  void set_options(const pose_resampler_options& options) noexcept { options_ = options; }

  /// Adds a captured frame (its time is frame.t, seconds). Returns false, and keeps the state,
  /// when frame.t is not finite. Otherwise:
  /// - t greater than the newest frame's: appended (the oldest of the 4 kept is dropped);
  /// - t equal to the newest frame's: replaces it;
  /// - t earlier than the newest frame's: the stream is taken as restarted: everything kept is
  ///   dropped and the frame becomes the only one.
  /// The stored copy is sanitised so that sample() can never produce non-finite values:
  /// rotations are normalised; a non-finite (or zero) rotation, position, expression or
  /// blendshape weight is replaced by the previous kept frame's (identity, default hips, 0 when
  /// there is none); expression and blendshape weights, confidences and foot contacts are
  /// clamped to [0, 1] (NaN: 0).
  bool push(const proxy_pose& frame) noexcept {
    if (!std::isfinite(frame.t)) return false;
    if (count_ > 0 && frame.t <= newest().t) {
      if (frame.t == newest().t) {
        --count_;
      } else {
        count_ = 0;
      }
    }
    const proxy_pose* prev = count_ > 0 ? &newest() : nullptr;
    int slot;
    if (count_ < k_pose_resampler_capacity) {
      slot = (head_ + count_) % k_pose_resampler_capacity;
      ++count_;
    } else {
      slot = head_;
      head_ = (head_ + 1) % k_pose_resampler_capacity;
    }
    proxy_pose& dst = frames_[slot];
    if (prev == &dst) prev = nullptr;  // cannot happen with capacity > 1; defensive
    dst.t = frame.t;
    for (int b = 0; b < k_bone_count; ++b) {
      const glm::quat& q = frame.rotations[b];
      const float n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
      if (n2 > 1e-12f && std::isfinite(n2)) {
        dst.rotations[b] = q * (1.f / std::sqrt(n2));
      } else {
        dst.rotations[b] = prev ? prev->rotations[b] : identity_quat();
      }
      dst.confidence[b] = clamp01(frame.confidence[b]);
    }
    if (is_finite(frame.hips_position)) {
      dst.hips_position = frame.hips_position;
    } else {
      dst.hips_position = prev ? prev->hips_position : glm::vec3(0.f, k_default_hips_height, 0.f);
    }
    for (int e = 0; e < k_expression_count; ++e) {
      const float w = frame.expressions[e];
      dst.expressions[e] = std::isfinite(w) ? clamp01(w) : (prev ? prev->expressions[e] : 0.f);
    }
    for (int s = 0; s < k_blendshape_count; ++s) {
      const float w = frame.blendshapes[s];
      dst.blendshapes[s] = std::isfinite(w) ? clamp01(w) : (prev ? prev->blendshapes[s] : 0.f);
    }
    for (int f = 0; f < 2; ++f) dst.foot_contact[f] = clamp01(frame.foot_contact[f]);
    return true;
  }

  /// The pose at time `t` (seconds) into `out`, with out.t = t. Returns false, leaving `out`
  /// untouched, when no frame was pushed or `t` is not finite. Otherwise:
  /// - t at or before the oldest kept frame: that frame;
  /// - between two kept frames a (t_a <= t <= t_b) and b, with u = (t - t_a) / (t_b - t_a):
  ///   rotations slerp_shortest(a, b, u), hips position, expressions, blendshapes and foot
  ///   contacts lerped, confidence min(a, b); exactly at a kept frame's time: that frame (same
  ///   quaternion signs);
  /// - after the newest frame b (previous frame a): extrapolation at constant angular and
  ///   linear velocity, slerp_shortest(a, b, 1 + h / (t_b - t_a)) with h = min(t - t_b,
  ///   max_extrapolation_seconds), hips position likewise, expressions, blendshapes and foot
  ///   contacts likewise but clamped to [0, 1], confidence min(a, b); with only one frame kept:
  ///   that frame.
  /// Whatever was pushed, the result is finite: a value the blend cannot give finite (frames
  /// too close in time to divide by, values near the float limits) is the later frame's.
  bool sample(double t, proxy_pose& out) const noexcept {
    if (count_ == 0 || !std::isfinite(t)) return false;
    const proxy_pose& first = at(0);
    const proxy_pose& last = newest();
    if (t <= first.t || count_ == 1) {
      out = first;  // with one frame kept, first is also the newest: hold it
      out.t = t;
      return true;
    }
    if (t > last.t) {
      const proxy_pose& a = at(count_ - 2);
      const double h = std::fmin(t - last.t, std::fmax(0.0, options_.max_extrapolation_seconds));
      // Frames a denormal apart give a factor beyond the float range, whose cast would be
      // undefined: infinity makes blend hold the newest frame.
      const double u = 1.0 + h / (last.t - a.t);
      blend(a, last,
            u <= static_cast<double>(std::numeric_limits<float>::max())
                ? static_cast<float>(u)
                : std::numeric_limits<float>::infinity(),
            out);
      out.t = t;
      return true;
    }
    for (int k = 0; k + 1 < count_; ++k) {
      const proxy_pose& a = at(k);
      const proxy_pose& b = at(k + 1);
      if (t > b.t) continue;
      if (t == b.t) {
        out = b;
      } else if (t == a.t) {
        out = a;
      } else {
        blend(a, b, static_cast<float>((t - a.t) / (b.t - a.t)), out);
      }
      out.t = t;
      return true;
    }
    out = last;  // unreachable: t <= last.t was established above
    out.t = t;
    return true;
  }

  /// Drops every kept frame.
  void reset() noexcept {
    count_ = 0;
    head_ = 0;
  }
  /// Number of kept frames (0 .. 4).
  int size() const noexcept { return count_; }
  bool empty() const noexcept { return count_ == 0; }
  /// The k-th oldest kept frame (0 = oldest); k must be in [0, size()).
  const proxy_pose& frame(int k) const noexcept { return at(k); }

 private:
  static float clamp01(float v) noexcept {
    if (!(v > 0.f)) return 0.f;  // also NaN -> 0
    return v < 1.f ? v : 1.f;
  }
  const proxy_pose& at(int k) const noexcept {
    return frames_[(head_ + k) % k_pose_resampler_capacity];
  }
  const proxy_pose& newest() const noexcept { return at(count_ - 1); }

  // out = a + u (b - a) in each channel (u may exceed 1 when extrapolating). Does not set t.
  // What could still come out non-finite holds b's value instead: everything when u is not
  // finite (two frames closer in time than the division can resolve, an infinite extrapolation
  // limit), a hips axis that overflows (values near the float limits). Rotations are
  // renormalised because slerp's two weights at a large u lose the unit length to rounding.
  // The hips lerp is written (1 - u) a + u b so that it cannot overflow for u in [0, 1].
  static void blend(const proxy_pose& a, const proxy_pose& b, float u, proxy_pose& out) noexcept {
    if (!std::isfinite(u)) {
      out = b;  // the caller sets t
      for (int i = 0; i < k_bone_count; ++i)
        out.confidence[i] = a.confidence[i] < b.confidence[i] ? a.confidence[i] : b.confidence[i];
      return;
    }
    const float v = 1.f - u;
    for (int i = 0; i < k_bone_count; ++i) {
      const glm::quat q = slerp_shortest(a.rotations[i], b.rotations[i], u);
      const float n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
      out.rotations[i] =
          n2 > 1e-12f && std::isfinite(n2) ? q * (1.f / std::sqrt(n2)) : b.rotations[i];
      out.confidence[i] = a.confidence[i] < b.confidence[i] ? a.confidence[i] : b.confidence[i];
    }
    for (int k = 0; k < 3; ++k) {
      const float p = v * a.hips_position[k] + u * b.hips_position[k];
      out.hips_position[k] = std::isfinite(p) ? p : b.hips_position[k];
    }
    for (int e = 0; e < k_expression_count; ++e)  // clamp01 also turns NaN into 0
      out.expressions[e] = clamp01(v * a.expressions[e] + u * b.expressions[e]);
    for (int s = 0; s < k_blendshape_count; ++s)
      out.blendshapes[s] = clamp01(v * a.blendshapes[s] + u * b.blendshapes[s]);
    for (int f = 0; f < 2; ++f)
      out.foot_contact[f] = clamp01(v * a.foot_contact[f] + u * b.foot_contact[f]);
  }

  pose_resampler_options options_;
  std::array<proxy_pose, k_pose_resampler_capacity> frames_;
  int head_ = 0;
  int count_ = 0;
};

}  // namespace avatarmap
