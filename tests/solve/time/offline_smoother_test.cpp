// offline_smoother: zero phase, exactness on constants, no flips through the double cover,
// gap filling by slerp (known answers), long gaps easing to rest, low-confidence bones
// following their measurement, segments, the window bound and no allocation per frame.
#include "avatarmap/time/offline_smoother.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#define AVATARMAP_COUNTING_NEW_COUNTER_ONLY  // solve/allocation_test.cpp defines the allocator
#include "support/counting_new.hpp"

namespace avatarmap {
namespace {

constexpr double k_fps = 30.0;
const int k_arm = idx(bone::left_upper_arm);

glm::quat about(const glm::vec3& axis, float radians) {
  return glm::angleAxis(radians, glm::normalize(axis));
}

float degrees_between(const glm::quat& a, const glm::quat& b) {
  return angle_between(a, b) * 180.f / k_pi;
}

// A pose at frame i: every bone observed, identity.
proxy_pose frame_at(int i) {
  proxy_pose p;
  p.t = i / k_fps;
  p.confidence.fill(1.f);
  return p;
}

// Runs every pose through a smoother and returns what came out, in order.
std::vector<proxy_pose> run(const std::vector<proxy_pose>& in,
                            const offline_smoother_options& o = {}) {
  offline_smoother s(o);
  std::vector<proxy_pose> out;
  proxy_pose p;
  for (const proxy_pose& q : in) {
    EXPECT_TRUE(s.push(q));
    while (s.pop(p)) out.push_back(p);
  }
  s.finish();
  while (s.pop(p)) out.push_back(p);
  return out;
}

TEST(OfflineSmoother, DefaultsAreValidAndBadOptionsNameTheField) {
  EXPECT_TRUE(offline_smoother_options{}.validate().ok());
  offline_smoother_options o;
  o.finger_sigma_seconds = -1.f;
  EXPECT_NE(o.validate().message().find("finger_sigma_seconds"), std::string::npos);
  o = {};
  o.strength = std::nanf("");
  EXPECT_NE(o.validate().message().find("strength"), std::string::npos);
  o = {};
  o.max_gap_seconds = 1e9f;
  EXPECT_NE(o.validate().message().find("max_gap_seconds"), std::string::npos);
  o = {};
  o.capacity_frames = 2;
  EXPECT_NE(o.validate().message().find("capacity_frames"), std::string::npos);
  o = {};
  o.degree = 1;
  EXPECT_NE(o.validate().message().find("degree"), std::string::npos);
}

TEST(OfflineSmoother, EveryPoseComesOutOnceInOrderAfterTheLookahead) {
  offline_smoother s;
  EXPECT_DOUBLE_EQ(s.lookahead_seconds(), 1.5);  // max_gap 1.5 s = hold 0.5 + ease 1.0
  proxy_pose p;
  int popped = 0;
  for (int i = 0; i < 300; ++i) {
    s.push(frame_at(i));
    while (s.pop(p)) {
      EXPECT_DOUBLE_EQ(p.t, popped / k_fps);
      // Out only once 1.5 s of later frames are in (45 frames at 30 fps).
      EXPECT_GE(i - popped, 45);
      ++popped;
    }
  }
  s.finish();
  while (s.pop(p)) {
    EXPECT_DOUBLE_EQ(p.t, popped / k_fps);
    ++popped;
  }
  EXPECT_EQ(popped, 300);
  EXPECT_FALSE(s.pop(p));
}

TEST(OfflineSmoother, ConstantStaysExact) {
  std::vector<proxy_pose> in;
  for (int i = 0; i < 120; ++i) {
    proxy_pose p = frame_at(i);
    for (int b = 0; b < k_bone_count; ++b)
      p.rotations[b] = about(glm::vec3(1.f, 0.3f * b, -0.5f), 0.05f * b - 1.f);
    p.hips_position = glm::vec3(0.1f, 0.9f, -0.2f);
    for (int e = 0; e < k_expression_count; ++e) p.expressions[e] = 0.05f * e;
    for (int s = 0; s < k_blendshape_count; ++s) p.blendshapes[s] = 0.015f * s;
    in.push_back(p);
  }
  const auto out = run(in);
  ASSERT_EQ(out.size(), in.size());
  for (size_t i = 0; i < out.size(); ++i) {
    for (int b = 0; b < k_bone_count; ++b)
      ASSERT_LT(degrees_between(out[i].rotations[b], in[i].rotations[b]), 0.01f) << i << " " << b;
    EXPECT_NEAR(out[i].hips_position.x, 0.1f, 1e-6f);
    EXPECT_NEAR(out[i].hips_position.y, 0.9f, 1e-6f);
    EXPECT_NEAR(out[i].hips_position.z, -0.2f, 1e-6f);
    for (int e = 0; e < k_expression_count; ++e)
      EXPECT_NEAR(out[i].expressions[e], 0.05f * e, 1e-6f);
    for (int s = 0; s < k_blendshape_count; ++s)
      EXPECT_NEAR(out[i].blendshapes[s], 0.015f * s, 1e-6f);
    EXPECT_EQ(out[i].confidence, in[i].confidence);
  }
}

// Angle (radians) of the upper arm about X in pose p.
float arm_angle(const proxy_pose& p) {
  glm::quat q = p.rotations[k_arm];
  if (q.w < 0.f) q = -q;
  return 2.f * std::atan2(q.x, q.w);
}

TEST(OfflineSmoother, ZeroPhaseASineComesOutWithoutDelay) {
  // 1 Hz, 60 degrees of amplitude plus a little high-frequency wobble (noise to remove).
  std::vector<proxy_pose> in;
  for (int i = 0; i < 300; ++i) {
    proxy_pose p = frame_at(i);
    const double t = p.t;
    const float a =
        float(60.0 * k_pi / 180.0 * std::sin(2.0 * k_pi * t) + 0.1 * ((i % 2) ? 1.0 : -1.0));
    p.rotations[k_arm] = about(glm::vec3(1.f, 0.f, 0.f), a);
    in.push_back(p);
  }
  // The quadratic fit alone, at a body sigma of 0.1 s (the default is 0.15 s, and narrower on
  // cleaner input: adapt_to_noise).
  offline_smoother_options o;
  o.body_sigma_seconds = 0.10f;
  o.adapt_to_noise = false;
  const auto out = run(in, o);
  ASSERT_EQ(out.size(), in.size());
  // Each peak of the output is at the input's peak frame (within one frame): 0.25 s + k s.
  for (int k = 1; k < 9; ++k) {
    const int peak = int(std::lround((0.25 + k) * k_fps));
    int best = peak - 8;
    for (int i = peak - 8; i <= peak + 8; ++i)
      if (arm_angle(out[i]) > arm_angle(out[best])) best = i;
    EXPECT_LE(std::abs(best - peak), 1) << "peak " << k;
    // The quadratic fit keeps the amplitude of a 1 Hz motion (a mean would flatten it).
    EXPECT_NEAR(arm_angle(out[peak]) * 180.f / k_pi, 60.f, 1.5f);
  }
  // And the wobble (0.1 rad) is smoothed away; what is left is the fit's bias on a 1 Hz sine
  // of 60 degrees (about 1 degree at the peaks with the default sigma of 0.1 s).
  for (int i = 30; i < 270; ++i)
    EXPECT_NEAR(arm_angle(out[i]), float(60.0 * k_pi / 180.0 * std::sin(2.0 * k_pi * i / k_fps)),
                0.025f)
        << i;
}

TEST(OfflineSmoother, PathThroughTheHemisphereBoundaryHasNoFlip) {
  // A rotation about Y from 150 to 210 degrees and back; the input keeps w >= 0, so its sign
  // flips where the angle passes 180 degrees. Averaging through the double cover would give a
  // near-zero quaternion (a wild rotation) there.
  std::vector<proxy_pose> in;
  std::vector<glm::quat> truth;
  for (int i = 0; i < 240; ++i) {
    proxy_pose p = frame_at(i);
    const float deg = 180.f + 30.f * float(std::sin(2.0 * k_pi * p.t / 4.0));
    glm::quat q = about(glm::vec3(0.f, 1.f, 0.f), deg * k_pi / 180.f);
    truth.push_back(q);
    if (q.w < 0.f) q = -q;
    p.rotations[k_arm] = q;
    in.push_back(p);
  }
  const auto out = run(in);
  ASSERT_EQ(out.size(), in.size());
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_LT(degrees_between(out[i].rotations[k_arm], truth[i]), 0.2f) << i;
    if (i > 0)
      EXPECT_LT(degrees_between(out[i].rotations[k_arm], out[i - 1].rotations[k_arm]), 2.f) << i;
  }
}

// Poses with the upper arm at `a` (observed) for t < t0, not observed in [t0, t1) with a
// garbage rotation, and at `b` (observed) from t1 on.
std::vector<proxy_pose> gap_recording(const glm::quat& a, const glm::quat& b, int f0, int f1,
                                      int frames, float gap_confidence = 0.f) {
  std::vector<proxy_pose> in;
  for (int i = 0; i < frames; ++i) {
    proxy_pose p = frame_at(i);
    if (i < f0) {
      p.rotations[k_arm] = a;
    } else if (i < f1) {
      p.rotations[k_arm] = about(glm::vec3(0.f, 0.f, 1.f), 2.5f);  // what a lost bone held
      p.confidence[k_arm] = gap_confidence;
    } else {
      p.rotations[k_arm] = b;
    }
    in.push_back(p);
  }
  return in;
}

TEST(OfflineSmoother, ShortGapIsTheSlerpBetweenBothSides) {
  const glm::quat a = about(glm::vec3(1.f, 0.f, 0.f), 0.4f);
  const glm::quat b = about(glm::vec3(0.f, 1.f, 1.f), -0.9f);
  const int f0 = 60, f1 = 90;  // last observed frame 59, next observed 90: 31 frames apart
  const auto out = run(gap_recording(a, b, f0, f1, 180));
  ASSERT_EQ(out.size(), 180u);
  for (int i = f0; i < f1; ++i) {
    const float u = float(i - (f0 - 1)) / float(f1 - (f0 - 1));
    EXPECT_LT(degrees_between(out[i].rotations[k_arm], slerp_shortest(a, b, u)), 0.01f) << i;
    EXPECT_EQ(out[i].confidence[k_arm], 0.f);  // still marked as not observed
  }
  // The observed spans stay where they were (a quadratic fit of a constant is the constant,
  // also one-sided at the gap's edges).
  EXPECT_LT(degrees_between(out[f0 - 1].rotations[k_arm], a), 0.01f);
  EXPECT_LT(degrees_between(out[f1].rotations[k_arm], b), 0.01f);
}

TEST(OfflineSmoother, GapLongerThanTheLimitHoldsThenEasesToRest) {
  const glm::quat a = about(glm::vec3(1.f, 0.f, 0.f), 0.8f);
  const glm::quat b = about(glm::vec3(0.f, 1.f, 0.f), -0.7f);
  const int f0 = 30, f1 = 30 + 150;  // a 5 s gap
  const auto out = run(gap_recording(a, b, f0, f1, 300));
  ASSERT_EQ(out.size(), 300u);
  const glm::quat rest = identity_quat();
  // Held for hold_seconds (0.5 s = 15 frames) after the last observed frame (29)...
  EXPECT_LT(degrees_between(out[29 + 15].rotations[k_arm], a), 0.01f);
  // ... eased to rest by hold + ease (1.5 s = 45 frames), at rest through the middle ...
  for (int i = 29 + 45; i <= f1 - 45; ++i)
    EXPECT_LT(degrees_between(out[i].rotations[k_arm], rest), 0.01f) << i;
  // ... halfway along the ease (smoothstep 0.5) a quarter of the way through the fill.
  const glm::quat half = slerp_shortest(a, rest, 0.5f);
  EXPECT_LT(degrees_between(out[29 + 15 + 15].rotations[k_arm], half), 0.01f);
  // and symmetrically towards the next observed frame (held for the last 0.5 s before it).
  EXPECT_LT(degrees_between(out[f1 - 15].rotations[k_arm], b), 0.01f);
  EXPECT_LT(degrees_between(out[f1 - 30].rotations[k_arm], slerp_shortest(b, rest, 0.5f)), 0.01f);
  // Nothing snaps: neighbouring outputs never differ by more than a smooth ease allows.
  for (int i = 1; i < 300; ++i)
    EXPECT_LT(degrees_between(out[i].rotations[k_arm], out[i - 1].rotations[k_arm]), 3.f) << i;
}

TEST(OfflineSmoother, GapAtTheStartIsTheInputUntilTheFirstObservationIsInSight) {
  const glm::quat a = about(glm::vec3(1.f, 0.f, 0.f), 0.8f);
  // Not observed for the first 3 s, observed afterwards at a.
  const auto in = gap_recording(a, a, 0, 90, 150);
  const auto out = run(in);
  // Neither side within reach (the lookahead is 1.5 s = 45 frames): what the input says (the
  // solver's own hold and ease).
  for (int i = 0; i < 90 - 46; ++i)
    EXPECT_LT(degrees_between(out[i].rotations[k_arm], in[i].rotations[k_arm]), 0.01f) << i;
  // Within the hold time before it, the first observation is held backwards.
  for (int i = 90 - 15; i < 90; ++i)
    EXPECT_LT(degrees_between(out[i].rotations[k_arm], a), 0.01f) << i;
}

TEST(OfflineSmoother, BoneObservedNowhereKeepsTheInput) {
  // A bone the solver sets from priors (confidence always 0): its rotation is the input's.
  std::vector<proxy_pose> in;
  const glm::quat prior = about(glm::vec3(0.f, 0.f, 1.f), 0.3f);
  for (int i = 0; i < 150; ++i) {
    proxy_pose p = frame_at(i);
    p.rotations[idx(bone::jaw)] = prior;
    p.confidence[idx(bone::jaw)] = 0.f;
    in.push_back(p);
  }
  for (const proxy_pose& p : run(in))
    EXPECT_LT(degrees_between(p.rotations[idx(bone::jaw)], prior), 0.01f);
}

TEST(OfflineSmoother, LowConfidenceBoneFollowsItsMeasurement) {
  // An occluded arm the estimator still places (confidence 0.2) keeps moving through a 1 s
  // burst: it is smoothed, not replaced by the slerp between the burst's edges.
  std::vector<proxy_pose> in;
  auto truth = [](double t) { return about(glm::vec3(1.f, 0.f, 0.f), float(std::sin(3.0 * t))); };
  for (int i = 0; i < 180; ++i) {
    proxy_pose p = frame_at(i);
    p.rotations[k_arm] = truth(p.t);
    if (i >= 60 && i < 90) p.confidence[k_arm] = 0.2f;
    in.push_back(p);
  }
  const auto out = run(in);
  float worst = 0.f, worst_fill = 0.f;
  for (int i = 60; i < 90; ++i) {
    worst = std::max(worst, degrees_between(out[i].rotations[k_arm], truth(i / k_fps)));
    const glm::quat fill = slerp_shortest(truth(59 / k_fps), truth(90 / k_fps), (i - 59) / 31.f);
    worst_fill = std::max(worst_fill, degrees_between(fill, truth(i / k_fps)));
  }
  // The arm swings ~70 degrees through the burst at up to 3 rad/s: a fill between the edges
  // would be ~50 degrees off; the wide smoothing of the measurement stays within ~9 (the bias
  // of a 0.3 s kernel on a swing this fast).
  EXPECT_GT(worst_fill, 40.f);
  EXPECT_LT(worst, 10.f);
}

// 150 frames of a still left index finger at `a`, with garbage rotations during frames 60-79
// where `low_bone` has confidence 0.1 (the finger itself, or its lower arm).
std::vector<proxy_pose> finger_burst(const glm::quat& a, int low_bone) {
  const int finger = idx(bone::left_index_proximal);
  std::vector<proxy_pose> in;
  for (int i = 0; i < 150; ++i) {
    proxy_pose p = frame_at(i);
    p.rotations[finger] = a;
    if (i >= 60 && i < 80) {
      p.confidence[low_bone] = 0.1f;
      p.rotations[finger] = about(glm::vec3(1.f, 0.f, 0.f), 1.5f);  // garbage
    }
    in.push_back(p);
  }
  return in;
}

TEST(OfflineSmoother, BarelySeenFingersAreFilledNotSmoothed) {
  // A hand whose own points are barely visible (confidence 0.1): its fingers are filled from
  // both sides like a gap, not taken from the unreliable points (an arm at 0.1 is smoothed).
  const int finger = idx(bone::left_index_proximal);
  const glm::quat a = about(glm::vec3(0.f, 0.f, 1.f), 0.5f);
  const auto out = run(finger_burst(a, finger));
  for (int i = 60; i < 80; ++i) {
    EXPECT_LT(degrees_between(out[i].rotations[finger], a), 0.01f) << i;
    EXPECT_EQ(out[i].confidence[finger], 0.1f);  // the input's confidence is written unchanged
  }
}

// A left index finger (or another bone) swinging (up to 3 rad/s) with Gaussian noise of `noise`
// radians per axis, and during frames 120-149 confidence 0.2 with noise of `burst_noise`
// instead; returns the largest error over the burst's frames.
float finger_burst_error(float noise, float burst_noise, unsigned seed,
                         int finger = idx(bone::left_index_proximal)) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.f, 1.f);
  auto truth = [](double t) { return about(glm::vec3(0.f, 0.f, 1.f), float(std::sin(3.0 * t))); };
  std::vector<proxy_pose> in;
  for (int i = 0; i < 360; ++i) {
    proxy_pose p = frame_at(i);
    const bool burst = i >= 120 && i < 150;
    const float sigma = burst ? burst_noise : noise;
    const glm::vec3 e(n(rng), n(rng), n(rng));
    p.rotations[finger] = glm::normalize(
        truth(p.t) * glm::quat(1.f, 0.5f * sigma * e.x, 0.5f * sigma * e.y, 0.5f * sigma * e.z));
    if (burst) p.confidence[finger] = 0.2f;
    in.push_back(p);
  }
  const auto out = run(in);
  float worst = 0.f;
  for (int i = 120; i < 150; ++i)
    worst = std::max(worst, degrees_between(out[i].rotations[finger], truth(i / k_fps)));
  return worst;
}

