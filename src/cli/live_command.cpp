// `avatarmap live INPUT`: the library's live loop (live/live_session.hpp) fed by its grabber
// (live/live_capture.hpp). A camera, a network stream, or a file paced to its time stamps as
// a camera would deliver it (devices and URLs deliver at their own pace; docs/live.md) is
// pushed into the session; frames the estimator cannot keep up with are dropped. Each
// processed frame is solved, filtered by the live filter (pose_filter, unless --filter none)
// and handed to the stream's resampler; the session's output thread samples it at --fps (a
// higher rate than capture) into this command's outputs: OUT.pose.jsonl, the viewer (--serve)
// and a VMC protocol receiver (--vmc, cli/live_vmc.hpp). This file only translates the flags
// and prints.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/core/limits.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/jobs/people.hpp"
#include "avatarmap/live/live_capture.hpp"
#include "avatarmap/live/live_session.hpp"
#include "avatarmap/media/video_source.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "avatarmap/stream/pose_server.hpp"
#include "avatarmap/time/foot_contacts.hpp"
#include "cli/capture_setup.hpp"
#include "cli/commands.hpp"
#include "cli/live_vmc.hpp"
#include "cli/option_flags.hpp"
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
    "delivered -> pose ready). --people N follows up to N people, each solved on its own\n"
    "and sent to its own outputs: a file per person, the k-th --vmc for the person in\n"
    "slot k, one viewer avatar per person (docs/capture-people.md).\n"
    "\n"
    "Options:\n"
    "  -o, --output PATH     write the resampled poses (*.pose.jsonl, atomically); with\n"
    "                        --people N > 1 one PATH.pID.pose.jsonl per person (its id)\n"
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
    std::fputs(input_options_help().c_str(), stdout);
    std::fputs(k_live_estimator_help, stdout);
    std::fputs(estimator_options_help(false).c_str(), stdout);
    std::fputs("\nSolver (docs/solver.md, docs/contacts.md):\n", stdout);
    std::fputs(option_flags_help(k_solver_option_table, solver_options{}).c_str(), stdout);
    std::fputs(
        "  --no-foot-contacts    no foot contacts (foot_contact 0, the hips as solved)\n"
        "  --no-root-follow      contacts detected, the hips as solved\n",
        stdout);
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
  solver_options so;
  foot_contact_options contacts;
  contacts.enabled = !a.flag("--no-foot-contacts");
  contacts.root_follows_contacts = !a.flag("--no-root-follow");
  if (!parse_estimator_options(a, false, ec, error) || !parse_input_options(a, vo, error) ||
      !parse_option_flags(a, k_solver_option_table, so, error)) {
    std::fprintf(stderr, "avatarmap live: %s\n", error.c_str());
    return 2;
  }
  if (so.mirror) {
    std::fprintf(stderr,
                 "avatarmap live: --mirror is for landmark files; a mirrored camera preview is "
                 "--mirrored (the input is flipped before estimation)\n");
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
  if (!(out_fps > 0 && out_fps <= k_max_fps) || !(seconds >= 0)) {
    std::fprintf(stderr, "avatarmap live: --fps must be in (0, %s], --seconds >= 0\n",
                 limit_text(k_max_fps).c_str());
    return 2;
  }
  const bool several = ec.max_people > 1;
  if (several && out_path == "-") {
    std::fprintf(stderr,
                 "avatarmap live: -o -: several people cannot share standard output; give a "
                 "file (OUT.pose.jsonl: one OUT.pID.pose.jsonl per person)\n");
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
  // The live loop: landmarks -> proxy pose -> live filter -> resampler on the session's
  // worker (the C API's live handle runs the same), the outputs on its output thread.
  using clock_type = std::chrono::steady_clock;
  const video_info info = source.info();
  live_session_options lso;
  lso.pipeline.estimator = ec;
  lso.pipeline.solver = so;
  lso.pipeline.foot_contacts = contacts;
  lso.pipeline.solver.image_width = static_cast<float>(info.width);
  lso.pipeline.solver.image_height = static_cast<float>(info.height);
  lso.pipeline.filter.enabled = filter_name == "live";
  lso.latency_samples = 1 << 16;
  lso.output_fps = out_fps;
  // Worker thread: the estimator's timings, frames with a body, progress; an estimator error
  // stops the loop (reported below).
  timing_totals timings;
  long with_body = 0;
  status est_status;
  auto last_progress = clock_type::now();
  lso.on_frame = [&](const live_frame_report& r) {
    if (r.error != nullptr) {
      est_status = *r.error;
      return false;
    }
    if (r.timings != nullptr) timings.add(*r.timings);
    with_body += r.frame->has(frame_part::pose);
    if (progress) {
      const auto now = clock_type::now();
      if (std::chrono::duration<double>(now - last_progress).count() > 0.5) {
        last_progress = now;
        std::fprintf(stderr, "\rlive: t %.1f s, %ld dropped so far   ", r.t, r.dropped_so_far);
        std::fflush(stderr);
      }
    }
    return true;
  };
  // Output thread: the outputs, in order (each pose written, published, sent).
  pose_writer writer;
  const bool writing = !out_path.empty();
  // Several people: one file per person id (OUT.pID.pose.jsonl), opened when the id first
  // comes, all committed at the end.
  std::map<int, std::unique_ptr<pose_writer>> person_writers;
  pose_file_header out_header;
  out_header.fps = out_fps;
  status write_status;
  if (writing)
    lso.outputs.push_back([&](const proxy_pose& p, const live_output_report& r) {
      if (!write_status.ok()) return;
      if (!several) {
        write_status = writer.write(p);
        return;
      }
      std::unique_ptr<pose_writer>& w = person_writers[r.person];
      if (!w) {
        w = std::make_unique<pose_writer>();
        write_status = w->open(person_output_path(out_path, r.person), out_header);
        if (!write_status.ok()) return;
      }
      write_status = w->write(p);
    });
  if (!serve.empty())
    lso.outputs.push_back([&](const proxy_pose& p, const live_output_report& r) {
      server.publish(p, r.person, r.slot);
    });
  if (!serve.empty())
    lso.on_person_gone.push_back([&](int id, int slot) { server.clear(id, slot); });
  if (vmc.enabled())
    lso.outputs.push_back(
        [&](const proxy_pose& p, const live_output_report& r) { vmc.send(p, r); });
  std::unique_ptr<live_session> session;
  st = make_live_session(lso, session);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap live: %s\n", st.message().c_str());
    return 1;
  }
  // Opened before the first frame is pushed: no output runs before a pose exists.
  if (writing && !several) {
    st = writer.open(out_path, out_header);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap live: %s\n", st.message().c_str());
      return 1;
    }
  }

  live_feed_options fo;
  // Devices and live streams deliver at their own pace: pacing them would only add latency.
  // A stream with a duration is a file on a server (HTTP, HLS on demand): paced like a file.
  const video_source_kind kind = info.kind;
  const bool live_input = kind == video_source_kind::camera ||
                          (kind == video_source_kind::stream && info.duration <= 0);
  fo.pace_to_timestamps = !unpaced && !live_input;
  fo.wake_grabber = [&] { source.interrupt(); };
  fo.max_seconds = seconds;
  live_feed_stats feed;
  st = feed_live_session([&](image_view& v, double& t) { return source.next(v, t); }, *session, fo,
                         feed);
  // The session has stopped: its counts and latency are final.
  const live_session_stats stats = session->stats();
  if (!source.end_reason().empty())  // a device or stream that stalled or ended
    std::fprintf(stderr, "%slive: %s\n", progress ? "\n" : "", source.end_reason().c_str());
  if (st.ok()) st = est_status;
  if (st.ok()) st = write_status;
  if (st.ok() && writing && !several) st = writer.commit();
  for (auto& [id, w] : person_writers)
    if (st.ok()) st = w->commit();
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap live: %s\n", st.message().c_str());
    return 1;
  }
  if (progress) std::fputs("\r", stderr);
  if (quiet) return 0;
  std::fprintf(stderr,
               "live: %ld frames delivered in %.2f s, %ld processed (%.1f/s), %ld dropped; body in "
               "%ld\n",
               feed.grabbed, feed.wall_seconds, stats.processed,
               stats.processed / (feed.wall_seconds > 0 ? feed.wall_seconds : 1.0), stats.dropped,
               with_body);
  std::fprintf(stderr,
               "latency (frame delivered -> pose ready): mean %.1f ms, median %.1f, p95 %.1f, "
               "max %.1f\n",
               stats.latency_mean_ms, stats.latency_p50_ms, stats.latency_p95_ms,
               stats.latency_max_ms);
  timings.print(stderr);
  if (!several || !writing) {
    std::fprintf(stderr, "output: %ld poses at %.0f fps%s%s\n", stats.outputs, out_fps,
                 out_path.empty() ? "" : " -> ", out_path.c_str());
  } else {
    std::vector<int> ids;
    for (const auto& [id, w] : person_writers) ids.push_back(id);
    std::fprintf(stderr, "output: %ld ticks at %.0f fps -> %zu files (%s), people %s\n",
                 stats.outputs, out_fps, person_writers.size(),
                 person_output_path(out_path, ids.empty() ? 0 : ids.front()).c_str(),
                 person_id_list(ids).c_str());
  }
  vmc.print_summary(stderr);
  return 0;
}

}  // namespace avatarmap::cli
