// Output formats by extension and the one clip writer (include/avatarmap/jobs/clip_output.hpp):
// the table is case-insensitive, an unknown extension gets one message listing the formats,
// every format is written and reads back, and a refused clip writes nothing.
#include "avatarmap/jobs/clip_output.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/export/bvh.hpp"
#include "avatarmap/export/vrma.hpp"
#include "avatarmap/io/pose_file.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "support/hostile_gltf.hpp"
#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

TEST(clip_format, extensions_match_whatever_their_case) {
  struct known {
    const char* path;
    clip_format format;
  };
  const known cases[] = {
      {"walk.vrma", clip_format::vrma},
      {"WALK.VRMA", clip_format::vrma},
      {"dir.x/a.Vrma", clip_format::vrma},
      {"a.glb", clip_format::glb},
      {"a.GLB", clip_format::glb},
      {"a.bvh", clip_format::bvh},
      {"a.BvH", clip_format::bvh},
      {"a.pose.jsonl", clip_format::pose_jsonl},
      {"a.POSE.JSONL", clip_format::pose_jsonl},
      {"a.Pose.Jsonl", clip_format::pose_jsonl},
  };
  for (const known& c : cases) {
    const clip_format_info* f = find_clip_format(c.path);
    ASSERT_NE(f, nullptr) << c.path;
    EXPECT_EQ(f->format, c.format) << c.path;
  }
  for (const char* path :
       {"a.jsonl", "a.landmarks.jsonl", "a.vrma.txt", "a.gltf", "vrma", "", "a.vrm", "a.bvh "})
    EXPECT_EQ(find_clip_format(path), nullptr) << path;
  // What each needs: only .glb needs an avatar; .glb and .bvh use one when given.
  EXPECT_TRUE(find_clip_format("a.glb")->needs_avatar);
  EXPECT_FALSE(find_clip_format("a.bvh")->needs_avatar);
  EXPECT_TRUE(find_clip_format("a.bvh")->uses_avatar);
  EXPECT_FALSE(find_clip_format("a.vrma")->uses_avatar);
  EXPECT_FALSE(find_clip_format("a.pose.jsonl")->uses_avatar);
}

TEST(clip_format, an_unknown_extension_gets_one_message_listing_the_formats) {
  EXPECT_EQ(clip_format_list(), ".vrma, .glb, .bvh or .pose.jsonl");
  const clip_format_info* f = &k_clip_formats[0];
  const status st = clip_format_for("out/walk.fbx", f);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(f, nullptr);
  EXPECT_EQ(st.message(),
            "out/walk.fbx: unknown output format; the name must end in .vrma, .glb, .bvh or "
            ".pose.jsonl (any case)");
}

// 10 frames at 30 fps from t = 2 s: the spine bends, the hips move.
std::vector<proxy_pose> test_clip() {
  std::vector<proxy_pose> frames(10);
  for (int i = 0; i < 10; ++i) {
    proxy_pose& p = frames[static_cast<std::size_t>(i)];
    p.set_rest();
    p.t = 2.0 + i / 30.0;
    p.hips_position = glm::vec3(0.01f * i, 0.9f, 0.f);
    p.rotations[idx(bone::spine)] = axis_angle(glm::vec3(1, 0, 0), 0.04f * i);
    p.expressions[idx(expression::blink)] = 0.1f * i;
  }
  return frames;
}

float angle_between(const glm::quat& a, const glm::quat& b) {
  return 2.f * std::acos(std::min(1.f, std::abs(glm::dot(a, b))));
}

class clip_output : public ::testing::Test {
 protected:
  test::temp_dir dir{"clip_output"};
  std::vector<proxy_pose> frames = test_clip();
  clip_output_job job(const std::string& name, double fps) {
    clip_output_job j;
    j.path = dir.file(name);
    j.frames = &frames;
    j.fps = fps;
    return j;
  }
};