TEST(OfflineSmoother, LowConfidenceFingersAreUsedWhenTheyAreAsSteadyAsTheRest) {
  // The noise measured on the low-confidence frames decides: as steady as the confident ones
  // (a generator or estimator that only lowers the confidence), the burst is smoothed and
  // follows the swing; far noisier (a finger's direction nearly random), it is filled from the
  // burst's edges, which misses the swing's middle by ~50 degrees but is not random.
  const float used = finger_burst_error(0.05f, 0.05f, 3);
  const float filled = finger_burst_error(0.05f, 3.f, 3);
  EXPECT_LT(used, 12.f);
  EXPECT_GT(filled, 35.f);
  EXPECT_LT(filled, 70.f);
  // The filled burst is the same whatever garbage it holds (nothing of it is used).
  EXPECT_FLOAT_EQ(filled, finger_burst_error(0.05f, 2.5f, 3));
}

TEST(OfflineSmoother, ABarelySeenHandBoneIsSmoothedWhileAFingerAsNoisyIsFilled) {
  // A hand bone spans the palm: under noise that leaves a finger bone at random it still
  // carries the wrist's turn. Confident frames 0.02 rad, the burst 0.25 rad per axis (a
  // second-difference size ~1.1 rad per sample, ~12 x the confident frames', under 1.8): the
  // hand bone is smoothed through the burst and follows the swing; a finger with the same
  // numbers is filled from the burst's edges (its group asks for at most 5 x).
  const float hand = finger_burst_error(0.02f, 0.25f, 5, idx(bone::left_hand));
  const float finger = finger_burst_error(0.02f, 0.25f, 5, idx(bone::left_index_proximal));
  EXPECT_LT(hand, 25.f);
  EXPECT_GT(finger, 35.f);
  // Beyond 1.8 rad per sample (1 rad per axis) the hand bone is filled too.
  EXPECT_GT(finger_burst_error(0.02f, 1.f, 5, idx(bone::left_hand)), 35.f);
}

