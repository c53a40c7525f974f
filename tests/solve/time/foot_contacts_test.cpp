// The contact stage (time/foot_contacts.hpp) on hand-built proxy pose sequences with known
// answers: a still foot under drifting, noisy hips is planted and the hips stop drifting; a
// swinging foot is never planted; a foot that is not confident is never planted; a landing is
// planted within 2 frames live; nothing non-finite comes out; nothing is allocated per frame.
#include "avatarmap/time/foot_contacts.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#define AVATARMAP_COUNTING_NEW_COUNTER_ONLY
#include "avatarmap/solve/pose_stream.hpp"
#include "support/counting_new.hpp"

namespace avatarmap {
namespace {

constexpr double k_fps = 30.0;

// Standing in the rest pose (straight legs, feet flat), every bone observed.
proxy_pose standing(double t, const proxy_skeleton& sk) {
  proxy_pose p;
  p.t = t;
  p.confidence.fill(1.f);
  p.hips_position = glm::vec3(0.f, standing_hips_height(sk), 0.f);
  return p;
}

// World sole-middle points of both feet of `p` (what the stage anchors).
std::array<foot_measure, 2> feet_of(const proxy_pose& p, const proxy_skeleton& sk) {
  std::array<foot_measure, 2> m;
  measure_feet(sk, p, 0.f, m);
  return m;
}

// Runs `in` through a stage, returning every output (flushed at the end).
std::vector<proxy_pose> run(const std::vector<proxy_pose>& in, bool both_sided,
                            const foot_contact_options& o = {}) {
  foot_contact_stage stage(o, both_sided);
  std::vector<proxy_pose> out;
  proxy_pose p;
  for (const proxy_pose& q : in)
    if (stage.push(q, p)) out.push_back(p);
  while (stage.flush(p)) out.push_back(p);
  return out;
}

// 10 s of standing with the measured hips drifting 2 cm/s in X and 3 mm of noise on each axis.
std::vector<proxy_pose> standing_with_drift(const proxy_skeleton& sk, float drift, float noise) {
  std::mt19937 rng(7);
  std::normal_distribution<float> n(0.f, noise);
  std::vector<proxy_pose> v;
  for (int i = 0; i < 300; ++i) {
    const double t = i / k_fps;
    proxy_pose p = standing(t, sk);
    p.hips_position += glm::vec3(drift * float(t) + n(rng), 0.f, n(rng));
    v.push_back(p);
  }
  return v;
}

TEST(foot_contacts, still_feet_under_drifting_hips_are_planted_and_hold_the_hips) {
  const proxy_skeleton sk = make_proxy_skeleton();
  const auto in = standing_with_drift(sk, 0.02f, 0.003f);
  for (bool both : {false, true}) {
    SCOPED_TRACE(both ? "both-sided" : "causal");
    const auto out = run(in, both);
    ASSERT_EQ(out.size(), in.size());
    // The input's feet move: 2 cm/s of drift, 60 cm of noise travel over the take.
    const auto a_in = feet_of(in.front(), sk), b_in = feet_of(in.back(), sk);
    EXPECT_GT(glm::length(b_in[0].point - a_in[0].point), 0.15f);
    float path = 0.f, lo = 1e9f, hi = -1e9f;
    for (size_t i = 0; i < out.size(); ++i) {
      EXPECT_EQ(out[i].foot_contact[0], 1.f) << i;
      EXPECT_EQ(out[i].foot_contact[1], 1.f) << i;
      lo = std::min(lo, out[i].hips_position.x);
      hi = std::max(hi, out[i].hips_position.x);
      if (i > 0) {
        const auto a = feet_of(out[i - 1], sk), b = feet_of(out[i], sk);
        path += glm::length(b[0].point - a[0].point) + glm::length(b[1].point - a[1].point);
      }
    }
    // Mean speed of the two feet after the stage < 0.5 cm/s; the hips no longer drift (the
    // legs do not move, so the planted feet hold the hips exactly: range < 1 cm).
    const double seconds = in.back().t - in.front().t;
    EXPECT_LT(path / 2.0 / seconds, 0.005);
    EXPECT_LT(hi - lo, 0.01f);
    // Y untouched: the planted feet are the floor.
    EXPECT_NEAR(out[100].hips_position.y, in[100].hips_position.y, 1e-5f);
  }
}

TEST(foot_contacts, without_root_follow_only_the_contacts_are_written) {
  const proxy_skeleton sk = make_proxy_skeleton();
  const auto in = standing_with_drift(sk, 0.02f, 0.003f);
  foot_contact_options o;
  o.root_follows_contacts = false;
  const auto out = run(in, true, o);
  ASSERT_EQ(out.size(), in.size());
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].hips_position, in[i].hips_position);
    EXPECT_EQ(out[i].foot_contact[0], 1.f);
  }
  o.enabled = false;
  const auto off = run(in, true, o);
  for (size_t i = 0; i < off.size(); ++i) {
    EXPECT_EQ(off[i].hips_position, in[i].hips_position);
    EXPECT_EQ(off[i].foot_contact[0], 0.f);
  }
}

