// pose_stream: each filter mode gives exactly what its stages give when assembled by hand
// (frame_solver, pose_filter with channels, offline_smoother with the gate opened,
// landmark_filter, the foot contact stage — both-sided after the offline filter, causal
// otherwise — and pose_resampler), the fixed-rate grid gives the resampler's pose at
// t0 + j / fps for every j up to the newest pose, and the filter rules (filter_rules.hpp)
// validate and bound the smoothing strength once.
#include "avatarmap/solve/pose_stream.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "avatarmap/time/filter_rules.hpp"
#include "avatarmap/time/foot_contacts.hpp"
#include "avatarmap/time/offline_smoother.hpp"
#include "avatarmap/time/pose_filter.hpp"
#include "avatarmap/time/pose_resampler.hpp"

namespace avatarmap {
namespace {

constexpr double k_fps = 30.0;

// A noisy recording of the demo motion (noise so that the filters have work to do).
std::vector<landmark_frame> recording(int frames) {
  synth_options o;
  o.body_noise_sigma = o.hand_noise_sigma = o.face_noise_sigma = 0.003f;
  landmark_synth synth(o);
  std::vector<landmark_frame> out(static_cast<size_t>(frames));
  for (int i = 0; i < frames; ++i) {
    const double t = 1.0 + i / k_fps;
    synth.generate(demo_motion_pose(t, synth.skeleton()), out[static_cast<size_t>(i)]);
    out[static_cast<size_t>(i)].t = t;
  }
  return out;
}

// Bit-equal poses (the stream must be the same arithmetic, not an approximation).
void expect_same(const proxy_pose& a, const proxy_pose& b, const std::string& where) {
  ASSERT_EQ(a.t, b.t) << where;
  for (int k = 0; k < k_bone_count; ++k) {
    ASSERT_EQ(a.rotations[k], b.rotations[k]) << where << " bone " << k;
    ASSERT_EQ(a.confidence[k], b.confidence[k]) << where << " bone " << k;
  }
  ASSERT_EQ(a.hips_position, b.hips_position) << where;
  for (int e = 0; e < k_expression_count; ++e)
    ASSERT_EQ(a.expressions[e], b.expressions[e]) << where;
  ASSERT_EQ(a.foot_contact, b.foot_contact) << where;
}

// Pushes every frame and collects the output poses.
std::vector<proxy_pose> run(pose_stream& s, const std::vector<landmark_frame>& frames) {
  std::vector<proxy_pose> out;
  auto keep = [&out](const proxy_pose& p) {
    out.push_back(p);
    return status{};
  };
  for (const landmark_frame& f : frames) EXPECT_TRUE(s.push(f, keep).ok());
  EXPECT_TRUE(s.finish(keep).ok());
  return out;
}

TEST(pose_stream, live_is_solver_then_filter_on_its_channels_then_contacts_then_resampler) {
  const std::vector<landmark_frame> frames = recording(40);
  for (bool contacts_on : {true, false}) {
    SCOPED_TRACE(contacts_on ? "contacts" : "no contacts");
    pose_stream_options o;
    o.filters.filter_mode = pose_filter_mode::live;
    o.filters.filter_channels.position = false;  // a channel that keeps the solver's value
    o.filters.foot_contacts.enabled = contacts_on;
    pose_stream s(o);
    frame_solver solver;
    pose_filter filter;
    foot_contact_stage contacts({}, false);  // causal: no delay
    pose_resampler resampler;
    proxy_pose raw, filtered, want;
    std::vector<proxy_pose> got;
    long planted = 0;
    for (size_t i = 0; i < frames.size(); ++i) {
      solver.solve(frames[i], raw);
      filter.apply(raw, filtered);
      filtered.hips_position = raw.hips_position;
      if (contacts_on) {
        ASSERT_TRUE(contacts.push(filtered, want));
      } else {
        want = filtered;
      }
      planted += want.foot_contact[0] > 0.5f;
      resampler.push(want);
      got.clear();
      ASSERT_TRUE(s.push(frames[i], [&](const proxy_pose& p) {
                     got.push_back(p);
                     return status{};
                   }).ok());
      ASSERT_EQ(got.size(), 1u) << "one pose per frame";
      expect_same(got[0], want, "frame " + std::to_string(i));
      proxy_pose a, b;
      const double t = frames[i].t + 0.01;  // a little past the newest: the extrapolation
      ASSERT_TRUE(s.sample(t, a));
      ASSERT_TRUE(resampler.sample(t, b));
      expect_same(a, b, "sample " + std::to_string(i));
    }
    EXPECT_EQ(s.stats().frames, 40);
    EXPECT_EQ(s.stats().filtered, 40);
    EXPECT_EQ(s.stats().emitted, 40);
    EXPECT_EQ(s.stats().planted_frames[0], planted);
    if (contacts_on) EXPECT_GT(planted, 0) << "the demo motion stands on its left foot at times";
  }
}

TEST(pose_stream, offline_opens_the_gate_and_smooths_with_the_lookahead) {
  const std::vector<landmark_frame> frames = recording(90);
  pose_stream_options o;  // filters default: offline
  pose_stream s(o);
  solver_options gate_open;
  gate_open.confidence.lost_below = gate_open.confidence.found_above = 0.f;
  gate_open.confidence.regain_seconds = 0.f;
  frame_solver solver(gate_open);
  offline_smoother smoother;
  foot_contact_stage contacts({}, true);  // both-sided after the offline filter
  std::vector<proxy_pose> want;
  proxy_pose raw, p, q;
  for (const landmark_frame& f : frames) {
    solver.solve(f, raw);
    smoother.push(raw);
    while (smoother.pop(p))
      if (contacts.push(p, q)) want.push_back(q);
  }
  smoother.finish();
  while (smoother.pop(p))
    if (contacts.push(p, q)) want.push_back(q);
  while (contacts.flush(q)) want.push_back(q);
  const std::vector<proxy_pose> got = run(s, frames);
  ASSERT_EQ(got.size(), frames.size());
  ASSERT_EQ(want.size(), got.size());
  for (size_t i = 0; i < got.size(); ++i) expect_same(got[i], want[i], "pose " + std::to_string(i));
  float lo = 1e9f, hi = -1e9f;
  for (const proxy_pose& q : want) {
    lo = std::min(lo, q.hips_position.y);
    hi = std::max(hi, q.hips_position.y);
  }
  EXPECT_EQ(s.stats().hips_height_min, lo);
  EXPECT_EQ(s.stats().hips_height_max, hi);
}

TEST(pose_stream, none_with_points_filters_the_landmarks_before_solving) {
  const std::vector<landmark_frame> frames = recording(20);
  pose_stream_options o;
  o.filters.filter_mode = pose_filter_mode::none;
  o.filters.landmark_filter.enabled = true;
  pose_stream s(o);
  landmark_filter points(o.filters.landmark_filter);
  frame_solver solver;
  foot_contact_stage contacts({}, false);
  landmark_frame smoothed;
  proxy_pose raw, want;
  const std::vector<proxy_pose> got = run(s, frames);
  ASSERT_EQ(got.size(), frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    points.apply(frames[i], smoothed);
    solver.solve(smoothed, raw);
    ASSERT_TRUE(contacts.push(raw, want));
    expect_same(got[i], want, "frame " + std::to_string(i));
  }
}

TEST(pose_stream, output_fps_samples_the_grid_up_to_the_newest_pose) {
  // 30 fps in, 70 fps out (not a multiple): the grid t0 + j / 70 up to the last frame.
  const std::vector<landmark_frame> frames = recording(31);
  pose_stream_options o;
  o.filters.filter_mode = pose_filter_mode::live;
  o.output_fps = 70.0;
  pose_stream s(o);
  const std::vector<proxy_pose> got = run(s, frames);
  const double t0 = frames.front().t, t_last = frames.back().t;
  const long want_count = static_cast<long>(std::floor((t_last - t0) * 70.0 + 1e-6)) + 1;
  ASSERT_EQ(static_cast<long>(got.size()), want_count);
  EXPECT_EQ(s.stats().emitted, want_count);
  // Each is the resampler's pose at its grid time, over the live filter's poses known then.
  frame_solver solver;
  pose_filter filter;
  foot_contact_stage contacts({}, false);
  pose_resampler resampler;
  proxy_pose raw, filtered, contacted, want;
  size_t j = 0;
  for (const landmark_frame& f : frames) {
    solver.solve(f, raw);
    filter.apply(raw, filtered);
    ASSERT_TRUE(contacts.push(filtered, contacted));
    resampler.push(contacted);
    for (; j < got.size() && t0 + static_cast<double>(j) / 70.0 <= f.t + 1e-9; ++j) {
      const double t = t0 + static_cast<double>(j) / 70.0;
      ASSERT_TRUE(resampler.sample(t, want));
      want.t = t;
      expect_same(got[j], want, "grid pose " + std::to_string(j));
    }
  }
  EXPECT_EQ(j, got.size());
}

TEST(pose_stream, a_grid_too_long_is_an_error_naming_the_input_and_the_rate) {
  pose_stream_options o;
  o.filters.filter_mode = pose_filter_mode::none;
  o.output_fps = 1000.0;
  o.name = "take.landmarks.jsonl";
  o.output_fps_name = "--fps";
  pose_stream s(o);
  std::vector<landmark_frame> frames = recording(2);
  frames[1].t = frames[0].t + 5000.0;  // 5e6 poses at 1000 fps: more than 2^22
  long emitted = 0;
  auto count = [&](const proxy_pose&) {
    ++emitted;
    return status{};
  };
  ASSERT_TRUE(s.push(frames[0], count).ok());
  const status st = s.push(frames[1], count);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::invalid_argument);
  EXPECT_NE(st.message().find("take.landmarks.jsonl: --fps 1000.00 up to frame 1"),
            std::string::npos)
      << st.message();
  EXPECT_EQ(emitted, 1) << "nothing written past the frame before";
}

TEST(pose_stream, an_emit_error_ends_the_push_with_that_error) {
  pose_stream_options o;
  o.filters.filter_mode = pose_filter_mode::live;
  pose_stream s(o);
  const std::vector<landmark_frame> frames = recording(1);
  const status st =
      s.push(frames[0], [](const proxy_pose&) { return status::io_error("disk full"); });
  EXPECT_EQ(st.code(), status_code::io);
  EXPECT_EQ(st.message(), "disk full");
  EXPECT_EQ(s.stats().emitted, 0);
}

TEST(pose_stream, reset_and_restart) {
  const std::vector<landmark_frame> frames = recording(10);
  pose_stream_options o;
  o.filters.filter_mode = pose_filter_mode::live;
  pose_stream s(o);
  const std::vector<proxy_pose> first = run(s, frames);
  s.reset();
  proxy_pose p;
  EXPECT_FALSE(s.sample(0.0, p)) << "reset forgets the resampler";
  EXPECT_EQ(s.stats().frames, 0);
  const std::vector<proxy_pose> again = run(s, frames);
  ASSERT_EQ(again.size(), first.size());
  for (size_t i = 0; i < first.size(); ++i) expect_same(again[i], first[i], std::to_string(i));
  // restart: a new solver (another image size), the resampler kept.
  solver_options other;
  other.image_width = 640.f;
  other.image_height = 480.f;
  s.restart(other);
  EXPECT_EQ(s.solver().options().image_width, 640.f);
  EXPECT_TRUE(s.sample(frames.back().t, p));
}

TEST(filter_rules, validate_names_the_field) {
  pose_stream_filters f;
  EXPECT_TRUE(f.validate().ok());
  f.filter.rotation.min_cutoff = 0.f;
  EXPECT_EQ(f.validate().message(), "filter.rotation.min_cutoff must be finite and > 0");
  f = {};
  f.filter.expression.beta = -1.f;
  EXPECT_EQ(f.validate().message(), "filter.expression.beta must be finite and >= 0");
  f = {};
  f.filter_mode = static_cast<pose_filter_mode>(9);
  EXPECT_EQ(f.validate().message(), "filter_mode must be offline, live or none");
  f = {};
  f.offline.strength = 7.f;
  EXPECT_NE(f.validate().message().find("offline_smoother_options.strength"), std::string::npos);
  pose_stream_options o;
  o.output_fps = -1.0;
  o.output_fps_name = "--fps";
  EXPECT_NE(o.validate().message().find("--fps must be finite and >= 0"), std::string::npos);
  o = {};
  o.resampler.max_extrapolation_seconds = NAN;
  EXPECT_FALSE(o.validate().ok());
}

// The smoothing range is one rule: offline_smoother_options::validate, whose bound is
// 2 s / the widest default sigma (the fingers' 0.30 s).
TEST(filter_rules, smoothing_range_is_the_offline_filters_own) {
  EXPECT_FLOAT_EQ(k_max_smoothing, 2.f / 0.30f);
  EXPECT_TRUE(check_smoothing(0.0, "--smoothing").ok());
  EXPECT_TRUE(check_smoothing(1.0, "--smoothing").ok());
  EXPECT_TRUE(check_smoothing(6.6, "--smoothing").ok());
  for (double bad : {-0.1, 6.7, 10.0, double(NAN), double(INFINITY), 1e300}) {
    const status st = check_smoothing(bad, "--smoothing");
    ASSERT_FALSE(st.ok()) << bad;
    EXPECT_EQ(st.message(), "--smoothing must be finite and in [0, 6.66] (1 = default)");
    offline_smoother_options o;
    if (std::isfinite(bad) && std::fabs(bad) < 1e30) {
      o.strength = static_cast<float>(bad);
      EXPECT_FALSE(o.validate().ok()) << "the same rule: " << bad;
    }
  }
  offline_smoother_options at_bound;
  at_bound.strength = k_max_smoothing;
  EXPECT_TRUE(at_bound.validate().ok());
}

}  // namespace
}  // namespace avatarmap
