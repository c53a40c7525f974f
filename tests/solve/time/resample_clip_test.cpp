// resample_clip: counts, rebasing, known answers for a constant angular velocity, the
// tolerance for times that went through float, and hostile times (out of order, negative span,
// huge gaps, non-finite) refused with a message before anything is allocated.
#include "avatarmap/time/resample_clip.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "avatarmap/time/seconds_text.hpp"

namespace avatarmap {
namespace {

std::vector<proxy_pose> spin_clip(double fps, int n, double t0) {
  std::vector<proxy_pose> clip(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    clip[i].t = t0 + i / fps;
    clip[i][bone::head] = axis_angle({0, 1, 0}, static_cast<float>(0.5 * (clip[i].t - t0)));
    clip[i].hips_position = glm::vec3(static_cast<float>(clip[i].t - t0), 0.9f, 0.f);
  }
  return clip;
}

// A clip of frames at the given times (rest poses).
std::vector<proxy_pose> clip_at(std::initializer_list<double> times) {
  std::vector<proxy_pose> clip;
  for (double t : times) {
    proxy_pose p;
    p.t = t;
    clip.push_back(p);
  }
  return clip;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(ResampleClip, TwentyFiveToSixtyFollowsAConstantSpin) {
  const std::vector<proxy_pose> clip = spin_clip(25.0, 26, 3.0);  // 1 s from t = 3
  std::vector<proxy_pose> out;
  ASSERT_TRUE(resample_clip(clip, 60.0, true, out).ok());
  ASSERT_EQ(out.size(), 61u);
  for (size_t k = 0; k < out.size(); ++k) {
    const double t = k / 60.0;
    EXPECT_NEAR(out[k].t, t, 1e-12);
    const glm::quat want = axis_angle({0, 1, 0}, static_cast<float>(0.5 * t));
    EXPECT_LT(angle_between(out[k][bone::head], want), 0.01f * k_pi / 180.f) << k;
    EXPECT_NEAR(out[k].hips_position.x, t, 1e-5);
  }
  std::vector<proxy_pose> kept;
  ASSERT_TRUE(resample_clip(clip, 60.0, false, kept).ok());
  EXPECT_NEAR(kept.front().t, 3.0, 1e-12);
}

TEST(ResampleClip, FootContactIsInterpolatedLinearly) {
  std::vector<proxy_pose> clip(2);
  clip[0].t = 0.0;
  clip[1].t = 0.1;
  clip[0].foot_contact = {0.f, 1.f};
  clip[1].foot_contact = {1.f, 0.f};
  std::vector<proxy_pose> out;
  ASSERT_TRUE(resample_clip(clip, 40.0, true, out).ok());  // 0, 0.025, 0.05, 0.075, 0.1
  ASSERT_EQ(out.size(), 5u);
  for (size_t k = 0; k < out.size(); ++k) {
    EXPECT_NEAR(out[k].foot_contact[0], 0.25f * float(k), 1e-6f) << k;
    EXPECT_NEAR(out[k].foot_contact[1], 1.f - 0.25f * float(k), 1e-6f) << k;
  }
}

TEST(ResampleClip, ExpressionsAndBlendshapesAreInterpolatedLinearly) {
  std::vector<proxy_pose> clip(2);
  clip[0].t = 0.0;
  clip[1].t = 0.1;
  clip[0][expression::surprised] = 1.f;
  clip[1][blendshape::eye_wide_left] = 1.f;
  clip[0][blendshape::jaw_open] = 0.2f;
  clip[1][blendshape::jaw_open] = 0.6f;
  std::vector<proxy_pose> out;
  ASSERT_TRUE(resample_clip(clip, 40.0, true, out).ok());
  ASSERT_EQ(out.size(), 5u);
  for (size_t k = 0; k < out.size(); ++k) {
    const float u = 0.25f * float(k);
    EXPECT_NEAR(out[k][expression::surprised], 1.f - u, 1e-6f) << k;
    EXPECT_NEAR(out[k][blendshape::eye_wide_left], u, 1e-6f) << k;
    EXPECT_NEAR(out[k][blendshape::jaw_open], 0.2f + 0.4f * u, 1e-6f) << k;
    EXPECT_EQ(out[k][blendshape::eye_wide_right], 0.f) << k;
  }
}

TEST(ResampleClip, FloatTimesDoNotLoseTheLastFrameAndEdgeCases) {
  std::vector<proxy_pose> clip = spin_clip(30.0, 300, 0.0);
  clip.back().t = static_cast<float>(clip.back().t);  // 9.9666662 instead of 9.9666667
  std::vector<proxy_pose> out;
  ASSERT_TRUE(resample_clip(clip, 30.0, true, out).ok());
  EXPECT_EQ(out.size(), 300u);
  ASSERT_TRUE(resample_clip({}, 30.0, true, out).ok());
  EXPECT_TRUE(out.empty());
  ASSERT_TRUE(resample_clip(std::vector<proxy_pose>(1), 30.0, true, out).ok());
  EXPECT_EQ(out.size(), 1u);
}

TEST(ResampleClip, TheToleratedLastFrameIsAtTheLastKeyNotPastIt) {
  // 0.03332 s at 30 fps is 0.9996 frames: within the thousandth of tolerance, so 2 frames, and
  // the second is at the last key (+0.03332), not at 1/30 = 0.033333... past it (fuzz_vrma
  // found a clip read at 30 fps whose last frame lay past its keys).
  const std::vector<proxy_pose> clip = clip_at({5.0, 5.03332});
  std::vector<proxy_pose> out;
  ASSERT_TRUE(resample_clip(clip, 30.0, false, out).ok());
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].t, 5.0);
  EXPECT_EQ(out[1].t, 5.03332);
  ASSERT_TRUE(resample_clip(clip, 30.0, true, out).ok());
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].t, 5.03332 - 5.0);
  // Frames inside the clip keep t0 + k / fps exactly.
  EXPECT_EQ(resampled_frame_time(5.0, 6.0, 7, 30.0), 5.0 + 7.0 / 30.0);
}

