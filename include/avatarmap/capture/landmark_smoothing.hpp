// MediaPipe's temporal smoothing of landmarks in video mode (LandmarksSmoothingCalculator with
// its one_euro_filter, and VisibilitySmoothingCalculator's low-pass), so that a tracked video
// gives the landmarks Google's graphs give.
//
// This One Euro variant differs from time/one_euro.hpp (the solver's filter) on purpose, to
// match MediaPipe: the speed is estimated from the change of the RAW input (not of the
// output), the sampling rate comes from the timestamps, and values are scaled by 1 / object
// size (the landmarks' bounding box in pixels) before the speed is measured, so that the
// smoothing does not depend on how large the person is in the image.
//
// Allocation-free; fixed capacity of k_max_smoothed_points points.
#pragma once

#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap {

/// One Euro parameters as MediaPipe's OneEuroFilter options.
struct mediapipe_one_euro_params {
  float min_cutoff = 1.f;       // Hz
  float beta = 0.f;             // cutoff increase per unit of (scaled) speed
  float derivate_cutoff = 1.f;  // Hz, cutoff of the speed estimate
  bool disable_value_scaling = false;
  float min_allowed_object_scale = 1e-6f;  // smaller objects pass through unfiltered
};

/// MediaPipe's OneEuroFilter on one scalar.
class mediapipe_one_euro {
 public:
  /// Filters `value` at time `t` (seconds); `value_scale` multiplies the value change when the
  /// speed is measured. A time not after the previous one returns the value unfiltered.
  double apply(double t, double value_scale, double value) noexcept;
  void reset() noexcept;
  void set_params(const mediapipe_one_euro_params& p) noexcept { params_ = p; }

 private:
  struct low_pass {
    bool has = false;
    double raw = 0.0;
    double stored = 0.0;
    double apply(double v, double alpha) noexcept;
  };
  double alpha(double cutoff) const noexcept;
  mediapipe_one_euro_params params_{};
  double frequency_ = 30.0;  // MediaPipe's initial rate until two timestamps are seen
  double last_t_ = 0.0;
  bool has_t_ = false;
  low_pass x_;
  low_pass dx_;
};

/// MediaPipe's RelativeVelocityFilter (the "velocity_filter" of LandmarksSmoothingCalculator,
/// which pose graphs used before the One Euro filter): a low-pass whose weight of the new
/// value is 1 - 1 / (1 + velocity_scale * |speed|), the speed measured over up to
/// window_size past steps (only as far back as 1/30 s per step) on values scaled by
/// value_scale.
struct mediapipe_velocity_params {
  int window_size = 5;  // 1..16
  float velocity_scale = 10.f;
};

class mediapipe_velocity_filter {
 public:
  double apply(double t, double value_scale, double value) noexcept;
  void reset() noexcept;
  void set_params(const mediapipe_velocity_params& p) noexcept { params_ = p; }

 private:
  struct step {
    double distance = 0.0;
    double duration = 0.0;
  };
  static constexpr int k_capacity = 16;
  mediapipe_velocity_params params_{};
  step window_[k_capacity];
  int window_count_ = 0;  // newest first
  bool has_ = false;
  double last_t_ = 0.0, last_value_ = 0.0, last_scale_ = 1.0, stored_ = 0.0;
};

inline constexpr int k_max_smoothed_points = k_face_mesh_iris_count;

/// Smooths a set of landmarks (x, y, z per point) over time.
class landmark_smoother {
 public:
  explicit landmark_smoother(const mediapipe_one_euro_params& params = {}) noexcept;
  /// The velocity filter instead of One Euro (at most k_max_velocity_points points).
  explicit landmark_smoother(const mediapipe_velocity_params& params) noexcept;
  static constexpr int k_max_velocity_points = 40;
  /// Filters `count` points (<= k_max_smoothed_points) in place at time `t` (seconds).
  /// `normalized`: x, y are fractions of the image and z is in units of its width (the
  /// object scale is then measured in pixels, as MediaPipe does, so image_width/height must
  /// be > 0); otherwise the points are metric and image sizes are ignored. Non-finite points
  /// reset the filters and pass through. A different count than last time resets too.
  void apply(double t, landmark* points, int count, bool normalized, int image_width,
             int image_height) noexcept;
  void reset() noexcept;

 private:
  mediapipe_one_euro_params params_;
  bool velocity_ = false;
  int count_ = 0;
  mediapipe_one_euro filters_[k_max_smoothed_points][3];
  mediapipe_velocity_filter velocity_filters_[k_max_velocity_points][3];
};

/// VisibilitySmoothingCalculator's low-pass on visibility (alpha: weight of the new value).
class visibility_smoother {
 public:
  explicit visibility_smoother(float alpha = 0.1f) noexcept : alpha_(alpha) {}
  void apply(landmark* points, int count) noexcept;
  void reset() noexcept { count_ = 0; }

 private:
  float alpha_;
  int count_ = 0;
  float stored_[k_max_smoothed_points] = {};
};

}  // namespace avatarmap
