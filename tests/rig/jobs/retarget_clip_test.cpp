// Retargeting a clip (include/avatarmap/jobs/retarget_clip.hpp): the standing hips height is
// the 90th percentile of the clip's hips heights and must be a finite height above the floor;
// the job gives what a retargeter built with that height gives frame by frame.
#include "avatarmap/jobs/retarget_clip.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "avatarmap/core/rotation.hpp"

namespace avatarmap {
namespace {

std::vector<proxy_pose> clip_with_heights(const std::vector<float>& heights) {
  std::vector<proxy_pose> frames(heights.size());
  for (std::size_t i = 0; i < heights.size(); ++i) {
    frames[i].set_rest();
    frames[i].t = static_cast<double>(i) / 30.0;
    frames[i].hips_position = glm::vec3(0.01f * static_cast<float>(i), heights[i], 0.f);
  }
  return frames;
}

TEST(standing_hips_height, is_the_90th_percentile_whatever_the_order) {
  // 20 heights 0.05 .. 1.00 shuffled: sorted, index 20 * 9 / 10 = 18 holds 0.95.
  std::vector<float> h;
  for (int i = 1; i <= 20; ++i) h.push_back(0.05f * static_cast<float>(i));
  std::mt19937 rng(3);
  std::shuffle(h.begin(), h.end(), rng);
  float out = 0.f;
  ASSERT_TRUE(standing_hips_height(clip_with_heights(h), "clip", out).ok());
  EXPECT_FLOAT_EQ(out, 0.95f);
  // 10 frames: index 9, the highest. One frame: itself.
  ASSERT_TRUE(standing_hips_height(
                  clip_with_heights({0.5f, 0.9f, 0.1f, 0.2f, 0.3f, 0.4f, 0.6f, 0.7f, 0.8f, 0.85f}),
                  "clip", out)
                  .ok());
  EXPECT_FLOAT_EQ(out, 0.9f);
  ASSERT_TRUE(standing_hips_height(clip_with_heights({0.93f}), "clip", out).ok());
  EXPECT_FLOAT_EQ(out, 0.93f);
  // A squat (low heights) and one outlier below the floor do not move it.
  std::vector<float> squats(100, 0.95f);
  for (int i = 0; i < 40; ++i) squats[static_cast<std::size_t>(i)] = 0.5f;
  squats[50] = -3.f;
  ASSERT_TRUE(standing_hips_height(clip_with_heights(squats), "clip", out).ok());
  EXPECT_FLOAT_EQ(out, 0.95f);
}

TEST(standing_hips_height, refuses_no_frames_and_heights_that_are_not_above_the_floor) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  struct bad {
    std::vector<float> heights;
    const char* words;
  };
  const bad cases[] = {
      {{}, "no frames"},
      {std::vector<float>(10, 0.f), "standing hips height"},
      {std::vector<float>(10, -0.9f), "standing hips height"},
      {std::vector<float>(10, nan), "standing hips height"},
      {std::vector<float>(10, inf), "standing hips height"},
      // NaN sorts last: with 2 of 10 frames NaN, index 9 is NaN.
      {{0.9f, 0.9f, 0.9f, 0.9f, 0.9f, 0.9f, 0.9f, 0.9f, nan, nan}, "standing hips height"},
  };
  for (const bad& c : cases) {
    float out = 1.f;
    const status st = standing_hips_height(clip_with_heights(c.heights), "walk.pose.jsonl", out);
    ASSERT_FALSE(st.ok()) << c.words;
    EXPECT_EQ(out, 0.f);
    EXPECT_EQ(st.message().rfind("walk.pose.jsonl: ", 0), 0u) << st.message();
    EXPECT_NE(st.message().find(c.words), std::string::npos) << st.message();
  }
  // One NaN among 20 frames ranks last, above index 18: the percentile is a real height.
  std::vector<float> h(20, 0.9f);
  h[4] = nan;
  float out = 0.f;
  EXPECT_TRUE(standing_hips_height(clip_with_heights(h), "clip", out).ok());
  EXPECT_FLOAT_EQ(out, 0.9f);
}

// A small humanoid rig: hips at 1 m, a spine, two legs with feet on the floor.
rig small_rig() {
  raw_rig raw;
  raw.source = rig_source::test;
  auto add = [&raw](const char* name, int parent, glm::vec3 t, bone b) {
    raw_rig::node n;
    n.name = name;
    n.parent = parent;
    n.rest.translation = t;
    raw.nodes.push_back(n);
    const int i = static_cast<int>(raw.nodes.size()) - 1;
    raw.declared_humanoid[idx(b)] = i;
    return i;
  };
  const int hips = add("hips", -1, {0.f, 1.f, 0.f}, bone::hips);
  add("spine", hips, {0.f, 0.1f, 0.f}, bone::spine);
  const int lu = add("l_up", hips, {0.1f, -0.05f, 0.f}, bone::left_upper_leg);
  const int ll = add("l_low", lu, {0.f, -0.45f, 0.f}, bone::left_lower_leg);
  add("l_foot", ll, {0.f, -0.5f, 0.f}, bone::left_foot);
  const int ru = add("r_up", hips, {-0.1f, -0.05f, 0.f}, bone::right_upper_leg);
  const int rl = add("r_low", ru, {0.f, -0.45f, 0.f}, bone::right_lower_leg);
  add("r_foot", rl, {0.f, -0.5f, 0.f}, bone::right_foot);
  rig r;
  const status st = build_rig(raw, r);
  EXPECT_TRUE(st.ok()) << st.message();
  return r;
}

std::vector<proxy_pose> moving_clip(int n) {
  std::vector<proxy_pose> frames(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    proxy_pose& p = frames[static_cast<std::size_t>(i)];
    p.set_rest();
    p.t = i / 30.0;
    p.hips_position = glm::vec3(0.02f * i, 0.8f + 0.01f * static_cast<float>(i % 7), 0.1f);
    p.rotations[idx(bone::spine)] = axis_angle(glm::vec3(1, 0, 0), 0.05f * i);
    p.rotations[idx(bone::left_upper_leg)] = axis_angle(glm::vec3(0, 0, 1), -0.03f * i);
  }
  return frames;
}

TEST(retarget_clip_job, gives_what_a_retargeter_at_the_standing_height_gives) {
  const rig r = small_rig();
  const std::vector<proxy_pose> frames = moving_clip(30);
  for (bool ground : {false, true}) {
    retarget_clip_job job;
    job.frames = &frames;
    job.target = &r;
    job.binding = r.declared_humanoid;
    job.keep_feet_on_ground = ground;
    std::vector<rig_pose> got;
    float height = 0.f;
    const status st = job.run(got, &height);
    ASSERT_TRUE(st.ok()) << st.message();
    EXPECT_EQ(st.code(), status_code::ok);

    // Independent reference: heights sorted by hand, the value at index n * 9 / 10.
    std::vector<float> h;
    for (const proxy_pose& p : frames) h.push_back(p.hips_position.y);
    std::sort(h.begin(), h.end());
    EXPECT_FLOAT_EQ(height, h[h.size() * 9 / 10]);
    retarget_options ro;
    ro.performer_hips_height = h[h.size() * 9 / 10];
    ro.keep_feet_on_ground = ground;
    retargeter rt;
    ASSERT_TRUE(rt.build(r, r.declared_humanoid, ro).ok());
    ASSERT_EQ(got.size(), frames.size());
    for (std::size_t i = 0; i < frames.size(); ++i) {
      rig_pose want;
      rt.prepare(want);
      rt.apply(frames[i], want);
      EXPECT_EQ(got[i].hips_joint, want.hips_joint);
      EXPECT_EQ(got[i].hips_translation, want.hips_translation) << "frame " << i;
      ASSERT_EQ(got[i].local_rotations.size(), want.local_rotations.size());
      for (std::size_t j = 0; j < want.local_rotations.size(); ++j)
        EXPECT_EQ(got[i].local_rotations[j], want.local_rotations[j]) << "frame " << i;
    }
  }
}

TEST(retarget_clip_job, refuses_a_clip_without_height_unless_root_motion_is_off) {
  const rig r = small_rig();
  std::vector<proxy_pose> frames = moving_clip(10);
  for (proxy_pose& p : frames) p.hips_position.y = 0.f;
  retarget_clip_job job;
  job.frames = &frames;
  job.target = &r;
  job.binding = r.declared_humanoid;
  job.what = "flat.vrma";
  std::vector<rig_pose> got(3);
  status st = job.run(got);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::invalid_argument);
  EXPECT_NE(st.message().find("flat.vrma"), std::string::npos) << st.message();
  EXPECT_TRUE(got.empty());
  // Without root motion the height is not used: the hips keep their rest translation.
  job.root_motion = false;
  st = job.run(got);
  ASSERT_TRUE(st.ok()) << st.message();
  ASSERT_EQ(got.size(), frames.size());
  EXPECT_EQ(got[5].hips_translation,
            r.rest_local[static_cast<std::size_t>(got[5].hips_joint)].translation);
}

