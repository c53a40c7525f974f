// capture_pipeline (image -> landmarks -> pose -> live filter) and live_session (push from one
// thread, a worker on the newest image, sample from any, outputs on the session's clock),
// driven by the "replay" backend so that no models are needed: the pipeline must give exactly
// what the solver and the filter give on the same landmarks, and the session must process,
// drop, stop and report as documented.
#include "avatarmap/live/live_session.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/io/landmark_file.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "avatarmap/time/pose_filter.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

constexpr int k_frames = 40;
constexpr double k_fps = 30.0;

// A recording of the scripted demo motion with a little noise (so the filter works).
std::string write_recording(const test::temp_dir& dir) {
  const std::string path = dir.file("take.landmarks.jsonl");
  synth_options o;
  o.body_noise_sigma = o.hand_noise_sigma = o.face_noise_sigma = 0.002f;
  landmark_synth synth(o);
  landmark_writer w;
  EXPECT_TRUE(w.open(path, {}).ok());
  landmark_frame f;
  for (int i = 0; i < k_frames; ++i) {
    const double t = 2.0 + i / k_fps;
    synth.generate(demo_motion_pose(t, synth.skeleton()), f);
    f.t = t;
    EXPECT_TRUE(w.write(f).ok());
  }
  EXPECT_TRUE(w.commit().ok());
  return path;
}

capture_pipeline_options replay_options(const std::string& path) {
  capture_pipeline_options o;
  o.backend = "replay";
  o.estimator.source = path;
  o.estimator.hands = o.estimator.face = true;
  return o;
}

float degrees(const glm::quat& a, const glm::quat& b) { return angle_between(a, b) * 180.f / k_pi; }

TEST(check_image, names_what_is_wrong) {
  std::vector<std::uint8_t> px(64 * 48 * 4);
  const image_view good{px.data(), 64, 48, 64 * 3, pixel_format::rgb8};
  EXPECT_TRUE(check_image(good).ok());
  auto message = [](image_view v) { return check_image(v).message(); };
  image_view v = good;
  v.data = nullptr;
  EXPECT_NE(message(v).find("no pixels"), std::string::npos);
  v = good;
  v.width = 0;
  EXPECT_NE(message(v).find("width and height"), std::string::npos);
  v = good;
  v.height = k_max_image_side + 1;
  EXPECT_NE(message(v).find("16384"), std::string::npos);
  v = good;
  v.stride_bytes = 64 * 3 - 1;
  EXPECT_NE(message(v).find("stride_bytes (191) must be at least width x 3 = 192"),
            std::string::npos)
      << message(v);
  v = good;
  v.format = pixel_format::rgba8;  // now 4 bytes a pixel: the stride is short
  EXPECT_FALSE(check_image(v).ok());
  v.format = static_cast<pixel_format>(77);
  EXPECT_NE(message(v).find("unknown pixel format"), std::string::npos);
}

TEST(capture_pipeline, gives_what_the_solver_and_filter_give_on_the_same_landmarks) {
  test::temp_dir dir("capture_pipeline");
  const std::string path = write_recording(dir);
  std::unique_ptr<capture_pipeline> p;
  ASSERT_TRUE(capture_pipeline::create(replay_options(path), p).ok());

  landmark_reader reader;
  ASSERT_TRUE(reader.open(path).ok());
  frame_solver solver;
  pose_filter filter;
  landmark_frame want_frame, got_frame;
  proxy_pose want, got;
  for (int i = 0; i < k_frames; ++i) {
    ASSERT_EQ(reader.next(want_frame), read_result::frame);
    solver.solve(want_frame, want);
    filter.apply(want, want);
    const double t = 2.0 + i / k_fps;
    ASSERT_TRUE(p->process(image_view{}, t, got_frame, got).ok()) << i;
    EXPECT_DOUBLE_EQ(got.t, t);
    EXPECT_TRUE(got_frame.has(frame_part::pose));
    for (int b = 0; b < k_bone_count; ++b)
      ASSERT_LT(degrees(got.rotations[b], want.rotations[b]), 1e-4f)
          << "frame " << i << " bone " << b;
  }
  // Past the recording's end the replay backend fails: an error, not a crash.
  EXPECT_FALSE(p->process(image_view{}, 99.0, got_frame, got).ok());
  // A time that is not finite.
  EXPECT_FALSE(p->process(image_view{}, NAN, got_frame, got).ok());
}

