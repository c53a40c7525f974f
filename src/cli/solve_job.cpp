#include "cli/solve_job.hpp"

#include <unistd.h>

#include <algorithm>

#include "avatarmap/time/seconds_text.hpp"

namespace avatarmap::cli {

solve_file_job make_cli_solve_job() {
  solve_file_job job;
  job.output_fps_name = "--fps";
  return job;
}

bool shows_progress(progress_mode mode) {
  return mode == progress_mode::on || (mode == progress_mode::automatic && isatty(STDERR_FILENO));
}

void print_solve_progress(const solve_file_progress& p) {
  std::fprintf(stderr, "\rsolve: %ld frames, %s s of capture, %.0f frames/s   ", p.frames,
               seconds_text(p.capture_seconds, 1).c_str(),
               p.frames / std::max(p.elapsed_seconds, 1e-9));
  std::fflush(stderr);
}

status run_solve_job(solve_file_job job, progress_mode progress, solve_file_summary& out) {
  const bool show_progress = shows_progress(progress);
  if (show_progress) job.progress = print_solve_progress;
  job.warning = [](const std::string& w) { std::fprintf(stderr, "warning: %s\n", w.c_str()); };
  status st = job.run(out);
  if (!st.ok()) {
    if (st.code() == status_code::parse && out.input_opened && !job.skip_bad_lines)
      return st.with_message(st.message() + " (use --skip-bad-lines to go on)");
    return st;
  }
  if (show_progress) std::fputs("\r", stderr);
  return {};
}

void print_summary(const solve_file_job& job, const solve_file_summary& s, std::FILE* to) {
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
  if (s.frames > 0) {
    if (!s.fov_estimated)
      std::fprintf(to, "camera field of view: %.1f degrees (--fov)\n", s.horizontal_fov_degrees);
    else if (s.fov_evidence_frames > 0)
      std::fprintf(to,
                   "camera field of view: %.1f degrees, estimated from the pose in %ld frames "
                   "(--fov DEG to set it)\n",
                   s.horizontal_fov_degrees, s.fov_evidence_frames);
    else
      std::fprintf(to,
                   "camera field of view: %.1f degrees assumed; the pose's image and world "
                   "points did not tell it (--fov DEG to set it)\n",
                   s.horizontal_fov_degrees);
    if (s.gravity_evidence_frames > 0 || s.floor_evidence_points > 0)
      std::fprintf(to,
                   "camera pitch %.1f degrees (+ = looking down), roll %.1f, from %ld standing "
                   "frames and %ld floor points\n",
                   s.camera_pitch_degrees, s.camera_roll_degrees, s.gravity_evidence_frames,
                   s.floor_evidence_points);
    else if (s.image_width > 0.f)
      std::fprintf(to,
                   "camera pitch and roll: level assumed (no standing frame, no walk over the "
                   "floor)\n");
  }
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
