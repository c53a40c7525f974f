#include "avatarmap/jobs/solve_file.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/jobs/clip_output.hpp"  // k_max_output_fps
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/time/pose_resampler.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "avatarmap/time/seconds_text.hpp"
#include "common/frame_prefetcher.hpp"

namespace avatarmap {

namespace {
using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

// Warnings of one kind after which the rest are only counted (the summary has the totals).
constexpr long k_warnings_per_kind = 5;

status check_one_euro(const char* name, const one_euro_params& p) {
  if (!(std::isfinite(p.min_cutoff) && p.min_cutoff > 0.f))
    return status::error(std::string("filter.") + name + ".min_cutoff must be finite and > 0");
  if (!(std::isfinite(p.beta) && p.beta >= 0.f))
    return status::error(std::string("filter.") + name + ".beta must be finite and >= 0");
  if (!(std::isfinite(p.d_cutoff) && p.d_cutoff > 0.f))
    return status::error(std::string("filter.") + name + ".d_cutoff must be finite and > 0");
  return {};
}

// The parts of the per-frame work that are large (a landmark frame is ~20 kB, a pose ~1 kB):
// on the heap, so that a caller on a small stack (a C API user's thread) is safe.
struct solve_state {
  explicit solve_state(const solve_file_job& job, const solver_options& options)
      : solver(options),
        filter(job.filter),
        smoother(job.offline),
        points_filter(job.landmark_filter) {}
  frame_solver solver;
  pose_filter filter;
  offline_smoother smoother;
  landmark_filter points_filter;
  landmark_frame smoothed;
  landmark_frame frame;  // the direct source's storage (threads == 1)
  pose_resampler resampler;
  proxy_pose solved, filtered, sampled;
};

// Reads straight from the reader on this thread (threads == 1); the same interface as
// jobs_detail::frame_prefetcher.
struct direct_source {
  landmark_reader& reader;
  landmark_frame& frame_storage;
  read_result next() { return reader.next(frame_storage); }
  const landmark_frame& frame() const { return frame_storage; }
  const std::string& error() const { return reader.error(); }
  void release() {}
};

// Pulls frames from the job's `source` on this thread; the same interface again.
struct callback_source {
  const std::function<status(landmark_frame&, bool&)>& source;
  landmark_frame& frame_storage;
  std::string message;
  read_result next() {
    bool end = false;
    status st = source(frame_storage, end);
    if (!st.ok()) {
      message = st.message();
      return read_result::error;
    }
    return end ? read_result::end : read_result::frame;
  }
  const landmark_frame& frame() const { return frame_storage; }
  const std::string& error() const { return message; }
  void release() {}
};

}  // namespace

status solve_file_job::validate() const {
  if (input.empty() && !source)
    return status::error("solve_file_job.input is empty: give a landmark file or a source");
  if (!sink && output.empty())
    return status::error("solve_file_job.output is empty: give a *.pose.jsonl path or a sink");
  if (status st = options.validate(); !st.ok())
    return status::error("solve_file_job.options: " + st.message());
  if (!(std::isfinite(image_width) && std::isfinite(image_height) && image_width >= 0.f &&
        image_height >= 0.f) ||
      (image_width > 0.f) != (image_height > 0.f))
    return status::error(
        "solve_file_job.image_width/image_height must be finite and >= 0, both given or "
        "neither (0 = from the file)");
  if (!(std::isfinite(output_fps) && output_fps >= 0.0 && output_fps <= k_max_output_fps))
    return status::error(output_fps_name + " must be 0 (one pose per frame) or in (0, 1000], got " +
                         seconds_text(output_fps, 6));
  if (threads != 1 && threads != 2)
    return status::error("solve_file_job.threads is 1 or 2, got " + std::to_string(threads));
  status st = check_one_euro("rotation", filter.rotation);
  if (st.ok()) st = check_one_euro("position", filter.position);
  if (st.ok()) st = check_one_euro("expression", filter.expression);
  if (!st.ok()) return status::error("solve_file_job." + st.message());
  if (filter_mode != pose_filter_mode::offline && filter_mode != pose_filter_mode::live &&
      filter_mode != pose_filter_mode::none)
    return status::error("solve_file_job.filter_mode must be offline, live or none");
  if (status o = offline.validate(); !o.ok()) return status::error("solve_file_job." + o.message());
  return {};
}

status solve_file_job::run(solve_file_summary& s) const {
  s = solve_file_summary{};
  auto fail = [&s](job_failure why, status st) {
    s.failure = why;
    return st;
  };
  if (status st = validate(); !st.ok()) return fail(job_failure::invalid_argument, st);
  const auto t0 = clock_type::now();
  landmark_reader reader;
  status st;
  if (!source) {
    st = reader.open(input);
    if (!st.ok()) return fail(job_failure::input_io, st);
  }
  // Frames from a source have no header: its defaults (no image size, no fps).
  const landmark_file_header& header = reader.header();

  solver_options solve_options = options;
  if (image_width > 0.f) {
    solve_options.image_width = image_width;
    solve_options.image_height = image_height;
  } else if (header.image_width > 0 && header.image_height > 0) {
    solve_options.image_width = static_cast<float>(header.image_width);
    solve_options.image_height = static_cast<float>(header.image_height);
  } else if (!(options.image_width > 0.f)) {
    s.image_size_assumed = true;
  }
  if (filter_mode == pose_filter_mode::offline) {
    // The smoother sees the future, so it, not the causal gate, decides what was observed.
    // A bone found again is the measurement at once (no blend from the held rotation).
    solve_options.confidence.lost_below = 0.f;
    solve_options.confidence.found_above = 0.f;
    solve_options.confidence.regain_seconds = 0.f;
  }
  s.image_width = solve_options.image_width;
  s.image_height = solve_options.image_height;
  st = solve_options.validate();
  if (!st.ok()) return fail(job_failure::invalid_argument, st);

  pose_writer writer;
  pose_file_header ph;
  ph.present = true;
  ph.fps = output_fps > 0.0 ? output_fps : header.fps;
  s.fps = ph.fps;
  pose_write_options wo;
  wo.write_confidence = write_confidence;
  if (!sink) {
    st = writer.open(output, ph, wo);
    if (!st.ok()) return fail(job_failure::output_io, st);
  }
  auto emit = [&](const proxy_pose& p) { return sink ? sink(p) : writer.write(p); };

  auto state = std::make_unique<solve_state>(*this, solve_options);
  frame_solver& solver = state->solver;
  auto last_progress = t0;
  // output_fps: poses are written at t_render0 + j / fps for j = 0, 1, 2, ... (t_render0 = the
  // first frame's time); j_next is the next one to write. A counted j (not a time advanced by
  // 1 / fps) keeps the number of poses per frame exact and bounded whatever the times' magnitude.
  const double fps = output_fps;
  const std::string& fps_name = output_fps_name;
  double t_render0 = 0.0;
  // The first and newest frame read (resampling needs times in order; checked as frames are
  // read, before the filter's delay).
  double t_read_first = 0.0, t_read_newest = 0.0;
  bool have_read = false;
  long j_next = 0;
  bool have_render = false;
  s.hips_height_min = 1e9f;
  s.hips_height_max = -1e9f;
  job_failure why = job_failure::none;  // set with each error below

  // Everything after the filter, for one filtered pose: hips range, resampling, writing.
  long delivered = 0;  // filtered poses so far (their frame index, for messages)
  auto deliver = [&](const proxy_pose& filtered) -> status {
    const long index = delivered++;
    s.hips_height_min = std::min(s.hips_height_min, filtered.hips_position.y);
    s.hips_height_max = std::max(s.hips_height_max, filtered.hips_position.y);
    if (fps > 0.0) {
      if (!state->resampler.push(filtered)) return {};
      if (!have_render) {
        t_render0 = filtered.t;
        have_render = true;
      }
      // The last render time at or before this frame (1e-9 s of tolerance): an estimate,
      // then at most a step or two to settle rounding (times are within
      // k_max_clip_seconds of t_render0, so j stays far below LONG_MAX).
      auto at_or_before = [&](long j) {
        return t_render0 + static_cast<double>(j) / fps <= filtered.t + 1e-9;
      };
      // Checked as a double before any cast: an absurd rate must not overflow the count.
      const double estimate = std::floor((filtered.t - t_render0) * fps) + 2.0;
      if (!(estimate - static_cast<double>(j_next) + static_cast<double>(s.poses_written) <=
            static_cast<double>(k_max_resampled_frames))) {
        why = job_failure::invalid_argument;
        return status::error(input + ": " + fps_name + " " + seconds_text(fps, 2) +
                             " up to frame " + std::to_string(index) +
                             " (t = " + seconds_text(filtered.t) + " s) would write more than " +
                             std::to_string(k_max_resampled_frames) + " poses; lower " + fps_name +
                             " or split the input");
      }
      long j_last = static_cast<long>(estimate) - 2;
      for (int step = 0; step < 2 && at_or_before(j_last + 1); ++step) ++j_last;
      for (int step = 0; step < 2 && j_last >= j_next && !at_or_before(j_last); ++step) --j_last;
      for (; j_next <= j_last; ++j_next) {
        const double rt = t_render0 + static_cast<double>(j_next) / fps;
        if (!state->resampler.sample(rt, state->sampled)) break;
        state->sampled.t = rt;
        if (status w = emit(state->sampled); !w.ok()) {
          why = job_failure::output_io;
          return w;
        }
        ++s.poses_written;
      }
    } else {
      if (status w = emit(filtered); !w.ok()) {
        why = job_failure::output_io;
        return w;
      }
      ++s.poses_written;
    }
    return {};
  };
  // One pass over the frames of `src` (the reader itself, or a prefetcher parsing on a second
  // thread): solve, filter, resample, write.
  auto process = [&](auto& src) -> status {
    for (;;) {
      const read_result r = src.next();
      if (r == read_result::end) return {};
      if (r == read_result::error) {
        if (source) {
          why = job_failure::invalid_argument;
          return status::error(src.error());
        }
        if (!skip_bad_lines) {
          why = job_failure::input_parse;
          return status::error(src.error());
        }
        ++s.bad_lines;
        if (s.bad_lines <= k_warnings_per_kind && warning) warning("skipped " + src.error());
        src.release();
        continue;
      }
      const landmark_frame& frame = src.frame();
      const long index = s.frames + s.out_of_order;  // 0-based among the good frames
      if (fps > 0.0 && have_read) {
        if (frame.t < t_read_newest) {
          // Resampling cannot go back in time. The frame is left out entirely (solving it would
          // also restart the pose filter), with a warning.
          ++s.out_of_order;
          if (s.out_of_order <= k_warnings_per_kind && warning)
            warning("frame " + std::to_string(index) + " (t = " + seconds_text(frame.t) +
                    " s) is earlier than the frame before it (t = " + seconds_text(t_read_newest) +
                    " s); skipped (" + fps_name + " needs times in order)");
          src.release();
          continue;
        }
        if (frame.t - t_read_first > k_max_clip_seconds) {
          // The times are readable but too far apart for the asked rate: an argument error,
          // as for resample_clip (not a malformed line).
          why = job_failure::invalid_argument;
          return status::error(
              input + ": frame " + std::to_string(index) + " (t = " + seconds_text(frame.t) +
              " s) is " + seconds_text(frame.t - t_read_first, 2) + " s after the first frame; " +
              fps_name + " resamples at most " + seconds_text(k_max_clip_seconds, 0) +
              " s (24 h): check the times or solve without " + fps_name);
        }
      }
      if (!have_read) t_read_first = frame.t;
      have_read = true;
      t_read_newest = frame.t;
      if (s.frames == 0) s.t_first = frame.t;
      s.t_last = frame.t;
      ++s.frames;
      for (int p = 0; p < k_frame_part_count; ++p)
        if (frame.has(static_cast<frame_part>(p))) ++s.part_frames[p];
      if (frame.has(frame_part::face) && frame.face_count == k_face_mesh_iris_count)
        ++s.face_iris_frames;

      if (landmark_filter.enabled) {
        state->points_filter.apply(frame, state->smoothed);
        solver.solve(state->smoothed, state->solved);
      } else {
        solver.solve(frame, state->solved);
      }
      src.release();
      if (filter_mode == pose_filter_mode::offline) {
        state->smoother.push(state->solved);
        while (state->smoother.pop(state->filtered))
          if (status w = deliver(state->filtered); !w.ok()) return w;
      } else {
        if (filter_mode == pose_filter_mode::live)
          filter_pose_channels(state->filter, filter_channels, state->solved, state->filtered);
        else
          state->filtered = state->solved;
        if (status w = deliver(state->filtered); !w.ok()) return w;
      }
      if (progress && (s.frames & 255) == 0) {
        const auto now = clock_type::now();
        if (std::chrono::duration<double>(now - last_progress).count() > 0.25) {
          last_progress = now;
          progress({s.frames, s.t_last - s.t_first, seconds_since(t0)});
        }
      }
    }
  };
  if (source) {
    callback_source from_source{source, state->frame, {}};
    st = process(from_source);
  } else if (threads > 1) {
    jobs_detail::frame_prefetcher prefetcher(reader, !skip_bad_lines);
    st = process(prefetcher);
  } else {
    direct_source direct{reader, state->frame};
    st = process(direct);
  }
  if (st.ok() && filter_mode == pose_filter_mode::offline) {
    state->smoother.finish();
    while (st.ok() && state->smoother.pop(state->filtered)) st = deliver(state->filtered);
  }
  if (!st.ok()) return fail(why, st);
  if (!sink) st = writer.commit();
  if (!st.ok()) return fail(job_failure::output_io, st);
  s.seconds = seconds_since(t0);
  if (s.frames == 0) s.hips_height_min = s.hips_height_max = 0.f;
  s.horizontal_fov_degrees = state->solver.horizontal_fov_degrees();
  s.fov_estimated = solve_options.horizontal_fov_degrees == 0.f;
  s.fov_evidence_frames = state->solver.fov_evidence_frames();
  return {};
}

}  // namespace avatarmap
