// avatarmap: the command-line tool. See `avatarmap --help` and docs/cli.md.
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include "avatarmap/version.hpp"
#include "cli/commands.hpp"
#include "io/atomic_file.hpp"

namespace {

const char* k_usage =
    "avatarmap " AVATARMAP_VERSION_STRING
    " - monocular landmarks to expressive avatar animation\n"
    "\n"
    "Usage:\n"
    "  avatarmap solve IN.landmarks.jsonl -o OUT.pose.jsonl [options]\n"
    "      Landmarks -> proxy pose (VRM 1.0 bones, hips position, expressions).\n"
    "  avatarmap capture INPUT -o OUT.landmarks.jsonl [--hands] [--face] [--overlay OUT.mp4]\n"
    "      Video, image or image sequence -> landmarks (MediaPipe's models on ONNX Runtime).\n"
    "  avatarmap animate VIDEO -o OUT.vrma|OUT.glb|OUT.bvh [--avatar AVATAR]\n"
    "      capture + convert in one command: video in, avatar animation out.\n"
    "  avatarmap live INPUT [-o OUT.pose.jsonl] [--fps 60] [--hands] [--face] [--serve PORT]\n"
    "      Latest-frame live loop (camera, or a file paced as one) with latency figures.\n"
    "  avatarmap view [FILE.pose.jsonl|FILE.vrma] --avatar AVATAR.vrm [--port 8080]\n"
    "      Browser viewer: the avatar posed live (live --serve) or playing FILE.\n"
    "  avatarmap convert IN -o OUT [--avatar AVATAR] [--rig auto|NAME|FILE.json] [--fps N]\n"
    "      Landmarks, poses or .vrma in; .vrma, .glb (animated avatar), .bvh or poses out.\n"
    "  avatarmap synth -o OUT.landmarks.jsonl [--truth OUT.pose.jsonl] [--scenario clean|noisy]\n"
    "      Writes a synthetic recording (scripted or random motion) and its ground truth.\n"
    "  avatarmap eval-pose TRUTH.pose.jsonl SOLVED.pose.jsonl [--json]\n"
    "      Bone-direction and head-orientation errors of solved poses against the truth.\n"
    "  avatarmap demo [--keep DIR]\n"
    "      Synthesises a recording, solves it and prints the summary (no input needed).\n"
    "  avatarmap import-tfjs IMAGE.json WORLD.json --size WxH --fps F -o OUT.landmarks.jsonl\n"
    "      Converts tfjs-models' reference pose landmarks (pixels + world) to our format.\n"
    "  avatarmap backends\n"
    "      Lists the landmark estimator backends in this build.\n"
    "  avatarmap inspect AVATAR [--json]\n"
    "      Prints an avatar file's format, joints, humanoid bones, hips height, expressions.\n"
    "  avatarmap --version | --help | COMMAND --help\n";

// Runs the command `cmd`; -1 when there is no such command.
int dispatch(const std::string& cmd, int argc, char** argv) {
  if (cmd == "solve") return avatarmap::cli::run_solve(argc, argv);
  if (cmd == "convert") return avatarmap::cli::run_convert(argc, argv);
  if (cmd == "capture") return avatarmap::cli::run_capture(argc, argv);
  if (cmd == "animate") return avatarmap::cli::run_animate(argc, argv);
  if (cmd == "live") return avatarmap::cli::run_live_command(argc, argv);
  if (cmd == "synth") return avatarmap::cli::run_synth(argc, argv);
  if (cmd == "demo") return avatarmap::cli::run_demo(argc, argv);
  if (cmd == "import-tfjs") return avatarmap::cli::run_import_tfjs(argc, argv);
  if (cmd == "backends") return avatarmap::cli::run_backends(argc, argv);
  if (cmd == "inspect") return avatarmap::cli::run_inspect(argc, argv);
  if (cmd == "eval-pose") return avatarmap::cli::run_eval_pose(argc, argv);
  if (cmd == "view") return avatarmap::cli::run_view(argc, argv);
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  // Ctrl-C, kill or a closed terminal remove the temporary files of outputs being written
  // (the previous outputs stay as they were) before the process dies by the signal.
  avatarmap::io_detail::install_temp_cleanup_handlers();
  // Over a file-size limit (ulimit -f) a write then fails with EFBIG and the tool reports it
  // like a full disk, keeping the previous output, instead of dying by SIGXFSZ.
  std::signal(SIGXFSZ, SIG_IGN);
  if (argc < 2) {
    std::fputs(k_usage, stderr);
    return 2;
  }
  std::string cmd = argv[1];
  if (cmd == "--help" || cmd == "-h" || cmd == "help") {
    std::fputs(k_usage, stdout);
    return 0;
  }
  if (cmd == "--version") {
    std::printf("avatarmap %s\n", AVATARMAP_VERSION_STRING);
    return 0;
  }
  // Every library call reports through a status; an exception reaching here is either memory
  // running out (an input too large for this machine) or a defect. Either way the stack
  // unwinds, so outputs being written are discarded and the previous files stay as they were.
  try {
    if (const int code = dispatch(cmd, argc, argv); code >= 0) return code;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr,
                 "avatarmap %s: out of memory (the input is too large for this machine; split it "
                 "into shorter files)\n",
                 cmd.c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "avatarmap %s: internal error (%s); please report it with the input\n",
                 cmd.c_str(), e.what());
    return 1;
  }
  std::fprintf(stderr, "avatarmap: unknown command '%s'\n\n%s", cmd.c_str(), k_usage);
  return 2;
}
