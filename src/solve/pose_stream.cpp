#include "avatarmap/solve/pose_stream.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "avatarmap/time/resample_clip.hpp"  // k_max_resampled_frames
#include "avatarmap/time/seconds_text.hpp"

namespace avatarmap {

namespace {

// The solver's options as the stream runs them: the offline filter sees the future, so it, not
// the causal gate, decides what was observed, and a bone found again is the measurement at
// once (no blend from the held rotation).
solver_options stream_solver_options(const solver_options& solver, pose_filter_mode mode) {
  solver_options s = solver;
  if (mode == pose_filter_mode::offline) {
    s.confidence.lost_below = 0.f;
    s.confidence.found_above = 0.f;
    s.confidence.regain_seconds = 0.f;
  }
  return s;
}

}  // namespace

struct pose_stream::point_stage {
  explicit point_stage(const landmark_filter_options& o) : filter(o) {}
  landmark_filter filter;
  landmark_frame smoothed;
};

status pose_stream_options::validate() const {
  if (status st = stream_solver_options(solver, filters.filter_mode).validate(); !st.ok())
    return st;
  if (status st = filters.validate(); !st.ok()) return st;
  if (!(std::isfinite(resampler.max_extrapolation_seconds) &&
        resampler.max_extrapolation_seconds >= 0.0))
    return status::error("resampler.max_extrapolation_seconds must be finite and >= 0");
  if (!(std::isfinite(output_fps) && output_fps >= 0.0))
    return status::error(output_fps_name + " must be finite and >= 0 (0 = one pose per frame)");
  return {};
}

pose_stream::pose_stream(const pose_stream_options& options)
    : options_(options),
      solver_(stream_solver_options(options.solver, options.filters.filter_mode)),
      filter_(options.filters.filter),
      contacts_(options.filters.foot_contacts,
                options.filters.filter_mode == pose_filter_mode::offline),
      resampler_(options.resampler) {
  assert(options.validate().ok());
  if (options.filters.filter_mode == pose_filter_mode::offline)
    smoother_ = std::make_unique<offline_smoother>(options.filters.offline);
  if (options.filters.landmark_filter.enabled)
    points_ = std::make_unique<point_stage>(options.filters.landmark_filter);
}

pose_stream::~pose_stream() = default;

void pose_stream::solve_points(const landmark_frame& frame) {
  if (points_) {
    points_->filter.apply(frame, points_->smoothed);
    solver_.solve(points_->smoothed, solved_);
  } else {
    solver_.solve(frame, solved_);
  }
}

void pose_stream::solve(const landmark_frame& frame) {
  ++stats_.frames;
  solve_points(frame);
  switch (options_.filters.filter_mode) {
    case pose_filter_mode::offline:
      smoother_->push(solved_);
      return;
    case pose_filter_mode::live:
      filter_pose_channels(filter_, options_.filters.filter_channels, solved_, staged_);
      break;
    case pose_filter_mode::none:
      staged_ = solved_;
      break;
  }
  pending_ = true;
}

void pose_stream::finish_filter() noexcept {
  if (smoother_) smoother_->finish();
  finishing_ = true;
}

bool pose_stream::next_filtered() noexcept {
  for (;;) {
    bool got = false;
    if (smoother_) {
      got = smoother_->pop(staged_);
    } else {
      got = pending_;
      pending_ = false;
    }
    if (got) {
      if (contacts_.push(staged_, filtered_)) break;
      continue;  // the both-sided stage holds it until it sees enough ahead
    }
    if (finishing_ && contacts_.flush(filtered_)) break;
    return false;
  }
  for (int f = 0; f < 2; ++f) stats_.planted_frames[f] += filtered_.foot_contact[f] > 0.5f;
  const float y = filtered_.hips_position.y;
  if (stats_.filtered == 0) {
    stats_.hips_height_min = stats_.hips_height_max = y;
  } else {
    stats_.hips_height_min = std::min(stats_.hips_height_min, y);
    stats_.hips_height_max = std::max(stats_.hips_height_max, y);
  }
  ++stats_.filtered;
  pushed_ = (options_.sample_any_time || options_.output_fps > 0.0) && resampler_.push(filtered_);
  return true;
}

status pose_stream::grid_last(long& j_last) {
  const double fps = options_.output_fps;
  const double t = filtered_.t;
  if (!have_grid_) {
    t_grid0_ = t;
    have_grid_ = true;
  }
  // The last grid time at or before this pose (1e-9 s of tolerance): an estimate, then at
  // most a step or two to settle rounding.
  auto at_or_before = [&](long j) { return t_grid0_ + static_cast<double>(j) / fps <= t + 1e-9; };
  // Checked as a double before any cast: an absurd rate must not overflow the count.
  const double estimate = std::floor((t - t_grid0_) * fps) + 2.0;
  if (!(estimate - static_cast<double>(j_next_) + static_cast<double>(stats_.emitted) <=
        static_cast<double>(k_max_resampled_frames))) {
    const std::string& fps_name = options_.output_fps_name;
    return status::error(options_.name + ": " + fps_name + " " + seconds_text(fps, 2) +
                         " up to frame " + std::to_string(stats_.filtered - 1) +
                         " (t = " + seconds_text(t) + " s) would write more than " +
                         std::to_string(k_max_resampled_frames) + " poses; lower " + fps_name +
                         " or split the input");
  }
  j_last = static_cast<long>(estimate) - 2;
  for (int step = 0; step < 2 && at_or_before(j_last + 1); ++step) ++j_last;
  for (int step = 0; step < 2 && j_last >= j_next_ && !at_or_before(j_last); ++step) --j_last;
  return {};
}

void pose_stream::reset() {
  solver_.reset();
  reset_after_solver();
}

void pose_stream::reset_after_solver() {
  filter_.reset();
  if (smoother_) smoother_->reset();
  if (points_) points_->filter.reset();
  contacts_.reset();
  resampler_.reset();
  pending_ = pushed_ = finishing_ = false;
  stats_ = {};
  t_grid0_ = 0.0;
  have_grid_ = false;
  j_next_ = 0;
}

void pose_stream::learn_camera(const landmark_frame& frame) { solve_points(frame); }

void pose_stream::restart_take(bool keep_view) {
  solver_.restart_take(keep_view);
  // The contact stage holds feet on the performer's proportions as the warm-up learnt them
  // (set once here, not per frame: the poses out must not depend on how far the solver runs
  // ahead of the filters).
  contacts_.set_leg_length(solver_.performer_leg_length());
  reset_after_solver();
}

void pose_stream::restart(const solver_options& solver) {
  options_.solver = solver;
  solver_ = frame_solver(stream_solver_options(solver, options_.filters.filter_mode));
  filter_.reset();
  if (points_) points_->filter.reset();
}

}  // namespace avatarmap