// A left hand (hand and fingers) absent (confidence 0) except frames [from, to) where it is
// seen turned by `wild`, then seen still at `a` from frame 60 on.
std::vector<proxy_pose> hand_flicker(int from, int to, const glm::quat& wild, const glm::quat& a) {
  const int first = idx(bone::left_hand), fingers = idx(bone::left_thumb_metacarpal);
  std::vector<proxy_pose> in;
  for (int i = 0; i < 150; ++i) {
    proxy_pose p = frame_at(i);
    for (int b = 0; b < k_bone_count; ++b) {
      if (b != first && (b < fingers || b >= fingers + 15)) continue;
      const bool seen = (i >= from && i < to) || i >= 60;
      p.confidence[b] = seen ? 1.f : 0.f;
      // The solver holds what it saw last while the hand is unseen.
      p.rotations[b] = i >= 60 ? a : i >= from ? wild : identity_quat();
    }
    in.push_back(p);
  }
  return in;
}

TEST(OfflineSmoother, AHandSeenForAFewFramesBetweenAbsencesIsTakenForAFalseDetection) {
  const int hand = idx(bone::left_hand), finger = idx(bone::left_index_distal);
  const glm::quat wild = about(glm::vec3(0.f, 1.f, 0.f), 2.9f);
  const glm::quat a = about(glm::vec3(1.f, 0.f, 0.f), 0.4f);
  // Seen for 4 frames (0.13 s) at frames 20-23: ignored; the hand is what the input showed
  // before it (rest) until the real hand comes in sight, never the wild turn.
  const auto out = run(hand_flicker(20, 24, wild, a));
  for (int i = 0; i < 150; ++i)
    for (int b : {hand, finger}) {
      EXPECT_GT(degrees_between(out[i].rotations[b], wild), 120.f) << i;
      EXPECT_LT(degrees_between(out[i].rotations[b], identity_quat()), 23.f) << i;  // 0 .. a
      if (i >= 60) EXPECT_LT(degrees_between(out[i].rotations[b], a), 0.01f) << i;
      if (i >= 20 && i < 24) EXPECT_EQ(out[i].confidence[b], 0.f) << i;  // not believed
    }
  // Seen for 12 frames (0.4 s): a real hand, kept.
  const auto kept = run(hand_flicker(20, 32, wild, a));
  for (int i = 22; i < 30; ++i) {
    EXPECT_LT(degrees_between(kept[i].rotations[hand], wild), 0.01f) << i;
    EXPECT_EQ(kept[i].confidence[hand], 1.f);
  }
}

