// Temporal smoothing of whole frames with One Euro filters (avatarmap/time/one_euro.hpp):
// - pose_filter: a proxy_pose's 55 local bone rotations, hips position, expression weights and
//   ARKit blendshape weights;
// - landmark_filter: every point of every part of a landmark_frame.
// Both keep their state in fixed-size arrays (no allocation, ever), take the time step from
// the frames' timestamps `t` (seconds), and are meant to be fed one stream in time order.
//
// Time handling (both filters):
// - first frame after construction or reset(): passes through unchanged;
// - t equal to the previous frame's t (a duplicate): the previous output is returned again;
// - t earlier than the previous frame's t, or non-finite: the stream is treated as restarted:
//   the filter resets and the frame passes through.
#pragma once

#include <array>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/time/one_euro.hpp"

namespace avatarmap {

namespace detail {
// Time step for a new frame at `t`, or a negative value when the filter must reset (first
// frame, time going backwards or non-finite). 0 means a duplicate timestamp.
inline float frame_dt(bool has_last, double last_t, double t) noexcept {
  if (!has_last || !std::isfinite(t) || t < last_t) return -1.f;
  return static_cast<float>(t - last_t);
}
}  // namespace detail

/// Options of pose_filter. The defaults are tuned for human motion captured at 25-30 fps by a
/// monocular estimator (docs/smoothing.md, "Live: lag against jitter", has the sweep they were
/// chosen from with tools/eval/live_filter.sh):
/// - rotation: One Euro at 0.7 Hz at rest, beta 0.3 s/rad on the speed measured as the angle
///   from the last output (one_euro_speed::output_change), that speed low-passed at 1 Hz;
///   then extrapolated along the low-passed angular velocity by 3/4 of the low-pass's own lag,
///   at most 50 ms. At 30 fps a bone turning steadily at 1, 3 and 6 rad/s is trailed by about
///   39, 13 and 9 ms (the One Euro filter of 1.5 Hz / beta 0.5 without extrapolation, the
///   default before 0.2: 56, 35 and 24 ms), a still noisy bone jitters ~15% less than with
///   it, and a turn at 3 rad/s that stops dead is overshot by ~4 degrees for ~0.3 s.
/// - position (hips, metres): 1 Hz at rest (the root is the noisiest, most visible signal),
///   beta 2 s/m: ~4 Hz at walking speed (1.5 m/s), ~7 Hz for a jump.
/// - expression (weights 0..1, the expressions and the 52 blendshapes alike): 3 Hz at rest,
///   beta 1 s: a blink (0 -> 1 in ~0.1 s, ~10/s) gets ~13 Hz, i.e. passes almost unfiltered
///   while flicker of a still face is damped.
/// - d_cutoff 1 Hz for position and expressions, as the paper recommends.
struct pose_filter_options {
  one_euro_params rotation{0.7f, 0.3f, 1.0f};
  one_euro_params position{1.0f, 2.0f, 1.0f};
  one_euro_params expression{3.0f, 1.0f, 1.0f};
  /// How the rotations' speed is measured and how far they are extrapolated (one_euro.hpp).
  one_euro_quat_options rotation_options{one_euro_speed::output_change, 0.75f, 0.05f,
                                         one_euro_velocity::filtered};
  bool enabled = true;  // false: apply() copies its input and keeps no history
};

/// Filters a stream of proxy poses. Confidence is copied unchanged; `t` is the input's.
/// Thread-safety: one instance per stream; not shared between threads without a lock.
class pose_filter {
 public:
  explicit pose_filter(const pose_filter_options& options = {}) noexcept { set_options(options); }

  /// New options. The history is kept (the new parameters apply from the next frame), except
  /// that disabling clears it.
  void set_options(const pose_filter_options& options) noexcept {
    options_ = options;
    for (auto& f : rotations_) {
      f.set_params(options.rotation);
      f.set_options(options.rotation_options);
    }
    position_.set_params(options.position);
    for (auto& f : expressions_) f.set_params(options.expression);
    for (auto& f : blendshapes_) f.set_params(options.expression);
    if (!options.enabled) reset();
  }
  const pose_filter_options& options() const noexcept { return options_; }

  /// Forgets the history: the next frame passes through.
  void reset() noexcept {
    for (auto& f : rotations_) f.reset();
    position_.reset();
    for (auto& f : expressions_) f.reset();
    for (auto& f : blendshapes_) f.reset();
    has_last_ = false;
  }

  /// Filters `in` into `out`; `out` may be `in` (in-place). Never fails and never writes a
  /// non-finite value: non-finite rotations, positions or weights in `in` are treated as
  /// missing (the previous output is held; identity / default hips / 0 before any).
  void apply(const proxy_pose& in, proxy_pose& out) noexcept {
    if (&in != &out) out = in;
    if (!options_.enabled) return;
    float dt = detail::frame_dt(has_last_, last_t_, in.t);
    if (dt < 0.f) {
      reset();
      dt = 0.f;  // first samples pass through regardless of dt
    }
    last_t_ = in.t;
    has_last_ = true;
    for (int b = 0; b < k_bone_count; ++b) out.rotations[b] = rotations_[b](in.rotations[b], dt);
    out.hips_position = position_(in.hips_position, dt);
    if (!position_.initialized()) out.hips_position = glm::vec3(0.f, k_default_hips_height, 0.f);
    for (int e = 0; e < k_expression_count; ++e)
      out.expressions[e] = expressions_[e](in.expressions[e], dt);
    for (int s = 0; s < k_blendshape_count; ++s)
      out.blendshapes[s] = blendshapes_[s](in.blendshapes[s], dt);
  }