TEST_F(clip_output, vrma_reads_back_at_its_own_times_or_resampled) {
  clip_output_summary s;
  clip_output_job j = job("own.VRMA", 0.0);
  ASSERT_TRUE(j.run(s).ok());
  EXPECT_EQ(s.format->format, clip_format::vrma);
  EXPECT_EQ(s.frames_written, 10u);
  vrma_clip clip;
  status st = read_vrma(j.path, clip);
  ASSERT_TRUE(st.ok()) << st.message();
  ASSERT_EQ(clip.frames.size(), 10u);
  for (std::size_t i = 0; i < 10; ++i) {
    EXPECT_NEAR(clip.frames[i].t, i / 30.0, 1e-5);  // starts at 0
    EXPECT_LT(angle_between(clip.frames[i].rotations[idx(bone::spine)],
                            frames[i].rotations[idx(bone::spine)]),
              1e-3f);
  }
  // At 60 fps: 0.3 s -> 19 frames, the odd ones halfway between the clip's.
  j = job("sixty.vrma", 60.0);
  ASSERT_TRUE(j.run(s).ok());
  EXPECT_EQ(s.frames_written, 19u);
  ASSERT_TRUE(read_vrma(j.path, clip).ok());
  ASSERT_EQ(clip.frames.size(), 19u);
  EXPECT_LT(angle_between(clip.frames[3].rotations[idx(bone::spine)],
                          axis_angle(glm::vec3(1, 0, 0), 0.06f)),
            1e-3f);
}

TEST_F(clip_output, pose_jsonl_reads_back_with_its_header_fps) {
  clip_output_summary s;
  clip_output_job j = job("own.pose.jsonl", 0.0);
  j.source_fps = 25.0;
  ASSERT_TRUE(j.run(s).ok());
  pose_reader reader;
  ASSERT_TRUE(reader.open(j.path).ok());
  EXPECT_DOUBLE_EQ(reader.header().fps, 25.0);  // source_fps at fps 0
  std::vector<proxy_pose> got;
  proxy_pose p;
  while (reader.next(p) == read_result::frame) got.push_back(p);
  ASSERT_EQ(got.size(), 10u);
  EXPECT_NEAR(got[9].t, 2.3, 1e-6);  // own times, not rebased
  EXPECT_NEAR(got[9].expressions[idx(expression::blink)], 0.9f, 1e-6f);

  j = job("fifteen.Pose.Jsonl", 15.0);
  ASSERT_TRUE(j.run(s).ok());
  ASSERT_TRUE(reader.open(j.path).ok());
  EXPECT_DOUBLE_EQ(reader.header().fps, 15.0);
  got.clear();
  while (reader.next(p) == read_result::frame) got.push_back(p);
  ASSERT_EQ(got.size(), 5u);  // 0.3 s at 15 fps
  EXPECT_NEAR(got[4].t, 4 / 15.0, 1e-6);
  EXPECT_NEAR(got[4].hips_position.x, 0.08f, 1e-5f);
}

TEST_F(clip_output, proxy_bvh_reads_back) {
  clip_output_summary s;
  clip_output_job j = job("proxy.bvh", 30.0);
  ASSERT_TRUE(j.run(s).ok());
  bvh_clip clip;
  const status st = read_bvh(j.path, clip);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(clip.frame_count, 10);
  EXPECT_NEAR(clip.frame_time, 1.0 / 30.0, 1e-9);
  ASSERT_FALSE(clip.joints.empty());
  EXPECT_EQ(clip.joints[0].name, "hips");
  // Root position in centimetres.
  EXPECT_NEAR(clip.position(9, 0).x, 9.f, 1e-3f);
  EXPECT_NEAR(clip.position(9, 0).y, 90.f, 1e-3f);
}

// The minimal VRM 1.0 avatar of the hostile-glTF tests: hips at 1 m and a spine.
struct small_avatar {
  std::string path;
  rig r;
};

small_avatar write_avatar(const test::temp_dir& dir) {
  small_avatar a;
  a.path = dir.file("avatar.vrm");
  test::write_text(a.path, test::make_glb(test::minimal_vrm1()));
  raw_rig raw;
  status st = load_avatar(a.path, raw);
  EXPECT_TRUE(st.ok()) << st.message();
  st = build_rig(raw, a.r);
  EXPECT_TRUE(st.ok()) << st.message();
  return a;
}

