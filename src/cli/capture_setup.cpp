#include "cli/capture_setup.hpp"

#include <cstdlib>

#include "avatarmap/capture/capture_file.hpp"

namespace avatarmap::cli {

const char* const k_estimator_options_help =
    "  --model lite|full|heavy  pose landmark model (default full)\n"
    "  --hands / --no-hands  estimate both hands (21 points each, image + world)\n"
    "  --face / --no-face    estimate the face mesh (468 points)\n"
    "  --hand-model lite|full  hand landmark model (default full)\n"
    "  --precision float|int8  model precision (default float). int8 (the int8 models\n"
    "                        scripts/prepare_capture.sh builds) is faster but leaves Google's\n"
    "                        tolerances on some references, on CPUs without VNNI on most\n"
    "                        (docs/capture.md \"int8 models\")\n"
    "  --mirrored            the input is mirrored (a selfie preview); sides stay the person's\n"
    "  --threads N           threads for the models (default 2; 1 is better when another\n"
    "                        process keeps a core busy)\n"
    "  --lanes 1|2           with hands or face and 2+ threads: 2 (default) runs the hands\n"
    "                        and face beside the body (of the next frame, for files), each\n"
    "                        model on one thread; 1 runs every model on all threads in turn\n"
    "  --spin                let ONNX Runtime's threads spin between operators: faster on an\n"
    "                        idle machine, much slower when another process is busy\n"
    "  --models DIR          converted models (default: $AVATARMAP_MODELS/onnx, else the cache\n"
    "                        scripts/prepare_capture.sh fills)\n"
    "  --static              detect on every frame (images unrelated to each other)\n";

const char* const k_input_options_help =
    "INPUT is a video file, an image, a folder of images, a printf pattern\n"
    "(frames/%05d.png), a device FORMAT:DEVICE (v4l2:/dev/video0, x11grab::0.0, a test\n"
    "pattern lavfi:testsrc=size=640x480:rate=30) or a URL (udp://127.0.0.1:5000,\n"
    "rtp://, rtsp://HOST/PATH, srt://, http(s)://, tcp://, ...); an unknown scheme or device\n"
    "is refused with the list this build has (docs/live.md).\n"
    "\n"
    "Input options:\n"
    "  --video-size WxH      devices: frame size to ask for (e.g. 1280x720)\n"
    "  --framerate N         devices: frame rate to ask for\n"
    "  --input-format NAME   devices: pixel format or codec to ask for (v4l2: mjpeg, yuyv422)\n"
    "  --open-seconds S      devices and URLs: give up when no picture came within S s of\n"
    "                        opening (default 10)\n"
    "  --stall-seconds S     devices and URLs: stop when no frame came for S s (default 5):\n"
    "                        \"no frame from INPUT for S s: the stream stalled or ended\"\n"
    "\n";

bool parse_input_options(args& a, video_source_options& out, std::string& error) {
  a.value("--video-size", out.video_size);
  a.value("--input-format", out.input_format);
  a.number("--framerate", out.framerate);
  a.number("--open-seconds", out.open_timeout_seconds);
  a.number("--stall-seconds", out.stall_timeout_seconds);
  int w = 0, h = 0;
  if (!a.error().empty())
    error = a.error();
  else if (!out.video_size.empty() && !parse_image_size(out.video_size, w, h))
    error = "--video-size wants WIDTHxHEIGHT (e.g. 1280x720), got '" + out.video_size + "'";
  else if (!(out.framerate >= 0 && out.framerate <= 1000))
    error = "--framerate must be in (0, 1000] frames per second";
  else if (!(out.open_timeout_seconds >= 0.1 && out.open_timeout_seconds <= 3600) ||
           !(out.stall_timeout_seconds >= 0.1 && out.stall_timeout_seconds <= 3600))
    error = "--open-seconds and --stall-seconds must be in 0.1..3600";
  return error.empty();
}

namespace {

std::string default_models_dir() {
  if (const char* m = std::getenv("AVATARMAP_MODELS"); m && *m) return std::string(m) + "/onnx";
#ifdef AVATARMAP_DEFAULT_MODELS_DIR
  return AVATARMAP_DEFAULT_MODELS_DIR;
#else
  return ".cache/avatarmap/models/onnx";
#endif
}

}  // namespace

bool parse_estimator_options(args& a, bool hands_face_default, estimator_options& out,
                             std::string& error) {
  estimator_options& o = out;
  o.source = default_models_dir();
  std::string model = "full", hand_model = "full", precision = "float";
  a.value("--model", model);
  a.value("--precision", precision);
  a.value("--hand-model", hand_model);
  a.value("--models", o.source);
  int threads = 2, lanes = 2;
  a.integer("--threads", threads, 1, 64);
  a.integer("--lanes", lanes, 1, 2);
  o.static_images = a.flag("--static");
  o.mirrored_input = a.flag("--mirrored");
  o.spin = a.flag("--spin");
  o.hands = hands_face_default;
  o.face = hands_face_default;
  if (a.flag("--hands")) o.hands = true;
  if (a.flag("--no-hands")) o.hands = false;
  if (a.flag("--face")) o.face = true;
  if (a.flag("--no-face")) o.face = false;
  o.model_complexity = model == "lite" ? 0 : model == "full" ? 1 : model == "heavy" ? 2 : -1;
  o.hand_model_complexity = hand_model == "lite" ? 0 : hand_model == "full" ? 1 : -1;
  if (o.model_complexity < 0) {
    error = "--model is lite, full or heavy";
    return false;
  }
  if (o.hand_model_complexity < 0) {
    error = "--hand-model is lite or full";
    return false;
  }
  if (precision != "float" && precision != "int8") {
    error = "--precision is float or int8";
    return false;
  }
  o.precision = precision == "int8" ? model_precision::int8 : model_precision::float32;
  if (!a.error().empty()) {
    error = a.error();
    return false;
  }
  o.threads = threads;
  o.lanes = lanes;
  return true;
}

namespace {
status with_models_hint(const status& st) {
  if (st.ok()) return st;
  return status::error(st.message() +
                       " (scripts/prepare_capture.sh fetches and converts the "
                       "models; --models DIR points elsewhere)");
}
}  // namespace

status make_estimator(const estimator_options& options, std::unique_ptr<estimator>& out) {
  return with_models_hint(create_estimator("onnx", options, out));
}

status make_capture_pipeline(const capture_pipeline_options& options,
                             std::unique_ptr<capture_pipeline>& out) {
  return with_models_hint(capture_pipeline::create(options, out));
}

void timing_totals::add(const estimator_timings& t) {
  sum += t;
  pose_detector_frames += t.pose_detector_ms > 0;
  palm_frames += t.palm_detector_ms > 0;
  face_detector_frames += t.face_detector_ms > 0;
  ++frames;
}

void timing_totals::print(std::FILE* to) const {
  if (startup_ms > 0) std::fprintf(to, "start-up: %.0f ms (models)\n", startup_ms);
  if (frames == 0) return;
  const double n = static_cast<double>(frames);
  std::fprintf(to, "per frame (ms, mean over %ld frames): all stages %.2f", frames,
               sum.total_ms / n);
  auto stage = [&](const char* name, double ms) {
    if (ms > 0) std::fprintf(to, ", %s %.2f", name, ms / n);
  };
  stage("pose landmarks", sum.pose_landmark_ms);
  stage("hand landmarks", sum.hand_landmark_ms);
  stage("face mesh", sum.face_mesh_ms);
  std::fputc('\n', to);
  auto detector = [&](const char* name, double ms, long runs) {
    if (runs > 0) std::fprintf(to, "  %s ran on %ld frames, %.2f ms each\n", name, runs, ms / runs);
  };
  detector("pose detector", sum.pose_detector_ms, pose_detector_frames);
  detector("palm detector", sum.palm_detector_ms, palm_frames);
  detector("face detector", sum.face_detector_ms, face_detector_frames);
}

long resident_kib() { return resident_memory_kib(); }

}  // namespace avatarmap::cli
