// `avatarmap capture INPUT -o OUT.landmarks.jsonl`: video, image, image sequence, device or
// network stream in, landmarks out, through the ONNX backend (body, hands, face), with an
// optional overlay.
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/capture/video_source.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "cli/capture_setup.hpp"
#include "cli/cli_args.hpp"
#include "cli/commands.hpp"
#include "cli/overlay_output.hpp"
#include "jobs/prefetch_ring.hpp"

namespace avatarmap::cli {
namespace {

const char* k_capture_help =
    "Usage: avatarmap capture INPUT -o OUT.landmarks.jsonl [options]\n"
    "\n"
    "Estimates landmarks on every frame of INPUT (a video file, an image, a folder of images,\n"
    "a printf pattern like frames/%05d.png, a device or a network stream: see below) with\n"
    "MediaPipe's models run by ONNX Runtime, and writes them as *.landmarks.jsonl\n"
    "(docs/file-formats.md): the body (33 points, image + world) and, when asked, both hands\n"
    "and the face mesh. Video is tracked (detectors run only when a part is lost) and\n"
    "smoothed as MediaPipe does; --static treats every frame on its own. A device or stream\n"
    "is read until it ends, stalls (--stall-seconds) or --seconds have passed; what was\n"
    "captured is written.\n"
    "\n"
    "Options:\n"
    "  -o, --output PATH     where to write the landmarks (required; written atomically)\n"
    "  --overlay PATH        also draw the landmarks on the frames: PATH.mp4/.mkv/.avi writes\n"
    "                        a video, PATH.png one image (the first frame) and a pattern like\n"
    "                        overlay_%05d.png one image per frame\n"
    "  --loop N              run over INPUT N times (times keep increasing; for soak tests;\n"
    "                        files only)\n"
    "  --seconds S           stop after S seconds of input (frame times)\n"
    "  --progress / --quiet  force / silence the progress line (default: on a terminal)\n"
    "\n";
const char* k_capture_estimator_help = "Estimator options:\n";

}  // namespace

// Priority of the decoding thread of a file capture (see decode below).
constexpr int k_decoder_nice = 10;

int run_capture(int argc, char** argv) {
  args a(argc, argv, 2);
  if (a.flag("--help") || a.flag("-h")) {
    std::fputs(k_capture_help, stdout);
    std::fputs(k_input_options_help, stdout);
    std::fputs(k_capture_estimator_help, stdout);
    std::fputs(k_estimator_options_help, stdout);
    return 0;
  }
  std::string out_path, overlay_path, error;
  a.value("--output", out_path, "-o");
  a.value("--overlay", overlay_path);
  double loops = 1, seconds = 0;
  a.number("--loop", loops);
  a.number("--seconds", seconds);
  bool progress = isatty(STDERR_FILENO);
  if (a.flag("--progress")) progress = true;
  const bool quiet = a.flag("--quiet");
  if (quiet) progress = false;
  estimator_options ec;
  video_source_options vo;
  if (!parse_estimator_options(a, false, ec, error) || !parse_input_options(a, vo, error)) {
    std::fprintf(stderr, "avatarmap capture: %s\n", error.c_str());
    return 2;
  }
  if (!a.error().empty() || !a.check_no_options() || a.rest().size() != 1 || out_path.empty()) {
    std::fprintf(stderr, "avatarmap capture: %s\n",
                 !a.error().empty()     ? a.error().c_str()
                 : a.rest().size() != 1 ? "give exactly one input (see --help)"
                                        : "give the output with -o OUT.landmarks.jsonl");
    return 2;
  }
  if (!(loops >= 1 && loops <= 1e6) || loops != static_cast<long>(loops)) {
    std::fprintf(stderr, "avatarmap capture: --loop wants a whole number >= 1\n");
    return 2;
  }
  if (!(seconds >= 0)) {
    std::fprintf(stderr, "avatarmap capture: --seconds must be >= 0\n");
    return 2;
  }
  const std::string input = a.rest()[0];

  video_source source;
  video_source_quiet_log(true);
  status st = source.open(input, vo);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
    return 1;
  }
  const bool live_input = source.info().kind == video_source_kind::camera ||
                          source.info().kind == video_source_kind::stream;
  if (live_input && loops > 1) {
    std::fprintf(stderr, "avatarmap capture: --loop is for files, not devices or streams\n");
    return 2;
  }
  std::unique_ptr<estimator> est;
  const auto startup_t0 = std::chrono::steady_clock::now();
  st = make_estimator(ec, est);
  const std::chrono::duration<double, std::milli> startup =
      std::chrono::steady_clock::now() - startup_t0;
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
    return 1;
  }
  const video_info info = source.info();
  overlay_output overlay;
  if (!overlay_path.empty()) {
    st = overlay.open(overlay_path, info.width, info.height, info.fps > 0 ? info.fps : 30.0);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap capture: --overlay: %s\n", st.message().c_str());
      return 1;
    }
  }
  landmark_writer writer;
  landmark_file_header h;
  h.present = true;
  h.image_width = info.width;
  h.image_height = info.height;
  h.fps = info.fps;
  st = writer.open(out_path, h);
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
    return 1;
  }

  // Frames are decoded on a second thread, a few ahead of the estimator (prefetch_ring):
  // decoding then overlaps inference. With --loop the decoder reopens the input and keeps
  // the clock running one frame period past the last frame.
  struct decoded {
    std::vector<std::uint8_t> pixels;
    image_view view{};
    double t = 0.0;
    read_result kind = read_result::end;
    std::string error;
  };
  const long passes = static_cast<long>(loops);
  long pass = 0;
  double t_offset = 0.0, t_last = 0.0;
  bool decoder_niced = false;
  auto decode = [&](decoded& d) {
    if (!decoder_niced) {
      // A file's decoder runs ahead (the ring holds a few frames): at a lower priority (nice
      // 10, this thread only) it takes the moments the two lanes wait for each other rather
      // than their time (docs/capture.md: +4 % / +7 % frames/s on the two videos). Not for a
      // device or stream, which must be read as it comes.
      decoder_niced = true;
      if (!live_input)
        setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), k_decoder_nice);
    }
    for (;;) {
      image_view v;
      double t = 0.0;
      d.kind = source.next(v, t);
      if (d.kind == read_result::end && ++pass < passes) {
        t_offset = t_last + (info.fps > 0 ? 1.0 / info.fps : 1.0 / 30.0);
        const status o = source.open(input, vo);
        if (o.ok()) continue;
        d.kind = read_result::error;
        d.error = o.message();
        return false;
      }
      if (d.kind == read_result::end) return false;
      if (d.kind == read_result::frame && seconds > 0 && t + t_offset >= seconds) {
        d.kind = read_result::end;
        return false;
      }
      if (d.kind == read_result::error) {
        d.error = source.error();
        return true;
      }
      const size_t row = static_cast<size_t>(v.width) * 3;
      if (d.pixels.size() < row * static_cast<size_t>(v.height))
        d.pixels.resize(row * static_cast<size_t>(v.height));
      for (int y = 0; y < v.height; ++y)
        std::memcpy(d.pixels.data() + row * y, v.data + static_cast<size_t>(v.stride_bytes) * y,
                    row);
      d.view = {d.pixels.data(), v.width, v.height, static_cast<int>(row), v.format};
      d.t = t + t_offset;
      t_last = d.t;
      return true;
    }
  };

  using clock_type = std::chrono::steady_clock;
  const auto t0 = clock_type::now();
  auto last = t0;
  long frames = 0, errors = 0, part_frames[k_frame_part_count] = {};
  long rss_warm = 0, rss_peak = 0;
  timing_totals timings;
  timings.startup_ms = startup.count();
  landmark_frame frame;
  estimate_args ea;
  ea.hands = ec.hands;
  ea.face = ec.face;
  jobs_detail::prefetch_ring<decoded> ring(3, decode);
  // A frame given back by the estimator: counted, written, drawn.
  auto emit = [&](const decoded& d) {
    frame.t = d.t;
    for (int p = 0; p < k_frame_part_count; ++p)
      part_frames[p] += frame.has(static_cast<frame_part>(p));
    if (const estimator_timings* et = est->last_timings()) timings.add(*et);
    status w = writer.write(frame);
    if (w.ok() && overlay.is_open()) w = overlay.write(d.view, frame);
    if (!w.ok()) return w;
    ++frames;
    if (frames == 100) rss_warm = resident_kib();
    if (frames % 100 == 0) rss_peak = std::max(rss_peak, resident_kib());
    if (progress) {
      const auto now = clock_type::now();
      if (std::chrono::duration<double>(now - last).count() > 0.5) {
        last = now;
        const double el = std::chrono::duration<double>(now - t0).count();
        const double total = static_cast<double>(info.frame_count) * loops;
        if (total > 0)
          std::fprintf(stderr, "\rcapture: %ld/%.0f frames (%.0f%%), %.1f frames/s   ", frames,
                       total, 100.0 * frames / total, frames / el);
        else
          std::fprintf(stderr, "\rcapture: %ld frames, %.1f frames/s   ", frames, frames / el);
        std::fflush(stderr);
      }
    }
    return status{};
  };
  // Frames go through estimate_pipelined(): with two lanes the estimator gives a frame back
  // one call later (its body ran beside the previous frame's hands and face), so the decoded
  // frame in flight is held in the ring until then.
  const bool delayed = est->pipeline_delay() > 0;
  const decoded* in_flight = nullptr;
  bool ready = false;
  for (;;) {
    decoded& d = ring.next();
    if (d.kind != read_result::frame && in_flight) {  // end or a broken frame: drain first
      st = est->estimate_pipelined(nullptr, frame, ready);
      if (st.ok() && ready) st = emit(*in_flight);
      if (!st.ok()) {
        std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
        return 1;
      }
      ring.release();
      in_flight = nullptr;
    }
    if (d.kind == read_result::end) break;
    if (d.kind == read_result::error) {
      ++errors;
      std::fprintf(stderr, "warning: %s\n", d.error.c_str());
      ring.release();
      continue;
    }
    ea.image = d.view;
    ea.t = d.t;
    st = est->estimate_pipelined(&ea, frame, ready);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap capture: frame at %.3f s: %s\n", ea.t, st.message().c_str());
      return 1;
    }
    if (ready) st = emit(in_flight ? *in_flight : d);
    if (!st.ok()) {
      std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
      return 1;
    }
    if (!delayed) {
      ring.release();
    } else {
      if (in_flight) ring.release();
      in_flight = &d;
    }
  }
  if (!source.end_reason().empty())  // a device or stream that stalled or ended
    std::fprintf(stderr, "%scapture: %s\n", progress ? "\n" : "", source.end_reason().c_str());
  st = writer.commit();
  if (st.ok() && overlay.is_open()) st = overlay.close();
  if (!st.ok()) {
    std::fprintf(stderr, "avatarmap capture: %s\n", st.message().c_str());
    return 1;
  }
  const double el = std::chrono::duration<double>(clock_type::now() - t0).count();
  if (progress) std::fputs("\r", stderr);
  if (quiet) return 0;
  std::fprintf(stderr, "captured %ld frames (%dx%d, %s) in %.2f s: %.1f frames/s end to end%s\n",
               frames, info.width, info.height, info.codec.c_str(), el, frames / (el > 0 ? el : 1),
               errors ? (", " + std::to_string(errors) + " frames not decoded").c_str() : "");
  std::fprintf(stderr, "found: body in %ld frames", part_frames[0]);
  if (ea.hands)
    std::fprintf(stderr, ", left hand %ld, right hand %ld",
                 part_frames[static_cast<int>(frame_part::left_hand)],
                 part_frames[static_cast<int>(frame_part::right_hand)]);
  if (ea.face) std::fprintf(stderr, ", face %ld", part_frames[static_cast<int>(frame_part::face)]);
  std::fputc('\n', stderr);
  if (const std::string d = est->describe(); !d.empty()) std::fprintf(stderr, "%s\n", d.c_str());
  timings.print(stderr);
  if (rss_warm > 0) {
    rss_peak = std::max(rss_peak, resident_kib());
    std::fprintf(stderr, "memory: %.1f MiB resident after 100 frames, %.1f MiB at most after\n",
                 rss_warm / 1024.0, rss_peak / 1024.0);
  }
  std::fprintf(stderr, "wrote %s\n", out_path.c_str());
  if (!overlay_path.empty()) std::fprintf(stderr, "wrote %s\n", overlay_path.c_str());
  return 0;
}

}  // namespace avatarmap::cli
