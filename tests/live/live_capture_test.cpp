// Tests of live_capture.hpp: latest-frame-only processing. A synthetic source publishes
// numbered frames; a slow consumer must always get the newest frame, never an old one, and
// every frame is either processed or counted as dropped. Timings are not asserted.
#include "avatarmap/live/live_capture.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace avatarmap {
namespace {

// Frames of 4 x 2 RGB pixels whose first byte is the frame number (mod 256).
struct numbered_source {
  int count;
  double fps;
  int next = 0;
  int error_at = -1;
  std::vector<std::uint8_t> pixels = std::vector<std::uint8_t>(4 * 2 * 3 + 5);  // stride 17
  read_result operator()(image_view& out, double& t) {
    if (count >= 0 && next >= count) return read_result::end;
    const int i = next++;
    if (i == error_at) return read_result::error;
    pixels[0] = static_cast<std::uint8_t>(i);
    out = {pixels.data(), 4, 2, 17, pixel_format::rgb8};
    t = i / fps;
    return read_result::frame;
  }
};

TEST(live_capture, slow_consumer_gets_the_newest_frames_and_drops_are_counted) {
  numbered_source src{60, 200.0};  // 0.3 s of frames at 200 fps
  std::vector<long> seen;
  seen.reserve(100);
  live_options o;
  live_stats s;
  const status st = run_live(
      std::ref(src),
      [&](const image_view& img, const live_frame_info& info) {
        EXPECT_EQ(img.width, 4);
        EXPECT_EQ(img.stride_bytes, 12) << "rows are packed in the copy";
        EXPECT_EQ(img.data[0], static_cast<std::uint8_t>(info.index)) << "pixels match the index";
        EXPECT_DOUBLE_EQ(info.t, info.index / 200.0);
        seen.push_back(info.index);
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        return true;
      },
      o, s);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(s.grabbed, 60);
  EXPECT_EQ(s.processed, static_cast<long>(seen.size()));
  EXPECT_EQ(s.processed + s.dropped, s.grabbed);
  EXPECT_GT(s.dropped, 0) << "a 20 ms consumer cannot keep up with 200 fps";
  for (size_t i = 1; i < seen.size(); ++i) EXPECT_GT(seen[i], seen[i - 1]);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 59) << "the last frame is always processed";
  EXPECT_GT(s.latency_max_ms, 0.0);
  EXPECT_LE(s.latency_p50_ms, s.latency_p95_ms);
  EXPECT_LE(s.latency_p95_ms, s.latency_max_ms);
}

TEST(live_capture, read_errors_are_skipped_and_counted) {
  numbered_source src{10, 1000.0};
  src.error_at = 3;
  live_options o;
  o.pace_to_timestamps = false;
  live_stats s;
  long last = -1;
  ASSERT_TRUE(run_live(
                  std::ref(src),
                  [&](const image_view&, const live_frame_info& info) {
                    EXPECT_NE(info.index, 3);
                    last = info.index;
                    return true;
                  },
                  o, s)
                  .ok());
  EXPECT_EQ(s.read_errors, 1);
  EXPECT_EQ(s.grabbed, 9);
  EXPECT_EQ(s.processed + s.dropped, 9);
  EXPECT_EQ(last, 9);
}

TEST(live_capture, consumer_and_time_limit_stop_an_endless_source) {
  numbered_source endless{-1, 1000.0};
  live_options o;
  o.pace_to_timestamps = false;
  live_stats s;
  ASSERT_TRUE(run_live(
                  std::ref(endless),
                  [&](const image_view&, const live_frame_info& i) { return i.index < 5; }, o, s)
                  .ok());
  EXPECT_GE(s.processed, 1);
  numbered_source endless2{-1, 100.0};
  o.pace_to_timestamps = true;
  o.max_seconds = 0.2;
  ASSERT_TRUE(
      run_live(
          std::ref(endless2), [&](const image_view&, const live_frame_info&) { return true; }, o, s)
          .ok());
  EXPECT_GE(s.processed, 1);
  EXPECT_LT(s.grabbed, 1000) << "paced at 100 fps, 0.2 s cannot publish 1000 frames";
}

// A grabber blocked in a read (a stalled stream) is woken by wake_grabber when the loop stops
// for its own reasons; a source that ended is not woken.
TEST(live_capture, wake_grabber_unblocks_a_blocked_source) {
  std::mutex m;
  std::condition_variable cv;
  bool woken = false;
  int wakes = 0;
  int calls = 0;
  std::vector<std::uint8_t> px(4 * 2 * 3);
  // Frame 0 at once, then blocks until woken (an hour at most), then ends.
  auto blocking = [&](image_view& out, double& t) {
    if (calls++ == 0) {
      out = {px.data(), 4, 2, 12, pixel_format::rgb8};
      t = 0;
      return read_result::frame;
    }
    std::unique_lock<std::mutex> lock(m);
    cv.wait_for(lock, std::chrono::hours(1), [&] { return woken; });
    return read_result::end;
  };
  live_options o;
  o.pace_to_timestamps = false;
  o.max_seconds = 0.2;
  o.wake_grabber = [&] {
    std::lock_guard<std::mutex> lock(m);
    woken = true;
    ++wakes;
    cv.notify_all();
  };
  live_stats s;
  ASSERT_TRUE(run_live(
                  blocking, [](const image_view&, const live_frame_info&) { return true; }, o, s)
                  .ok());
  EXPECT_EQ(wakes, 1);
  EXPECT_EQ(s.processed, 1);

  numbered_source ending{3, 1000.0};
  wakes = 0;
  o.max_seconds = 0;
  ASSERT_TRUE(
      run_live(
          std::ref(ending), [](const image_view&, const live_frame_info&) { return true; }, o, s)
          .ok());
  EXPECT_EQ(wakes, 0) << "the source ended by itself";
  EXPECT_EQ(s.grabbed, 3);
}

TEST(live_capture, rejects_bad_options) {
  numbered_source src{1, 30.0};
  live_options o;
  o.latency_samples = 0;
  live_stats s;
  EXPECT_FALSE(
      run_live(
          std::ref(src), [](const image_view&, const live_frame_info&) { return true; }, o, s)
          .ok());
  EXPECT_FALSE(run_live(frame_grabber{}, frame_consumer{}, live_options{}, s).ok());
}

}  // namespace
}  // namespace avatarmap
