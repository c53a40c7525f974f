// `avatarmap render ANIMATION -o OUT.mp4`: the animation rendered by the browser viewer in
// headless Chromium to a video (render_job, docs/render.md). Argument translation only.
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "avatarmap/media/video_source.hpp"
#include "avatarmap/render/render_job.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"

namespace avatarmap::cli {
namespace {

const char* k_render_help =
    "Usage: avatarmap render ANIMATION -o OUT.mp4 [options]\n"
    "\n"
    "Renders ANIMATION on an avatar to a video with the browser viewer's render mode in\n"
    "headless Chromium (Debian's chromium), so that it looks as `avatarmap view` shows it.\n"
    "Frame i is drawn at i / fps seconds (not the wall clock); the camera is framed on the\n"
    "motion. ANIMATION is:\n"
    "  FILE.pose.jsonl   proxy poses (avatarmap solve, convert -o X.pose.jsonl)\n"
    "  FILE.vrma         a VRM Animation (convert, animate)\n"
    "  FILE.bvh          motion capture, read as `convert` reads it\n"
    "  FILE.glb          an avatar with its animation (convert/animate -o X.glb): no --avatar\n"
    "\n"
    "Options:\n"
    "  -o, --output OUT  the video: .mp4, .mov or .mkv (H.264), written atomically\n"
    "  --avatar PATH     the VRM 0.x or 1.0 avatar (default: the built-in one)\n"
    "  --size WxH        video size in pixels (default 1280x720; with --video each half is\n"
    "                    W/2 x H)\n"
    "  --fps N           frames per second, 1..240 (default: a pose file's own rate, else 30)\n"
    "  --stills T1,T2,...\n"
    "                    also write the frames nearest these times (seconds) as PNGs:\n"
    "                    OUT's name without its extension + _t<seconds>.png\n"
    "  --video SOURCE    the source video on the left, the avatar on the right, matched by\n"
    "                    time\n"
    "  --landmarks L.landmarks.jsonl\n"
    "                    draw these landmarks on the source video (needs --video)\n"
    "  --framing body|face\n"
    "                    what the camera frames: the whole motion (default), or the head\n"
    "                    in close-up, as a webcam sees a face\n"
    "  --chromium PATH   the browser to run (default: chromium on the PATH)\n"
    "  --quiet           no progress line\n"
    "\n"
    "Needs chromium (sudo apt-get install chromium) and the viewer's modules\n"
    "(scripts/fetch_viewer_modules.sh). Ctrl-C stops it and leaves nothing behind.\n";

std::atomic<bool> g_cancel{false};
void on_stop_signal(int) { g_cancel.store(true); }

bool parse_size(const std::string& text, int& w, int& h) {
  char* end = nullptr;
  const long a = std::strtol(text.c_str(), &end, 10);
  if (end == text.c_str() || (*end != 'x' && *end != 'X')) return false;
  const char* second = end + 1;
  const long b = std::strtol(second, &end, 10);
  if (end == second || *end != '\0') return false;
  if (a < 1 || a > 100000 || b < 1 || b > 100000) return false;
  w = static_cast<int>(a);
  h = static_cast<int>(b);
  return true;
}

bool parse_times(const std::string& text, std::vector<double>& out) {
  for (std::size_t start = 0; start <= text.size();) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(start, end - start);
    char* stop = nullptr;
    const double v = std::strtod(item.c_str(), &stop);
    if (item.empty() || *stop != '\0') return false;
    out.push_back(v);
    start = end + 1;
  }
  return true;
}

// The job's messages start with "render: " (its own) or name a file (its readers').
std::string without_prefix(const std::string& message) {
  return message.rfind("render: ", 0) == 0 ? message.substr(8) : message;
}

}  // namespace

int run_render(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_render_help, stdout);
    return 0;
  }
  render_options o;
  std::string size, stills, framing;
  a.value("--output", o.output, "-o");
  a.value("--avatar", o.avatar);
  a.value("--size", size);
  a.number("--fps", o.fps);
  a.value("--stills", stills);
  a.value("--video", o.video);
  a.value("--landmarks", o.landmarks);
  a.value("--chromium", o.chromium);
  a.value("--framing", framing);
  const bool quiet = a.flag("--quiet");
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() != 1) {
    std::fprintf(
        stderr, "avatarmap render: %s\n",
        !a.error().empty() ? a.error().c_str() : "give one ANIMATION and -o OUT.mp4 (see --help)");
    return 2;
  }
  o.animation = a.rest()[0];
  if (!size.empty() && !parse_size(size, o.width, o.height)) {
    std::fprintf(stderr, "avatarmap render: --size: '%s' is not WxH (e.g. 1280x720)\n",
                 size.c_str());
    return 2;
  }
  if (framing == "face") {
    o.framing = render_options::framing_kind::face;
  } else if (!framing.empty() && framing != "body") {
    std::fprintf(stderr, "avatarmap render: --framing takes body or face, got '%s'\n",
                 framing.c_str());
    return 2;
  }
  if (!stills.empty() && !parse_times(stills, o.stills)) {
    std::fprintf(stderr, "avatarmap render: --stills: '%s' is not times in seconds T1,T2,...\n",
                 stills.c_str());
    return 2;
  }
  if (status st = o.validate(); !st) {
    std::fprintf(stderr, "avatarmap render: %s\n", without_prefix(st.message()).c_str());
    return 2;
  }
  video_source_quiet_log(true);  // FFmpeg's encoder notes; errors still reach the status
  g_cancel.store(false);
  o.cancel = &g_cancel;
  // Ctrl-C and kill stop the job, which stops the browser and removes what it wrote.
  auto old_int = std::signal(SIGINT, on_stop_signal);
  auto old_term = std::signal(SIGTERM, on_stop_signal);
  const bool tty = isatty(fileno(stderr));
  long last_shown = -1;
  render_summary summary;
  const status st = render_job(
      o,
      [&](const render_progress& p) {
        if (quiet) return;
        // On a terminal: one line rewritten; otherwise a line per 10 %.
        const long step = tty ? p.done : p.done * 10 / (p.total > 0 ? p.total : 1);
        if (step == last_shown && p.done != p.total) return;
        last_shown = step;
        std::fprintf(stderr, "%srender: frame %lld / %lld, %.1f frames/s%s", tty ? "\r" : "",
                     static_cast<long long>(p.done), static_cast<long long>(p.total),
                     p.frames_per_second, tty && p.done != p.total ? "" : "\n");
      },
      &summary);
  std::signal(SIGINT, old_int);
  std::signal(SIGTERM, old_term);
  if (!st) {
    if (tty && !quiet && last_shown >= 0) std::fputs("\n", stderr);
    std::fprintf(stderr, "avatarmap render: %s\n", without_prefix(st.message()).c_str());
    if (g_cancel.load()) std::raise(SIGINT);  // die by the signal, as other commands do
    return 1;
  }
  if (!quiet) {
    std::fprintf(stderr,
                 "render: wrote %s: %lld frames, %dx%d at %g fps (%s) in %.1f s (%.1f frames/s "
                 "rendering)\n",
                 o.output.c_str(), static_cast<long long>(summary.frames), summary.width,
                 summary.height, summary.fps, summary.encoder.c_str(), summary.seconds,
                 summary.render_seconds > 0 ? summary.frames / summary.render_seconds : 0.0);
    for (const std::string& still : summary.stills)
      std::fprintf(stderr, "render: wrote %s\n", still.c_str());
    std::fprintf(stderr, "render: the viewer's render-mode page for this camera: ?%s\n",
                 summary.viewer_query.c_str());
  }
  return 0;
}

}  // namespace avatarmap::cli
