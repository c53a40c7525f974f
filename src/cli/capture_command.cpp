// `avatarmap capture INPUT -o OUT.landmarks.jsonl`: video, image, image sequence, device or
// network stream in, landmarks out, through the ONNX backend (body, hands, face), with an
// optional overlay. The workflow is the library's capture_file_job (the C API's
// avm_capture_file runs it too); this file parses the arguments and prints.
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "avatarmap/capture/capture_file.hpp"
#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/media/video_source.hpp"
#include "cli/capture_setup.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"
#include "cli/option_flags.hpp"
#include "cli/overlay_output.hpp"

namespace avatarmap::cli {
namespace {

const char* k_capture_help =
    "Usage: avatarmap capture INPUT -o OUT.landmarks.jsonl [options]\n"
    "\n"
    "Estimates landmarks on every frame of INPUT (a video file, an image, a folder of images,\n"
    "a printf pattern like frames/%05d.png, a device or a network stream: see below) with\n"
    "MediaPipe's models run by ONNX Runtime, and writes them as *.landmarks.jsonl\n"
    "(docs/file-formats.md): the body (33 points, image + world) and, when asked, both hands\n"
    "and the face mesh. Video is tracked (detectors run only when a part is lost) and\n"
    "smoothed as MediaPipe does; --static treats every frame on its own. A device or stream\n"
    "is read until it ends, stalls (--stall-seconds) or --seconds have passed; what was\n"
    "captured is written. --people N follows up to N people, each with its own id, hands\n"
    "and face: the file is then version 2, one line per person in view and frame (none\n"
    "when nobody is), and --overlay draws every person in a colour of its own with its id\n"
    "above it (docs/capture-people.md).\n"
    "\n"
    "Options:\n";

// capture's own flags (beside the estimator and input tables).
const cli_flag k_capture_flags[] = {
    {"--output", "-o", "PATH", "where to write the landmarks (required; written atomically)"},
    {"--overlay", nullptr, "PATH",
     "also draw the landmarks on the frames: PATH.mp4/.mkv/.avi writes a video, PATH.png one "
     "image (the first frame) and a pattern like overlay_%05d.png one image per frame"},
    {"--loop", nullptr, "N",
     "run over INPUT N times (times keep increasing; for soak tests; files only)"},
    {"--seconds", nullptr, "S", "stop after S seconds of input (frame times)"},
    {"--progress", nullptr, nullptr, "force the progress line (default: on a terminal)"},
    {"--quiet", nullptr, nullptr, "no progress line and no summary"},
};
const char* k_capture_estimator_help = "Estimator options (hands and face off unless asked):\n";

}  // namespace

void add_capture_command_flag_specs(bool hands_face_default, std::vector<flag_spec>& out) {
  add_flag_specs(k_capture_flags, out);
  add_capture_flag_specs(hands_face_default, out);
}

int run_capture(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_capture_help, stdout);
    std::fputs((cli_flags_help(k_capture_flags) + "\n").c_str(), stdout);
    std::fputs(input_options_help().c_str(), stdout);
    std::fputs(k_capture_estimator_help, stdout);
    std::fputs(estimator_options_help(false).c_str(), stdout);
    return 0;
  }
  std::string out_path, overlay_path, error;
  a.value("--output", out_path, "-o");
  a.value("--overlay", overlay_path);
  double loops = 1, seconds = 0;
  a.number("--loop", loops);
  a.number("--seconds", seconds);
  bool progress = isatty(STDERR_FILENO);
  if (a.flag("--progress")) progress = true;
  const bool quiet = a.flag("--quiet");
  if (quiet) progress = false;
  capture_file_job job;
  if (!parse_estimator_options(a, false, job.options, error) ||
      !parse_input_options(a, job.video, error)) {
    std::fprintf(stderr, "avatarmap capture: %s\n", error.c_str());
    return 2;
  }
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() != 1 || out_path.empty()) {
    std::fprintf(stderr, "avatarmap capture: %s\n",
                 !a.error().empty()     ? a.error().c_str()
                 : a.rest().size() != 1 ? "give exactly one input (see --help)"
                                        : "give the output with -o OUT.landmarks.jsonl");
    return 2;
  }
  if (!(loops >= 1 && loops <= 1e6) || loops != static_cast<long>(loops)) {
    std::fprintf(stderr, "avatarmap capture: --loop wants a whole number >= 1\n");
    return 2;
  }
  if (!(seconds >= 0)) {
    std::fprintf(stderr, "avatarmap capture: --seconds must be >= 0\n");
    return 2;
  }
  job.input = a.rest()[0];
  job.output = out_path;
  job.loops = static_cast<long>(loops);
  job.seconds = seconds;
  job.allow_live_input = true;
  if (names_live_input(job.input) && job.loops > 1) {
    std::fprintf(stderr, "avatarmap capture: --loop is for files, not devices or streams\n");
    return 2;
  }
  job.make_estimator = make_estimator;  // its error says how to get the models
  video_source_quiet_log(true);

  // The overlay: opened once the input's size is known, fed every frame, closed last.
  overlay_output overlay;
  if (!overlay_path.empty()) {
    job.on_open = [&](const video_info& info) {
      const status st =
          overlay.open(overlay_path, info.width, info.height, info.fps > 0 ? info.fps : 30.0);
      return st.prefixed("--overlay: ");
    };
    job.on_frame = [&](const image_view& image, const landmark_frame& frame,
                       const estimator::people_view& people) {
      return overlay.write(image, frame, people);
    };
    job.on_finish = [&] { return overlay.close(); };
  }
  job.warning = [](const std::string& w) { std::fprintf(stderr, "warning: %s\n", w.c_str()); };
  if (progress)
    job.progress = [](const capture_file_progress& p) {
      const double el = p.elapsed_seconds;
      if (p.total_frames > 0)
        std::fprintf(stderr, "\rcapture: %ld/%.0f frames (%.0f%%), %.1f frames/s   ", p.frames,
                     static_cast<double>(p.total_frames),
                     100.0 * p.frames / static_cast<double>(p.total_frames), p.frames / el);
      else
        std::fprintf(stderr, "\rcapture: %ld frames, %.1f frames/s   ", p.frames, p.frames / el);
      std::fflush(stderr);
    };

  capture_file_summary s;
  const status st = job.run(s);
  if (!s.end_reason.empty())  // a device or stream that stalled or ended
    std::fprintf(stderr, "%scapture: %s\n", progress ? "\n" : "", s.end_reason.c_str());
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
    return 1;
  }
  const double el = s.capture_seconds;
  if (progress) std::fputs("\r", stderr);
  if (quiet) return 0;
  const long frames = s.frames, errors = s.frames_not_decoded;
  std::fprintf(stderr, "captured %ld frames (%dx%d, %s) in %.2f s: %.1f frames/s end to end%s\n",
               frames, s.input.width, s.input.height, s.input.codec.c_str(), el,
               frames / (el > 0 ? el : 1),
               errors ? (", " + std::to_string(errors) + " frames not decoded").c_str() : "");
  // Several people: the counts are of lines, one per person and frame.
  if (job.options.max_people > 1)
    std::fprintf(stderr, "people: %ld ids, %ld lines, someone in %ld of %ld frames\n", s.people_ids,
                 s.person_lines, s.frames_with_people, frames);
  std::fprintf(stderr, "found: body in %ld %s", s.part_frames[0],
               job.options.max_people > 1 ? "lines" : "frames");
  if (job.options.hands)
    std::fprintf(stderr, ", left hand %ld, right hand %ld",
                 s.part_frames[static_cast<int>(frame_part::left_hand)],
                 s.part_frames[static_cast<int>(frame_part::right_hand)]);
  if (job.options.face)
    std::fprintf(stderr, ", face %ld", s.part_frames[static_cast<int>(frame_part::face)]);
  std::fputc('\n', stderr);
  if (!s.estimator_description.empty())
    std::fprintf(stderr, "%s\n", s.estimator_description.c_str());
  timing_totals timings;
  timings.sum = s.timing_sum;
  timings.frames = s.timed_frames;
  timings.pose_detector_frames = s.pose_detector_frames;
  timings.palm_frames = s.palm_frames;
  timings.face_detector_frames = s.face_detector_frames;
  timings.startup_ms = s.startup_ms;
  timings.print(stderr);
  if (s.resident_kib_after_100 > 0)
    std::fprintf(stderr, "memory: %.1f MiB resident after 100 frames, %.1f MiB at most after\n",
                 s.resident_kib_after_100 / 1024.0, s.resident_kib_peak / 1024.0);
  std::fprintf(stderr, "wrote %s\n", out_path.c_str());
  if (!overlay_path.empty()) std::fprintf(stderr, "wrote %s\n", overlay_path.c_str());
  return 0;
}

}  // namespace avatarmap::cli