TEST(ResampleClip, RefusesABadFrameRate) {
  const std::vector<proxy_pose> clip = spin_clip(30.0, 10, 0.0);
  for (double fps : {0.0, -30.0, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    std::vector<proxy_pose> out(3);
    const status s = resample_clip(clip, fps, true, out, "walk.pose.jsonl");
    ASSERT_FALSE(s.ok()) << fps;
    EXPECT_TRUE(out.empty());
    EXPECT_TRUE(contains(s.message(), "walk.pose.jsonl: the frame rate")) << s.message();
  }
  std::vector<proxy_pose> out;
  EXPECT_FALSE(resample_clip({}, 0.0, true, out).ok());  // even for an empty clip
}

TEST(ResampleClip, OutOfOrderAndNegativeSpanAreRefusedNamingTheFrame) {
  std::vector<proxy_pose> out;
  // A capture whose last frame is stamped before its first: a negative span (the old code cast
  // it to an unsigned count and aborted with std::length_error).
  status s = resample_clip(clip_at({5.0, 5.1, 5.2, 1.0}), 60.0, true, out, "cap.jsonl");
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(out.empty());
  EXPECT_TRUE(contains(s.message(),
                       "cap.jsonl: frame 3 (t = 1.000 s) is earlier than frame 2 "
                       "(t = 5.200 s)"))
      << s.message();
  EXPECT_TRUE(contains(s.message(), "time order")) << s.message();
  // Out of order in the middle only.
  s = resample_clip(clip_at({0.0, 0.2, 0.1, 0.3}), 60.0, true, out);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "frame 2")) << s.message();
  // Equal times are in order: the later frame wins.
  std::vector<proxy_pose> dup = clip_at({0.0, 0.5, 0.5, 1.0});
  dup[2].hips_position.x = 7.f;
  ASSERT_TRUE(resample_clip(dup, 2.0, true, out).ok());
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[1].hips_position.x, 7.f);
}

TEST(ResampleClip, SortingPutsAClipInOrderStably) {
  std::vector<proxy_pose> clip = clip_at({0.3, 0.1, 0.2, 0.1});
  clip[1].hips_position.x = 1.f;  // the first of the two frames at 0.1 s
  clip[3].hips_position.x = 2.f;
  EXPECT_EQ(sort_clip_by_time(clip), 2u);  // 0.3 -> 0.1 and 0.2 -> 0.1 go back
  ASSERT_EQ(clip.size(), 4u);
  EXPECT_EQ(clip[0].t, 0.1);
  EXPECT_EQ(clip[0].hips_position.x, 1.f);
  EXPECT_EQ(clip[1].t, 0.1);
  EXPECT_EQ(clip[1].hips_position.x, 2.f);
  EXPECT_EQ(clip[2].t, 0.2);
  EXPECT_EQ(clip[3].t, 0.3);
  EXPECT_EQ(sort_clip_by_time(clip), 0u);
  // NaN goes last (and resampling then refuses it) instead of breaking the sort.
  std::vector<proxy_pose> with_nan = clip_at({0.2, std::nan(""), 0.1});
  EXPECT_EQ(sort_clip_by_time(with_nan), 1u);
  EXPECT_EQ(with_nan[0].t, 0.1);
  EXPECT_EQ(with_nan[1].t, 0.2);
  EXPECT_TRUE(std::isnan(with_nan[2].t));
}

TEST(ResampleClip, NonFiniteTimesAreRefused) {
  std::vector<proxy_pose> out;
  for (double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity()}) {
    status s = resample_clip(clip_at({0.0, bad, 1.0}), 30.0, true, out, "x");
    ASSERT_FALSE(s.ok());
    EXPECT_TRUE(contains(s.message(), "x: frame 1 has no finite time")) << s.message();
    s = resample_clip(clip_at({bad}), 30.0, true, out, "x");
    EXPECT_FALSE(s.ok());
  }
}