TEST(retarget_clip_job, validate_names_each_broken_field) {
  const rig r = small_rig();
  const std::vector<proxy_pose> frames = moving_clip(3);
  const std::vector<proxy_pose> none;
  auto good = [&] {
    retarget_clip_job j;
    j.frames = &frames;
    j.target = &r;
    j.binding = r.declared_humanoid;
    return j;
  };
  ASSERT_TRUE(good().validate().ok());
  retarget_clip_job j = good();
  j.frames = nullptr;
  EXPECT_NE(j.validate().message().find("frames"), std::string::npos);
  j = good();
  j.frames = &none;
  EXPECT_NE(j.validate().message().find("no frames"), std::string::npos);
  j = good();
  j.target = nullptr;
  EXPECT_NE(j.validate().message().find("target"), std::string::npos);
  j = good();
  j.binding[idx(bone::spine)] = r.joint_count();
  EXPECT_NE(j.validate().message().find("binding[spine]"), std::string::npos)
      << j.validate().message();
  // A binding the retargeter refuses (no hips) is a parse-class failure, naming the problem.
  j = good();
  j.binding[idx(bone::hips)] = -1;
  std::vector<rig_pose> out;
  const status st = j.run(out);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::parse);
  EXPECT_NE(st.message().find("hips"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace avatarmap
