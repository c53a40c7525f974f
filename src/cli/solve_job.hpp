// The CLI's side of the solve-file job (avatarmap/jobs/solve_file.hpp), shared by `solve`,
// `demo` and `convert`: the progress line and warnings on stderr, the --skip-bad-lines hint,
// and the summary.
#pragma once

#include <cstdio>

#include "avatarmap/core/status.hpp"
#include "avatarmap/jobs/solve_file.hpp"

namespace avatarmap::cli {

enum class progress_mode { automatic, on, off };

/// A solve_file_job whose messages use the CLI's option names (--fps).
solve_file_job make_cli_solve_job();

/// Whether `mode` shows a progress line (automatic: when stderr is a terminal).
bool shows_progress(progress_mode mode);

/// The progress line of a landmark solve on stderr ("\rsolve: N frames, ..."), for
/// solve_file_job::progress; end it with "\r" when the run is over.
void print_solve_progress(const solve_file_progress& p);

/// Runs `job` with a progress line on stderr (`progress`: automatic = when stderr is a
/// terminal) and its warnings on stderr ("warning: ..."); a malformed line's error gets the
/// --skip-bad-lines hint.
status run_solve_job(solve_file_job job, progress_mode progress, solve_file_summary& out);

void print_summary(const solve_file_job& job, const solve_file_summary& s, std::FILE* to);

}  // namespace avatarmap::cli
