// `avatarmap live INPUT`: the latest-frame live loop (capture/live_capture.hpp). A camera, a
// network stream, or a file paced to its time stamps as a camera would deliver it (devices and
// URLs deliver at their own pace; docs/live.md); frames the estimator cannot
// keep up with are dropped. Each processed frame is solved, filtered by the live filter
// (pose_filter, unless --filter none) and pushed to the pose resampler; an output thread
// samples it at --fps (a higher rate than capture) into OUT.pose.jsonl and, with --vmc, to a
// VMC protocol receiver (cli/live_vmc.hpp).
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>

#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/live/live_capture.hpp"
#include "avatarmap/media/video_source.hpp"
#include "avatarmap/stream/pose_server.hpp"
#include "avatarmap/time/pose_resampler.hpp"
#include "cli/capture_setup.hpp"
#include "cli/commands.hpp"
#include "cli/live_vmc.hpp"
#include "cli/viewer_setup.hpp"

namespace avatarmap::cli {
namespace {

const char* k_live_help =
    "Usage: avatarmap live INPUT [-o OUT.pose.jsonl] [options]\n"
    "\n"
    "Runs the capture live: INPUT is a camera or other device (v4l2:/dev/video0), a network\n"
    "stream (udp://127.0.0.1:5000, rtsp://, srt://, http://, ...) or a file, which is then\n"
    "delivered at its own frame rate as a camera would. A device or stream that sends no frame\n"
    "for --stall-seconds, or ends, stops the loop with a message; -o is still written.\n"
    "Only the newest frame is processed; frames that arrive while the estimator is busy are\n"
    "dropped and counted. Each result is solved into a proxy pose, filtered and handed to\n"
    "the resampler, and the output runs at --fps from it (slerp between captured frames,\n"
    "short extrapolation past the newest). Prints capture rate, drops and latency (frame\n"
    "delivered -> pose ready).\n"
    "\n"
    "Options:\n"
    "  -o, --output PATH     write the resampled poses (*.pose.jsonl, atomically)\n"
    "  --fps N               output rate (default 60)\n"
    "  --filter live|none    live (default): the causal filter of `solve --filter live`\n"
    "                        (docs/smoothing.md; with the capture's own smoothing of the body\n"
    "                        points a bone turning at 3 rad/s trails by ~23 ms at 30 fps);\n"
    "                        none: the solver's poses as they are\n"
    "  --seconds S           stop after S seconds (default: when the input ends)\n"
    "  --unpaced             deliver file frames as fast as they decode (stress test)\n"
    "  --serve [HOST:]PORT   serve the browser viewer and stream the output poses to it, on\n"
    "                        the built-in avatar (docs/viewer.md; host default 127.0.0.1,\n"
    "                        port 0 picks one)\n"
    "  --quiet               no progress line and no summary\n"
    "\n";
const char* k_live_estimator_help = "Estimator options (hands and face off unless asked):\n";

}  // namespace

int run_live_command(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_live_help, stdout);
    std::fputs(k_input_options_help, stdout);
    std::fputs(k_live_estimator_help, stdout);
    std::fputs(k_estimator_options_help, stdout);
    std::fputs("\nVMC protocol output (docs/vmc.md):\n", stdout);
    std::fputs(k_live_vmc_help, stdout);
    return 0;
  }
  std::string out_path, error;
  a.value("--output", out_path, "-o");
  double out_fps = 60.0, seconds = 0.0;
  a.number("--fps", out_fps);
  a.number("--seconds", seconds);
  std::string filter_name = "live";
  a.value("--filter", filter_name);
  const bool unpaced = a.flag("--unpaced");
  std::string serve;
  a.value("--serve", serve);
  const bool quiet = a.flag("--quiet");
  const bool progress = !quiet && isatty(STDERR_FILENO);
  live_vmc vmc;
  if (const int rc = vmc.read_options(a)) return rc;
  estimator_options ec;
  video_source_options vo;
  if (!parse_estimator_options(a, false, ec, error) || !parse_input_options(a, vo, error)) {
    std::fprintf(stderr, "avatarmap live: %s\n", error.c_str());
    return 2;
  }
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() != 1) {
    std::fprintf(stderr, "avatarmap live: %s\n",
                 !a.error().empty() ? a.error().c_str() : "give exactly one input (see --help)");
    return 2;
  }
  if (filter_name != "live" && filter_name != "none") {
    std::fprintf(stderr, "avatarmap live: --filter is live or none, got '%s'\n",
                 filter_name.c_str());
    return 2;
  }
  if (!(out_fps > 0 && out_fps <= 1000) || !(seconds >= 0)) {
    std::fprintf(stderr, "avatarmap live: --fps must be in (0, 1000], --seconds >= 0\n");
    return 2;
  }
  pose_server_options serve_options = default_viewer_options("live", "--serve");
  if (!serve.empty() && !parse_host_port(serve, serve_options.host, serve_options.port, error)) {
    std::fprintf(stderr, "avatarmap live: --serve: %s\n", error.c_str());
    return 2;
  }
  // The viewer's server first: a port in use is reported before the models load.
  pose_server server;  // its own thread; publish() never waits for a page
  if (!serve.empty()) {
    if (quiet) serve_options.on_event = nullptr;
    if (status avatar_status = use_builtin_avatar(serve_options); !avatar_status)  // from memory
      std::fprintf(stderr, "live: the built-in avatar: %s\n", avatar_status.message().c_str());
    const status serve_status = server.start(serve_options);
    if (!serve_status.ok()) {
      std::fprintf(stderr, "avatarmap live: %s\n", serve_status.message().c_str());
      return 1;
    }
    std::fprintf(stderr, "live: viewer at %s (poses on %s)\n", server.url().c_str(),
                 k_pose_socket_path);
    print_exposure("live", server);
  }
  if (const int rc = vmc.open()) return rc;
  video_source source;
  video_source_quiet_log(true);
  status st = source.open(a.rest()[0], vo);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap live: %s\n", st.message().c_str());
    return 1;
  }
  // Each frame: landmarks -> proxy pose -> live filter, the library's capture pipeline (the C
  // API's estimator and live handles run the same).
  const video_info info = source.info();
  capture_pipeline_options po;
  po.estimator = ec;
  po.solver.image_width = static_cast<float>(info.width);
  po.solver.image_height = static_cast<float>(info.height);
  po.filter.enabled = filter_name == "live";
  std::unique_ptr<capture_pipeline> pipeline;
  st = make_capture_pipeline(po, pipeline);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap live: %s\n", st.message().c_str());
    return 1;
  }
  pose_writer writer;
  const bool writing = !out_path.empty();
  if (!out_path.empty()) {
    pose_file_header h;
    h.fps = out_fps;
    st = writer.open(out_path, h);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap live: %s\n", st.message().c_str());
      return 1;
    }
  }

  // Stream time: the capture clock of the newest processed frame, advanced by wall time.
  using clock_type = std::chrono::steady_clock;
  std::mutex m;
  pose_resampler resampler;
  bool have_pose = false;
  double stream_t = 0.0;                 // capture time of the newest pose
  clock_type::time_point stream_wall{};  // when it was pushed
  std::atomic<bool> done{false};
  // The output thread waits for its next period on this, so a stop is seen at once whatever
  // --fps is (a plain sleep of one period made `--fps 0.05 --seconds 2` last 20 s).
  std::mutex stop_m;
  std::condition_variable stop_cv;
  long written = 0;
  status write_status;
  std::thread output([&] {
    proxy_pose p;
    const auto period = std::chrono::duration_cast<clock_type::duration>(
        std::chrono::duration<double>(1.0 / out_fps));
    auto next = clock_type::now();
    double last_t = -INFINITY;  // output times always increase (processing time varies)
    while (!done.load()) {
      next += period;
      {
        std::unique_lock<std::mutex> lock(stop_m);
        if (stop_cv.wait_until(lock, next, [&] { return done.load(); })) break;
      }
      {
        std::lock_guard<std::mutex> lock(m);
        if (!have_pose) continue;
        const double t = std::max(
            last_t + 1e-6,
            stream_t + std::chrono::duration<double>(clock_type::now() - stream_wall).count());
        if (!resampler.sample(t, p)) continue;
        last_t = t;
        p.t = t;
        if (writing && write_status.ok()) write_status = writer.write(p);
        ++written;
        if (!serve.empty()) server.publish(p);
        vmc.pose_sampled();
      }
      vmc.send(p);  // outside the lock: never blocks, but need not hold up the capture side
    }
  });

  landmark_frame frame;
  proxy_pose pose;
  timing_totals timings;
  long with_body = 0;
  auto last_progress = clock_type::now();
  live_options lo;
  // Devices and live streams deliver at their own pace: pacing them would only add latency.
  // A stream with a duration is a file on a server (HTTP, HLS on demand): paced like a file.
  const video_source_kind kind = source.info().kind;
  const bool live_input = kind == video_source_kind::camera ||
                          (kind == video_source_kind::stream && source.info().duration <= 0);
  lo.pace_to_timestamps = !unpaced && !live_input;
  lo.wake_grabber = [&] { source.interrupt(); };
  lo.max_seconds = seconds;
  live_stats stats;
  status est_status;
  st = run_live([&](image_view& v, double& t) { return source.next(v, t); },
                [&](const image_view& img, const live_frame_info& info_) {
                  const auto arrived = clock_type::now() -
                                       std::chrono::duration_cast<clock_type::duration>(
                                           std::chrono::duration<double, std::milli>(info_.age_ms));
                  est_status = pipeline->process(img, info_.t, frame, pose);
                  if (!est_status.ok()) return false;
                  if (const estimator_timings* et = pipeline->last_timings()) timings.add(*et);
                  with_body += frame.has(frame_part::pose);
                  {
                    std::lock_guard<std::mutex> lock(m);
                    resampler.push(pose);
                    have_pose = true;
                    stream_t = pose.t;
                    stream_wall = clock_type::now();
                    vmc.frame_pushed(arrived);
                  }
                  if (progress) {
                    const auto now = clock_type::now();
                    if (std::chrono::duration<double>(now - last_progress).count() > 0.5) {
                      last_progress = now;
                      std::fprintf(stderr, "\rlive: t %.1f s, %ld dropped so far   ", info_.t,
                                   info_.dropped_so_far);
                      std::fflush(stderr);
                    }
                  }
                  return true;
                },
                lo, stats);
  {
    std::lock_guard<std::mutex> lock(stop_m);
    done.store(true);
  }
  stop_cv.notify_all();
  output.join();
  if (!source.end_reason().empty())  // a device or stream that stalled or ended
    std::fprintf(stderr, "%slive: %s\n", progress ? "\n" : "", source.end_reason().c_str());
  if (st.ok()) st = est_status;
  if (st.ok()) st = write_status;
  if (st.ok() && writing) st = writer.commit();
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap live: %s\n", st.message().c_str());
    return 1;
  }
  if (progress) std::fputs("\r", stderr);
  if (quiet) return 0;
  std::fprintf(stderr,
               "live: %ld frames delivered in %.2f s, %ld processed (%.1f/s), %ld dropped; body in "
               "%ld\n",
               stats.grabbed, stats.wall_seconds, stats.processed,
               stats.processed / (stats.wall_seconds > 0 ? stats.wall_seconds : 1.0), stats.dropped,
               with_body);
  std::fprintf(stderr,
               "latency (frame delivered -> pose ready): mean %.1f ms, median %.1f, p95 %.1f, "
               "max %.1f\n",
               stats.latency_mean_ms, stats.latency_p50_ms, stats.latency_p95_ms,
               stats.latency_max_ms);
  timings.print(stderr);
  std::fprintf(stderr, "output: %ld poses at %.0f fps%s%s\n", written, out_fps,
               out_path.empty() ? "" : " -> ", out_path.c_str());
  vmc.print_summary(stderr);
  return 0;
}

}  // namespace avatarmap::cli
