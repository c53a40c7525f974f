// `avatarmap solve`: *.landmarks.jsonl -> *.pose.jsonl.
#include <cstdio>
#include <string>
#include <vector>

#include "avatarmap/jobs/people.hpp"
#include "avatarmap/jobs/solve_file.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"
#include "cli/filter_option.hpp"
#include "cli/option_flags.hpp"
#include "cli/solve_job.hpp"

namespace avatarmap::cli {
namespace {

const char* k_solve_help =
    "Usage: avatarmap solve IN.landmarks.jsonl -o OUT.pose.jsonl [options]\n"
    "\n"
    "Turns a landmark recording into proxy poses: VRM 1.0 bone rotations {x,y,z,w}, the hips\n"
    "position in metres and expression weights, one JSON line per frame (docs/file-formats.md).\n"
    "IN may be '-' for standard input, OUT '-' for standard output. OUT is written atomically.\n"
    "\n"
    "Options:\n";

// solve's own flags (beside the solver and solve-file tables).
const cli_flag k_solve_flags[] = {
    {"--output", "-o", "PATH", "where to write the poses (required)"},
    {"--image-size", nullptr, "WxH",
     "image size in pixels (default: the file's header; without one, square pixels are "
     "assumed and a warning is printed)"},
    {"--filter", nullptr, "offline|live|none",
     "offline (default): zero-lag smoothing of the solved poses that sees 1.5 s ahead, and "
     "bones not seen for up to 1.5 s filled from both sides; live: the causal One Euro filter "
     "of a live stream; none. Older names: euro = live, landmarks = One Euro on the landmarks "
     "only, both = landmarks and live"},
    {"--parts", nullptr, "LIST", k_parts_flag_help},
    {"--progress", nullptr, nullptr,
     "force the progress line (default: when stderr is a terminal)"},
    {"--quiet", nullptr, nullptr, "no progress line"},
};

}  // namespace

int run_solve(int argc, char** argv) {
  args a(argc, argv, 2);
  solve_file_job job = make_cli_solve_job();
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_solve_help, stdout);
    std::fputs(cli_flags_help(k_solve_flags).c_str(), stdout);
    std::fputs(option_flags_help(k_solver_option_table, job.options).c_str(), stdout);
    std::fputs(option_flags_help(k_solve_file_option_table, job).c_str(), stdout);
    return 0;
  }
  progress_mode progress = progress_mode::automatic;
  std::string value, error;
  a.value("--output", job.output, "-o");
  if (a.flag("--progress")) progress = progress_mode::on;
  if (a.flag("--quiet")) progress = progress_mode::off;
  if (a.value("--image-size", value)) {
    int w = 0, h = 0;
    if (parse_image_size(value, w, h)) {
      job.image_width = static_cast<float>(w);
      job.image_height = static_cast<float>(h);
    } else {
      std::fprintf(stderr, "avatarmap solve: --image-size wants WxH in pixels, e.g. 1280x720\n");
      return 2;
    }
  }
  if (a.value("--filter", value) && !apply_filter_option(value, job)) {
    std::fprintf(stderr, "avatarmap solve: --filter is %s, got '%s'\n", k_filter_names,
                 value.c_str());
    return 2;
  }
  if (!parse_option_flags(a, k_solver_option_table, job.options, error) ||
      !parse_option_flags(a, k_solve_file_option_table, job, error)) {
    std::fprintf(stderr, "avatarmap solve: %s\n", error.c_str());
    return 2;
  }
  if (!parse_parts_flag(a, job.options.parts, error)) {
    std::fprintf(stderr, "avatarmap solve: %s\n", error.c_str());
    return 2;
  }
  if (!a.error().empty() || !a.check_no_options()) {
    std::fprintf(stderr, "avatarmap solve: %s\n", a.error().c_str());
    return 2;
  }
  if (a.rest().size() != 1) {
    std::fprintf(stderr, "avatarmap solve: give exactly one input file (see --help)\n");
    return 2;
  }
  job.input = a.rest()[0];
  if (job.output.empty()) {
    std::fprintf(stderr, "avatarmap solve: give the output file with -o OUT.pose.jsonl\n");
    return 2;
  }
  status st = job.options.validate();
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap solve: %s\n", st.message().c_str());
    return 2;
  }
  // One run per person of a file of several (jobs/people.hpp).
  std::vector<person_run> runs;
  st = plan_person_runs(job.input, job.person, job.output, runs);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap solve: %s\n", st.message().c_str());
    return st.code() == status_code::invalid_argument ? 2 : 1;
  }
  for (const person_run& r : runs) {
    solve_file_job one = job;
    one.person = r.person;
    one.output = r.output;
    if (runs.size() > 1) std::fprintf(stderr, "person %d -> %s\n", r.person, r.output.c_str());
    solve_file_summary summary;
    st = run_solve_job(one, progress, summary);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap solve: %s\n", st.message().c_str());
      return 1;
    }
    print_summary(one, summary, stderr);
  }
  return 0;
}

}  // namespace avatarmap::cli
