#include "avatarmap/capture/capture_file.hpp"

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/media/video_source.hpp"  // shown_input
#include "common/prefetch_ring.hpp"

namespace avatarmap {

namespace {

using clock_type = std::chrono::steady_clock;

double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

// Priority of a file's decoding thread: it runs ahead (the ring holds a few frames), so at a
// lower priority it takes the moments the two lanes wait for each other rather than their
// time (docs/capture.md: +4 % / +7 % frames/s on the two test videos). Not for a device or
// stream, which must be read as it comes.
constexpr int k_decoder_nice = 10;
// Frames decoded ahead of the estimator.
constexpr int k_decode_ahead = 3;
// How often progress is reported, seconds.
constexpr double k_progress_seconds = 0.5;
// Resident memory is sampled every this many frames.
constexpr long k_memory_sample_frames = 100;

void lower_this_thread_priority() {
#if defined(__linux__)
  setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), k_decoder_nice);
#endif
}

void add_timings(const estimator_timings& t, capture_file_summary& s) {
  s.timing_sum += t;
  s.pose_detector_frames += t.pose_detector_ms > 0;
  s.palm_frames += t.palm_detector_ms > 0;
  s.face_detector_frames += t.face_detector_ms > 0;
  ++s.timed_frames;
}

// A decoded frame in the ring: its own copy of the pixels (the source's are valid only until
// its next frame).
struct decoded {
  std::vector<std::uint8_t> pixels;
  image_view view{};
  double t = 0.0;
  read_result kind = read_result::end;
  std::string error;
};

}  // namespace

long resident_memory_kib() {
  std::ifstream f("/proc/self/status");
  std::string key;
  while (f >> key) {
    if (key == "VmRSS:") {
      long v = 0;
      f >> v;
      return v;
    }
    f.ignore(1 << 12, '\n');
  }
  return 0;
}

bool names_live_input(const std::string& input) {
  std::error_code ec;
  if (std::filesystem::exists(input, ec)) return false;
  if (input.rfind("file:", 0) == 0) return false;
  if (input.find("://") != std::string::npos) return true;
  const std::size_t colon = input.find(':');
  if (colon == std::string::npos || colon < 2) return false;
  for (std::size_t i = 0; i < colon; ++i) {
    const char c = input[i];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_'))
      return false;
  }
  return true;
}

status capture_file_job::validate() const {
  if (input.empty())
    return status::error("capture_file_job.input is empty: give a video or images");
  if (output.empty())
    return status::error("capture_file_job.output is empty: give a *.landmarks.jsonl path");
  if (!(loops >= 1 && loops <= 1000000))
    return status::error("capture_file_job.loops must be in [1, 1000000], got " +
                         std::to_string(loops));
  if (!(std::isfinite(seconds) && seconds >= 0.0))
    return status::error("capture_file_job.seconds must be finite and >= 0 (0 = all)");
  if (names_live_input(input)) {
    if (!allow_live_input)
      return status::error(shown_input(input) +
                           ": a device or stream; give a video file, an image, a folder of "
                           "images or a pattern (live input: avm_live or `avatarmap live`)");
    if (loops > 1) return status::error("loops is for files, not devices or streams");
  }
  return {};
}

