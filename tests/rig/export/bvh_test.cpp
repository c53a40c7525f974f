// Tests of the BVH writer and reader (include/avatarmap/export/bvh.hpp).
#include "avatarmap/export/bvh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

using namespace avatarmap;

namespace {

// Angle (degrees) between two rotations: 2 atan2(|v|, |w|) of a⁻¹ b in double (acos of a
// dot product is ill-conditioned near 0 and would report float rounding as ~0.05 degrees).
double angle_deg(const glm::quat& a, const glm::quat& b) {
  glm::dquat da(a.w, a.x, a.y, a.z), db(b.w, b.x, b.y, b.z);
  glm::dquat r = glm::conjugate(glm::normalize(da)) * glm::normalize(db);
  return 2.0 * std::atan2(glm::length(glm::dvec3(r.x, r.y, r.z)), std::abs(r.w)) * 180.0 /
         3.14159265358979323846;
}

int joint_index(const bvh_clip& clip, const std::string& name) {
  for (std::size_t i = 0; i < clip.joints.size(); ++i)
    if (clip.joints[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace

TEST(bvh, write_read_round_trip) {
  std::mt19937 rng(11);
  std::normal_distribution<float> n(0.f, 1.f);
  std::vector<proxy_pose> frames(30);
  for (int f = 0; f < 30; ++f) {
    frames[f].t = f / 60.0;
    for (int b = 0; b < k_bone_count; ++b)
      frames[f].rotations[b] = glm::normalize(glm::quat(n(rng), n(rng), n(rng), n(rng)));
    frames[f].hips_position = glm::vec3(0.1f * n(rng), 0.9f + 0.05f * n(rng), 0.1f * n(rng));
  }
  // Gimbal lock (X = +-90 degrees) and the identity.
  frames[0][bone::spine] = axis_angle(glm::vec3(1, 0, 0), 0.5f * k_pi);
  frames[0][bone::chest] =
      axis_angle(glm::vec3(1, 0, 0), -0.5f * k_pi) * axis_angle(glm::vec3(0, 1, 0), 0.3f);
  frames[0][bone::neck] = glm::quat(1.f, 0.f, 0.f, 0.f);

  for (bvh_units units : {bvh_units::centimetres, bvh_units::metres}) {
    test::temp_dir dir("bvh");
    std::string path = dir.file("out.bvh");
    bvh_write_options opt;
    opt.units = units;
    status s = write_bvh(path, frames, opt);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(dir.entries().size(), 1u);
    bvh_clip clip;
    s = read_bvh(path, clip);
    ASSERT_TRUE(s.ok()) << s.message();
    ASSERT_EQ(clip.joints.size(), static_cast<std::size_t>(k_bone_count));
    EXPECT_EQ(clip.frame_count, 30);
    EXPECT_NEAR(clip.frame_time, 1.0 / 60.0, 1e-9);
    EXPECT_EQ(clip.channel_count, 6 + 3 * (k_bone_count - 1));
    const float scale = units == bvh_units::centimetres ? 100.f : 1.f;
    proxy_skeleton sk = make_proxy_skeleton();
    double worst = 0.0;
    for (int b = 0; b < k_bone_count; ++b) {
      int j = joint_index(clip, std::string(bone_name(static_cast<bone>(b))));
      ASSERT_GE(j, 0);
      int p = bone_parent(b);
      EXPECT_EQ(
          clip.joints[j].parent,
          p == k_no_parent ? -1 : joint_index(clip, std::string(bone_name(static_cast<bone>(p)))));
      glm::vec3 expect_offset = p == k_no_parent ? glm::vec3(0.f) : sk.offsets[b] * scale;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(clip.joints[j].offset[c], expect_offset[c], 1e-5f);
      for (int f = 0; f < 30; ++f)
        worst = std::max(worst, angle_deg(clip.local_rotation(f, j), frames[f].rotations[b]));
    }
    EXPECT_LT(worst, 0.01);
    std::printf("[ bvh ] max rotation error %.3g degrees\n", worst);
    for (int f = 0; f < 30; ++f)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(clip.position(f, 0)[c], frames[f].hips_position[c] * scale, 1e-5f * scale);
    // Leaves have End Sites, inner joints not.
    EXPECT_TRUE(clip.joints[joint_index(clip, "head")].has_end_site == false);
    EXPECT_TRUE(clip.joints[joint_index(clip, "leftToes")].has_end_site);
    EXPECT_TRUE(clip.joints[joint_index(clip, "jaw")].has_end_site);
  }
}

TEST(bvh, resamples_at_fixed_fps) {
  std::vector<proxy_pose> frames(2);
  frames[0].t = 5.0;
  frames[1].t = 6.0;
  frames[1][bone::spine] = axis_angle(glm::vec3(0, 0, 1), 1.f);
  bvh_write_options opt;
  opt.fps = 10.0;
  test::temp_dir dir("bvh");
  std::string path = dir.file("r.bvh");
  ASSERT_TRUE(write_bvh(path, frames, opt).ok());
  bvh_clip clip;
  ASSERT_TRUE(read_bvh(path, clip).ok());
  EXPECT_EQ(clip.frame_count, 11);
  EXPECT_NEAR(clip.frame_time, 0.1, 1e-9);
  EXPECT_NEAR(rotation_angle(clip.local_rotation(5, joint_index(clip, "spine"))), 0.5f, 1e-5f);
}

TEST(bvh, cmu_clips_parse) {
  std::string dir = test::test_data_path("motion/cmu-bvh");
  if (dir.empty()) GTEST_SKIP() << test::k_no_test_data;
  for (const char* name : {"131_01.bvh", "131_02.bvh", "131_03.bvh"}) {
    bvh_clip clip;
    status s = read_bvh(dir + "/" + name, clip);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(clip.joints.size(), 31u) << name;
    EXPECT_NEAR(1.0 / clip.frame_time, 120.0, 0.01) << name;
    EXPECT_GT(clip.frame_count, 0);
    EXPECT_EQ(clip.values.size(), static_cast<std::size_t>(clip.frame_count) * clip.channel_count);
    EXPECT_EQ(clip.joints[0].name, "Hips");
    EXPECT_EQ(clip.joints[0].channels.size(), 6u);
  }
}

TEST(bvh, malformed_files_give_errors) {
  test::temp_dir dir("bvh");
  bvh_clip clip;
  auto expect_error = [&](const std::string& name, const std::string& content,
                          const std::string& words) {
    std::string path = dir.file(name);
    test::write_text(path, content);
    status s = read_bvh(path, clip);
    EXPECT_FALSE(s.ok()) << name;
    EXPECT_NE(s.message().find(path), std::string::npos) << s.message();
    if (!words.empty()) EXPECT_NE(s.message().find(words), std::string::npos) << s.message();
  };
  EXPECT_FALSE(read_bvh(dir.file("missing.bvh"), clip).ok());
  expect_error("empty.bvh", "", "empty");
  std::mt19937 rng(2);
  std::string noise(2000, '\0');
  for (char& c : noise) c = static_cast<char>(rng());
  expect_error("noise.bvh", noise, "");
  std::vector<proxy_pose> frames(4);
  for (int f = 0; f < 4; ++f) frames[f].t = f * 0.1;
  std::string good_path = dir.file("good.bvh");
  ASSERT_TRUE(write_bvh(good_path, frames).ok());
  std::string good = test::read_text(good_path);
  expect_error("cut_motion.bvh", good.substr(0, good.size() - 40), "truncated MOTION");
  expect_error("cut_hier.bvh", good.substr(0, good.find("MOTION") / 2), "");
  std::string bad_channel = good;
  bad_channel.replace(bad_channel.find("Zrotation"), 9, "Wrotation");
  expect_error("channel.bvh", bad_channel, "unknown channel");
  // Hostile numbers and sizes (issue 8): doubles beyond the float range, non-finite tokens, a
  // "Frames:" line far larger than the file, deep nesting: errors, not infinities or huge
  // allocations.
  auto with_value = [&](const std::string& value) {
    std::string text = good;
    const std::size_t frame_time = text.find("Frame Time:");
    const std::size_t line_end = text.find('\n', frame_time);
    const std::size_t first_value_end = text.find(' ', line_end + 1);
    text.replace(line_end + 1, first_value_end - line_end - 1, value);
    return text;
  };
  expect_error("value_1e300.bvh", with_value("1e300"), "within the float range");
  expect_error("value_nan.bvh", with_value("nan"), "bad motion value \"nan\"");
  expect_error("value_inf.bvh", with_value("-inf"), "bad motion value");
  std::string big_offset = good;
  big_offset.replace(big_offset.find("OFFSET") + 7, 1, "1e39 ");
  expect_error("offset_1e39.bvh", big_offset, "within the float range");
  std::string many = good;
  const std::size_t frames_at = many.find("Frames:");
  many.replace(frames_at, many.find('\n', frames_at) - frames_at, "Frames: 1000000");
  expect_error("many_frames.bvh", many, "need 168000000 values, but the rest of the file holds");
  std::string too_many = good;
  too_many.replace(frames_at, too_many.find('\n', frames_at) - frames_at, "Frames: 1e12");
  expect_error("too_many_frames.bvh", too_many, "Frames: expects a whole number");
  auto nested = [](int levels) {
    std::string t = "HIERARCHY\nROOT j0\n{\nOFFSET 0 0 0\nCHANNELS 0\n";
    for (int i = 1; i < levels; ++i) t += "JOINT j" + std::to_string(i) + "\n{\nOFFSET 0 1 0\n";
    t += "End Site\n{\nOFFSET 0 1 0\n}\n";
    for (int i = 0; i < levels; ++i) t += "}\n";
    return t + "MOTION\nFrames: 1\nFrame Time: 0.1\n\n";
  };
  test::write_text(dir.file("deep256.bvh"), nested(256));
  status deep_ok = read_bvh(dir.file("deep256.bvh"), clip);
  EXPECT_TRUE(deep_ok.ok()) << deep_ok.message();
  EXPECT_EQ(clip.joints.size(), 256u);
  expect_error("deep257.bvh", nested(257), "nested deeper than 256 levels");
  expect_error("deep100k.bvh", nested(100000), "nested deeper than 256 levels");
  for (int trial = 0; trial < 300; ++trial) {
    std::string bad = good.substr(0, rng() % good.size());
    for (int k = 0; k < 4 && !bad.empty(); ++k) bad[rng() % bad.size()] = static_cast<char>(rng());
    std::string path = dir.file("fuzz.bvh");
    test::write_text(path, bad);
    (void)read_bvh(path, clip);  // must not crash
  }
}
