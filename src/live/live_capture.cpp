#include "avatarmap/live/live_capture.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <exception>
#include <mutex>
#include <thread>

namespace avatarmap {

namespace {

using clock_type = std::chrono::steady_clock;

// A frame copied out of the source's buffer, rows packed.
struct frame_slot {
  std::vector<std::uint8_t> pixels;
  image_view view{};
  double t = 0.0;
  long index = 0;
  clock_type::time_point published{};

  void copy_from(const image_view& v, double time, long i) {
    const int bpp = image_bytes_per_pixel(v.format);
    const size_t row = static_cast<size_t>(v.width) * bpp;
    const size_t need = row * static_cast<size_t>(v.height);
    if (pixels.size() < need) pixels.resize(need);  // first frame, or a larger one
    for (int y = 0; y < v.height; ++y)
      std::memcpy(pixels.data() + row * y, v.data + static_cast<size_t>(v.stride_bytes) * y, row);
    view = {pixels.data(), v.width, v.height, static_cast<int>(row), v.format};
    t = time;
    index = i;
  }
};

}  // namespace

status run_live(const frame_grabber& grab, const frame_consumer& consume,
                const live_options& options, live_stats& stats) {
  stats = {};
  if (options.latency_samples < 1) return status::error("run_live: latency_samples must be >= 1");
  if (!grab || !consume) return status::error("run_live: grabber and consumer are required");

  std::mutex m;
  std::condition_variable cv;
  frame_slot back, ready, work;  // grabber's, mailbox, consumer's
  bool has_ready = false;
  bool source_done = false;
  std::atomic<bool> stop{false};
  long grabbed = 0, dropped = 0, read_errors = 0;

  const auto t_start = clock_type::now();
  std::thread grabber([&] {
    bool first = true;
    double t0 = 0.0;
    clock_type::time_point w0;
    long index = 0;
    image_view v;
    double t = 0.0;
    while (!stop.load(std::memory_order_relaxed)) {
      const read_result r = grab(v, t);
      if (r == read_result::end) break;
      if (r == read_result::error) {
        ++read_errors;
        ++index;
        continue;
      }
      back.copy_from(v, t, index++);
      if (options.pace_to_timestamps) {
        if (first) {
          t0 = t;
          w0 = clock_type::now();
        } else {
          const auto due = w0 + std::chrono::duration_cast<clock_type::duration>(
                                    std::chrono::duration<double>(std::max(0.0, t - t0)));
          // Sleep in slices so that stop is noticed.
          while (!stop.load(std::memory_order_relaxed) && clock_type::now() < due)
            std::this_thread::sleep_for(std::min<clock_type::duration>(
                due - clock_type::now(), std::chrono::milliseconds(20)));
        }
        first = false;
      }
      back.published = clock_type::now();
      {
        std::lock_guard<std::mutex> lock(m);
        if (has_ready) ++dropped;
        std::swap(back, ready);
        has_ready = true;
        ++grabbed;
      }
      cv.notify_one();
    }
    {
      std::lock_guard<std::mutex> lock(m);
      source_done = true;
    }
    cv.notify_one();
  });

  std::vector<double> latencies(static_cast<size_t>(options.latency_samples));
  long samples = 0;
  double sum = 0.0, mx = 0.0;
  std::exception_ptr failure;
  try {
    for (;;) {
      long dropped_now = 0;
      {
        std::unique_lock<std::mutex> lock(m);
        const auto deadline =
            options.max_seconds > 0
                ? t_start + std::chrono::duration_cast<clock_type::duration>(
                                std::chrono::duration<double>(options.max_seconds))
                : clock_type::time_point::max();
        if (!cv.wait_until(lock, deadline, [&] { return has_ready || source_done; })) break;
        if (!has_ready) break;  // source done and nothing left
        std::swap(ready, work);
        has_ready = false;
        dropped_now = dropped;
      }
      live_frame_info info;
      info.index = work.index;
      info.t = work.t;
      info.dropped_so_far = dropped_now;
      info.age_ms =
          std::chrono::duration<double, std::milli>(clock_type::now() - work.published).count();
      const bool go_on = consume(work.view, info);
      const double lat =
          std::chrono::duration<double, std::milli>(clock_type::now() - work.published).count();
      latencies[static_cast<size_t>(samples % options.latency_samples)] = lat;
      ++samples;
      sum += lat;
      mx = std::max(mx, lat);
      if (!go_on) break;
      if (options.max_seconds > 0 &&
          std::chrono::duration<double>(clock_type::now() - t_start).count() >= options.max_seconds)
        break;
    }
  } catch (...) {
    failure = std::current_exception();
  }
  stop.store(true);
  bool source_ended = false;
  {
    std::lock_guard<std::mutex> lock(m);
    source_ended = source_done;
  }
  if (!source_ended && options.wake_grabber) {
    try {
      options.wake_grabber();
    } catch (...) {
      if (!failure) failure = std::current_exception();
    }
  }
  grabber.join();
  if (failure) std::rethrow_exception(failure);

  stats.grabbed = grabbed;
  stats.processed = samples;
  stats.dropped = dropped + (has_ready ? 1 : 0);  // a frame left in the mailbox is dropped too
  stats.read_errors = read_errors;
  stats.wall_seconds = std::chrono::duration<double>(clock_type::now() - t_start).count();
  if (samples > 0) {
    const size_t n = static_cast<size_t>(std::min<long>(samples, options.latency_samples));
    latencies.resize(n);
    std::sort(latencies.begin(), latencies.end());
    stats.latency_mean_ms = sum / static_cast<double>(samples);
    stats.latency_p50_ms = latencies[n / 2];
    stats.latency_p95_ms = latencies[std::min(n - 1, n * 95 / 100)];
    stats.latency_max_ms = mx;
  }
  return {};
}

}  // namespace avatarmap
