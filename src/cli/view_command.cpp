// `avatarmap view [FILE] [--avatar AVATAR.vrm] [--video VIDEO]`: serves the browser viewer
// (docs/viewer.md) with the avatar, and the page plays FILE itself with its controls (play/pause,
// timeline, speed, loop): a .vrma clip, a .glb's own animation (the .glb is the avatar), a
// *.pose.jsonl by its time stamps (also streamed over the server's WebSocket by a
// pose_file_player, for `view --connect` pages), a .bvh converted by the library to proxy poses
// and served from memory. --connect points the page at a `live --serve` server instead.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "avatarmap/export/vrma.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/jobs/clip_output.hpp"
#include "avatarmap/jobs/convert_file.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/stream/pose_file_player.hpp"
#include "avatarmap/stream/pose_server.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"
#include "cli/viewer_setup.hpp"
#include "common/file_extension.hpp"
#include "common/pose_text.hpp"

extern char** environ;

namespace avatarmap::cli {
namespace {

const char* k_view_help =
    "Usage: avatarmap view [FILE] [--avatar AVATAR.vrm] [--video VIDEO] [options]\n"
    "\n"
    "Serves the browser viewer: a page (three.js + three-vrm) that shows AVATAR.vrm playing\n"
    "FILE, with play/pause (Space), a timeline, speed and loop controls and an Open button\n"
    "(or drop a .vrm, .vrma, .glb or .pose.jsonl on the page), or posed by proxy poses sent\n"
    "over a WebSocket. Prints the page's URL on standard output; open it in a browser (with\n"
    "--host 0.0.0.0 it is this machine's loopback URL; the addresses other machines use\n"
    "follow on standard error). Runs until Ctrl-C (or --seconds).\n"
    "  FILE.pose.jsonl   played by the page at its own time stamps; also streamed in a loop\n"
    "                    over the WebSocket, as `avatarmap live --serve` streams live poses\n"
    "  FILE.vrma         played by the page (three-vrm-animation)\n"
    "  FILE.glb          the avatar with its animation (`avatarmap convert -o FILE.glb`),\n"
    "                    played by the page; no --avatar\n"
    "  FILE.bvh          converted to proxy poses (as `avatarmap convert FILE.bvh -o\n"
    "                    X.pose.jsonl` does) and played by the page\n"
    "  no FILE           the avatar in its rest pose, or the poses of --connect\n"
    "\n"
    "Options:\n"
    "  --avatar PATH         the VRM 0.x or 1.0 avatar to show (default: the built-in one,\n"
    "                        as `avatarmap avatar` writes it, served from memory)\n"
    "  --video PATH          a video (.mp4, .m4v, .webm, .ogv, .mov; the browser must decode\n"
    "                        it) shown beside the avatar, kept at the animation's time\n"
    "  --port P              port to serve on (default 8080; 0 picks a free one)\n"
    "  --host H              address to listen on (default 127.0.0.1: this machine only;\n"
    "                        0.0.0.0 shows the page, avatar and poses to the network, with a\n"
    "                        warning; requests must then name this machine: a loopback\n"
    "                        name, one of its addresses or its host name)\n"
    "  --allow-host N[,N...]\n"
    "                        further names (or addresses) requests may give as their Host\n"
    "                        beyond loopback, e.g. the machine's DNS name\n"
    "  --connect [HOST:]PORT\n"
    "                        the page takes its poses from `avatarmap live --serve PORT`\n"
    "                        (host default 127.0.0.1)\n"
    "  --open                open the page in the desktop's browser (xdg-open)\n"
    "  --seconds S           stop after S seconds\n"
    "  --quiet               no lines about pages connecting, leaving or refused (the\n"
    "                        warning about --host beyond loopback stays)\n"
    "\n"
    "The page's modules come from scripts/fetch_viewer_modules.sh (run by scripts/setup.sh);\n"
    "AVATARMAP_VIEWER_MODULES and AVATARMAP_VIEWER_PAGE override where they are looked for.\n";

volatile std::sig_atomic_t g_stop = 0;
void on_stop_signal(int) { g_stop = 1; }

// Opens `url` with xdg-open without waiting for the browser; false when it cannot be run.
bool open_in_browser(const std::string& url) {
  pid_t pid = 0;
  std::string program = "xdg-open";
  char* argv[] = {program.data(), const_cast<char*>(url.c_str()), nullptr};
  if (posix_spawnp(&pid, "xdg-open", nullptr, nullptr, argv, environ) != 0) return false;
  std::thread([pid] { waitpid(pid, nullptr, 0); }).detach();
  return true;
}

// True when `path` names a video the page can be given: its extension, any case.
bool video_file_name(const std::string& path) {
  for (const char* e : {".mp4", ".m4v", ".webm", ".ogv", ".mov"})
    if (path.size() > std::strlen(e) && jobs_detail::ends_with_nocase(path, e)) return true;
  return false;
}

// The clip's frames as *.pose.jsonl text (a header line, then one line per pose, written by the
// pose writer's formatter), for the page to fetch from memory.
status pose_lines(const motion_clip& motion, std::string& out) {
  out = "{\"format\":\"avatarmap.pose\",\"version\":1";
  if (motion.source_fps > 0) out += ",\"fps\":" + std::to_string(motion.source_fps);
  out += "}\n";
  std::vector<char> line(io_detail::k_pose_line_max + io_detail::k_shortest_float_room);
  for (const proxy_pose& pose : motion.frames) {
    io_detail::memory_text text(line.data(), io_detail::k_pose_line_max);
    if (!io_detail::put_pose_line(text, pose, pose_write_options{}))
      return status::error("a pose of the motion does not fit a pose line");
    out.append(text.data(), text.size());
  }
  return {};
}

}  // namespace

int run_view(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_view_help, stdout);
    return 0;
  }
  std::string avatar, host = "127.0.0.1", connect, allow_hosts, video;
  int port = 8080;
  double seconds = 0;
  a.value("--avatar", avatar);
  a.value("--video", video);
  a.value("--host", host);
  a.integer("--port", port, 0, 65535);
  a.value("--connect", connect);
  a.value("--allow-host", allow_hosts);
  a.number("--seconds", seconds);
  const bool open = a.flag("--open");
  const bool quiet = a.flag("--quiet");
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() > 1) {
    std::fprintf(stderr, "avatarmap view: %s\n",
                 !a.error().empty() ? a.error().c_str() : "give at most one FILE (see --help)");
    return 2;
  }
  if (!(seconds >= 0)) {
    std::fprintf(stderr, "avatarmap view: --seconds must be >= 0\n");
    return 2;
  }
  const std::string file = a.rest().empty() ? std::string() : a.rest()[0];
  // The file's kind by its extension, any case (as the clip writers read output names).
  const clip_format_info* kind = file.empty() ? nullptr : find_clip_format(file);
  const bool pose_file = kind != nullptr && kind->format == clip_format::pose_jsonl;
  const bool clip_file = kind != nullptr && kind->format == clip_format::vrma;
  const bool glb_file = kind != nullptr && kind->format == clip_format::glb;
  const bool bvh_file = kind != nullptr && kind->format == clip_format::bvh;
  if (!file.empty() && kind == nullptr) {
    std::fprintf(stderr,
                 "avatarmap view: %s: FILE must be a .pose.jsonl, .vrma, .glb (an avatar with its "
                 "animation) or .bvh; convert other motion with `avatarmap convert`\n",
                 file.c_str());
    return 2;
  }
  if (glb_file && !avatar.empty()) {
    std::fprintf(stderr,
                 "avatarmap view: %s is the avatar with its animation: give no --avatar with a "
                 ".glb\n",
                 file.c_str());
    return 2;
  }
  if (!video.empty() && !video_file_name(video)) {
    std::fprintf(stderr,
                 "avatarmap view: --video %s: give a .mp4, .m4v, .webm, .ogv or .mov file\n",
                 video.c_str());
    return 2;
  }
  pose_server_options o = default_viewer_options("view", "--port");
  if (quiet) o.on_event = nullptr;
  o.host = host;
  o.port = port;
  for (std::size_t start = 0; start < allow_hosts.size();) {
    std::size_t end = allow_hosts.find(',', start);
    if (end == std::string::npos) end = allow_hosts.size();
    if (end > start) o.allowed_hosts.push_back(allow_hosts.substr(start, end - start));
    start = end + 1;
  }
  if (!connect.empty()) {
    if (pose_file || bvh_file) {
      std::fprintf(stderr,
                   "avatarmap view: --connect and a %s are two sources of poses: give one\n",
                   pose_file ? ".pose.jsonl" : ".bvh");
      return 2;
    }
    std::string live_host = "127.0.0.1", error;
    int live_port = 0;
    if (!parse_host_port(connect, live_host, live_port, error) || live_port == 0) {
      std::fprintf(stderr, "avatarmap view: --connect: %s\n",
                   error.empty() ? "the port of a live server cannot be 0" : error.c_str());
      return 2;
    }
    const bool v6 = live_host.find(':') != std::string::npos;
    o.pose_socket_url = "ws://" + (v6 ? "[" + live_host + "]" : live_host) + ":" +
                        std::to_string(live_port) + k_pose_socket_path;
  }

  // Without --avatar: the built-in avatar (`avatarmap avatar`), served from memory (no file).
  // A given avatar and the clip are checked by the project's own readers (docs/security.md)
  // before a browser is given them.
  const bool builtin = avatar.empty() && !glb_file;
  if (glb_file) avatar = file;
  if (builtin) {
    if (status st = use_builtin_avatar(o); !st) {
      std::fprintf(stderr,
                   "avatarmap view: the built-in avatar: %s (--avatar FILE.vrm shows another)\n",
                   st.message().c_str());
      return 1;
    }
  } else {
    raw_rig rig;
    if (status st = load_avatar(avatar, rig); !st) {
      std::fprintf(stderr, "avatarmap view: %s\n", st.message().c_str());
      return 1;
    }
    if (rig.source != rig_source::vrm0 && rig.source != rig_source::vrm1) {
      std::fprintf(stderr,
                   "avatarmap view: %s is not a VRM avatar (no VRM humanoid): the viewer shows "
                   "VRM 0.x and 1.0 models (.vrm)\n",
                   avatar.c_str());
      return 1;
    }
    o.avatar_path = avatar;
    o.avatar_animated = glb_file;
  }
  pose_file_player player;
  std::size_t bvh_frames = 0;
  double bvh_seconds = 0;
  if (pose_file) {
    if (status st = player.open(file); !st) {
      std::fprintf(stderr, "avatarmap view: %s\n", st.message().c_str());
      return 1;
    }
    o.poses_path = file;
  } else if (bvh_file) {
    motion_clip motion;
    status st = read_motion(file, nullptr, motion);
    if (st && motion.frames.empty()) st = status::error(file + " holds no motion frames");
    if (st) st = pose_lines(motion, o.poses_data);
    if (!st) {
      std::fprintf(stderr,
                   "avatarmap view: %s (view plays .pose.jsonl, .vrma, .glb and the .bvh files "
                   "`avatarmap convert` reads)\n",
                   st.message().c_str());
      return 1;
    }
    bvh_frames = motion.frames.size();
    bvh_seconds = motion.frames.back().t - motion.frames.front().t;
    o.poses_name = file.substr(file.find_last_of('/') + 1);
  } else if (clip_file) {
    vrma_clip clip;
    if (status st = read_vrma(file, clip); !st) {
      std::fprintf(stderr, "avatarmap view: %s\n", st.message().c_str());
      return 1;
    }
    o.clip_path = file;
  }
  o.video_path = video;

  pose_server server;
  if (status st = server.start(o); !st) {
    std::fprintf(stderr, "avatarmap view: %s\n", st.message().c_str());
    return 1;
  }
  std::printf("%s\n", server.url().c_str());
  std::fflush(stdout);
  print_exposure("view", server);
  if (!quiet) {
    std::fprintf(stderr, "view: showing %s", builtin ? "the built-in avatar" : avatar.c_str());
    if (pose_file)
      std::fprintf(stderr,
                   ", the page plays %s (%ld poses, %.1f s), also streamed in a loop over the "
                   "WebSocket",
                   file.c_str(), player.frames(), player.duration());
    else if (bvh_file)
      std::fprintf(stderr, ", the page plays %s (%zu poses, %.1f s, converted to proxy poses)",
                   file.c_str(), bvh_frames, bvh_seconds);
    else if (clip_file || glb_file)
      std::fprintf(stderr, ", the page plays %s%s", file.c_str(), glb_file ? "'s animation" : "");
    if (!video.empty()) std::fprintf(stderr, " beside the video %s", video.c_str());
    if (!o.pose_socket_url.empty())
      std::fprintf(stderr, ", poses from %s", o.pose_socket_url.c_str());
    std::fprintf(stderr, "; %s\n", seconds > 0 ? "stops after --seconds" : "Ctrl-C stops");
  }
  if (pose_file) player.start([&server](const proxy_pose& p) { server.publish(p); });
  if (open && !open_in_browser(server.url()))
    std::fprintf(stderr, "view: could not run xdg-open; open %s yourself\n", server.url().c_str());

  g_stop = 0;
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  const auto start = std::chrono::steady_clock::now();
  status playing;
  while (!g_stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (seconds > 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= seconds)
      break;
    if (pose_file && !(playing = player.error()).ok()) break;
  }
  player.stop();
  const pose_server_stats stats = server.stats();
  server.stop();
  if (!playing.ok()) {
    std::fprintf(stderr, "avatarmap view: %s\n", playing.message().c_str());
    return 1;
  }
  if (!quiet) {
    std::fprintf(stderr, "view: %ld page connections, %ld poses sent", stats.connections,
                 stats.sent);
    if (stats.refused > 0)
      std::fprintf(stderr, ", %ld requests refused for their Host or Origin", stats.refused);
    if (stats.first_posed_frame_ms >= 0)
      std::fprintf(stderr, "; the last page drew its first posed frame %.0f ms after loading",
                   stats.first_posed_frame_ms);
    std::fputs("\n", stderr);
  }
  return 0;
}

}  // namespace avatarmap::cli
