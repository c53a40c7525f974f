#include "avatarmap/capture/landmark_smoothing.hpp"

#include <algorithm>
#include <cmath>

namespace avatarmap {

namespace {
constexpr double k_two_pi = 6.28318530717958647692;
}

double mediapipe_one_euro::low_pass::apply(double v, double a) noexcept {
  stored = has ? a * v + (1.0 - a) * stored : v;
  raw = v;
  has = true;
  return stored;
}

double mediapipe_one_euro::alpha(double cutoff) const noexcept {
  const double te = 1.0 / frequency_;
  const double tau = 1.0 / (k_two_pi * std::max(cutoff, 1e-9));
  return 1.0 / (1.0 + tau / te);
}

double mediapipe_one_euro::apply(double t, double value_scale, double value) noexcept {
  if (has_t_ && !(t > last_t_)) return value;
  if (has_t_) frequency_ = 1.0 / (t - last_t_);
  last_t_ = t;
  has_t_ = true;
  const double dvalue = x_.has ? (value - x_.raw) * value_scale * frequency_ : 0.0;
  const double edvalue = dx_.apply(dvalue, alpha(params_.derivate_cutoff));
  const double cutoff = params_.min_cutoff + params_.beta * std::fabs(edvalue);
  return x_.apply(value, alpha(cutoff));
}

void mediapipe_one_euro::reset() noexcept {
  frequency_ = 30.0;
  has_t_ = false;
  last_t_ = 0.0;
  x_ = {};
  dx_ = {};
}

double mediapipe_velocity_filter::apply(double t, double value_scale, double value) noexcept {
  if (has_ && !(t > last_t_)) return value;
  double alpha = 1.0;
  if (has_) {
    const double distance = value * value_scale - last_value_ * last_scale_;
    const double duration = t - last_t_;
    double cum_distance = distance, cum_duration = duration;
    // MediaPipe assumes 30 values a second: older steps count only while they fit in
    // (1 + window) thirtieths of a second.
    const double max_duration = (1 + window_count_) / 30.0;
    for (int i = 0; i < window_count_; ++i) {
      if (cum_duration + window_[i].duration > max_duration) break;
      cum_distance += window_[i].distance;
      cum_duration += window_[i].duration;
    }
    const double velocity = cum_distance / cum_duration;
    alpha = 1.0 - 1.0 / (1.0 + params_.velocity_scale * std::fabs(velocity));
    const int cap = std::clamp(params_.window_size, 1, k_capacity);
    for (int i = std::min(window_count_, cap - 1); i > 0; --i) window_[i] = window_[i - 1];
    window_[0] = {distance, duration};
    window_count_ = std::min(window_count_ + 1, cap);
  }
  last_value_ = value;
  last_scale_ = value_scale;
  last_t_ = t;
  stored_ = has_ ? alpha * value + (1.0 - alpha) * stored_ : value;
  has_ = true;
  return stored_;
}

void mediapipe_velocity_filter::reset() noexcept {
  has_ = false;
  window_count_ = 0;
}

landmark_smoother::landmark_smoother(const mediapipe_velocity_params& params) noexcept
    : velocity_(true) {
  for (auto& f : velocity_filters_)
    for (auto& c : f) c.set_params(params);
}

landmark_smoother::landmark_smoother(const mediapipe_one_euro_params& params) noexcept
    : params_(params) {
  for (auto& f : filters_)
    for (auto& c : f) c.set_params(params);
}

void landmark_smoother::reset() noexcept {
  for (int i = 0; i < count_; ++i) {
    if (velocity_) {
      for (auto& c : velocity_filters_[i]) c.reset();
    } else {
      for (auto& c : filters_[i]) c.reset();
    }
  }
  count_ = 0;
}

void landmark_smoother::apply(double t, landmark* p, int count, bool normalized, int image_width,
                              int image_height) noexcept {
  count = std::clamp(count, 0, velocity_ ? k_max_velocity_points : k_max_smoothed_points);
  if (count != count_) reset();
  const double sx = normalized ? image_width : 1.0;
  const double sy = normalized ? image_height : 1.0;
  const double sz = normalized ? image_width : 1.0;
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  for (int i = 0; i < count; ++i) {
    if (!std::isfinite(p[i].x) || !std::isfinite(p[i].y) || !std::isfinite(p[i].z)) {
      reset();
      return;
    }
    const double x = p[i].x * sx, y = p[i].y * sy;
    if (i == 0) {
      x0 = x1 = x;
      y0 = y1 = y;
    }
    x0 = std::min(x0, x);
    x1 = std::max(x1, x);
    y0 = std::min(y0, y);
    y1 = std::max(y1, y);
  }
  if (count == 0) return;
  count_ = count;
  // Object scale: the mean side of the bounding box (pixels for image landmarks).
  const double object_scale = ((x1 - x0) + (y1 - y0)) * 0.5;
  double value_scale = 1.0;
  if (velocity_) {
    if (object_scale < 1e-6) return;
    value_scale = 1.0 / object_scale;
    for (int i = 0; i < count; ++i) {
      p[i].x = static_cast<float>(velocity_filters_[i][0].apply(t, value_scale, p[i].x * sx) / sx);
      p[i].y = static_cast<float>(velocity_filters_[i][1].apply(t, value_scale, p[i].y * sy) / sy);
      p[i].z = static_cast<float>(velocity_filters_[i][2].apply(t, value_scale, p[i].z * sz) / sz);
    }
    return;
  }
  if (!params_.disable_value_scaling) {
    if (object_scale < params_.min_allowed_object_scale) return;  // too small: unfiltered
    value_scale = 1.0 / object_scale;
  }
  for (int i = 0; i < count; ++i) {
    p[i].x = static_cast<float>(filters_[i][0].apply(t, value_scale, p[i].x * sx) / sx);
    p[i].y = static_cast<float>(filters_[i][1].apply(t, value_scale, p[i].y * sy) / sy);
    p[i].z = static_cast<float>(filters_[i][2].apply(t, value_scale, p[i].z * sz) / sz);
  }
}

void visibility_smoother::apply(landmark* p, int count) noexcept {
  count = std::clamp(count, 0, k_max_smoothed_points);
  const bool fresh = count != count_;
  count_ = count;
  for (int i = 0; i < count; ++i) {
    const float v = p[i].visibility;
    if (!std::isfinite(v)) continue;
    stored_[i] = fresh ? v : alpha_ * v + (1.f - alpha_) * stored_[i];
    p[i].visibility = stored_[i];
  }
}

}  // namespace avatarmap
