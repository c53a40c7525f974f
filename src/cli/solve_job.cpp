#include "cli/solve_job.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/time/pose_resampler.hpp"
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
  double next_render_t = 0.0;
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
      if (job.output_fps > 0.0) {
        if (!resampler.push(filtered)) continue;
        if (!have_render) {
          next_render_t = filtered.t;
          have_render = true;
        }
        long k = 0;
        const double base = next_render_t;
        for (double rt = base; rt <= filtered.t + 1e-9; rt = base + double(++k) / job.output_fps) {
          if (!resampler.sample(rt, sampled)) break;
          sampled.t = rt;
          status w = emit(sampled);
          if (!w.ok()) return w;
          ++s.poses_written;
          next_render_t = base + double(k + 1) / job.output_fps;
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
          std::fprintf(stderr, "\rsolve: %ld frames, %.1f s of capture, %.0f frames/s   ", s.frames,
                       s.t_last - s.t_first, s.frames / std::max(el, 1e-9));
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
  std::fprintf(to,
               "solved %ld frames (%.2f s of capture, t = %.3f .. %.3f) in %.3f s: %.0f frames/s\n",
               s.frames, s.t_last - s.t_first, s.t_first, s.t_last, s.seconds,
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
  std::fprintf(to, "wrote %ld poses to %s%s\n", s.poses_written, job.output.c_str(),
               job.output_fps > 0.0 ? " (resampled)" : "");
}

}  // namespace avatarmap::cli