TEST_F(clip_output, avatar_outputs_write_the_rig_at_the_default_rate) {
  const small_avatar a = write_avatar(dir);
  for (const char* name : {"rig.bvh", "rig.GLB"}) {
    clip_output_job j = job(name, 0.0);
    j.avatar_path = a.path;
    j.avatar_rig = &a.r;
    j.avatar_binding = a.r.declared_humanoid;
    std::vector<rig_pose> poses;
    j.out_rig_poses = &poses;
    clip_output_summary s;
    const status st = j.run(s);
    ASSERT_TRUE(st.ok()) << st.message();
    EXPECT_DOUBLE_EQ(s.fps, k_default_rig_fps);
    EXPECT_EQ(s.frames_written, 10u);  // 0.3 s at 30 fps
    EXPECT_FLOAT_EQ(s.standing_hips_height, 0.9f);
    ASSERT_EQ(poses.size(), 10u);
    ASSERT_TRUE(std::filesystem::exists(j.path)) << name;
  }
  bvh_clip clip;
  ASSERT_TRUE(read_bvh(dir.file("rig.bvh"), clip).ok());
  EXPECT_EQ(clip.frame_count, 10);
  EXPECT_EQ(clip.joints[0].name, "hips");  // the avatar's joints, not the 55 proxy bones
  EXPECT_LT(clip.joints.size(), 5u);
  // The .glb is the avatar with an animation: it loads as an avatar again.
  raw_rig raw;
  const status st = load_avatar(dir.file("rig.GLB"), raw);
  ASSERT_TRUE(st.ok()) << st.message();
}

TEST_F(clip_output, refusals_name_the_file_and_write_nothing) {
  test::write_text(dir.file("keep.vrma"), "precious");
  const std::vector<proxy_pose> none;
  std::vector<proxy_pose> day = test_clip();
  day.back().t = 2.0 + 1e6;
  struct refusal {
    const char* name;
    double fps;
    const std::vector<proxy_pose>* frames;
    const char* words;
  };
  const refusal cases[] = {
      {"keep.txt", 0.0, &frames, ".vrma, .glb, .bvh or .pose.jsonl"},
      {"keep.vrma", -1.0, &frames, "fps"},
      {"keep.vrma", NAN, &frames, "fps"},
      {"keep.vrma", 1001.0, &frames, "fps"},
      {"keep.vrma", 0.0, &none, "no frames"},
      {"keep.glb", 30.0, &frames, "needs an avatar"},
      {"keep.vrma", 0.0, &day, "more than a clip may span (86400 s = 24 h)"},
      {"keep.pose.jsonl", 0.0, &day, "86400 s"},
  };
  for (const refusal& c : cases) {
    clip_output_job j = job(c.name, c.fps);
    j.frames = c.frames;
    EXPECT_FALSE(j.validate().ok()) << c.name;
    clip_output_summary s;
    const status st = j.run(s);
    ASSERT_FALSE(st.ok()) << c.name;
    EXPECT_EQ(st.code(), status_code::invalid_argument) << c.name;
    EXPECT_NE(st.message().find(j.path), std::string::npos) << st.message();
    EXPECT_NE(st.message().find(c.words), std::string::npos) << st.message();
  }
  // Messages about the times name `what` (the input) when given.
  clip_output_job j = job("keep.vrma", 0.0);
  j.frames = &day;
  j.what = "gap.landmarks.jsonl";
  EXPECT_EQ(j.validate().message().rfind("gap.landmarks.jsonl: the frame times span", 0), 0u)
      << j.validate().message();
  // A folder that does not exist: an output error naming the file.
  clip_output_job k = job("no-such-dir/x.bvh", 0.0);
  clip_output_summary s;
  const status st = k.run(s);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::io);
  EXPECT_NE(st.message().find("no-such-dir/x.bvh"), std::string::npos) << st.message();
  EXPECT_EQ(test::read_text(dir.file("keep.vrma")), "precious");
  for (const std::string& e : dir.entries()) EXPECT_EQ(e, "keep.vrma");
}

TEST_F(clip_output, out_of_order_frames_are_refused_when_resampling_and_kept_as_read_otherwise) {
  std::swap(frames[3], frames[4]);
  clip_output_summary s;
  clip_output_job j = job("sorted.vrma", 30.0);
  status st = j.run(s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("frame 4"), std::string::npos) << st.message();
  // .pose.jsonl at fps 0 passes the frames through as they are.
  j = job("as_read.pose.jsonl", 0.0);
  st = j.run(s);
  ASSERT_TRUE(st.ok()) << st.message();
  pose_reader reader;
  ASSERT_TRUE(reader.open(j.path).ok());
  proxy_pose p;
  for (int i = 0; i < 4; ++i) ASSERT_EQ(reader.next(p), read_result::frame);
  EXPECT_NEAR(p.t, frames[3].t, 1e-9);
}

}  // namespace
}  // namespace avatarmap