TEST(ResampleClip, HugeSpansAreRefusedBeforeAllocating) {
  std::vector<proxy_pose> out;
  // Two frames 10^6 s apart (60 million frames at 60 fps).
  status s = resample_clip(clip_at({0.0, 1e6}), 60.0, true, out, "gap.pose.jsonl");
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(out.empty());
  EXPECT_TRUE(contains(s.message(), "gap.pose.jsonl: the frame times span 1000000.00 s"))
      << s.message();
  EXPECT_TRUE(contains(s.message(), "86400 s")) << s.message();
  // A key at 10^9 s, at any rate.
  s = resample_clip(clip_at({0.0, 1e9}), 0.001, true, out);
  EXPECT_FALSE(s.ok());
  // 1.7e308 s apart: the span overflows to +inf; the message stays short.
  s = resample_clip(clip_at({-1.7e308, 1.7e308}), 30.0, true, out);
  ASSERT_FALSE(s.ok());
  EXPECT_LT(s.message().size(), 300u) << s.message();
  EXPECT_TRUE(contains(s.message(), "inf")) << s.message();
}

TEST(ResampleClip, LimitsExactlyAtAndJustOver) {
  std::size_t count = 0;
  // The span limit: exactly 24 h passes (at 1 fps: 86401 frames), a millisecond more fails.
  ASSERT_TRUE(resampled_frame_count(10.0, 10.0 + k_max_clip_seconds, 1.0, "x", count).ok());
  EXPECT_EQ(count, 86401u);
  EXPECT_FALSE(resampled_frame_count(10.0, 10.0 + k_max_clip_seconds + 1e-3, 1.0, "x", count).ok());
  EXPECT_EQ(count, 0u);
  // The frame limit: span * fps + 1 == 2^22 passes, one frame more fails.
  const double fps = 100.0;
  const double span_at = (static_cast<double>(k_max_resampled_frames) - 1.0) / fps;  // 41943.03 s
  ASSERT_TRUE(resampled_frame_count(0.0, span_at, fps, "x", count).ok());
  EXPECT_EQ(count, k_max_resampled_frames);
  const status over = resampled_frame_count(0.0, span_at + 1.0 / fps, fps, "x", count);
  ASSERT_FALSE(over.ok());
  EXPECT_TRUE(contains(over.message(), "4194305 frames, more than the 4194304")) << over.message();
  // Real use fits: 6 hours at 120 fps and 12 hours at 60 fps.
  EXPECT_TRUE(resampled_frame_count(0.0, 6 * 3600.0, 120.0, "x", count).ok());
  EXPECT_EQ(count, 6u * 3600u * 120u + 1u);
  EXPECT_TRUE(resampled_frame_count(0.0, 12 * 3600.0, 60.0, "x", count).ok());
  // The clip's own clock may be far from 0 (wall-clock seconds); only the span counts.
  std::vector<proxy_pose> out;
  ASSERT_TRUE(resample_clip(clip_at({1.7e9, 1.7e9 + 1.0}), 30.0, true, out).ok());
  EXPECT_EQ(out.size(), 31u);
  EXPECT_DOUBLE_EQ(out.back().t, 1.0);
}

TEST(ResampleClip, ValuesAtTheFloatLimitsInterpolateFinite) {
  const float max = std::numeric_limits<float>::max();
  std::vector<proxy_pose> clip = clip_at({0.0, 1.0});
  clip[0].hips_position = glm::vec3(-max, max, -max);
  clip[1].hips_position = glm::vec3(max, -max, max);
  std::vector<proxy_pose> out;
  ASSERT_TRUE(resample_clip(clip, 4.0, true, out).ok());
  ASSERT_EQ(out.size(), 5u);
  for (const proxy_pose& p : out)
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(p.hips_position[k])) << p.t;
  EXPECT_FLOAT_EQ(out[1].hips_position.x, -0.5f * max);
  EXPECT_NEAR(out[2].hips_position.x, 0.f, 1e32f);
  EXPECT_EQ(out[4].hips_position.x, max);
}

TEST(SecondsText, StaysShortForAnyValue) {
  EXPECT_EQ(seconds_text(1.5), "1.500");
  EXPECT_EQ(seconds_text(-2.25, 1), "-2.2");
  EXPECT_EQ(seconds_text(1.7e308, 2), "1.7e+308");
  EXPECT_EQ(seconds_text(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(seconds_text(std::nan("")), "nan");
  EXPECT_LE(seconds_text(-1.7976931348623157e308, 9).size(), 20u);
  EXPECT_LE(seconds_text(999999999.123456789, 9).size(), 20u);
}

}  // namespace
}  // namespace avatarmap