TEST(capture_pipeline, refuses_an_unknown_backend_naming_the_built_ones) {
  capture_pipeline_options o;
  o.backend = "magic";
  std::unique_ptr<capture_pipeline> p;
  const status st = capture_pipeline::create(o, p);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("replay"), std::string::npos) << st.message();
  EXPECT_EQ(p, nullptr);
}

// Waits (up to 10 s) until the worker has dealt with every pushed image.
live_session_stats settle(const live_session& s) {
  live_session_stats st = s.stats();
  for (int i = 0; i < 1000 && st.processed + st.dropped + st.failed < st.pushed; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    st = s.stats();
  }
  return st;
}

TEST(live_session, processes_the_newest_image_and_samples_between_poses) {
  test::temp_dir dir("live_session");
  live_session_options o;
  o.pipeline = replay_options(write_recording(dir));
  std::unique_ptr<live_session> s;
  ASSERT_TRUE(live_session::create(o, s).ok());
  proxy_pose p;
  EXPECT_FALSE(s->sample(0.0, p));  // nothing processed yet
  EXPECT_FALSE(s->latest(p));

  std::vector<std::uint8_t> px(4 * 4 * 3, 128);
  const image_view img{px.data(), 4, 4, 12, pixel_format::rgb8};
  // One image at a time, each waited for: every one is processed, none dropped.
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(s->push(img, i / k_fps).ok());
    const live_session_stats st = settle(*s);
    EXPECT_EQ(st.processed, i + 1);
  }
  live_session_stats st = s->stats();
  EXPECT_EQ(st.pushed, 5);
  EXPECT_EQ(st.dropped, 0);
  EXPECT_EQ(st.failed, 0);
  EXPECT_DOUBLE_EQ(st.newest_t, 4 / k_fps);
  EXPECT_GT(st.latency_max_ms, 0.0);
  EXPECT_LE(st.latency_p50_ms, st.latency_p95_ms);
  ASSERT_TRUE(s->latest(p));
  EXPECT_DOUBLE_EQ(p.t, 4 / k_fps);
  // Between two processed poses: the slerp between them.
  proxy_pose a, b, mid;
  ASSERT_TRUE(s->sample(3 / k_fps, a));
  ASSERT_TRUE(s->sample(4 / k_fps, b));
  ASSERT_TRUE(s->sample(3.5 / k_fps, mid));
  EXPECT_DOUBLE_EQ(mid.t, 3.5 / k_fps);
  const int arm = idx(bone::left_lower_arm);
  const glm::quat half = slerp_shortest(a.rotations[arm], b.rotations[arm], 0.5f);
  EXPECT_LT(degrees(mid.rotations[arm], half), 0.01f);

  // Many at once: each image is processed or dropped (replaced while the worker was busy);
  // none is lost from the count, and the newest is always processed.
  for (int i = 5; i < 30; ++i) ASSERT_TRUE(s->push(img, i / k_fps).ok());
  st = settle(*s);
  EXPECT_EQ(st.processed + st.dropped + st.failed, st.pushed);
  EXPECT_EQ(st.pushed, 30);
  ASSERT_TRUE(s->latest(p));
  EXPECT_DOUBLE_EQ(p.t, 29 / k_fps);
}

TEST(live_session, bad_pushes_are_refused_and_worker_errors_counted) {
  test::temp_dir dir("live_session_bad");
  live_session_options o;
  o.pipeline = replay_options(write_recording(dir));
  std::unique_ptr<live_session> s;
  ASSERT_TRUE(live_session::create(o, s).ok());
  std::vector<std::uint8_t> px(4 * 4 * 3, 0);
  const image_view img{px.data(), 4, 4, 12, pixel_format::rgb8};
  EXPECT_FALSE(s->push(image_view{}, 0.0).ok());
  EXPECT_FALSE(s->push(img, INFINITY).ok());
  image_view short_stride = img;
  short_stride.stride_bytes = 5;
  EXPECT_FALSE(s->push(short_stride, 0.0).ok());
  EXPECT_EQ(s->stats().pushed, 0);
  // More images than the recording has, each waited for: the ones past its end fail in the
  // worker (counted, the message kept), and the session keeps running.
  for (int i = 0; i < k_frames + 3; ++i) {
    ASSERT_TRUE(s->push(img, i / k_fps).ok());
    settle(*s);
  }
  const live_session_stats st = s->stats();
  EXPECT_EQ(st.processed, k_frames);
  EXPECT_EQ(st.failed, 3);
  EXPECT_FALSE(s->last_error().ok());

  live_session_options bad = o;
  bad.latency_samples = 0;
  std::unique_ptr<live_session> none;
  EXPECT_FALSE(live_session::create(bad, none).ok());
  EXPECT_EQ(none, nullptr);
  bad = o;
  bad.output_fps = 1001.0;
  EXPECT_FALSE(live_session::create(bad, none).ok());
  bad = o;
  bad.pipeline.resampler.max_extrapolation_seconds = -1.0;
  EXPECT_FALSE(live_session::create(bad, none).ok());
}