 private:
  pose_filter_options options_;
  std::array<one_euro_filter_quat, k_bone_count> rotations_;
  one_euro_filter_vec3 position_;
  std::array<one_euro_filter, k_expression_count> expressions_;
  std::array<one_euro_filter, k_blendshape_count> blendshapes_;
  double last_t_ = 0.0;
  bool has_last_ = false;
};

namespace detail {
constexpr bool is_world_part(frame_part p) {
  return p == frame_part::pose_world || p == frame_part::left_hand_world ||
         p == frame_part::right_hand_world;
}
// Capacity (points) of a part's storage in landmark_frame.
constexpr int part_capacity(frame_part p) { return frame_part_capacity(p); }
constexpr int part_offset(frame_part p) {
  int o = 0;
  for (int q = 0; q < static_cast<int>(p); ++q) o += part_capacity(static_cast<frame_part>(q));
  return o;
}
inline constexpr int k_frame_point_capacity =
    part_offset(frame_part::face) + k_face_mesh_iris_count;
}  // namespace detail

/// Options of landmark_filter. Image parts are in normalised image units (fractions of the
/// width), world parts in metres; both with speed in units per second. Defaults for 25-30 fps
/// MediaPipe output: 1 Hz at rest removes the landmark models' sub-pixel jitter; beta 10
/// raises the cutoff to ~11 Hz at 1 unit/s (a hand crossing the image in a second, or moving
/// at 1 m/s), so fast gestures keep up.
struct landmark_filter_options {
  one_euro_params image{1.0f, 10.0f, 1.0f};
  one_euro_params world{1.0f, 10.0f, 1.0f};
  bool enabled = true;  // false: apply() copies its input and keeps no history
};

/// Filters the x, y, z of every point of a stream of landmark frames; visibility and presence
/// are copied. Per part and per point: a part absent from a frame resets that part's filters
/// (when it comes back it starts fresh), a point with a non-finite coordinate is copied as is
/// ("not seen") and resets that point's filter, face points beyond face_count are reset.
/// Thread-safety: one instance per stream.
class landmark_filter {
 public:
  explicit landmark_filter(const landmark_filter_options& options = {}) noexcept {
    set_options(options);
  }

  void set_options(const landmark_filter_options& options) noexcept {
    options_ = options;
    for (int p = 0; p < k_frame_part_count; ++p) {
      const auto part = static_cast<frame_part>(p);
      const one_euro_params& params = detail::is_world_part(part) ? options.world : options.image;
      for (int i = 0; i < detail::part_capacity(part); ++i) filter(part, i).set_params(params);
    }
    if (!options.enabled) reset();
  }
  const landmark_filter_options& options() const noexcept { return options_; }

  void reset() noexcept {
    for (auto& f : filters_) f.reset();
    has_last_ = false;
  }

  /// Filters `in` into `out`; `out` may be `in` (in-place). Copies t, parts and face_count;
  /// the storage of parts absent from `in` is left as it was in `out`.
  void apply(const landmark_frame& in, landmark_frame& out) noexcept {
    out.t = in.t;
    out.parts = in.parts;
    out.face_count = in.face_count;
    float dt = detail::frame_dt(has_last_, last_t_, in.t);
    if (dt < 0.f || !options_.enabled) {
      reset();
      dt = 0.f;
    }
    last_t_ = in.t;
    has_last_ = options_.enabled;
    for (int p = 0; p < k_frame_part_count; ++p) {
      const auto part = static_cast<frame_part>(p);
      const landmark* src = points(in, part);
      landmark* dst = points(out, part);
      const int n = detail::part_capacity(part);
      const int used = !in.has(part) ? 0
                       : part == frame_part::face
                           ? (in.face_count < 0 ? 0 : (in.face_count > n ? n : in.face_count))
                           : n;
      for (int i = used; i < n; ++i) filter(part, i).reset();
      for (int i = 0; i < used; ++i) {
        const landmark& l = src[i];
        const glm::vec3 v(l.x, l.y, l.z);
        landmark r = l;
        if (!options_.enabled) {
          // plain copy
        } else if (!is_finite(v)) {
          filter(part, i).reset();
        } else {
          const glm::vec3 f = filter(part, i)(v, dt);
          r.x = f.x;
          r.y = f.y;
          r.z = f.z;
        }
        dst[i] = r;
      }
    }
  }

 private:
  static landmark* points(landmark_frame& f, frame_part p) { return f.points(p); }
  static const landmark* points(const landmark_frame& f, frame_part p) { return f.points(p); }
  one_euro_filter_vec3& filter(frame_part p, int i) noexcept {
    return filters_[detail::part_offset(p) + i];
  }

  landmark_filter_options options_;
  std::array<one_euro_filter_vec3, detail::k_frame_point_capacity> filters_;
  double last_t_ = 0.0;
  bool has_last_ = false;
};

}  // namespace avatarmap
