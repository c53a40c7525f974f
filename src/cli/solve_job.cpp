#include "cli/solve_job.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/time/pose_resampler.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "avatarmap/time/seconds_text.hpp"
#include "cli/frame_prefetcher.hpp"

namespace avatarmap::cli {

namespace {
using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}
}  // namespace

status run_solve_job(const solve_job& job, solve_summary& s) {
  s = solve_summary{};
  const auto t0 = clock_type::now();
  landmark_reader reader;
  status st = reader.open(job.input);
  if (!st.ok()) return st;
  const landmark_file_header& header = reader.header();

  solver_options options = job.options;
  if (job.image_width > 0.f) {
    options.image_width = job.image_width;
    options.image_height = job.image_height;
  } else if (header.image_width > 0 && header.image_height > 0) {
    options.image_width = static_cast<float>(header.image_width);
    options.image_height = static_cast<float>(header.image_height);
  } else {
    s.image_size_assumed = true;
  }
  s.image_width = options.image_width;
  s.image_height = options.image_height;
  st = options.validate();
  if (!st.ok()) return st;

  pose_writer writer;
  pose_file_header ph;
  ph.fps = job.output_fps > 0.0 ? job.output_fps : header.fps;
  pose_write_options wo;
  wo.write_confidence = job.write_confidence;
  if (!job.sink) {
    st = writer.open(job.output, ph, wo);
    if (!st.ok()) return st;
  }
  auto emit = [&](const proxy_pose& p) { return job.sink ? job.sink(p) : writer.write(p); };

  frame_solver solver(options);
  pose_filter filter(job.filter);
  landmark_filter points_filter(job.landmark_filter);
  landmark_frame smoothed;
  pose_resampler resampler;
  landmark_frame frame;
  proxy_pose solved, filtered, sampled;
  const bool show_progress = job.progress == progress_mode::on ||
                             (job.progress == progress_mode::automatic && isatty(STDERR_FILENO));
  auto last_progress = t0;
  // --fps: poses are written at t_render0 + j / fps for j = 0, 1, 2, ... (t_render0 = the first
  // frame's time); j_next is the next one to write. A counted j (not a time advanced by 1 / fps)
  // keeps the number of poses per frame exact and bounded whatever the times' magnitude.
  const double fps = job.output_fps;
  double t_render0 = 0.0, t_newest = 0.0;
  long j_next = 0;
  bool have_render = false;
  s.hips_height_min = 1e9f;
  s.hips_height_max = -1e9f;

  // One pass over the frames of `src` (the reader itself, or a prefetcher parsing on a second
  // thread): solve, filter, resample, write.
  auto process = [&](auto& src) -> status {
    for (;;) {
      const read_result r = src.next();
      if (r == read_result::end) return {};
      if (r == read_result::error) {
        if (!job.skip_bad_lines)
          return status::error(src.error() + " (use --skip-bad-lines to go on)");
        ++s.bad_lines;
        if (s.bad_lines <= 5) std::fprintf(stderr, "warning: skipped %s\n", src.error().c_str());
        src.release();
        continue;
      }
      const landmark_frame& frame = src.frame();
      const long index = s.frames + s.out_of_order;  // 0-based among the good frames
      if (fps > 0.0 && have_render) {
        if (frame.t < t_newest) {
          // Resampling cannot go back in time. The frame is left out entirely (solving it would
          // also restart the pose filter), with a warning.
          ++s.out_of_order;
          if (s.out_of_order <= 5)
            std::fprintf(stderr,
                         "warning: frame %ld (t = %s s) is earlier than the frame before it "
                         "(t = %s s); skipped (--fps needs times in order)\n",
                         index, seconds_text(frame.t).c_str(), seconds_text(t_newest).c_str());
          src.release();
          continue;
        }
        if (frame.t - t_render0 > k_max_clip_seconds)
          return status::error(job.input + ": frame " + std::to_string(index) +
                               " (t = " + seconds_text(frame.t) + " s) is " +
                               seconds_text(frame.t - t_render0, 2) +
                               " s after the first frame; --fps resamples at most " +
                               seconds_text(k_max_clip_seconds, 0) +
                               " s (24 h): check the times or solve without --fps");
      }
      if (s.frames == 0) s.t_first = frame.t;
      s.t_last = frame.t;
      ++s.frames;
      for (int p = 0; p < k_frame_part_count; ++p)
        if (frame.has(static_cast<frame_part>(p))) ++s.part_frames[p];
      if (frame.has(frame_part::face) && frame.face_count == k_face_mesh_iris_count)
        ++s.face_iris_frames;

      if (job.landmark_filter.enabled) {
        points_filter.apply(frame, smoothed);
        solver.solve(smoothed, solved);
      } else {
        solver.solve(frame, solved);
      }
      src.release();
      filter.apply(solved, filtered);
      s.hips_height_min = std::min(s.hips_height_min, filtered.hips_position.y);
      s.hips_height_max = std::max(s.hips_height_max, filtered.hips_position.y);
      if (fps > 0.0) {
        if (!resampler.push(filtered)) continue;
        if (!have_render) {
          t_render0 = filtered.t;
          have_render = true;
        }
        t_newest = filtered.t;
        // The last render time at or before this frame (1e-9 s of tolerance): an estimate,
        // then at most a step or two to settle rounding (times are within
        // k_max_clip_seconds of t_render0, so j stays far below LONG_MAX).
        auto at_or_before = [&](long j) {
          return t_render0 + static_cast<double>(j) / fps <= filtered.t + 1e-9;
        };
        // Checked as a double before any cast: an absurd rate must not overflow the count.
        const double estimate = std::floor((filtered.t - t_render0) * fps) + 2.0;
        if (!(estimate - static_cast<double>(j_next) + static_cast<double>(s.poses_written) <=
              static_cast<double>(k_max_resampled_frames)))
          return status::error(job.input + ": --fps " + seconds_text(fps, 2) + " up to frame " +
                               std::to_string(index) + " (t = " + seconds_text(filtered.t) +
                               " s) would write more than " +
                               std::to_string(k_max_resampled_frames) +
                               " poses; lower --fps or split the input");
        long j_last = static_cast<long>(estimate) - 2;
        for (int step = 0; step < 2 && at_or_before(j_last + 1); ++step) ++j_last;
        for (int step = 0; step < 2 && j_last >= j_next && !at_or_before(j_last); ++step) --j_last;
        for (; j_next <= j_last; ++j_next) {
          const double rt = t_render0 + static_cast<double>(j_next) / fps;
          if (!resampler.sample(rt, sampled)) break;
          sampled.t = rt;
          status w = emit(sampled);
          if (!w.ok()) return w;
          ++s.poses_written;
        }
      } else {
        status w = emit(filtered);
        if (!w.ok()) return w;
        ++s.poses_written;
      }
      if (show_progress && (s.frames & 255) == 0) {
        auto now = clock_type::now();
        if (std::chrono::duration<double>(now - last_progress).count() > 0.25) {
          last_progress = now;
          double el = seconds_since(t0);
          std::fprintf(stderr, "\rsolve: %ld frames, %s s of capture, %.0f frames/s   ", s.frames,
                       seconds_text(s.t_last - s.t_first, 1).c_str(),
                       s.frames / std::max(el, 1e-9));
          std::fflush(stderr);
        }
      }
    }
  };
  if (job.threads > 1) {
    frame_prefetcher prefetcher(reader, !job.skip_bad_lines);
    st = process(prefetcher);
  } else {
    struct direct_source {
      landmark_reader& reader;
      landmark_frame& frame_storage;
      read_result next() { return reader.next(frame_storage); }
      const landmark_frame& frame() const { return frame_storage; }
      const std::string& error() const { return reader.error(); }
      void release() {}
    } direct{reader, frame};
    st = process(direct);
  }
  if (!st.ok()) return st;
  if (show_progress) std::fputs("\r", stderr);
  if (!job.sink) st = writer.commit();
  if (!st.ok()) return st;
  s.seconds = seconds_since(t0);
  if (s.frames == 0) {
    s.hips_height_min = s.hips_height_max = 0.f;
  }
  return {};
}