// The left leg swings +-45 degrees about X at 1 Hz (the foot sweeps at up to 4 m/s past the
// floor and stops only at the ends, over 15 cm up); the right foot stands.
std::vector<proxy_pose> swinging(const proxy_skeleton& sk, double seconds) {
  std::vector<proxy_pose> v;
  for (int i = 0; i < int(seconds * k_fps); ++i) {
    const double t = i / k_fps;
    proxy_pose p = standing(t, sk);
    const float a = glm::radians(45.f) * float(std::cos(2.0 * glm::pi<double>() * t));
    p[bone::left_upper_leg] = glm::angleAxis(a, glm::vec3(1.f, 0.f, 0.f));
    v.push_back(p);
  }
  return v;
}

TEST(foot_contacts, a_swinging_foot_is_never_planted) {
  const proxy_skeleton sk = make_proxy_skeleton();
  const auto in = swinging(sk, 5.0);
  for (bool both : {false, true}) {
    SCOPED_TRACE(both ? "both-sided" : "causal");
    const auto out = run(in, both);
    ASSERT_EQ(out.size(), in.size());
    for (size_t i = 0; i < out.size(); ++i) {
      EXPECT_EQ(out[i].foot_contact[0], 0.f) << i;
      EXPECT_EQ(out[i].foot_contact[1], 1.f) << i;
    }
    // The standing foot holds the hips where they were (the swing does not move them).
    for (const proxy_pose& p : out) EXPECT_NEAR(p.hips_position.x, 0.f, 1e-4f);
  }
}

TEST(foot_contacts, a_foot_that_is_not_confident_is_never_planted) {
  const proxy_skeleton sk = make_proxy_skeleton();
  auto in = standing_with_drift(sk, 0.f, 0.002f);
  for (size_t i = 0; i < in.size(); ++i) {
    in[i].confidence[idx(bone::left_lower_leg)] = 0.005f;  // below min_confidence (0.01)
    in[i].confidence[idx(bone::right_toes)] = 0.f;         // never seen
  }
  for (bool both : {false, true}) {
    const auto out = run(in, both);
    for (const proxy_pose& p : out) {
      EXPECT_EQ(p.foot_contact[0], 0.f);
      EXPECT_EQ(p.foot_contact[1], 0.f);
      // No foot planted: the hips as measured.
    }
    EXPECT_NEAR(out[200].hips_position.x, in[200].hips_position.x, 1e-5f);
  }
}

TEST(foot_contacts, a_foot_reported_outside_the_image_is_planted) {
  // BlazePose reports a foot outside the image (or turned away) with a visibility of a few
  // percent; its pose is what the avatar shows, so a still, low foot is held all the same.
  const proxy_skeleton sk = make_proxy_skeleton();
  auto in = standing_with_drift(sk, 0.02f, 0.002f);
  for (proxy_pose& p : in) p.confidence[idx(bone::left_foot)] = 0.02f;
  for (bool both : {false, true}) {
    const auto out = run(in, both);
    EXPECT_EQ(out[100].foot_contact[0], 1.f);
    EXPECT_EQ(out[100].foot_contact[1], 1.f);
  }
}

