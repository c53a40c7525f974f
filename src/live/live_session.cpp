#include "avatarmap/live/live_session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "avatarmap/landmarks/landmark_frame.hpp"

namespace avatarmap {

namespace {

using clock_type = std::chrono::steady_clock;

// An image copied out of the caller's memory, rows packed.
struct image_copy {
  std::vector<std::uint8_t> pixels;
  image_view view{};
  double t = 0.0;
  clock_type::time_point pushed{};

  void copy_from(const image_view& v, double time) {
    const size_t row = static_cast<size_t>(v.width) * image_bytes_per_pixel(v.format);
    const size_t need = row * static_cast<size_t>(v.height);
    if (pixels.size() < need) pixels.resize(need);  // the first image, or a larger one
    for (int y = 0; y < v.height; ++y)
      std::memcpy(pixels.data() + row * y, v.data + static_cast<size_t>(v.stride_bytes) * y, row);
    view = {pixels.data(), v.width, v.height, static_cast<int>(row), v.format};
    t = time;
    pushed = clock_type::now();
  }
  void swap(image_copy& o) noexcept {
    pixels.swap(o.pixels);
    std::swap(view, o.view);
    std::swap(t, o.t);
    std::swap(pushed, o.pushed);
  }
};

}  // namespace

struct live_session::impl {
  std::unique_ptr<capture_pipeline> pipeline;
  int latency_capacity = 1;

  // Images: `incoming` is the pushing thread's own (under `push_m`: pushes from several
  // threads are serialised); `waiting` is handed over under `m`; `work` is the worker's own.
  std::mutex push_m;
  image_copy incoming, waiting, work;
  std::mutex m;
  std::condition_variable cv;
  bool has_waiting = false;
  bool stop = false;
  long pushed = 0, dropped = 0;

  // Results, under `out_m`.
  mutable std::mutex out_m;
  pose_resampler resampler;
  proxy_pose newest;
  bool has_pose = false;
  long processed = 0, failed = 0;
  std::vector<double> latencies;  // a ring of latency_capacity samples
  long latency_count = 0;
  status error;

  // The worker's scratch.
  landmark_frame frame;
  proxy_pose pose;
  std::thread worker;

  void run() {
    for (;;) {
      {
        std::unique_lock<std::mutex> lock(m);
        cv.wait(lock, [&] { return stop || has_waiting; });
        if (stop) return;
        work.swap(waiting);
        has_waiting = false;
      }
      const status st = pipeline->process(work.view, work.t, frame, pose);
      const double ms =
          std::chrono::duration<double, std::milli>(clock_type::now() - work.pushed).count();
      std::lock_guard<std::mutex> lock(out_m);
      if (!st.ok()) {
        ++failed;
        error = st;
        continue;
      }
      resampler.push(pose);
      newest = pose;
      has_pose = true;
      ++processed;
      latencies[static_cast<size_t>(latency_count % latency_capacity)] = ms;
      ++latency_count;
    }
  }
};

live_session::live_session(std::unique_ptr<impl> p) : impl_(std::move(p)) {}

status live_session::create(const live_session_options& options,
                            std::unique_ptr<live_session>& out) {
  out.reset();
  if (options.latency_samples < 1)
    return status::error("live_session_options.latency_samples must be >= 1");
  if (!(options.resampler.max_extrapolation_seconds >= 0.0) ||
      !std::isfinite(options.resampler.max_extrapolation_seconds))
    return status::error(
        "live_session_options.resampler.max_extrapolation_seconds must be finite and >= 0");
  auto p = std::make_unique<impl>();
  if (status st = capture_pipeline::create(options.pipeline, p->pipeline); !st.ok()) return st;
  p->resampler = pose_resampler(options.resampler);
  p->latency_capacity = options.latency_samples;
  p->latencies.assign(static_cast<size_t>(options.latency_samples), 0.0);
  p->newest.set_rest();
  impl* raw = p.get();
  p->worker = std::thread([raw] { raw->run(); });
  out.reset(new live_session(std::move(p)));
  return {};
}

live_session::~live_session() {
  {
    std::lock_guard<std::mutex> lock(impl_->m);
    impl_->stop = true;
  }
  impl_->cv.notify_one();
  if (impl_->worker.joinable()) impl_->worker.join();
}

status live_session::push(const image_view& image, double t) {
  if (!std::isfinite(t)) return status::error("live_session::push: t must be finite");
  if (status st = check_image(image); !st.ok()) return st;
  impl& s = *impl_;
  std::lock_guard<std::mutex> push_lock(s.push_m);
  s.incoming.copy_from(image, t);
  {
    std::lock_guard<std::mutex> lock(s.m);
    if (s.has_waiting) ++s.dropped;
    s.waiting.swap(s.incoming);
    s.has_waiting = true;
    ++s.pushed;
  }
  s.cv.notify_one();
  return {};
}

bool live_session::sample(double t, proxy_pose& out) const {
  std::lock_guard<std::mutex> lock(impl_->out_m);
  if (!impl_->has_pose) return false;
  if (!impl_->resampler.sample(t, out)) return false;
  out.t = t;
  return true;
}

bool live_session::latest(proxy_pose& out) const {
  std::lock_guard<std::mutex> lock(impl_->out_m);
  if (!impl_->has_pose) return false;
  out = impl_->newest;
  return true;
}

live_session_stats live_session::stats() const {
  live_session_stats s;
  std::vector<double> kept;
  {
    std::lock_guard<std::mutex> lock(impl_->m);
    s.pushed = impl_->pushed;
    s.dropped = impl_->dropped;
  }
  {
    std::lock_guard<std::mutex> lock(impl_->out_m);
    s.processed = impl_->processed;
    s.failed = impl_->failed;
    s.newest_t = impl_->has_pose ? impl_->newest.t : 0.0;
    const long n = std::min<long>(impl_->latency_count, impl_->latency_capacity);
    kept.assign(impl_->latencies.begin(), impl_->latencies.begin() + n);
  }
  if (!kept.empty()) {
    std::sort(kept.begin(), kept.end());
    auto at = [&](double q) {
      return kept[std::min(kept.size() - 1, static_cast<size_t>(q * (kept.size() - 1) + 0.5))];
    };
    s.latency_p50_ms = at(0.5);
    s.latency_p95_ms = at(0.95);
    s.latency_max_ms = kept.back();
  }
  return s;
}

status live_session::last_error() const {
  std::lock_guard<std::mutex> lock(impl_->out_m);
  return impl_->error;
}

}  // namespace avatarmap