void print_summary(const solve_job& job, const solve_summary& s, std::FILE* to) {
  std::fprintf(to, "solved %ld frames (%s s of capture, t = %s .. %s) in %.3f s: %.0f frames/s\n",
               s.frames, seconds_text(s.t_last - s.t_first, 2).c_str(),
               seconds_text(s.t_first).c_str(), seconds_text(s.t_last).c_str(), s.seconds,
               s.frames / std::max(s.seconds, 1e-9));
  std::fprintf(to, "parts seen: pose %ld, pose_world %ld, left hand %ld, right hand %ld, face %ld",
               s.part_frames[0], s.part_frames[1], std::max(s.part_frames[2], s.part_frames[3]),
               std::max(s.part_frames[4], s.part_frames[5]), s.part_frames[6]);
  if (s.part_frames[6] > 0) std::fprintf(to, " (%ld with iris)", s.face_iris_frames);
  std::fprintf(to, "\n");
  if (s.frames > 0)
    std::fprintf(to, "hips height: %.3f .. %.3f m\n", s.hips_height_min, s.hips_height_max);
  if (s.image_size_assumed)
    std::fprintf(to,
                 "warning: the input has no image_size header and no --image-size was given: "
                 "square pixels assumed (face ratios and root motion may be off)\n");
  if (s.bad_lines > 0) std::fprintf(to, "skipped %ld malformed lines\n", s.bad_lines);
  if (s.out_of_order > 0)
    std::fprintf(to,
                 "skipped %ld frames earlier than the frame before them (--fps needs times in "
                 "order)\n",
                 s.out_of_order);
  std::fprintf(to, "wrote %ld poses to %s%s\n", s.poses_written, job.output.c_str(),
               job.output_fps > 0.0 ? " (resampled)" : "");
}

}  // namespace avatarmap::cli
