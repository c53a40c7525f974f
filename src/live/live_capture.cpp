#include "avatarmap/live/live_capture.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <thread>

namespace avatarmap {

status feed_live_session(const frame_grabber& grab, live_session& session,
                         const live_feed_options& options, live_feed_stats& stats) {
  using clock_type = std::chrono::steady_clock;
  stats = {};
  if (!grab) return status::error("feed_live_session: a grabber is required");
  if (!(options.max_seconds >= 0.0))
    return status::error("feed_live_session: max_seconds must be >= 0");

  std::atomic<bool> stop{false};
  std::atomic<bool> grabber_done{false};
  long grabbed = 0, read_errors = 0, refused = 0;
  bool source_ended = false;
  std::exception_ptr failure;

  const auto t_start = clock_type::now();
  std::thread grabber([&] {
    try {
      bool first = true;
      double t0 = 0.0;
      clock_type::time_point w0;
      image_view v;
      double t = 0.0;
      while (!stop.load(std::memory_order_relaxed)) {
        const read_result r = grab(v, t);
        if (r == read_result::end) {
          source_ended = true;
          break;
        }
        if (r == read_result::error) {
          ++read_errors;
          continue;
        }
        if (options.pace_to_timestamps) {
          if (first) {
            t0 = t;
            w0 = clock_type::now();
          } else {
            const auto due = w0 + std::chrono::duration_cast<clock_type::duration>(
                                      std::chrono::duration<double>(std::max(0.0, t - t0)));
            // Sleep in slices so that a stop is noticed.
            while (!stop.load(std::memory_order_relaxed) && clock_type::now() < due)
              std::this_thread::sleep_for(std::min<clock_type::duration>(
                  due - clock_type::now(), std::chrono::milliseconds(20)));
          }
          first = false;
        }
        if (stop.load(std::memory_order_relaxed)) break;
        if (session.push(v, t).ok()) {
          ++grabbed;
        } else if (session.stopped()) {
          break;  // the session stopped by itself: the calling thread is waking up
        } else {
          ++refused;  // a bad image (or a time that is not finite): skipped
        }
      }
    } catch (...) {
      failure = std::current_exception();
    }
    // Set before finish(), so that the calling thread, woken by the session's stop, never
    // wakes a grabber that has returned.
    grabber_done.store(true);
    // The source ended (or failed): the session processes what is waiting, then stops.
    if (source_ended || failure) session.finish();
  });

  if (options.max_seconds > 0.0)
    session.wait_stopped_until(t_start + std::chrono::duration_cast<clock_type::duration>(
                                             std::chrono::duration<double>(options.max_seconds)));
  else
    session.wait_stopped();
  stop.store(true);
  std::exception_ptr wake_failure;
  if (!grabber_done.load() && options.wake_grabber) {
    try {
      options.wake_grabber();
    } catch (...) {
      wake_failure = std::current_exception();
    }
  }
  grabber.join();
  session.stop();
  if (failure) std::rethrow_exception(failure);
  if (wake_failure) std::rethrow_exception(wake_failure);

  stats.grabbed = grabbed;
  stats.read_errors = read_errors;
  stats.refused = refused;
  stats.source_ended = source_ended;
  stats.wall_seconds = std::chrono::duration<double>(clock_type::now() - t_start).count();
  return {};
}

}  // namespace avatarmap
