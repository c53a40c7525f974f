// Tests of live_capture.hpp: the grabber feeding a live session (the "replay" backend, so no
// models). A synthetic source delivers numbered frames; a slow worker (on_frame sleeps) must
// always get the newest frame, never an old one, every frame is either processed or counted
// as dropped, and the feed stops on the source's end, a time limit or the session's own
// stop, waking a grabber blocked in its source. Timings are not asserted.
#include "avatarmap/live/live_capture.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/live/live_session.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

// Frames of 4 x 2 RGB pixels (stride 17) whose first byte is the frame number (mod 256).
struct numbered_source {
  int count;
  double fps;
  int next = 0;
  int error_at = -1;
  std::vector<std::uint8_t> pixels = std::vector<std::uint8_t>(4 * 2 * 3 + 5);
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

// A session on the replay backend over a recording of `frames` frames (each processed image
// takes the recording's next frame; the session gives it the pushed time).
std::unique_ptr<live_session> make_session(const test::temp_dir& dir, int frames,
                                           live_session_options o = {}) {
  const std::string path = dir.file("take.landmarks.jsonl");
  landmark_synth synth;
  landmark_writer w;
  EXPECT_TRUE(w.open(path, {}).ok());
  landmark_frame f;
  for (int i = 0; i < frames; ++i) {
    synth.generate(demo_motion_pose(i / 30.0, synth.skeleton()), f);
    f.t = i / 30.0;
    EXPECT_TRUE(w.write(f).ok());
  }
  EXPECT_TRUE(w.commit().ok());
  o.pipeline.backend = "replay";
  o.pipeline.estimator.source = path;
  std::unique_ptr<live_session> s;
  const status st = live_session::create(o, s);
  EXPECT_TRUE(st.ok()) << st.message();
  return s;
}

TEST(live_capture, a_slow_worker_gets_the_newest_frames_and_drops_are_counted) {
  test::temp_dir dir("live_feed_slow");
  std::vector<long> seen;
  seen.reserve(100);
  live_session_options so;
  so.on_frame = [&](const live_frame_report& r) {
    EXPECT_EQ(r.error, nullptr);
    EXPECT_DOUBLE_EQ(r.t, r.index / 200.0) << "the report is the pushed frame's";
    EXPECT_DOUBLE_EQ(r.pose->t, r.t);
    seen.push_back(r.index);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return true;
  };
  std::unique_ptr<live_session> session = make_session(dir, 80, so);
  ASSERT_NE(session, nullptr);
  numbered_source src{60, 200.0};  // 0.3 s of frames at 200 fps
  live_feed_options o;
  live_feed_stats f;
  const status st = feed_live_session(std::ref(src), *session, o, f);
  ASSERT_TRUE(st.ok()) << st.message();
  const live_session_stats s = session->stats();
  EXPECT_TRUE(f.source_ended);
  EXPECT_EQ(f.grabbed, 60);
  EXPECT_EQ(s.pushed, 60);
  EXPECT_EQ(s.processed, static_cast<long>(seen.size()));
  EXPECT_EQ(s.processed + s.dropped, s.pushed);
  EXPECT_GT(s.dropped, 0) << "a 20 ms worker cannot keep up with 200 fps";
  for (size_t i = 1; i < seen.size(); ++i) EXPECT_GT(seen[i], seen[i - 1]);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 59) << "at the source's end the last frame is always processed";
  EXPECT_GT(s.latency_max_ms, 0.0);
  EXPECT_LE(s.latency_p50_ms, s.latency_p95_ms);
  EXPECT_LE(s.latency_p95_ms, s.latency_max_ms);
  EXPECT_TRUE(session->stopped());
  EXPECT_FALSE(session->push(image_view{src.pixels.data(), 4, 2, 17, pixel_format::rgb8}, 9.0).ok())
      << "a stopped session takes no more frames";
}

