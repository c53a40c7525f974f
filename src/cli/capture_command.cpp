// `avatarmap capture INPUT -o OUT.landmarks.jsonl`: video, image or image sequence in,
// landmarks out, through the ONNX backend (body in this version).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/capture/video_source.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"

namespace avatarmap::cli {
namespace {

const char* k_capture_help =
    "Usage: avatarmap capture INPUT -o OUT.landmarks.jsonl [options]\n"
    "\n"
    "Estimates landmarks on every frame of INPUT (a video file, an image, a folder of images\n"
    "or a printf pattern like frames/%05d.png) with MediaPipe's models run by ONNX Runtime,\n"
    "and writes them as *.landmarks.jsonl (docs/file-formats.md). This version estimates the\n"
    "body (33 points, image + world); hands and face come next.\n"
    "\n"
    "Options:\n"
    "  -o, --output PATH     where to write the landmarks (required; written atomically)\n"
    "  --model lite|full|heavy  pose landmark model (default full)\n"
    "  --threads N           ONNX Runtime threads (default 1: the decoder keeps the other core)\n"
    "  --models DIR          converted models (default: $AVATARMAP_MODELS/onnx, else the\n"
    "                        cache scripts/prepare_capture.sh fills)\n"
    "  --static              detect on every frame (images unrelated to each other)\n"
    "  --progress / --quiet  force / silence the progress line (default: on a terminal)\n";

std::string default_models_dir() {
  if (const char* m = std::getenv("AVATARMAP_MODELS"); m && *m) return std::string(m) + "/onnx";
#ifdef AVATARMAP_DEFAULT_MODELS_DIR
  return AVATARMAP_DEFAULT_MODELS_DIR;
#else
  return ".cache/avatarmap/models/onnx";
#endif
}

}  // namespace

int run_capture(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_capture_help, stdout);
    return 0;
  }
  std::string out_path, model = "full", models_dir = default_models_dir();
  a.value("--output", out_path, "-o");
  a.value("--model", model);
  a.value("--models", models_dir);
  double threads = 1;
  a.number("--threads", threads);
  const bool static_images = a.flag("--static");
  bool progress = isatty(STDERR_FILENO);
  if (a.flag("--progress")) progress = true;
  if (a.flag("--quiet")) progress = false;
  if (a.flag("--hands") || a.flag("--face")) {
    std::fprintf(stderr,
                 "avatarmap capture: hands and face are not estimated by this version yet "
                 "(body only)\n");
    return 2;
  }
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() != 1 || out_path.empty()) {
    std::fprintf(stderr, "avatarmap capture: %s\n",
                 !a.error().empty()     ? a.error().c_str()
                 : a.rest().size() != 1 ? "give exactly one input (see --help)"
                                        : "give the output with -o OUT.landmarks.jsonl");
    return 2;
  }
  const int complexity = model == "lite" ? 0 : model == "full" ? 1 : model == "heavy" ? 2 : -1;
  if (complexity < 0 || !(threads >= 1 && threads <= 64)) {
    std::fprintf(stderr, "avatarmap capture: --model is lite, full or heavy; --threads 1..64\n");
    return 2;
  }

  video_source source;
  status st = source.open(a.rest()[0]);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
    return 1;
  }
  estimator_options eo;
  eo.source = models_dir;
  eo.threads = static_cast<int>(threads);
  eo.model_complexity = complexity;
  eo.static_images = static_images;
  std::unique_ptr<estimator> est;
  st = create_estimator("onnx", eo, est);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap capture: %s (run scripts/prepare_capture.sh)\n",
                 st.message().c_str());
    return 1;
  }
  const video_info info = source.info();
  landmark_writer writer;
  landmark_file_header h;
  h.present = true;
  h.image_width = info.width;
  h.image_height = info.height;
  h.fps = info.fps;
  st = writer.open(out_path, h);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
    return 1;
  }

  using clock_type = std::chrono::steady_clock;
  const auto t0 = clock_type::now();
  auto last = t0;
  long frames = 0, with_pose = 0, errors = 0;
  image_view image;
  double t = 0.0;
  landmark_frame frame;
  for (;;) {
    const read_result r = source.next(image, t);
    if (r == read_result::end) break;
    if (r == read_result::error) {
      ++errors;
      std::fprintf(stderr, "warning: %s\n", source.error().c_str());
      continue;
    }
    estimate_args ea;
    ea.image = image;
    ea.t = t;
    ea.hands = ea.face = false;
    st = est->estimate(ea, frame);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap capture: frame at %.3f s: %s\n", t, st.message().c_str());
      return 1;
    }
    frame.t = t;
    if (frame.has(frame_part::pose)) ++with_pose;
    st = writer.write(frame);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
      return 1;
    }
    ++frames;
    if (progress) {
      const auto now = clock_type::now();
      if (std::chrono::duration<double>(now - last).count() > 0.5) {
        last = now;
        const double el = std::chrono::duration<double>(now - t0).count();
        std::fprintf(stderr, "\rcapture: %ld frames, %.1f frames/s   ", frames, frames / el);
        std::fflush(stderr);
      }
    }
  }
  st = writer.commit();
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
    return 1;
  }
  const double el = std::chrono::duration<double>(clock_type::now() - t0).count();
  if (progress) std::fputs("\r", stderr);
  std::fprintf(stderr,
               "captured %ld frames (%dx%d, %s) in %.2f s: %.1f frames/s end to end; a person in "
               "%ld frames%s\n",
               frames, info.width, info.height, info.codec.c_str(), el, frames / (el > 0 ? el : 1),
               with_pose,
               errors ? (", " + std::to_string(errors) + " frames not decoded").c_str() : "");
  std::fprintf(stderr, "wrote %s\n", out_path.c_str());
  return 0;
}

}  // namespace avatarmap::cli