TEST(OfflineSmoother, HandFollowsItsArmWhenAsked) {
  // hands_follow_arms (off by default: a close-up of a hand has a sure hand model and an arm
  // the body model barely sees): the arm in a burst (0.1) caps the sure hand's fingers, which
  // are then filled from both sides.
  const int finger = idx(bone::left_index_proximal);
  const glm::quat a = about(glm::vec3(0.f, 0.f, 1.f), 0.5f);
  const std::vector<proxy_pose> in = finger_burst(a, idx(bone::left_lower_arm));
  offline_smoother_options o;
  o.hands_follow_arms = true;
  const auto out = run(in, o);
  const auto plain = run(in);
  for (int i = 60; i < 80; ++i) {
    EXPECT_LT(degrees_between(out[i].rotations[finger], a), 0.01f) << i;
    EXPECT_EQ(out[i].confidence[finger], 1.f);  // the input's confidence is written unchanged
  }
  // Without it the sure hand is believed.
  EXPECT_GT(degrees_between(plain[70].rotations[finger], a), 30.f);
}

TEST(OfflineSmoother, LowFrameRatesAreStillSmoothed) {
  // 5 fps: a body sigma of 0.1 s is half a frame; the one-frame floor smooths
  // alternating noise on a still arm, and a slow swing is kept.
  const double fps = 5.0;
  std::vector<proxy_pose> in;
  for (int i = 0; i < 60; ++i) {
    proxy_pose p = frame_at(i);
    p.t = i / fps;
    p.rotations[k_arm] = about(glm::vec3(1.f, 0.f, 0.f), (i % 2 ? 1.f : -1.f) * 0.1f);
    in.push_back(p);
  }
  offline_smoother_options floor, no_floor;
  floor.body_sigma_seconds = no_floor.body_sigma_seconds = 0.1f;
  floor.adapt_to_noise = no_floor.adapt_to_noise = false;
  no_floor.min_sigma_frames = 0.f;
  const auto floored = run(in, floor), bare = run(in, no_floor);
  const glm::quat still = identity_quat();
  EXPECT_GT(degrees_between(bare[30].rotations[k_arm], still), 4.f);  // barely smoothed
  EXPECT_LT(degrees_between(floored[30].rotations[k_arm], still), 2.f);
  offline_smoother_options bad;
  bad.min_sigma_frames = -1.f;
  EXPECT_NE(bad.validate().message().find("min_sigma_frames"), std::string::npos);
}

