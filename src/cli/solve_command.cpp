// `avatarmap solve`: *.landmarks.jsonl -> *.pose.jsonl.
#include <cstdio>
#include <string>

#include "avatarmap/jobs/solve_file.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"
#include "cli/filter_option.hpp"
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
    "Options:\n"
    "  -o, --output PATH      where to write the poses (required)\n"
    "  --mirror               mirror the performer (for mirrored webcam recordings)\n"
    "  --image-size WxH       image size in pixels (default: the file's header; without one,\n"
    "                         square pixels are assumed and a warning is printed)\n"
    "  --filter offline|live|none\n"
    "                         offline (default): zero-lag smoothing of the solved poses that\n"
    "                         sees 1.5 s ahead, and bones not seen for up to 1.5 s filled\n"
    "                         from both sides; live: the causal One Euro filter of a live\n"
    "                         stream; none. Older names: euro = live, landmarks = One Euro\n"
    "                         on the landmarks only, both = landmarks and live\n"
    "  --smoothing S          scale on the offline filter's time constants (default 1; 0 =\n"
    "                         fill gaps only, 2 = twice as smooth)\n"
    "  --min-cutoff HZ        live: One Euro cutoff at rest for rotations (default 0.7)\n"
    "  --beta B               live: One Euro speed coefficient for rotations (default 0.3)\n"
    "  --fps N                resample the output at N frames per second (slerp between\n"
    "                         capture frames); default: one pose per input frame. Frames\n"
    "                         earlier than the one before are skipped (a warning); at most\n"
    "                         24 h of capture and 4194304 poses\n"
    "  --parts LIST           comma list of body,hands,face,root (default: all)\n"
    "  --fov DEG              camera's horizontal field of view (head under perspective, root\n"
    "                         motion); default: estimated from the pose's image and world\n"
    "                         points when they form one pinhole view, else 60\n"
    "  --no-hand-fit          use the hand landmarks as they are (default: each hand's\n"
    "                         points fitted to its shape learnt over the take, a rigid palm\n"
    "                         and fingers of constant length; docs/solver.md)\n"
    "  --skip-bad-lines       report malformed lines and go on (default: stop at the first)\n"
    "  --threads 1|2          2 (default) parses the input on a second thread\n"
    "  --confidence           also write per-bone confidence\n"
    "  --progress / --quiet   force / silence the progress line (default: when stderr is a\n"
    "                         terminal)\n";

}  // namespace

int run_solve(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_solve_help, stdout);
    return 0;
  }
  solve_file_job job = make_cli_solve_job();
  progress_mode progress = progress_mode::automatic;
  std::string value;
  a.value("--output", job.output, "-o");
  job.options.mirror = a.flag("--mirror");
  job.options.fit_hand_shape = !a.flag("--no-hand-fit");
  job.skip_bad_lines = a.flag("--skip-bad-lines");
  job.write_confidence = a.flag("--confidence");
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
  double num = 0.0;
  if (a.number("--smoothing", num) && !apply_smoothing_option(num, job)) {
    std::fprintf(stderr, "avatarmap solve: --smoothing is a scale in [0, 10] (1 = default)\n");
    return 2;
  }
  if (a.number("--min-cutoff", num)) job.filter.rotation.min_cutoff = static_cast<float>(num);
  if (a.number("--beta", num)) job.filter.rotation.beta = static_cast<float>(num);
  // Remembered separately: output_fps == 0 means "not resampled", but "--fps 0" is an error.
  const bool fps_given = a.number("--fps", num);
  if (fps_given) job.output_fps = num;
  if (a.number("--fov", num)) job.options.horizontal_fov_degrees = static_cast<float>(num);
  a.integer("--threads", job.threads, 1, 2);
  if (a.value("--parts", value)) {
    solve_parts p{false, false, false, false};
    size_t start = 0;
    while (start <= value.size()) {
      size_t end = value.find(',', start);
      std::string part =
          value.substr(start, end == std::string::npos ? std::string::npos : end - start);
      if (part == "body")
        p.body = true;
      else if (part == "hands")
        p.hands = true;
      else if (part == "face")
        p.face = true;
      else if (part == "root")
        p.hips_translation = true;
      else {
        std::fprintf(stderr,
                     "avatarmap solve: unknown part '%s' in --parts (body,hands,face,root)\n",
                     part.c_str());
        return 2;
      }
      if (end == std::string::npos) break;
      start = end + 1;
    }
    job.options.parts = p;
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
  if (fps_given && !(job.output_fps > 0.0 && job.output_fps <= 1000.0)) {
    std::fprintf(stderr, "avatarmap solve: --fps must be in (0, 1000]\n");
    return 2;
  }
  if (!(job.filter.rotation.min_cutoff > 0.f) || !(job.filter.rotation.beta >= 0.f)) {
    std::fprintf(stderr, "avatarmap solve: --min-cutoff must be > 0 and --beta >= 0\n");
    return 2;
  }
  status st = job.options.validate();
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap solve: %s\n", st.message().c_str());
    return 2;
  }
  solve_file_summary summary;
  st = run_solve_job(job, progress, summary);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap solve: %s\n", st.message().c_str());
    return 1;
  }
  print_summary(job, summary, stderr);
  return 0;
}

}  // namespace avatarmap::cli