// Standing on the left foot of skeleton `sk` while the left leg sweeps +-15 degrees about X
// (1 Hz) and the hips move so that the left sole stays exactly where it is on `sk`; the right
// leg is raised 40 degrees forward (high: never planted).
std::vector<proxy_pose> swaying_over_the_left_foot(const proxy_skeleton& sk) {
  std::vector<proxy_pose> v;
  glm::vec3 sole0(0.f);
  for (int i = 0; i < 90; ++i) {
    proxy_pose p = standing(i / k_fps, sk);
    const float a = glm::radians(15.f) * std::sin(2.f * k_pi * float(i) / 30.f);
    p[bone::left_upper_leg] = glm::angleAxis(a, glm::vec3(1.f, 0.f, 0.f));
    p[bone::right_upper_leg] = glm::angleAxis(glm::radians(-40.f), glm::vec3(1.f, 0.f, 0.f));
    std::array<foot_measure, 2> m;
    measure_feet(sk, p, 0.f, m);
    if (i == 0) sole0 = m[0].point;
    p.hips_position.x -= m[0].point.x - sole0.x;
    p.hips_position.z -= m[0].point.z - sole0.z;
    v.push_back(p);
  }
  return v;
}

TEST(foot_contacts, the_feet_are_held_on_the_performers_leg_length) {
  // The performer's legs are 15 % shorter than the 1.70 m proxy's. Told the leg length, the
  // stage sees the sole still and leaves the hips as measured; on the proxy's proportions the
  // same rotations move the sole, and the stage would move the hips to hold it.
  const proxy_skeleton proxy = make_proxy_skeleton();
  const proxy_skeleton performer = make_proxy_skeleton(0.85f * k_proxy_reference_height);
  const float leg =
      performer.lengths[idx(bone::left_upper_leg)] + performer.lengths[idx(bone::left_lower_leg)];
  const auto in = swaying_over_the_left_foot(performer);
  for (bool told : {true, false}) {
    SCOPED_TRACE(told ? "told the leg length" : "proxy proportions");
    foot_contact_stage stage({}, true);
    if (told) stage.set_leg_length(leg);
    EXPECT_NEAR(stage.skeleton().lengths[idx(bone::left_upper_leg)] +
                    stage.skeleton().lengths[idx(bone::left_lower_leg)],
                told ? leg : leg / 0.85f, 1e-5f);
    std::vector<proxy_pose> out;
    proxy_pose p;
    for (const proxy_pose& q : in)
      if (stage.push(q, p)) out.push_back(p);
    while (stage.flush(p)) out.push_back(p);
    ASSERT_EQ(out.size(), in.size());
    float worst = 0.f;
    for (size_t i = 0; i < out.size(); ++i) {
      EXPECT_EQ(out[i].foot_contact[0], 1.f) << i;
      EXPECT_EQ(out[i].foot_contact[1], 0.f) << i;
      worst = std::max(worst, glm::length(out[i].hips_position - in[i].hips_position));
    }
    if (told)
      EXPECT_LT(worst, 1e-4f);
    else
      EXPECT_GT(worst, 0.01f);  // the test tells the two apart
  }
  // 0, negative, NaN: the skeleton as given.
  foot_contact_stage stage({}, true);
  stage.set_leg_length(leg);
  stage.set_leg_length(std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(stage.skeleton().lengths[idx(bone::left_lower_leg)],
            proxy.lengths[idx(bone::left_lower_leg)]);
}

TEST(foot_contacts, a_planted_foot_that_keeps_moving_does_not_hold_the_body_back) {
  // Both feet low and under plant_speed (0.5 m/s), so both are planted (both-sided). Sliding
  // at 0.1 m/s (under half plant_speed) they hold the hips fully (for 2 s: carried 20 cm, under
  // release_distance and the measurement's drift allowance of 5 cm/s). At 0.4 m/s (a slow step)
  // each holds (0.5 - 0.4) / (0.5 - 0.25) = 40 % and its anchor follows it by the rest, so the
  // body still travels; once carried 12 cm + 5 cm/s since the plant (0.35 s) the feet are let
  // go and the body travels at the measured speed (all of it held, as before, it stood still).
  const proxy_skeleton sk = make_proxy_skeleton();
  for (float v : {0.1f, 0.4f}) {
    SCOPED_TRACE(v);
    std::vector<proxy_pose> in;
    for (int i = 0; i < 60; ++i) {
      proxy_pose p = standing(i / k_fps, sk);
      p.hips_position.x = v * float(p.t);
      in.push_back(p);
    }
    const auto out = run(in, true);
    const float travel = out[59].hips_position.x - out[0].hips_position.x;
    const float measured = in[59].hips_position.x - in[0].hips_position.x;
    if (v < 0.2f) {
      EXPECT_EQ(out[30].foot_contact[0], 1.f);
      EXPECT_EQ(out[30].foot_contact[1], 1.f);
      EXPECT_LT(travel, 0.01f);
    } else {
      EXPECT_EQ(out[5].foot_contact[0], 1.f);   // planted at first ...
      EXPECT_EQ(out[30].foot_contact[0], 0.f);  // ... let go once carried 17 cm
      EXPECT_EQ(out[30].foot_contact[1], 0.f);
      EXPECT_GT(travel, 0.6f * measured);
    }
  }
}

TEST(foot_contacts, feet_that_part_faster_than_release_speed_are_not_both_planted) {
  // A slow walk seen with noisy hips: each foot slower than plant_speed in the world (~0.44
  // and ~0.48 m/s), but parting from each other at ~0.9 m/s, faster than release_speed (0.8):
  // the swing foot (the faster) is not planted, the stance foot is.
  const proxy_skeleton sk = make_proxy_skeleton();
  const float leg = sk.lengths[idx(bone::left_upper_leg)] + sk.lengths[idx(bone::left_lower_leg)];
  std::vector<proxy_pose> in;
  for (int i = 0; i < 16; ++i) {
    proxy_pose p = standing(i / k_fps, sk);
    const float t = float(p.t);
    // The left foot swings back, the right forward, about the hips (the sole's middle is a
    // little farther from the hip than the ankle: ~9 % faster than these rates say).
    p[bone::left_upper_leg] = glm::angleAxis(0.40f / leg * t, glm::vec3(1.f, 0.f, 0.f));
    p[bone::right_upper_leg] = glm::angleAxis(-0.44f / leg * t, glm::vec3(1.f, 0.f, 0.f));
    in.push_back(p);
  }
  // Both below plant_speed and low (the known answer of the measure itself).
  const auto a = feet_of(in[7], sk), b = feet_of(in[9], sk);
  EXPECT_LT(glm::length(b[0].point - a[0].point) * k_fps / 2.0, 0.5);
  EXPECT_LT(glm::length(b[1].point - a[1].point) * k_fps / 2.0, 0.5);
  EXPECT_GT(glm::length((b[0].point - b[1].point) - (a[0].point - a[1].point)) * k_fps / 2.0, 0.8);
  // The distance rule (release_distance) would also lift the feet after 12 cm: this is the
  // speed rule's test.
  foot_contact_options o;
  o.release_distance = 5.f;
  const auto out = run(in, true, o);
  ASSERT_EQ(out.size(), in.size());
  for (int i = 2; i < 14; ++i) {
    EXPECT_EQ(out[i].foot_contact[1], 0.f) << i;  // the faster, swinging foot
    EXPECT_GT(out[i].foot_contact[0], 0.f) << i;  // the stance foot
  }
}

TEST(foot_contacts, a_slow_step_lifts_the_foot_once_it_has_moved_release_distance) {
  // The right foot slides 20 cm forward at 0.3 m/s (under plant_speed: planted by speed alone;
  // 2 cm up at the end, under plant_height)
  // while the left stands: released once 12 cm from where it planted (and from the left foot),
  // planted again where it settles. Both feet moving together (the hips' measurement drifting
  // under a standing person) lift nothing: the first test above.
  const proxy_skeleton sk = make_proxy_skeleton();
  const float leg = sk.lengths[idx(bone::left_upper_leg)] + sk.lengths[idx(bone::left_lower_leg)];
  std::vector<proxy_pose> in;
  for (int i = 0; i < 90; ++i) {
    proxy_pose p = standing(i / k_fps, sk);
    // Still for 0.5 s, then 0.67 s at ~0.3 m/s (0.20 m), then still.
    const float s = std::clamp(float(p.t) - 0.5f, 0.f, 0.667f) * 0.3f;
    p[bone::right_upper_leg] = glm::angleAxis(-s / leg, glm::vec3(1.f, 0.f, 0.f));
    in.push_back(p);
  }
  const auto out = run(in, true);
  ASSERT_EQ(out.size(), in.size());
  const auto start = feet_of(in[0], sk);
  int lifted = -1, replanted = -1;
  for (int i = 0; i < 90; ++i) {
    EXPECT_EQ(out[i].foot_contact[0], 1.f) << i;  // the standing foot
    if (lifted < 0 && out[i].foot_contact[1] < 1.f) lifted = i;
    if (lifted >= 0 && replanted < 0 && i > lifted && out[i].foot_contact[1] == 1.f) replanted = i;
  }
  ASSERT_GE(lifted, 0);
  // Lifted after 12 cm of the step (0.4 s at 0.3 m/s; give or take the sole's radius) ...
  const float moved = glm::length(feet_of(in[lifted], sk)[1].point - start[1].point);
  EXPECT_GT(moved, 0.10f);
  EXPECT_LT(moved, 0.18f);
  // ... and planted again as the step ends (frame 35; the both-sided speed looks 4 frames
  // ahead, and the contact takes 3 frames to reach 1), not while it still moves.
  EXPECT_GT(replanted, 30);
  EXPECT_LT(replanted, 45);
}

// The left leg hangs 30 degrees forward (12 cm up), comes down at 180 degrees/s and stops at
// frame `land`.
std::vector<proxy_pose> landing(const proxy_skeleton& sk, int land, int frames) {
  std::vector<proxy_pose> v;
  for (int i = 0; i < frames; ++i) {
    proxy_pose p = standing(i / k_fps, sk);
    const float deg = std::clamp(6.f * float(land - i), 0.f, 30.f);
    p[bone::left_upper_leg] = glm::angleAxis(glm::radians(-deg), glm::vec3(1.f, 0.f, 0.f));
    v.push_back(p);
  }
  return v;
}

TEST(foot_contacts, live_detects_a_landing_within_two_frames_without_delay) {
  const proxy_skeleton sk = make_proxy_skeleton();
  const int land = 10;
  const auto in = landing(sk, land, 30);
  foot_contact_stage stage({}, false);
  proxy_pose out;
  int first = -1;
  for (int i = 0; i < int(in.size()); ++i) {
    ASSERT_TRUE(stage.push(in[i], out)) << "no added latency: every push gives its pose";
    EXPECT_EQ(out.t, in[i].t);
    if (i < land) EXPECT_EQ(out.foot_contact[0], 0.f) << i;
    if (first < 0 && out.foot_contact[0] > 0.f) first = i;
  }
  EXPECT_GE(first, land);
  EXPECT_LE(first, land + 2);
  // It blends in (no snap), reaching 1 within blend_seconds.
  EXPECT_LT(in.size(), 100u);
  const auto o = run(in, false);
  EXPECT_LT(o[first].foot_contact[0], 1.f);
  EXPECT_EQ(o[first + 4].foot_contact[0], 1.f);
  // Both-sided: the landing frame itself.
  const auto b = run(in, true);
  int first_b = -1;
  for (int i = 0; i < int(b.size()) && first_b < 0; ++i)
    if (b[i].foot_contact[0] > 0.f) first_b = i;
  EXPECT_EQ(first_b, land);
}

TEST(foot_contacts, a_released_foot_lets_the_hips_go_on_without_a_jump) {
  const proxy_skeleton sk = make_proxy_skeleton();
  // Standing 1 s with drifting measured hips (the feet hold them), then the whole body slides
  // at 1 m/s (the feet too fast to stay planted): the hips must follow the measured motion
  // from where they were held, never jumping.
  std::vector<proxy_pose> in;
  for (int i = 0; i < 60; ++i) {
    const double t = i / k_fps;
    proxy_pose p = standing(t, sk);
    const float x = i < 30 ? 0.01f * float(t) : 0.01f + 1.f * float(t - 1.0);
    p.hips_position.x = x;
    in.push_back(p);
  }
  for (bool both : {false, true}) {
    const auto out = run(in, both);
    EXPECT_EQ(out[20].foot_contact[0], 1.f);
    EXPECT_EQ(out[59].foot_contact[0], 0.f);
    for (size_t i = 1; i < out.size(); ++i) {
      const float step = out[i].hips_position.x - out[i - 1].hips_position.x;
      EXPECT_LE(std::fabs(step), 1.f / 30.f + 1e-4f) << i;  // never more than the measured step
      EXPECT_GE(step, -1e-4f) << i;
    }
    // Sliding for 1 s at 1 m/s moves the hips by most of a metre.
    EXPECT_GT(out[59].hips_position.x - out[29].hips_position.x, 0.7f);
  }
}

TEST(foot_contacts, never_produces_non_finite_values) {
  const proxy_skeleton sk = make_proxy_skeleton();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<proxy_pose> in = standing_with_drift(sk, 0.01f, 0.003f);
  in.resize(60);
  in[10].hips_position.x = nan;
  in[11].hips_position.z = inf;
  in[12].rotations[idx(bone::left_foot)] = glm::quat(nan, 0.f, 0.f, 0.f);
  in[13].confidence[idx(bone::left_foot)] = nan;
  in[14].t = std::numeric_limits<double>::quiet_NaN();
  in[20].t = in[19].t;        // a repeated time
  in[30].t = in[29].t - 1.0;  // time backwards
  in[40].t = in[39].t + 5.0;  // a gap
  for (size_t i = 41; i < in.size(); ++i) in[i].t = in[i - 1].t + 1.0 / k_fps;
  for (bool both : {false, true}) {
    const auto out = run(in, both);
    ASSERT_EQ(out.size(), in.size());
    for (size_t i = 0; i < out.size(); ++i) {
      for (int f = 0; f < 2; ++f) {
        EXPECT_TRUE(out[i].foot_contact[f] >= 0.f && out[i].foot_contact[f] <= 1.f) << i;
      }
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(out[i].hips_position[k])) << i;
    }
  }
}