TEST(OfflineSmoother, OneSidedKernelsDoNotExtrapolate) {
  // At a segment's start the kernel sees only the future: a local quadratic fitted there
  // weighs the first sample by more than 1 (and its neighbours negatively), so a first sample
  // off by some angle would come out further off. It must not exceed its own error.
  for (int gap : {0, 1}) {
    SCOPED_TRACE(gap);
    std::vector<proxy_pose> in;
    const float amp = 0.1f;
    for (int i = 0; i < 60; ++i) {
      proxy_pose p = frame_at(i);
      if (i == 0) p.rotations[k_arm] = about(glm::vec3(0.f, 1.f, 0.f), amp);
      if (gap == 1 && i > 0 && i < 4) p.confidence[k_arm] = 0.f;  // and a hole after it
      in.push_back(p);
    }
    const auto out = run(in);
    EXPECT_LE(degrees_between(out[0].rotations[k_arm], identity_quat()), amp * 57.3f);
  }
}

// A swing of the arm (peak speed 3 rad/s) plus Gaussian noise of `noise` radians per axis;
// returns the mean error of the smoothed arm against the swing.
float swing_error(float noise, bool adapt, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.f, 1.f);
  auto truth = [](double t) { return about(glm::vec3(1.f, 0.f, 0.f), float(std::sin(3.0 * t))); };
  std::vector<proxy_pose> in;
  for (int i = 0; i < 600; ++i) {
    proxy_pose p = frame_at(i);
    const glm::vec3 e(n(rng), n(rng), n(rng));
    p.rotations[k_arm] =
        truth(p.t) * glm::quat(1.f, 0.5f * noise * e.x, 0.5f * noise * e.y, 0.5f * noise * e.z);
    p.rotations[k_arm] = glm::normalize(p.rotations[k_arm]);
    in.push_back(p);
  }
  offline_smoother_options o;
  o.adapt_to_noise = adapt;
  const auto out = run(in, o);
  double sum = 0.0;
  for (int i = 60; i < 540; ++i) sum += degrees_between(out[i].rotations[k_arm], truth(i / k_fps));
  return float(sum / 480.0);
}

