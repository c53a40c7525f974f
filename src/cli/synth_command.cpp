// `avatarmap synth`, `demo` and `import-tfjs`.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "avatarmap/core/limits.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/io/tfjs_import.hpp"
#include "avatarmap/jobs/mocap_synth.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "avatarmap/synth/synth_recording.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"
#include "common/atomic_file.hpp"

namespace avatarmap::cli {
namespace {

const char* k_synth_help =
    "Usage: avatarmap synth -o OUT.landmarks.jsonl [--truth OUT.pose.jsonl] [options]\n"
    "\n"
    "Writes the landmarks an estimator would report for a known motion, and with --truth the\n"
    "true poses at the same times (docs/accuracy.md, docs/file-formats.md). Without --scenario:\n"
    "a scripted 10-second motion (squats, waving, finger curls, blinking, talking) of a 1.70 m\n"
    "person seen by a 1280x720 camera with a 60 degree field of view, exact landmarks: pose\n"
    "(image + world), both hands, 478-point face.\n"
    "\n"
    "Options:\n"
    "  -o, --output PATH     output file (required; written atomically)\n"
    "  --truth PATH          also write the true poses (*.pose.jsonl; confidence 0 marks the\n"
    "                        bones of a limb in a low-visibility burst, 1 the others)\n"
    "  --scenario demo|clean|noisy\n"
    "                        preset (default demo): clean = fast random motion, random camera\n"
    "                        (field of view 50-90 degrees, 1.5-4 m, off centre), person\n"
    "                        1.55-1.90 m; noisy = clean + 10/5/1 mm noise on body/hands/face\n"
    "                        + low-visibility bursts of ~1 s on 12 % of each limb's time.\n"
    "                        The options below change the preset.\n"
    "  --seconds S           length (default 10; the demo motion loops every 10 s)\n"
    "  --fps F               frames per second (default 30)\n"
    "  --size WxH            image size in pixels (default 1280x720)\n"
    "  --seed N              seed of the motion, camera, noise and bursts (default 1)\n"
    "  --motion demo|random|head  the motion played; head = the torso upright, the head\n"
    "                        swept over pitch -70..+40, yaw +-70, roll +-35 degrees\n"
    "  --max-wrist-speed R   top speed of arms and fingers in the random motion, rad/s (6)\n"
    "  --finger-bend DEG     sideways bend range of finger joints in the random motion (10)\n"
    "  --fov DEG             horizontal field of view (fixes the random camera's draw)\n"
    "  --distance M          camera distance in metres (fixes the random camera's draw)\n"
    "  --height M            person height in metres\n"
    "  --noise MM            Gaussian noise on every 3-D point, millimetres (default 0)\n"
    "  --body-noise MM, --hand-noise MM, --face-noise MM   the same per part\n"
    "  --low-vis F           fraction of each limb's time in low-visibility bursts, [0, 0.9]\n"
    "  --low-vis-seconds S   mean burst length (default 1)\n"
    "  --low-vis-noise MM    extra Gaussian noise on a limb's 3-D points in a burst (30)\n"
    "  --no-hands, --no-face  leave those parts out\n"
    "\n"
    "From real motion capture (the world benchmark, docs/world-benchmark.md):\n"
    "  avatarmap synth --mocap CLIP.bvh -o OUT.landmarks.jsonl [options]\n"
    "  writes the pose landmarks (image + world) of the BVH's own joints seen by a pinhole\n"
    "  camera, and the camera to OUT.camera.json (or --camera-json PATH). The truth is the BVH\n"
    "  itself: `avatarmap eval-world CLIP.bvh SOLVED` samples it at the solved frames' times.\n"
    "  --units F             metres per BVH unit (default 0.056444, the CMU clips')\n"
    "  --fps F               frames per second (default 30), t = k / F from the BVH's start\n"
    "  --scenario blazepose|clean\n"
    "                        blazepose (default): world points leaning 10-25 deg toward the\n"
    "                        camera, 15 mm world noise, image noise 0.3 % of the image height,\n"
    "                        lower visibility for points turned away; clean: none of it\n"
    "  --seed N              draws the camera options not given, the lean and the noise (1)\n"
    "  --camera-height M     above the floor (drawn 0.5-2.0)\n"
    "  --distance M          horizontal distance to the performer's mean hips (drawn 2.5-5)\n"
    "  --lateral M           sideways, + to the performer's left (drawn -1..1)\n"
    "  --pitch DEG           + looks up (drawn: looking at the hips +- 20 % of the vertical\n"
    "                        field of view, within -30..20)\n"
    "  --roll DEG            about the optical axis (drawn -8..8)\n"
    "  --fov DEG             horizontal field of view (drawn 40-90)\n"
    "  --size WxH            image size (default 1280x720)\n"
    "  --lean DEG, --world-noise MM, --image-noise PCT   change the scenario's values\n"
    "  --camera-json PATH    where the camera goes (default OUT with .camera.json)\n";

struct synth_settings {
  std::string output;
  std::string truth;
  double seconds = 10.0;
  double fps = 30.0;
  bool hands = true;
  bool face = true;
  synth_options options;
};

status write_synth(const synth_settings& s, long& frames) {
  synth_options o = s.options;
  o.hands_image = o.hands_world = s.hands;
  o.face = s.face ? synth_face::mesh_478 : synth_face::none;
  status st = o.validate();
  if (!st.ok()) return st;
  synth_recording recording(o);
  landmark_writer writer;
  landmark_file_header h;
  h.present = true;
  h.image_width = o.image_width;
  h.image_height = o.image_height;
  h.fps = s.fps;
  st = writer.open(s.output, h);
  if (!st.ok()) return st;
  pose_writer truth;
  if (!s.truth.empty()) {
    pose_file_header th;
    th.present = true;
    th.fps = s.fps;
    pose_write_options wo;
    wo.write_confidence = true;  // the low-visibility marker
    st = truth.open(s.truth, th, wo);
    if (!st.ok()) return st;
  }
  landmark_frame frame;
  proxy_pose pose;
  frames = static_cast<long>(s.seconds * s.fps + 0.5);
  for (long i = 0; i < frames; ++i) {
    const double t = double(i) / s.fps;
    recording.generate(t, pose, frame);
    st = writer.write(frame);
    if (st.ok() && !s.truth.empty()) st = truth.write(pose);
    if (!st.ok()) return st;
  }
  // The truth first: a landmarks file without its truth would be measured against nothing.
  if (!s.truth.empty()) {
    st = truth.commit();
    if (!st.ok()) return st;
  }
  return writer.commit();
}

// Millimetres option -> metres field; false (err set) when out of [0, 1000] mm.
bool noise_option(args& a, const char* name, float& out_metres, std::string& err) {
  double v = 0;
  if (!a.number(name, v)) return true;
  if (!(v >= 0 && v <= 1000)) {
    err = std::string(name) + " must be in [0, 1000] mm";
    return false;
  }
  out_metres = static_cast<float>(v * 0.001);
  return true;
}

bool parse_synth(args& a, synth_settings& s, std::string& err) {
  double v = 0;
  std::string text;
  a.value("--output", s.output, "-o");
  a.value("--truth", s.truth);
  unsigned seed = 1;
  if (a.number("--seed", v)) {
    // Checked before the cast: a negative or huge double cast to unsigned is undefined.
    if (!(v >= 0 && v <= 4294967295.0 && v == static_cast<double>(static_cast<long long>(v)))) {
      err = "--seed must be an integer in [0, 4294967295]";
      return false;
    }
    seed = static_cast<unsigned>(v);
  }
  synth_scenario scenario = synth_scenario::demo;
  if (a.value("--scenario", text)) {
    const auto sc = synth_scenario_from_name(text);
    if (!sc) {
      err = "--scenario is demo, clean or noisy, got '" + text + "'";
      return false;
    }
    scenario = *sc;
  }
  synth_options& o = s.options;
  o = synth_scenario_options(scenario, seed);
  if (a.number("--seconds", v)) s.seconds = v;
  if (a.number("--fps", v)) s.fps = v;
  if (a.value("--size", text) && !parse_image_size(text, o.image_width, o.image_height)) {
    err = "--size wants WxH in pixels, e.g. 1280x720";
    return false;
  }
  if (a.value("--motion", text)) {
    if (text == "demo") {
      o.motion = synth_motion::demo;
    } else if (text == "random") {
      o.motion = synth_motion::random;
    } else if (text == "head") {
      o.motion = synth_motion::head;
    } else {
      err = "--motion is demo, random or head, got '" + text + "'";
      return false;
    }
  }
  if (a.number("--max-wrist-speed", v)) {
    if (!(v > 0 && v <= 100)) {
      err = "--max-wrist-speed must be in (0, 100] rad/s";
      return false;
    }
    o.max_wrist_speed = static_cast<float>(v);
  }
  if (a.number("--finger-bend", v)) {
    if (!(v >= 0 && v <= 45)) {
      err = "--finger-bend must be in [0, 45] degrees";
      return false;
    }
    o.finger_side_bend_degrees = static_cast<float>(v);
  }
  if (a.number("--fov", v)) {
    if (!(v > 1 && v < 179)) {
      err = "--fov must be in (1, 179) degrees";
      return false;
    }
    o.horizontal_fov_degrees = o.fov_min_degrees = o.fov_max_degrees = static_cast<float>(v);
  }
  if (a.number("--distance", v)) {
    if (!(v >= 0.1 && v <= 100)) {
      err = "--distance must be in [0.1, 100] metres";
      return false;
    }
    o.camera_position.z = o.distance_min = o.distance_max = static_cast<float>(v);
  }
  if (a.number("--height", v)) {
    if (!(v >= 0.5 && v <= 3)) {
      err = "--height must be in [0.5, 3] metres";
      return false;
    }
    o.person_height = static_cast<float>(v);
  }
  float all_noise = -1.f;
  if (!noise_option(a, "--noise", all_noise, err)) return false;
  if (all_noise >= 0.f) o.body_noise_sigma = o.hand_noise_sigma = o.face_noise_sigma = all_noise;
  if (!noise_option(a, "--body-noise", o.body_noise_sigma, err) ||
      !noise_option(a, "--hand-noise", o.hand_noise_sigma, err) ||
      !noise_option(a, "--face-noise", o.face_noise_sigma, err))
    return false;
  if (a.number("--low-vis", v)) {
    if (!(v >= 0 && v <= 0.9)) {
      err = "--low-vis must be in [0, 0.9] (a fraction of each limb's time)";
      return false;
    }
    o.low_visibility_fraction = static_cast<float>(v);
  }
  if (a.number("--low-vis-seconds", v)) {
    if (!(v > 0 && v <= 3600)) {
      err = "--low-vis-seconds must be in (0, 3600]";
      return false;
    }
    o.low_visibility_seconds = static_cast<float>(v);
  }
  if (!noise_option(a, "--low-vis-noise", o.low_visibility_noise_sigma, err)) return false;
  if (a.flag("--no-hands")) s.hands = false;
  if (a.flag("--no-face")) s.face = false;
  if (!a.error().empty()) {
    err = a.error();
    return false;
  }
  if (!(s.seconds > 0 && s.seconds <= 36000)) err = "--seconds must be in (0, 36000]";
  if (!(s.fps > 0 && s.fps <= k_max_fps))
    err = "--fps must be in (0, " + limit_text(k_max_fps) + "]";
  if (err.empty() && !s.truth.empty() && s.truth == s.output)
    err = "--truth and -o name the same file; give the truth its own file (e.g. X.pose.jsonl)";
  return err.empty();
}

// `synth --mocap CLIP.bvh`: landmarks of a real take (jobs/mocap_synth.hpp).
int run_mocap_synth(args& a, const std::string& bvh) {
  std::string output, camera_json, text;
  double v = 0, fps = 30.0, units = k_cmu_units_to_metres;
  unsigned seed = 1;
  std::string err;
  a.value("--output", output, "-o");
  a.value("--camera-json", camera_json);
  if (a.number("--units", v)) units = v;
  if (a.number("--fps", v)) fps = v;
  if (a.number("--seed", v)) {
    if (!(v >= 0 && v <= 4294967295.0 && v == static_cast<double>(static_cast<long long>(v))))
      err = "--seed must be an integer in [0, 4294967295]";
    seed = static_cast<unsigned>(std::max(0.0, std::min(v, 4294967295.0)));
  }
  mocap_scenario scenario = mocap_scenario::blazepose;
  if (a.value("--scenario", text)) {
    if (text == "clean") {
      scenario = mocap_scenario::clean;
    } else if (text != "blazepose") {
      err = "--scenario with --mocap is blazepose or clean, got '" + text + "'";
    }
  }
  mocap_camera_setup cam;
  cam.seed = seed;
  auto f = [&](const char* name, float& out) {
    if (a.number(name, v)) out = static_cast<float>(v);
  };
  f("--camera-height", cam.height);
  f("--distance", cam.distance);
  f("--lateral", cam.lateral);
  f("--pitch", cam.pitch_degrees);
  f("--roll", cam.roll_degrees);
  f("--fov", cam.fov_degrees);
  if (a.value("--size", text) && !parse_image_size(text, cam.image_width, cam.image_height))
    err = "--size wants WxH in pixels, e.g. 1280x720";
  mocap_synth_options o = mocap_synth_options::preset(scenario, seed);
  f("--lean", o.lean_degrees);
  if (a.number("--world-noise", v)) o.world_noise_m = static_cast<float>(v * 0.001);
  if (a.number("--image-noise", v)) o.image_noise = static_cast<float>(v * 0.01);
  if (err.empty() && !a.error().empty()) err = a.error();
  if (err.empty() && (!a.check_no_options() || !a.rest().empty()))
    err = a.error().empty() ? "unexpected argument (see --help)" : a.error();
  if (err.empty() && output.empty()) err = "give the output file with -o OUT.landmarks.jsonl";
  if (err.empty() && !(fps > 0 && fps <= 1000)) err = "--fps must be in (0, 1000]";
  if (err.empty() && !(units > 0 && units <= 1000)) err = "--units must be in (0, 1000]";
  if (err.empty()) {
    if (status st = cam.validate(); !st) err = st.message();
  }
  if (err.empty()) {
    if (status st = o.validate(); !st) err = st.message();
  }
  if (!err.empty()) {
    std::fprintf(stderr, "avatarmap synth: %s\n", err.c_str());
    return 2;
  }
  if (camera_json.empty()) {
    const std::string suffix = ".landmarks.jsonl";
    camera_json = output.size() > suffix.size() &&
                          output.compare(output.size() - suffix.size(), suffix.size(), suffix) == 0
                      ? output.substr(0, output.size() - suffix.size()) + ".camera.json"
                      : output + ".camera.json";
  }
  mocap_take take;
  status st = take.load(bvh, static_cast<float>(units));
  mocap_synth_job job;
  job.take = &take;
  job.camera = place_mocap_camera(take, cam);
  job.options = o;
  job.fps = fps;
  job.output = output;
  mocap_synth_summary sum;
  if (st) st = job.run(sum);
  const std::string json = mocap_camera_json(job.camera, sum.lean_degrees);
  if (st) st = io_detail::write_file_atomically(camera_json, json + "\n");
  if (!st) {
    std::fprintf(stderr, "avatarmap synth: %s\n", st.message().c_str());
    return 1;
  }
  std::fprintf(stderr,
               "wrote %ld frames (%.2f s at %g fps) of %s (skeleton %.2f m, floor %.3f m) to %s;\n"
               "%.1f %% of the points inside the image; camera: %s\n",
               sum.frames, take.duration(), fps, bvh.c_str(), take.rest_height(), take.floor_y(),
               output.c_str(), 100.0 * sum.inside_fraction, json.c_str());
  return 0;
}

}  // namespace

int run_synth(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_synth_help, stdout);
    return 0;
  }
  std::string mocap;
  if (a.value("--mocap", mocap)) return run_mocap_synth(a, mocap);
  for (const char* only : {"--units", "--camera-height", "--lateral", "--pitch", "--roll", "--lean",
                           "--world-noise", "--image-noise", "--camera-json"}) {
    std::string ignored;
    if (a.value(only, ignored)) {
      std::fprintf(stderr, "avatarmap synth: %s is for --mocap CLIP.bvh (see --help)\n", only);
      return 2;
    }
  }
  synth_settings s;
  std::string err;
  if (!parse_synth(a, s, err) || !a.check_no_options() || !a.rest().empty()) {
    std::fprintf(stderr, "avatarmap synth: %s\n",
                 !err.empty()         ? err.c_str()
                 : !a.error().empty() ? a.error().c_str()
                                      : "unexpected argument (see --help)");
    return 2;
  }
  if (s.output.empty()) {
    std::fprintf(stderr, "avatarmap synth: give the output file with -o OUT.landmarks.jsonl\n");
    return 2;
  }
  long frames = 0;
  status st = write_synth(s, frames);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap synth: %s\n", st.message().c_str());
    return 1;
  }
  std::fprintf(stderr, "wrote %ld synthetic frames (%.1f s at %.0f fps) to %s\n", frames, s.seconds,
               s.fps, s.output.c_str());
  return 0;
}

