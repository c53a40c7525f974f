// avm_solver_options (avatarmap.h) read into the library's options, with the checks the
// library does not do itself; shared by the solver handle and the file solve.
#pragma once

#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "avatarmap/time/pose_filter.hpp"
#include "avatarmap/time/pose_resampler.hpp"

namespace avatarmap::c_api {

// Options as the core wants them, after the checks the core does not do itself.
struct core_options {
  avatarmap::solver_options solver;
  avatarmap::pose_filter_options filter;
  avatarmap::pose_resampler_options resampler;
  avatarmap::pose_filter_channels channels;
  avatarmap::pose_filter_mode file_filter =
      avatarmap::pose_filter_mode::offline;  // avm_solve_file only
  float file_smoothing = 1.f;
  int file_threads = 2;                           // avm_solve_file, avm_solve_file_to_clip
  avatarmap::foot_contact_options foot_contacts;  // both paths (pose_stream_filters)
  int person = -1;                                // the file paths: which person of several
};

/// The defaults, as avm_solver_options_init() gives them.
avm_solver_options default_options();

/// Reads caller options (NULL = defaults) into `out`; on failure writes a message naming the
/// field and its range into `msg` and returns false.
bool read_options(const avm_solver_options* in, core_options& out, std::string& msg);

/// The library's solve-file job with these options, as avm_solve_file, avm_solve_frames,
/// avm_solve_file_to_clip and avm_convert_file run it: with file_threads 2 (the default) a file
/// is parsed ahead on a second thread of the job's own, as `avatarmap solve` does (frames from
/// memory are pulled on the calling thread whatever `threads` says). Input and output unset.
avatarmap::solve_file_job file_job(const core_options& o);

}  // namespace avatarmap::c_api