TEST(OfflineSmoother, AdaptsItsWidthToTheNoise) {
  // Exact input: adapting narrows the kernels, so a fast swing keeps its peaks.
  const float exact_fixed = swing_error(0.f, false, 1), exact_adapted = swing_error(0.f, true, 1);
  EXPECT_LT(exact_adapted, 0.5f * exact_fixed);
  EXPECT_LT(exact_adapted, 0.1f);
  // Much noisier than the reference: never wider than the tuned sigmas (wider would flatten
  // fast motion), so the same as without adapting.
  EXPECT_FLOAT_EQ(swing_error(0.3f, true, 2), swing_error(0.3f, false, 2));
  offline_smoother_options o;
  EXPECT_TRUE(o.adapt_to_noise);  // the default
}

TEST(OfflineSmoother, TimeGoingBackStartsANewSegmentAndNothingMixes) {
  const glm::quat a = about(glm::vec3(1.f, 0.f, 0.f), 0.5f);
  const glm::quat b = about(glm::vec3(0.f, 1.f, 0.f), -0.5f);
  std::vector<proxy_pose> in;
  for (int i = 0; i < 60; ++i) {
    proxy_pose p = frame_at(i);
    p.rotations[k_arm] = a;
    in.push_back(p);
  }
  for (int i = 0; i < 60; ++i) {  // the times start again at 0
    proxy_pose p = frame_at(i);
    p.rotations[k_arm] = b;
    p.confidence[k_arm] = i < 10 ? 0.f : 1.f;  // a gap at the start of the new segment
    in.push_back(p);
  }
  const auto out = run(in);
  ASSERT_EQ(out.size(), 120u);
  for (int i = 0; i < 60; ++i) EXPECT_LT(degrees_between(out[i].rotations[k_arm], a), 0.01f);
  // The gap is not filled from the old segment: it is held from the new one's side.
  for (int i = 60; i < 120; ++i) EXPECT_LT(degrees_between(out[i].rotations[k_arm], b), 0.01f);
  EXPECT_DOUBLE_EQ(out[60].t, 0.0);
}

TEST(OfflineSmoother, NonFiniteInputGivesFiniteOutput) {
  std::vector<proxy_pose> in;
  for (int i = 0; i < 90; ++i) {
    proxy_pose p = frame_at(i);
    if (i % 7 == 0) p.rotations[k_arm] = glm::quat(NAN, 0.f, 0.f, 1.f);
    if (i % 5 == 0) p.hips_position.y = INFINITY;
    if (i % 3 == 0) p.expressions[2] = NAN;
    if (i % 4 == 0) p.blendshapes[24] = INFINITY;
    if (i % 11 == 0) p.confidence[3] = NAN;
    in.push_back(p);
  }
  in[40].t = NAN;
  const auto out = run(in);
  ASSERT_EQ(out.size(), in.size());
  for (const proxy_pose& p : out) {
    for (int b = 0; b < k_bone_count; ++b) ASSERT_TRUE(is_finite(p.rotations[b]));
    ASSERT_TRUE(is_finite(p.hips_position));
    for (float e : p.expressions) ASSERT_TRUE(std::isfinite(e));
    for (float w : p.blendshapes) ASSERT_TRUE(std::isfinite(w));
  }
}

