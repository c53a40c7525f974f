// The solve pipeline shared by `solve` and `demo`: read landmarks, solve, filter, resample,
// write poses, with progress and a summary.
#pragma once

#include <cstdio>
#include <functional>
#include <string>

#include "avatarmap/core/status.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "avatarmap/time/pose_filter.hpp"

namespace avatarmap::cli {

enum class progress_mode { automatic, on, off };

struct solve_job {
  std::string input;
  std::string output;  // ignored when `sink` is set
  /// When set, every output pose goes here instead of a *.pose.jsonl file.
  std::function<status(const proxy_pose&)> sink;
  solver_options options{};
  float image_width = 0.f;  // 0 = from the file's header
  float image_height = 0.f;
  pose_filter_options filter{};
  landmark_filter_options landmark_filter = [] {
    landmark_filter_options o;
    o.enabled = false;  // off unless asked for (--filter landmarks|both)
    return o;
  }();
  /// 0 = one pose per input frame, in the file's order. > 0: poses at t_first + j / fps; a frame
  /// earlier than the one before it is skipped with a warning (counted in out_of_order), and a
  /// frame more than k_max_clip_seconds after the first, or more than k_max_resampled_frames
  /// poses in all, fail the job (avatarmap/time/resample_clip.hpp).
  double output_fps = 0.0;
  bool skip_bad_lines = false;
  bool write_confidence = false;
  progress_mode progress = progress_mode::automatic;
  /// 2 parses on a second thread while solving and writing on this one; 1 does it all here.
  int threads = 2;
};

struct solve_summary {
  long frames = 0;
  long poses_written = 0;
  long bad_lines = 0;
  /// With output_fps > 0: frames left out because their time was earlier than the frame before.
  long out_of_order = 0;
  long part_frames[k_frame_part_count] = {};
  long face_iris_frames = 0;
  double t_first = 0.0;
  double t_last = 0.0;
  double seconds = 0.0;
  float image_width = 0.f;
  float image_height = 0.f;
  bool image_size_assumed = false;
  float hips_height_min = 0.f;
  float hips_height_max = 0.f;
};

status run_solve_job(const solve_job& job, solve_summary& out);
void print_summary(const solve_job& job, const solve_summary& s, std::FILE* to);

}  // namespace avatarmap::cli