// The outputs hang off the session: its output thread samples the stream at output_fps on
// the stream's clock (times always increasing), hands each pose to every output in order, and
// marks the first output after each processed frame (for the outputs' own latency).
TEST(live_session, outputs_run_on_the_sessions_clock) {
  test::temp_dir dir("live_session_outputs");
  live_session_options o;
  o.pipeline = replay_options(write_recording(dir));
  o.output_fps = 200.0;
  std::mutex m;
  std::vector<double> times;
  std::vector<int> order;
  long carried = 0;
  o.outputs.push_back([&](const proxy_pose& p, const live_output_report& r) {
    std::lock_guard<std::mutex> lock(m);
    times.push_back(p.t);
    order.push_back(0);
    if (r.carries_new_frame) {
      ++carried;
      EXPECT_LE(r.pushed_at, std::chrono::steady_clock::now());
    }
  });
  o.outputs.push_back([&](const proxy_pose&, const live_output_report&) {
    std::lock_guard<std::mutex> lock(m);
    order.push_back(1);
  });
  std::unique_ptr<live_session> s;
  ASSERT_TRUE(live_session::create(o, s).ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  {
    std::lock_guard<std::mutex> lock(m);
    EXPECT_TRUE(times.empty()) << "no output before the first pose";
  }
  std::vector<std::uint8_t> px(4 * 4 * 3, 0);
  const image_view img{px.data(), 4, 4, 12, pixel_format::rgb8};
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(s->push(img, 2.0 + i / k_fps).ok());
    settle(*s);
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
  }
  s->stop();
  const live_session_stats st = s->stats();
  std::lock_guard<std::mutex> lock(m);
  ASSERT_GE(times.size(), 5u) << "200 fps for ~0.2 s";
  EXPECT_EQ(static_cast<long>(times.size()), st.outputs);
  for (size_t i = 1; i < times.size(); ++i) EXPECT_GT(times[i], times[i - 1]);
  EXPECT_GE(times.front(), 2.0) << "the stream's clock starts at the first pose's time";
  for (size_t i = 0; i < order.size(); ++i) EXPECT_EQ(order[i], static_cast<int>(i % 2));
  EXPECT_GE(carried, 1);
  EXPECT_LE(carried, st.processed);
}

// finish() drains the waiting image then stops; on_frame returning false stops the worker;
// a stopped session refuses pushes and calls nothing after stop().
TEST(live_session, finish_drains_and_on_frame_stops) {
  test::temp_dir dir("live_session_stop");
  live_session_options o;
  o.pipeline = replay_options(write_recording(dir));
  std::atomic<int> frames{0};
  o.on_frame = [&](const live_frame_report& r) {
    EXPECT_EQ(r.error, nullptr);
    return ++frames < 3;
  };
  std::unique_ptr<live_session> s;
  ASSERT_TRUE(live_session::create(o, s).ok());
  std::vector<std::uint8_t> px(4 * 4 * 3, 0);
  const image_view img{px.data(), 4, 4, 12, pixel_format::rgb8};
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(s->push(img, i / k_fps).ok());
    settle(*s);
  }
  s->wait_stopped();
  EXPECT_TRUE(s->stopped());
  EXPECT_FALSE(s->push(img, 1.0).ok());
  EXPECT_EQ(frames.load(), 3);
  s->stop();
  s->stop();  // idempotent

  live_session_options d;
  d.pipeline = replay_options(write_recording(dir));
  std::unique_ptr<live_session> drained;
  ASSERT_TRUE(live_session::create(d, drained).ok());
  ASSERT_TRUE(drained->push(img, 0.0).ok());
  drained->finish();
  EXPECT_FALSE(drained->push(img, 0.1).ok()) << "finishing: no more images";
  drained->wait_stopped();
  const live_session_stats st = drained->stats();
  EXPECT_EQ(st.pushed, 1);
  EXPECT_EQ(st.processed, 1) << "the waiting image is processed before the stop";
  EXPECT_EQ(st.dropped, 0);
}

}  // namespace
}  // namespace avatarmap