// Blendshapes are smoothed exactly like expressions (same kernel): a blendshape fed the same
// noisy signal as an expression comes out the same, and the noise is damped.
TEST(OfflineSmoother, BlendshapesAreSmoothedLikeExpressions) {
  std::vector<proxy_pose> in;
  std::uint32_t state = 7;
  for (int i = 0; i < 90; ++i) {
    proxy_pose p = frame_at(i);
    state = state * 1664525u + 1013904223u;
    const float w = 0.5f + 0.2f * (float(state >> 8) / float(1u << 24) - 0.5f);
    p[expression::aa] = w;
    p[blendshape::jaw_open] = w;
    in.push_back(p);
  }
  const auto out = run(in);
  ASSERT_EQ(out.size(), in.size());
  double jitter_in = 0, jitter_out = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i][blendshape::jaw_open], out[i][expression::aa]) << i;
    if (i > 0) {
      jitter_in += std::abs(in[i][blendshape::jaw_open] - in[i - 1][blendshape::jaw_open]);
      jitter_out += std::abs(out[i][blendshape::jaw_open] - out[i - 1][blendshape::jaw_open]);
    }
  }
  EXPECT_LT(jitter_out, 0.7 * jitter_in);
}

TEST(OfflineSmoother, WindowIsBoundedAndNothingIsAllocatedPerFrame) {
  offline_smoother_options o;
  offline_smoother s(o);
  proxy_pose in = frame_at(0), out;
  // The window at 30 fps: 1.5 s ahead + at most as much behind (3 sigma of the widest kernel,
  // which noise adaptation keeps within the lookahead) + the centre.
  const int bound = int(std::ceil(2.0 * s.lookahead_seconds() * k_fps)) + 2;
  const long before = g_allocations.load();
  long popped = 0;
  int most = 0;
  for (int i = 0; i < 18000; ++i) {
    in.t = i / k_fps;
    in.rotations[k_arm] = about(glm::vec3(1.f, 0.f, 0.f), float(std::sin(i * 0.1)));
    in.confidence[k_arm] = (i / 40) % 3 == 0 ? 0.f : 1.f;  // gaps as well
    ASSERT_TRUE(s.push(in));
    while (s.pop(out)) ++popped;
    most = std::max(most, s.buffered());
  }
  s.finish();
  while (s.pop(out)) ++popped;
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(popped, 18000);
  EXPECT_LE(most, bound);  // does not grow with the length of the stream
  EXPECT_LE(most, s.capacity());
}

// The estimate of bone b at frame c by its definition (offline_smoother.hpp), in double: over
// the frames within 3 sigma of the centre, each weighted by exp(-dt^2 / 2 sigma^2) x (its
// confidence, or 1 when `uniform`), leaving out those below `observed_above` when
// `observed_only`; each quaternion flipped to the centre's hemisphere; the value at the centre
// of the weighted least-squares quadratic in dt / sigma (the weighted mean where the normal
// equations are nearly singular, or for `degree` 0), normalised.
glm::quat reference_estimate(const std::vector<proxy_pose>& in, int c, int b, float sigma,
                             bool observed_only, bool uniform, int degree,
                             float observed_above = 0.5f) {
  const glm::quat ref = in[static_cast<size_t>(c)].rotations[b];
  double m[5] = {}, q[3][4] = {};
  for (int j = 0; j < int(in.size()); ++j) {
    const double dt = in[static_cast<size_t>(j)].t - in[static_cast<size_t>(c)].t;
    if (!(std::abs(dt) <= 3.0 * double(sigma))) continue;
    const float conf = in[static_cast<size_t>(j)].confidence[b];
    if (observed_only && !(conf >= observed_above)) continue;
    const double w = std::exp(-0.5 * dt * dt / (double(sigma) * sigma)) * (uniform ? 1.0 : conf);
    if (!(w > 0.0)) continue;
    const glm::quat& r = in[static_cast<size_t>(j)].rotations[b];
    const double sign =
        double(ref.x) * r.x + double(ref.y) * r.y + double(ref.z) * r.z + double(ref.w) * r.w < 0.0
            ? -1.0
            : 1.0;
    const double v[4] = {sign * r.x, sign * r.y, sign * r.z, sign * r.w};
    const double u = dt / sigma;
    for (int k = 0; k < 5; ++k) m[k] += w * std::pow(u, k);
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 4; ++i) q[k][i] += w * std::pow(u, k) * v[i];
  }
  // [m0 m1 m2; m1 m2 m3; m2 m3 m4] [a b c]' = q: a by Cramer's rule.
  const double det = m[0] * (m[2] * m[4] - m[3] * m[3]) - m[1] * (m[1] * m[4] - m[3] * m[2]) +
                     m[2] * (m[1] * m[3] - m[2] * m[2]);
  double r[4];
  for (int i = 0; i < 4; ++i) {
    if (degree == 2 && det > 1e-6 * m[0] * m[2] * m[4] && det > 0.0)
      r[i] = (q[0][i] * (m[2] * m[4] - m[3] * m[3]) - m[1] * (q[1][i] * m[4] - m[3] * q[2][i]) +
              m[2] * (q[1][i] * m[3] - m[2] * q[2][i])) /
             det;
    else
      r[i] = q[0][i] / m[0];
  }
  const double n = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
  return glm::quat(float(r[3] / n), float(r[0] / n), float(r[1] / n), float(r[2] / n));
}

