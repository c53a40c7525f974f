// `avatarmap demo [VIDEO]`: the main job on a built-in default (docs/cli.md "demo"). Without
// VIDEO the built-in avatar performs the synthetic scripted motion (`synth --truth`), rendered
// by the browser viewer (`render`) into a video; the video is captured (`capture`) and solved
// (the solve-file job) as any take is, the round trip is scored against the motion played
// (pose_accuracy), the result is written onto the built-in avatar (.glb, .vrma) and rendered
// beside the source video. With VIDEO the same chain runs on it (no score). Without the
// capture models or a browser it falls back to the synthetic landmarks (and says so). The
// stages are the commands' own (each written once); this file only chains them.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "avatarmap/avatar/builtin_avatar.hpp"
#include "avatarmap/export/vrma.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/io/resources.hpp"
#include "avatarmap/jobs/clip_output.hpp"
#include "avatarmap/render/render_job.hpp"
#include "avatarmap/rig/bound_avatar.hpp"
#include "avatarmap/synth/pose_accuracy.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"
#include "cli/solve_job.hpp"

namespace avatarmap::cli {
namespace {

const char* k_demo_help =
    "Usage: avatarmap demo [VIDEO] [--out DIR] [--keep] [--seconds S] [--size WxH]\n"
    "                      [--synthetic]\n"
    "\n"
    "The main job on a built-in default, written to DIR (--out, default ./avatarmap-demo):\n"
    "  no VIDEO  the built-in avatar performs a scripted motion (squats, waving, finger\n"
    "            curls, blinks, talking), rendered to DIR/source.mp4 by the viewer in headless\n"
    "            Chromium (avatarmap render); that video is captured with MediaPipe's models\n"
    "            and solved as any take is, and the round trip's error against the motion\n"
    "            played is printed (bone directions, degrees)\n"
    "  VIDEO     that video is captured and solved\n"
    "Then writes DIR/avatar.vrm (the built-in avatar), DIR/demo.glb (the avatar moving; any\n"
    "glTF viewer), DIR/demo.vrma (VRM Animation) and DIR/demo.mp4 (the source video with its\n"
    "landmarks beside the avatar), and prints the commands to watch them. Without the capture\n"
    "models (scripts/prepare_capture.sh) or Chromium it synthesises the landmarks of the\n"
    "scripted motion instead, and says so.\n"
    "\n"
    "Options:\n"
    "  --out DIR     the results' folder (default avatarmap-demo; created if needed)\n"
    "  --keep        also keep the intermediate files in DIR: truth.pose.jsonl (the motion\n"
    "                played), demo.landmarks.jsonl, demo.pose.jsonl (the solved poses)\n"
    "  --seconds S   length of the built-in clip, 1..60 (default 8)\n"
    "  --size WxH    size of the rendered videos (default 640x480; demo.mp4 is twice as wide\n"
    "                with a source video)\n"
    "  --synthetic   no video: solve synthesised landmarks of the scripted motion\n";

// One of the CLI's commands (commands.hpp's run_with_args), `v[0]` its name.
int run_command(std::vector<std::string> v, int (*fn)(int, char**)) {
  v.insert(v.begin(), "avatarmap");
  return run_with_args(std::move(v), fn);
}

// Writes the built-in avatar (1.70 m, the demo's person) to `avatar_path`, then `poses` on it as
// an animated .glb at `glb_path` through the library's clip writer; `out_frames` is the count
// written.
status write_on_builtin_avatar(const std::vector<proxy_pose>& poses, const std::string& avatar_path,
                               const std::string& glb_path, std::size_t& out_frames) {
  if (status st = write_builtin_avatar(avatar_path); !st) return st;
  bound_avatar avatar;  // bound as `convert --avatar` binds it: the file's VRM humanoid
  if (status st = bind_avatar(avatar_path, bind_avatar_options{}, avatar); !st) return st;
  clip_output_job out;
  out.path = glb_path;
  out.frames = &poses;
  out.avatar_path = avatar_path;
  out.avatar_rig = &avatar.rig;
  out.avatar_binding = avatar.binding;
  out.avatar_table = avatar.table();
  clip_output_summary summary;
  if (status st = out.run(summary); !st) return st;
  out_frames = summary.frames_written;
  return {};
}

int fail(const std::string& message) {
  std::fprintf(stderr, "avatarmap demo: %s\n", message.c_str());
  return 1;
}

// The intermediate files: in DIR with --keep, else in a private temporary folder removed at
// the end (whatever the outcome).
struct work_folder {
  std::string path;
  bool temporary = false;
  ~work_folder() {
    if (!temporary) return;
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

std::string shell_word(const std::string& s) {
  if (s.find_first_of(" \t'\"\\$`!*?[]{}()<>|&;#~") == std::string::npos && !s.empty()) return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

int run_demo(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_demo_help, stdout);
    return 0;
  }
  std::string out_dir = "avatarmap-demo", size = "640x480";
  double seconds = 8;
  const bool keep = a.flag("--keep");
  bool synthetic = a.flag("--synthetic");
  a.value("--out", out_dir);
  a.value("--size", size);
  const bool seconds_given = a.number("--seconds", seconds);
  std::string err = a.error();
  if (err.empty() && !(seconds >= 1 && seconds <= 60)) err = "--seconds must be in [1, 60]";
  if (err.empty() && !a.check_no_options()) err = a.error();
  if (err.empty() && a.rest().size() > 1) err = "give at most one VIDEO (see --help)";
  if (!err.empty()) {
    std::fprintf(stderr, "avatarmap demo: %s\n", err.c_str());
    return 2;
  }
  const std::string video = a.rest().empty() ? std::string() : a.rest()[0];
  if (!video.empty() && (synthetic || seconds_given)) {
    std::fprintf(stderr,
                 "avatarmap demo: --synthetic and --seconds are for the built-in clip, "
                 "not a VIDEO\n");
    return 2;
  }
  if (!video.empty() && !std::filesystem::is_regular_file(video)) {
    std::fprintf(stderr, "avatarmap demo: %s: no such file\n", video.c_str());
    return 2;
  }

  // The results' folder first, so that a bad one fails before any work.
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return fail("cannot create " + out_dir + ": " + ec.message());
  work_folder work;
  if (keep) {
    work.path = out_dir;
  } else {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/avatarmap-demo-XXXXXX";
    if (!mkdtemp(pattern.data())) return fail("cannot create a temporary folder");
    work.path = pattern;
    work.temporary = true;
  }
  const std::string truth = work.path + "/truth.pose.jsonl";
  const std::string landmarks = work.path + "/demo.landmarks.jsonl";
  const std::string solved = work.path + "/demo.pose.jsonl";
  const std::string prog = program_command();

  // What the round trip needs; without it the synthetic landmarks stand in.
  std::string source = video;
  if (video.empty() && !synthetic) {
    const resource_lookup models = find_resource(resource::models);
    if (models.folder.empty()) {
      std::printf(
          "demo: no capture models (%s prepares them): solving synthetic landmarks "
          "instead of a video\n",
          script_command("scripts/prepare_capture.sh").c_str());
      synthetic = true;
    } else if (find_render_browser().empty()) {
      std::printf(
          "demo: no Chromium to render the built-in clip (sudo apt-get install "
          "chromium): solving synthetic landmarks instead of a video\n");
      synthetic = true;
    }
  }
  if (video.empty()) {
    // The motion played, and the landmarks an estimator would report for it (2 mm noise).
    char secs[32];
    std::snprintf(secs, sizeof secs, "%g", seconds);
    if (run_command({"synth", "-o", landmarks, "--truth", truth, "--seconds", secs, "--noise", "2"},
                    run_synth) != 0)
      return 1;
    if (!synthetic) {
      source = out_dir + "/source.mp4";
      std::printf(
          "demo: the built-in avatar performing the scripted motion (%g s), rendered "
          "to %s\n",
          seconds, source.c_str());
      std::fflush(stdout);
      if (run_command({"render", truth, "-o", source, "--size", size}, run_render) != 0) return 1;
    } else {
      std::printf(
          "demo: synthesised %g s of the scripted motion's landmarks (squats, waving, "
          "finger curls, blinks, talking)\n",
          seconds);
    }
  }
  if (!source.empty()) {
    std::printf("demo: capturing %s (body, hands, face)\n", source.c_str());
    std::fflush(stdout);
    if (run_command({"capture", source, "--hands", "--face", "-o", landmarks}, run_capture) != 0)
      return 1;
  }

  solve_file_job job = make_cli_solve_job();
  job.input = landmarks;
  job.output = solved;
  solve_file_summary summary;
  if (status st = run_solve_job(job, progress_mode::automatic, summary); !st.ok())
    return fail(st.message());
  print_summary(job, summary, stdout);

  if (video.empty()) {
    pose_accuracy acc;
    status st = evaluate_pose_files(truth, solved, acc);
    if (!st.ok() && acc.frames == 0) return fail("scoring the round trip: " + st.message());
    const accuracy_figures& f = acc.all;
    std::printf(
        "demo: %s error against the motion played (%ld frames): bone directions "
        "%.1f deg mean (torso %.1f, arms %.1f, legs %.1f, fingers %.1f), head %.1f deg\n",
        synthetic ? "solve" : "round trip (render -> capture -> solve)", acc.frames,
        f.direction.mean(), f.groups[0].mean(), f.groups[1].mean(), f.groups[2].mean(),
        f.groups[3].mean(), f.head.mean());
  }

  // The motion on the built-in avatar (.glb), and as VRM Animation.
  std::vector<proxy_pose> poses;
  {
    pose_reader reader;
    status st = reader.open(solved);
    proxy_pose p;
    while (st.ok() && reader.next(p) == read_result::frame) poses.push_back(p);
    if (!st.ok()) return fail(st.message());
  }
  const std::string vrma = out_dir + "/demo.vrma", avatar = out_dir + "/avatar.vrm",
                    glb = out_dir + "/demo.glb", movie = out_dir + "/demo.mp4";
  if (status st = write_vrma(vrma, poses); !st.ok()) return fail(st.message());
  std::size_t written = 0;
  if (status st = write_on_builtin_avatar(poses, avatar, glb, written); !st.ok())
    return fail(st.message());
  std::printf("demo: wrote %s (the built-in avatar), %s (%zu frames on it) and %s\n",
              avatar.c_str(), glb.c_str(), written, vrma.c_str());

  bool rendered = false;
  if (!source.empty()) {
    std::printf("demo: rendering the result beside the source video to %s\n", movie.c_str());
    std::fflush(stdout);
    int w = 640, h = 480;
    if (std::sscanf(size.c_str(), "%dx%d", &w, &h) != 2) w = 640, h = 480;
    char wide[32];
    std::snprintf(wide, sizeof wide, "%dx%d", 2 * w, h);
    rendered = run_command({"render", solved, "-o", movie, "--size", wide, "--video", source,
                            "--landmarks", landmarks},
                           run_render) == 0;
    if (!rendered) std::fprintf(stderr, "avatarmap demo: the result's video was not written\n");
  }

  std::printf("\nwatch it:\n");
  if (rendered)
    std::printf("  %s    (any video player, e.g. ffplay %s)\n", movie.c_str(),
                shell_word(movie).c_str());
  std::printf("  %s view %s%s    (then open the address it prints)\n", shell_word(prog).c_str(),
              shell_word(glb).c_str(),
              source.empty() ? "" : (" --video " + shell_word(source)).c_str());
  std::printf("  or open %s in any glTF viewer (Blender: docs/blender.md)\n",
              shell_word(glb).c_str());
  std::printf("your own video: %s animate take.mp4 -o take.glb\n", shell_word(prog).c_str());
  return 0;
}

}  // namespace avatarmap::cli
