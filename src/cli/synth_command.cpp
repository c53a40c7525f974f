// `avatarmap synth`, `demo` and `import-tfjs`.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "avatarmap/export/vrma.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/io/tfjs_import.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"
#include "cli/solve_job.hpp"

namespace avatarmap::cli {
namespace {

const char* k_synth_help =
    "Usage: avatarmap synth -o OUT.landmarks.jsonl [options]\n"
    "\n"
    "Writes the landmarks an ideal estimator would report for a scripted 10-second motion\n"
    "(squats, waving, finger curls, blinking, talking) of a 1.70 m person seen by a 1280x720\n"
    "camera with a 60 degree field of view: pose (image + world), both hands, 478-point face.\n"
    "\n"
    "Options:\n"
    "  -o, --output PATH   output file (required; written atomically)\n"
    "  --seconds S         length (default 10; the motion loops every 10 s)\n"
    "  --fps F             frames per second (default 30)\n"
    "  --noise MM          Gaussian noise on every 3-D point, millimetres (default 0)\n"
    "  --seed N            noise seed (default 1)\n"
    "  --no-hands, --no-face  leave those parts out\n";

struct synth_settings {
  std::string output;
  double seconds = 10.0;
  double fps = 30.0;
  double noise_mm = 0.0;
  unsigned seed = 1;
  bool hands = true;
  bool face = true;
};

status write_synth(const synth_settings& s, long& frames) {
  synth_options o;
  o.hands_image = o.hands_world = s.hands;
  o.face = s.face ? synth_face::mesh_478 : synth_face::none;
  o.body_noise_sigma = o.hand_noise_sigma = o.face_noise_sigma =
      static_cast<float>(s.noise_mm * 0.001);
  o.seed = s.seed;
  status st = o.validate();
  if (!st.ok()) return st;
  landmark_synth synth(o);
  landmark_writer writer;
  landmark_file_header h;
  h.present = true;
  h.image_width = o.image_width;
  h.image_height = o.image_height;
  h.fps = s.fps;
  st = writer.open(s.output, h);
  if (!st.ok()) return st;
  landmark_frame frame;
  frames = static_cast<long>(s.seconds * s.fps + 0.5);
  for (long i = 0; i < frames; ++i) {
    const double t = double(i) / s.fps;
    synth.generate(demo_motion_pose(t, synth.skeleton()), frame);
    frame.t = t;
    st = writer.write(frame);
    if (!st.ok()) return st;
  }
  return writer.commit();
}

bool parse_synth(args& a, synth_settings& s, std::string& err) {
  double v = 0;
  a.value("--output", s.output, "-o");
  if (a.number("--seconds", v)) s.seconds = v;
  if (a.number("--fps", v)) s.fps = v;
  if (a.number("--noise", v)) s.noise_mm = v;
  if (a.number("--seed", v)) {
    // Checked before the cast: a negative or huge double cast to unsigned is undefined.
    if (!(v >= 0 && v <= 4294967295.0 && v == static_cast<double>(static_cast<long long>(v)))) {
      err = "--seed must be an integer in [0, 4294967295]";
      return false;
    }
    s.seed = static_cast<unsigned>(v);
  }
  if (a.flag("--no-hands")) s.hands = false;
  if (a.flag("--no-face")) s.face = false;
  if (!a.error().empty()) {
    err = a.error();
    return false;
  }
  if (!(s.seconds > 0 && s.seconds <= 36000)) err = "--seconds must be in (0, 36000]";
  if (!(s.fps > 0 && s.fps <= 1000)) err = "--fps must be in (0, 1000]";
  if (!(s.noise_mm >= 0 && s.noise_mm <= 1000)) err = "--noise must be in [0, 1000] mm";
  return err.empty();
}

}  // namespace

int run_synth(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_synth_help, stdout);
    return 0;
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

int run_demo(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(
        "Usage: avatarmap demo [--keep DIR]\n"
        "\n"
        "Synthesises a 10 s recording (avatarmap synth, 2 mm noise), solves it (avatarmap solve)\n"
        "and prints the summary, then writes the motion as demo.vrma. --keep DIR keeps\n"
        "demo.landmarks.jsonl, demo.pose.jsonl and demo.vrma there\n"
        "(DIR is created if needed); otherwise they go to a temporary folder that is removed.\n",
        stdout);
    return 0;
  }
  std::string keep;
  a.value("--keep", keep);
  if (!a.error().empty() || !a.check_no_options() || !a.rest().empty()) {
    std::fprintf(stderr, "avatarmap demo: %s\n",
                 a.error().empty() ? "unexpected argument (see --help)" : a.error().c_str());
    return 2;
  }
  std::string dir = keep;
  if (dir.empty()) {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/avatarmap-demo-XXXXXX";
    if (!mkdtemp(pattern.data())) {
      std::perror("avatarmap demo: cannot create a temporary folder");
      return 1;
    }
    dir = pattern;
  } else {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) {
      std::fprintf(stderr, "avatarmap demo: cannot create %s: %s\n", dir.c_str(),
                   ec.message().c_str());
      return 1;
    }
  }
  synth_settings s;
  s.output = dir + "/demo.landmarks.jsonl";
  s.noise_mm = 2.0;
  long frames = 0;
  status st = write_synth(s, frames);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap demo: %s\n", st.message().c_str());
    return 1;
  }
  std::printf(
      "synthesised %ld frames of a scripted motion (squats, waving, finger curls, "
      "blinks, talking): %s\n",
      frames, s.output.c_str());
  solve_file_job job = make_cli_solve_job();
  job.input = s.output;
  job.output = dir + "/demo.pose.jsonl";
  solve_file_summary summary;
  st = run_solve_job(job, progress_mode::off, summary);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap demo: %s\n", st.message().c_str());
    return 1;
  }
  print_summary(job, summary, stdout);
  // The same motion as a VRM Animation clip any VRM viewer can play.
  std::vector<proxy_pose> poses;
  {
    pose_reader reader;
    st = reader.open(job.output);
    proxy_pose p;
    while (st.ok() && reader.next(p) == read_result::frame) poses.push_back(p);
  }
  const std::string vrma = dir + "/demo.vrma";
  if (st.ok()) st = write_vrma(vrma, poses);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap demo: %s\n", st.message().c_str());
    return 1;
  }
  std::printf("wrote %zu frames of VRM Animation to %s\n", poses.size(), vrma.c_str());
  if (keep.empty()) {
    std::remove(s.output.c_str());
    std::remove(job.output.c_str());
    std::remove(vrma.c_str());
    rmdir(dir.c_str());
  }
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
        "*.landmarks.jsonl. --size is the video's size in pixels, --fps its frame rate.\n",
        stdout);
    return 0;
  }
  std::string out, size;
  double fps = 0;
  a.value("--output", out, "-o");
  a.value("--size", size);
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
  status st = import_tfjs_pose(a.rest()[0], a.rest()[1], w, h, fps, out);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap import-tfjs: %s\n", st.message().c_str());
    return 1;
  }
  std::fprintf(stderr, "wrote %s\n", out.c_str());
  return 0;
}

}  // namespace avatarmap::cli