TEST(OfflineSmoother, EstimatesEqualTheirDefinitionComputedPlainly) {
  // Every bone moving with noise, each input quaternion's sign drawn at random (the hemisphere
  // alignment must undo it); confidences that take each way of weighting: 1 everywhere (the
  // kernel's own moments serve all such bones), varying in [0.5, 1] (the left arm and hand),
  // briefly low (the right lower leg: smoothed by confidence over the wider kernel there),
  // briefly missing (the right index finger: a gap, not compared) and never observed (the jaw:
  // every frame alike).
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(-1.f, 1.f), half(0.5f, 1.f);
  std::normal_distribution<float> noise(0.f, 0.02f);
  std::vector<glm::vec3> axis(k_bone_count);
  std::vector<float> amplitude(k_bone_count), rate(k_bone_count);
  for (int b = 0; b < k_bone_count; ++b) {
    axis[b] = glm::normalize(glm::vec3(unit(rng), unit(rng), unit(rng)) + glm::vec3(0.f, 0.f, 2.f));
    amplitude[b] = 1.5f * half(rng);
    rate[b] = 4.f * half(rng);
  }
  const int leg = idx(bone::right_lower_leg), finger = idx(bone::right_index_proximal),
            jaw = idx(bone::jaw);
  auto left_arm = [](int b) {
    return b == idx(bone::left_upper_arm) || b == idx(bone::left_lower_arm) ||
           b == idx(bone::left_hand) ||
           (b >= idx(bone::left_thumb_metacarpal) && b <= idx(bone::left_little_distal));
  };
  std::vector<proxy_pose> in;
  for (int i = 0; i < 180; ++i) {
    proxy_pose p = frame_at(i);
    for (int b = 0; b < k_bone_count; ++b) {
      glm::quat q = about(axis[b], amplitude[b] * float(std::sin(rate[b] * p.t))) *
                    glm::quat(1.f, noise(rng), noise(rng), noise(rng));
      q = glm::normalize(q);
      p.rotations[b] = unit(rng) < 0.f ? -q : q;
      if (left_arm(b)) p.confidence[b] = half(rng);
    }
    if (i % 9 == 4) p.confidence[leg] = 0.3f;
    if (i >= 100 && i < 105) p.confidence[finger] = 0.f;
    p.confidence[jaw] = 0.f;
    in.push_back(p);
  }
  for (int degree : {2, 0}) {
    offline_smoother_options o;
    o.adapt_to_noise = false;  // the sigmas as given: body 0.15 s, fingers 0.3 s, low 0.3 s
    o.degree = degree;
    const auto out = run(in, o);
    ASSERT_EQ(out.size(), in.size());
    int compared = 0;
    for (int c = 0; c < int(in.size()); ++c) {
      for (int b = 0; b < k_bone_count; ++b) {
        const float conf = in[static_cast<size_t>(c)].confidence[b];
        const float sigma =
            b >= idx(bone::left_thumb_metacarpal) ? o.finger_sigma_seconds : o.body_sigma_seconds;
        glm::quat want;
        if (b == jaw)
          want = reference_estimate(in, c, b, sigma, false, true, degree);
        else if (conf >= o.observed_above)
          want = reference_estimate(in, c, b, sigma, true, false, degree);
        else if (b == leg)
          want = reference_estimate(in, c, b, o.low_confidence_sigma_seconds, false, false, degree);
        else
          continue;  // a gap
        const glm::quat& got = out[static_cast<size_t>(c)].rotations[b];
        for (int k = 0; k < 4; ++k)
          ASSERT_NEAR(got[k], want[k], 1e-5f)
              << "degree " << degree << " frame " << c << " bone "
              << bone_name(static_cast<bone>(b)) << " component " << k;
        ++compared;
      }
    }
    EXPECT_EQ(compared, 180 * k_bone_count - 5);
  }
}

TEST(OfflineSmoother, HighFrameRateBeyondTheCapacityStillStreams) {
  offline_smoother_options o;
  o.capacity_frames = 16;  // far less than 1.5 s at 30 fps
  offline_smoother s(o);
  proxy_pose p = frame_at(0), out;
  long popped = 0;
  for (int i = 0; i < 200; ++i) {
    p.t = i / k_fps;
    ASSERT_TRUE(s.push(p));
    while (s.pop(out)) ++popped;
    ASSERT_LE(s.buffered(), 16);
  }
  s.finish();
  while (s.pop(out)) ++popped;
  EXPECT_EQ(popped, 200);
}

}  // namespace
}  // namespace avatarmap