status capture_file_job::run(capture_file_summary& s) const {
  s = capture_file_summary{};
  const auto run_t0 = clock_type::now();
  auto fail = [&](const status& st) {
    s.seconds = seconds_since(run_t0);
    return st;
  };
  if (status st = validate(); !st.ok()) return fail(st);

  video_source source;
  if (status st = source.open(input, video); !st.ok()) return fail(st);
  const video_info info = source.info();
  s.input = info;
  const bool live_input =
      info.kind == video_source_kind::camera || info.kind == video_source_kind::stream;
  if (live_input && !allow_live_input)
    return fail(status::invalid_argument(shown_input(input) +
                                         ": a device or stream; give a video file, an image, a "
                                         "folder of images or a pattern"));
  if (live_input && loops > 1)
    return fail(status::invalid_argument("loops is for files, not devices or streams"));

  std::unique_ptr<estimator> est;
  const auto startup_t0 = clock_type::now();
  status st =
      make_estimator ? make_estimator(options, est) : create_estimator("onnx", options, est);
  s.startup_ms = seconds_since(startup_t0) * 1000.0;
  if (!st.ok()) return fail(st);  // io (models missing), unsupported (backend not built)
  if (on_open) {
    st = on_open(info);
    if (!st.ok()) return fail(st);
  }
  landmark_writer writer;
  landmark_file_header h;
  h.present = true;
  h.image_width = info.width;
  h.image_height = info.height;
  h.fps = info.fps;
  // Several people: version 2 (each line carries its person); one person stays version 1,
  // byte for byte as before.
  const bool several = options.max_people > 1;
  if (several) h.version = 2;
  st = writer.open(output, h);
  if (!st.ok()) return fail(st);

  // Frames are decoded on a second thread, a few ahead of the estimator (prefetch_ring):
  // decoding then overlaps inference. With loops the decoder reopens the input and keeps the
  // clock running one frame period past the last frame.
  long pass = 0;
  double t_offset = 0.0, t_last = 0.0;
  bool decoder_started = false;
  auto decode = [&](decoded& d) {
    if (!decoder_started) {
      decoder_started = true;
      if (!live_input) lower_this_thread_priority();
    }
    for (;;) {
      image_view v;
      double t = 0.0;
      d.kind = source.next(v, t);
      if (d.kind == read_result::end && ++pass < loops) {
        t_offset = t_last + (info.fps > 0 ? 1.0 / info.fps : 1.0 / 30.0);
        const status o = source.open(input, video);
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
        std::memcpy(d.pixels.data() + row * static_cast<size_t>(y),
                    v.data + static_cast<size_t>(v.stride_bytes) * static_cast<size_t>(y), row);
      d.view = {d.pixels.data(), v.width, v.height, static_cast<int>(row), v.format};
      d.t = t + t_offset;
      t_last = d.t;
      return true;
    }
  };

  const auto t0 = clock_type::now();
  auto last_progress = t0;
  const long total = info.frame_count > 0 ? static_cast<long>(info.frame_count) * loops : 0;
  landmark_frame frame;
  estimate_args ea;
  ea.hands = options.hands;
  ea.face = options.face;
  jobs_detail::prefetch_ring<decoded> ring(k_decode_ahead, decode);
  // A frame given back by the estimator: counted, written, handed to the hook.
  // Ids seen (several people), as a bitset over the first ids; fixed size, no allocation.
  std::array<std::uint64_t, k_max_people> ids_seen{};
  landmark_frame person_frame;
  auto emit = [&](const decoded& d) {
    frame.t = d.t;
    if (const estimator_timings* et = est->last_timings()) add_timings(*et, s);
    status w;
    const estimator::people_view people = several ? est->last_people() : estimator::people_view{};
    if (people.count >= 0) {
      // One line per person in view (none when nobody is), ascending by id.
      for (int i = 0; i < people.count && w.ok(); ++i) {
        landmark_frame& pf = person_frame;
        pf = people.frames[i];
        pf.t = d.t;
        for (int p = 0; p < k_frame_part_count; ++p)
          s.part_frames[p] += pf.has(static_cast<frame_part>(p));
        const int id = pf.person;
        if (id >= 0 && id < k_max_people * 64) {
          std::uint64_t& word = ids_seen[static_cast<std::size_t>(id / 64)];
          const std::uint64_t bit = std::uint64_t{1} << (id % 64);
          s.people_ids += (word & bit) ? 0 : 1;
          word |= bit;
        } else {
          ++s.people_ids;
        }
        w = writer.write(pf);
      }
      s.person_lines += people.count;
      s.frames_with_people += people.count > 0;
    } else {
      for (int p = 0; p < k_frame_part_count; ++p)
        s.part_frames[p] += frame.has(static_cast<frame_part>(p));
      w = writer.write(frame);
    }
    if (w.ok() && on_frame) w = on_frame(d.view, frame, people);
    if (!w.ok()) return w;
    ++s.frames;
    if (s.frames == k_memory_sample_frames) s.resident_kib_after_100 = resident_memory_kib();
    if (s.frames % k_memory_sample_frames == 0)
      s.resident_kib_peak = std::max(s.resident_kib_peak, resident_memory_kib());
    if (progress) {
      const auto now = clock_type::now();
      if (std::chrono::duration<double>(now - last_progress).count() > k_progress_seconds) {
        last_progress = now;
        progress({s.frames, total, std::chrono::duration<double>(now - t0).count()});
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
      if (!st.ok()) return fail(st);
      if (ready) st = emit(*in_flight);
      if (!st.ok()) return fail(st);
      ring.release();
      in_flight = nullptr;
    }
    if (d.kind == read_result::end) break;
    if (d.kind == read_result::error) {
      ++s.frames_not_decoded;
      if (warning) warning(d.error);
      ring.release();
      continue;
    }
    ea.image = d.view;
    ea.t = d.t;
    st = est->estimate_pipelined(&ea, frame, ready);
    if (!st.ok()) {
      char at[48];
      std::snprintf(at, sizeof at, "frame at %.3f s: ", ea.t);
      return fail(st.prefixed(at));
    }
    if (ready) st = emit(in_flight ? *in_flight : d);
    if (!st.ok()) return fail(st);
    if (!delayed) {
      ring.release();
    } else {
      if (in_flight) ring.release();
      in_flight = &d;
    }
  }
  s.end_reason = source.end_reason();
  st = writer.commit();
  if (!st.ok()) return fail(st);
  if (on_finish) {
    st = on_finish();
    if (!st.ok()) return fail(st);
  }
  s.capture_seconds = seconds_since(t0);
  s.estimator_description = est->describe();
  if (s.resident_kib_after_100 > 0)
    s.resident_kib_peak = std::max(s.resident_kib_peak, resident_memory_kib());
  s.seconds = seconds_since(run_t0);
  return {};
}

}  // namespace avatarmap