TEST(live_capture, read_errors_are_skipped_and_counted) {
  test::temp_dir dir("live_feed_errors");
  double last_t = -1;
  live_session_options so;
  so.on_frame = [&](const live_frame_report& r) {
    last_t = r.t;
    return true;
  };
  std::unique_ptr<live_session> session = make_session(dir, 20, so);
  ASSERT_NE(session, nullptr);
  numbered_source src{10, 1000.0};
  src.error_at = 3;
  live_feed_options o;
  o.pace_to_timestamps = false;
  live_feed_stats f;
  ASSERT_TRUE(feed_live_session(std::ref(src), *session, o, f).ok());
  EXPECT_EQ(f.read_errors, 1);
  EXPECT_EQ(f.grabbed, 9);
  const live_session_stats s = session->stats();
  EXPECT_EQ(s.processed + s.dropped, 9);
  EXPECT_DOUBLE_EQ(last_t, 9 / 1000.0) << "frame 3 is missing, frame 9 the last";
}

TEST(live_capture, the_session_and_a_time_limit_stop_an_endless_source) {
  test::temp_dir dir("live_feed_stop");
  live_session_options so;
  so.on_frame = [](const live_frame_report& r) { return r.index < 5; };
  std::unique_ptr<live_session> session = make_session(dir, 80, so);
  ASSERT_NE(session, nullptr);
  numbered_source endless{-1, 1000.0};
  live_feed_options o;
  o.pace_to_timestamps = false;
  live_feed_stats f;
  ASSERT_TRUE(feed_live_session(std::ref(endless), *session, o, f).ok());
  EXPECT_FALSE(f.source_ended);
  EXPECT_GE(session->stats().processed, 1);

  std::unique_ptr<live_session> session2 = make_session(dir, 80);
  ASSERT_NE(session2, nullptr);
  numbered_source endless2{-1, 100.0};
  o.pace_to_timestamps = true;
  o.max_seconds = 0.2;
  ASSERT_TRUE(feed_live_session(std::ref(endless2), *session2, o, f).ok());
  EXPECT_GE(session2->stats().processed, 1);
  EXPECT_LT(f.grabbed, 1000) << "paced at 100 fps, 0.2 s cannot push 1000 frames";
  EXPECT_FALSE(f.source_ended);
}

// A grabber blocked in a read (a stalled stream) is woken by wake_grabber when the feed stops
// for its own reasons; a source that ended is not woken.
TEST(live_capture, wake_grabber_unblocks_a_blocked_source) {
  test::temp_dir dir("live_feed_wake");
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
  live_feed_options o;
  o.pace_to_timestamps = false;
  o.max_seconds = 0.2;
  o.wake_grabber = [&] {
    std::lock_guard<std::mutex> lock(m);
    woken = true;
    ++wakes;
    cv.notify_all();
  };
  std::unique_ptr<live_session> session = make_session(dir, 10);
  ASSERT_NE(session, nullptr);
  live_feed_stats f;
  ASSERT_TRUE(feed_live_session(blocking, *session, o, f).ok());
  EXPECT_EQ(wakes, 1);
  EXPECT_EQ(session->stats().processed, 1);

  std::unique_ptr<live_session> session2 = make_session(dir, 10);
  ASSERT_NE(session2, nullptr);
  numbered_source ending{3, 1000.0};
  wakes = 0;
  o.max_seconds = 0;
  ASSERT_TRUE(feed_live_session(std::ref(ending), *session2, o, f).ok());
  EXPECT_EQ(wakes, 0) << "the source ended by itself";
  EXPECT_EQ(f.grabbed, 3);
  EXPECT_TRUE(f.source_ended);
}

TEST(live_capture, rejects_bad_options) {
  test::temp_dir dir("live_feed_bad");
  std::unique_ptr<live_session> session = make_session(dir, 2);
  ASSERT_NE(session, nullptr);
  live_feed_stats f;
  EXPECT_FALSE(feed_live_session(frame_grabber{}, *session, live_feed_options{}, f).ok());
  numbered_source src{1, 30.0};
  live_feed_options o;
  o.max_seconds = -1;
  EXPECT_FALSE(feed_live_session(std::ref(src), *session, o, f).ok());
}

}  // namespace
}  // namespace avatarmap