int run_import_tfjs(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(
        "Usage: avatarmap import-tfjs IMAGE.json WORLD.json --size WxH --fps F -o "
        "OUT.landmarks.jsonl\n"
        "\n"
        "Converts tfjs-models' reference BlazePose landmarks (a JSON list of frames of 33\n"
        "[x_px, y_px, z] image points, and one of 33 [x, y, z] world points in metres) into\n"
        "*.landmarks.jsonl. --size is the video's size in pixels, --fps its frame rate.\n"
        "\n"
        "  -o, --output PATH   the landmarks file to write (required; written atomically)\n"
        "  --hand left|right   the files are a hand recording (21 points per frame, e.g.\n"
        "                      asl_hand.full.json + asl_hand_3d.full.json), written as that hand\n"
        "                      (the files do not say which)\n",
        stdout);
    return 0;
  }
  std::string out, size, hand;
  double fps = 0;
  a.value("--output", out, "-o");
  a.value("--size", size);
  a.value("--hand", hand);
  a.number("--fps", fps);
  int w = 0, h = 0;
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() != 2 || out.empty() ||
      !parse_image_size(size, w, h) || !(fps > 0)) {
    std::fprintf(stderr,
                 "avatarmap import-tfjs: give IMAGE.json WORLD.json --size WxH --fps F -o OUT "
                 "(see --help)%s%s\n",
                 a.error().empty() ? "" : ": ", a.error().c_str());
    return 2;
  }
  if (!hand.empty() && hand != "left" && hand != "right") {
    std::fprintf(stderr, "avatarmap import-tfjs: --hand is left or right, got '%s'\n",
                 hand.c_str());
    return 2;
  }
  status st = hand.empty()
                  ? import_tfjs_pose(a.rest()[0], a.rest()[1], w, h, fps, out)
                  : import_tfjs_hand(a.rest()[0], a.rest()[1], w, h, fps, hand == "left", out);
  if (!st.ok() && hand.empty() && st.message().find("array of 21") != std::string::npos)
    st = st.with_message(st.message() + " (a hand recording: add --hand left|right)");
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap import-tfjs: %s\n", st.message().c_str());
    return 1;
  }
  std::fprintf(stderr, "wrote %s\n", out.c_str());
  return 0;
}

}  // namespace avatarmap::cli
