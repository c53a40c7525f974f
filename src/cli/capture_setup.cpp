#include "cli/capture_setup.hpp"

#include <cstdlib>
#include <string>
#include <vector>

#include "avatarmap/capture/capture_file.hpp"
#include "avatarmap/io/resources.hpp"

namespace avatarmap::cli {

namespace {

estimator_options start_options(bool hands_face_default) {
  estimator_options o;
  apply_option_defaults(k_estimator_option_table, o);
  o.hands = o.face = hands_face_default;
  return o;
}

}  // namespace

std::string estimator_options_help(bool hands_face_default) {
  return option_flags_help(k_estimator_option_table, start_options(hands_face_default));
}

std::string input_options_help() {
  return "INPUT is a video file, an image, a folder of images, a printf pattern\n"
         "(frames/%05d.png), a device FORMAT:DEVICE (v4l2:/dev/video0, x11grab::0.0, a test\n"
         "pattern lavfi:testsrc=size=640x480:rate=30) or a URL (udp://127.0.0.1:5000,\n"
         "rtp://, rtsp://HOST/PATH, srt://, http(s)://, tcp://, ...); an unknown scheme or "
         "device\nis refused with the list this build has (docs/live.md).\n"
         "\n"
         "Input options:\n" +
         option_flags_help(k_video_source_option_table, video_source_options{}) + "\n";
}

void add_capture_flag_specs(bool hands_face_default, std::vector<flag_spec>& out) {
  add_flag_specs(k_video_source_option_table, video_source_options{}, out);
  add_flag_specs(k_estimator_option_table, start_options(hands_face_default), out);
}

bool parse_input_options(args& a, video_source_options& out, std::string& error) {
  if (!parse_option_flags(a, k_video_source_option_table, out, error)) return false;
  int w = 0, h = 0;
  if (!out.video_size.empty() && !parse_image_size(out.video_size, w, h))
    error = "--video-size wants WIDTHxHEIGHT (e.g. 1280x720), got '" + out.video_size + "'";
  return error.empty();
}

bool parse_estimator_options(args& a, bool hands_face_default, estimator_options& out,
                             std::string& error) {
  estimator_options o = start_options(hands_face_default);
  if (!parse_option_flags(a, k_estimator_option_table, o, error)) return false;
  // An empty source makes make_estimator() say where the models were looked for.
  o.source = find_resource(resource::models, o.source).folder;
  out = o;
  return true;
}

namespace {
status with_models_hint(const status& st, const std::string& source) {
  if (st.ok()) return st;
  if (source.empty()) {
    const resource_lookup r = find_resource(resource::models);
    std::string tried;
    for (const std::string& t : r.tried) tried += (tried.empty() ? "" : ", ") + t;
    return st.with_message(st.message() + " (no models folder: looked in " +
                           (tried.empty() ? "nothing" : tried) + "; " +
                           script_command("scripts/prepare_capture.sh") +
                           " fetches and converts the models, --models DIR or $AVATARMAP_MODELS "
                           "points elsewhere)");
  }
  return st.with_message(st.message() + " (" + script_command("scripts/prepare_capture.sh") +
                         " fetches and converts the models; --models DIR points elsewhere)");
}
}  // namespace

status make_estimator(const estimator_options& options, std::unique_ptr<estimator>& out) {
  return with_models_hint(create_estimator("onnx", options, out), options.source);
}

status make_live_session(const live_session_options& options, std::unique_ptr<live_session>& out) {
  return with_models_hint(live_session::create(options, out), options.pipeline.estimator.source);
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