TEST(foot_contacts, options_are_validated_with_the_field_named) {
  EXPECT_TRUE(foot_contact_options{}.validate().ok());
  foot_contact_options o;
  o.blend_seconds = 0.f;
  EXPECT_NE(o.validate().message().find("foot_contacts.contact_blend_seconds"), std::string::npos);
  o = {};
  o.plant_speed = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(o.validate().message().find("contact_plant_speed"), std::string::npos);
  o = {};
  o.release_height = 0.01f;  // below plant_height
  EXPECT_NE(o.validate().message().find("contact_release_height"), std::string::npos);
  o = {};
  o.window_frames = 0;
  EXPECT_FALSE(o.validate().ok());
  pose_stream_filters f;
  f.foot_contacts.min_confidence = 2.f;
  EXPECT_NE(f.validate().message().find("foot_contacts.contact_min_confidence"), std::string::npos);
}

TEST(foot_contacts, the_stage_allocates_nothing_per_frame) {
  const proxy_skeleton sk = make_proxy_skeleton();
  const auto in = swinging(sk, 3.0);
  for (bool both : {false, true}) {
    foot_contact_stage stage({}, both);
    proxy_pose out;
    const long before = g_allocations.load();
    for (const proxy_pose& p : in) stage.push(p, out);
    while (stage.flush(out)) {
    }
    stage.reset();
    for (const proxy_pose& p : in) stage.push(p, out);
    EXPECT_EQ(g_allocations.load() - before, 0);
  }
}

}  // namespace
}  // namespace avatarmap
