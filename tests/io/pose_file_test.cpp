#include "avatarmap/io/pose_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "support/temp_dir.hpp"

namespace avatarmap {
namespace {

namespace fs = std::filesystem;

using test::read_text;
using test::temp_dir;
using test::write_text;

bool same_bits(float a, float b) { return std::memcmp(&a, &b, 4) == 0; }

std::vector<proxy_pose> make_poses(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<proxy_pose> poses(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    proxy_pose& p = poses[static_cast<std::size_t>(i)];
    p.t = i / 30.0 + 1e-9;
    p.hips_position = glm::vec3(g(rng), 0.9f + 0.1f * g(rng), g(rng));
    for (int b = 0; b < k_bone_count; ++b) {
      if ((b + i) % 7 == 0) continue;  // some bones stay identity
      p.rotations[b] = glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
    }
    for (auto& c : p.confidence) c = u(rng);
    for (auto& e : p.expressions) e = u(rng);
    // Every third pose has no blendshapes (the writer leaves the key out), one only jawOpen.
    if (i % 3 == 1)
      for (auto& w : p.blendshapes) w = u(rng);
    else if (i % 3 == 2)
      p[blendshape::jaw_open] = u(rng);
    p.foot_contact = {u(rng), i % 3 == 0 ? 1.f : 0.f};
  }
  return poses;
}

void expect_same_pose(const proxy_pose& a, const proxy_pose& b, bool with_confidence) {
  EXPECT_EQ(a.t, b.t);
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(same_bits(a.hips_position[k], b.hips_position[k]));
  for (int i = 0; i < k_bone_count; ++i) {
    SCOPED_TRACE(std::string(bone_name(static_cast<bone>(i))));
    EXPECT_TRUE(same_bits(a.rotations[i].x, b.rotations[i].x));
    EXPECT_TRUE(same_bits(a.rotations[i].y, b.rotations[i].y));
    EXPECT_TRUE(same_bits(a.rotations[i].z, b.rotations[i].z));
    EXPECT_TRUE(same_bits(a.rotations[i].w, b.rotations[i].w));
    if (with_confidence) EXPECT_TRUE(same_bits(a.confidence[i], b.confidence[i]));
  }
  for (int e = 0; e < k_expression_count; ++e)
    EXPECT_TRUE(same_bits(a.expressions[e], b.expressions[e]));
  for (int s = 0; s < k_blendshape_count; ++s)
    EXPECT_TRUE(same_bits(a.blendshapes[s], b.blendshapes[s]))
        << blendshape_name(static_cast<blendshape>(s));
  for (int f = 0; f < 2; ++f) EXPECT_TRUE(same_bits(a.foot_contact[f], b.foot_contact[f]));
}

void round_trip(const pose_write_options& options) {
  temp_dir dir;
  const std::string path = dir.file("a.pose.jsonl");
  auto poses = make_poses(25, 5);
  pose_file_header h;
  h.fps = 30;
  {
    pose_writer w;
    ASSERT_TRUE(w.open(path, h, options).ok());
    for (auto& p : poses) ASSERT_TRUE(w.write(p).ok());
    ASSERT_TRUE(w.commit().ok());
  }
  EXPECT_EQ(dir.entries().size(), 1u);
  pose_reader r;
  ASSERT_TRUE(r.open(path).ok());
  EXPECT_TRUE(r.header().present);
  EXPECT_EQ(r.header().fps, 30.0);
  proxy_pose p;
  for (auto& e : poses) {
    ASSERT_EQ(r.next(p), read_result::frame) << r.error();
    expect_same_pose(e, p, options.write_confidence);
  }
  EXPECT_EQ(r.next(p), read_result::end);
}

TEST(pose_file, round_trip_is_bit_exact) { round_trip({}); }
TEST(pose_file, round_trip_with_confidence_and_skipped_identities) {
  pose_write_options o;
  o.write_confidence = true;
  o.skip_identity = true;
  round_trip(o);
}

TEST(pose_file, writer_format) {
  temp_dir dir;
  const std::string path = dir.file("f.pose.jsonl");
  proxy_pose p;
  p.t = 0.5;
  p[bone::left_upper_arm] = glm::quat(0.5f, 0.5f, -0.5f, 0.5f);  // w, x, y, z
  p[expression::blink_left] = 0.25f;
  pose_write_options o;
  o.skip_identity = true;
  pose_writer w;
  ASSERT_TRUE(w.open(path, {}, o).ok());
  ASSERT_TRUE(w.write(p).ok());
  ASSERT_TRUE(w.commit().ok());
  std::string text = read_text(path);
  EXPECT_EQ(text.substr(0, text.find('\n')), "{\"format\":\"avatarmap.pose\",\"version\":1}");
  EXPECT_NE(text.find("{\"t\":0.5,\"hips_position\":[0,0.95,0],\"foot_contact\":[0,0],\"bones\":{"
                      "\"leftUpperArm\":"
                      "[0.5,-0.5,0.5,0.5]},\"expressions\":{\"blink\":0,\"blinkLeft\":0.25,"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("\"surprised\":0}}\n"), std::string::npos) << text;
  // All blendshapes 0: no "blendshapes" key at all.
  EXPECT_EQ(text.find("blendshapes"), std::string::npos) << text;
}

TEST(pose_file, blendshapes_are_written_by_arkit_name_when_any_is_non_zero) {
  temp_dir dir;
  const std::string path = dir.file("b.pose.jsonl");
  proxy_pose p;
  p[blendshape::jaw_open] = 0.5f;
  p[expression::happy] = 0.75f;
  pose_writer w;
  ASSERT_TRUE(w.open(path, {}).ok());
  ASSERT_TRUE(w.write(p).ok());
  ASSERT_TRUE(w.commit().ok());
  std::string text = read_text(path);
  EXPECT_NE(text.find("\"happy\":0.75,\"angry\":0,\"sad\":0,\"relaxed\":0,\"surprised\":0},"
                      "\"blendshapes\":{\"browDownLeft\":0,\"browDownRight\":0,"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("\"jawLeft\":0,\"jawOpen\":0.5,\"jawRight\":0,"), std::string::npos) << text;
  EXPECT_NE(text.find("\"noseSneerRight\":0,\"tongueOut\":0}}\n"), std::string::npos) << text;
}

TEST(pose_file, blendshapes_and_emotions_read_by_name_missing_ones_are_zero) {
  // A file written before 0.2.0 has no "blendshapes": all 0. A partial object sets only the
  // shapes it names; stale values from the previous frame never survive.
  const std::string text =
      "{\"t\":0,\"expressions\":{\"aa\":0.5}}\n"
      "{\"t\":1,\"expressions\":{\"sad\":0.25,\"relaxed\":1},"
      "\"blendshapes\":{\"eyeBlinkRight\":0.125,\"tongueOut\":1}}\n"
      "{\"t\":2}\n";
  pose_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size()).ok());
  proxy_pose p;
  p.blendshapes.fill(0.5f);
  ASSERT_EQ(r.next(p), read_result::frame) << r.error();
  for (float w : p.blendshapes) EXPECT_EQ(w, 0.f);
  ASSERT_EQ(r.next(p), read_result::frame) << r.error();
  EXPECT_EQ(p[expression::sad], 0.25f);
  EXPECT_EQ(p[expression::relaxed], 1.f);
  EXPECT_EQ(p[blendshape::eye_blink_right], 0.125f);
  EXPECT_EQ(p[blendshape::tongue_out], 1.f);
  float sum = 0.f;
  for (float w : p.blendshapes) sum += w;
  EXPECT_EQ(sum, 1.125f);
  ASSERT_EQ(r.next(p), read_result::frame) << r.error();
  for (float w : p.blendshapes) EXPECT_EQ(w, 0.f);
  EXPECT_EQ(p[expression::sad], 0.f);
}

TEST(pose_file, foot_contact_is_optional_clamped_and_checked) {
  // An older file has none: 0, 0. Values outside [0, 1] are clamped; a wrong count or a
  // non-number is an error naming the key.
  const std::string text =
      "{\"t\":0,\"hips_position\":[0,1,0]}\n"
      "{\"t\":1,\"foot_contact\":[0.25,1]}\n"
      "{\"t\":2,\"foot_contact\":[-3,7]}\n"
      "{\"t\":3,\"foot_contact\":[1]}\n";
  pose_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size()).ok());
  proxy_pose p;
  p.foot_contact = {0.5f, 0.5f};  // stale data must be reset
  ASSERT_EQ(r.next(p), read_result::frame) << r.error();
  EXPECT_EQ(p.foot_contact[0], 0.f);
  EXPECT_EQ(p.foot_contact[1], 0.f);
  ASSERT_EQ(r.next(p), read_result::frame) << r.error();
  EXPECT_EQ(p.foot_contact[0], 0.25f);
  EXPECT_EQ(p.foot_contact[1], 1.f);
  ASSERT_EQ(r.next(p), read_result::frame) << r.error();
  EXPECT_EQ(p.foot_contact[0], 0.f);
  EXPECT_EQ(p.foot_contact[1], 1.f);
  EXPECT_EQ(r.next(p), read_result::error);
  EXPECT_NE(r.error().find("\"foot_contact\""), std::string::npos) << r.error();
}

TEST(pose_file, missing_bones_are_identity_and_quaternions_are_normalised) {
  std::string text =
      "{\"t\":1,\"bones\":{\"head\":[0,0,0,2],\"neck\":[0,3,0,4]},\"unknown\":[{}],"
      "\"expressions\":{\"aa\":0.5}}\n";
  pose_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size()).ok());
  EXPECT_FALSE(r.header().present);
  proxy_pose p;
  p[bone::hips] = glm::quat(0.f, 1.f, 0.f, 0.f);  // stale data must be reset
  ASSERT_EQ(r.next(p), read_result::frame) << r.error();
  EXPECT_EQ(p[bone::hips], glm::quat(1.f, 0.f, 0.f, 0.f));
  EXPECT_EQ(p[bone::head], glm::quat(1.f, 0.f, 0.f, 0.f));
  EXPECT_FLOAT_EQ(p[bone::neck].y, 0.6f);
  EXPECT_FLOAT_EQ(p[bone::neck].w, 0.8f);
  EXPECT_EQ(p[expression::aa], 0.5f);
  EXPECT_EQ(p.hips_position, glm::vec3(0.f, k_default_hips_height, 0.f));
}

TEST(pose_file, missing_t_uses_header_fps) {
  std::string text = "{\"format\":\"avatarmap.pose\",\"version\":1,\"fps\":10}\n{}\n{}\n";
  pose_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size()).ok());
  proxy_pose p;
  ASSERT_EQ(r.next(p), read_result::frame);
  ASSERT_EQ(r.next(p), read_result::frame);
  EXPECT_DOUBLE_EQ(p.t, 0.1);
}

TEST(pose_file, header_fps_too_small_for_the_frame_times) {
  std::string text = "{\"format\":\"avatarmap.pose\",\"fps\":1e-310}\n{}\n{}\n";
  pose_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size(), "tiny.pose.jsonl").ok());
  proxy_pose p;
  ASSERT_EQ(r.next(p), read_result::frame);
  EXPECT_EQ(p.t, 0.0);
  ASSERT_EQ(r.next(p), read_result::error);
  EXPECT_NE(r.error().find("\"fps\" is too small"), std::string::npos) << r.error();
}

TEST(pose_file, malformed_lines) {
  struct bad_case {
    std::string line;
    const char* expected;
  };
  std::vector<bad_case> cases = {
      {"{\"t\":0,\"bones\":{\"leftElbow\":[0,0,0,1]}}", "unknown bone \"leftElbow\" in \"bones\""},
      {"{\"t\":0,\"bones\":{\"hips\":[0,0,null,1]}}", "bone \"hips\" has a null value"},
      {"{\"t\":0,\"bones\":{\"spine\":[0,0,0,0]}}", "bone \"spine\" is a zero quaternion"},
      {"{\"t\":0,\"bones\":{\"spine\":[0,0,1e400,1]}}", "bone \"spine\" has a non-finite"},
      {"{\"t\":0,\"bones\":{\"spine\":[0,0,1]}}", "bone \"spine\" has 3 values"},
      {"{\"t\":0,\"bones\":{\"spine\":[0,0,1,0,0]}}", "bone \"spine\" has too many values"},
      {"{\"t\":0,\"bones\":[]}", "expected '{'"},
      {"{\"t\":0,\"expressions\":{\"smile\":1}}", "unknown expression \"smile\""},
      {"{\"t\":0,\"expressions\":{\"aa\":null}}", "expression \"aa\" is null"},
      {"{\"t\":0,\"blendshapes\":{\"mouthSmile\":1}}",
       "unknown blendshape \"mouthSmile\" in \"blendshapes\""},
      {"{\"t\":0,\"blendshapes\":{\"jawOpen\":null}}", "blendshape \"jawOpen\" is null"},
      {"{\"t\":0,\"blendshapes\":{\"jawOpen\":1e999}}", "blendshape \"jawOpen\""},
      {"{\"t\":0,\"blendshapes\":[0.5]}", "expected '{'"},
      {"{\"t\":0,\"confidence\":{\"tail\":1}}", "unknown bone \"tail\" in \"confidence\""},
      {"{\"t\":0,\"hips_position\":[0,null,0]}", "\"hips_position\" has a null value"},
      {"{\"t\":0,\"hips_position\":[0,1]}", "\"hips_position\" has 2 values"},
      {"{\"bones\":{}}", "missing \"t\""},
      {"[]", "expected '{'"},
      {"{\"t\":0,\"bones\":{\"hips\":[0,0,0,1]", "expected ',' or '}'"},
      {"{\"t\":00.5}", "not a JSON number"},
      {"{\"t\":0,\"hips_position\":[0,01,0]}", "not a JSON number"},
      {"{\"t\":0,\"x\":" + std::string(257, '[') + std::string(257, ']') + "}", "nesting too deep"},
  };
  std::string text = "{\"format\":\"avatarmap.pose\",\"version\":1}\n";
  for (auto& c : cases) text += "{\"t\":1}\n" + c.line + "\n";
  pose_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size(), "p.jsonl").ok());
  proxy_pose p;
  long line = 1;
  for (auto& c : cases) {
    SCOPED_TRACE(c.line);
    ASSERT_EQ(r.next(p), read_result::frame) << r.error();
    ++line;
    ASSERT_EQ(r.next(p), read_result::error);
    ++line;
    EXPECT_EQ(r.line(), line);
    EXPECT_EQ(r.error().rfind("p.jsonl:" + std::to_string(line) + ": ", 0), 0u) << r.error();
    EXPECT_NE(r.error().find(c.expected), std::string::npos) << r.error();
  }
  EXPECT_EQ(r.next(p), read_result::end);
}

TEST(pose_file, unknown_names_point_to_the_docs) {
  std::string text = "{\"t\":0,\"bones\":{\"Hips\":[0,0,0,1]}}";
  pose_reader r;
  ASSERT_TRUE(r.open_memory(text.data(), text.size()).ok());
  proxy_pose p;
  ASSERT_EQ(r.next(p), read_result::error);
  EXPECT_NE(r.error().find("docs/file-formats.md"), std::string::npos) << r.error();
}

TEST(pose_file, non_finite_values_are_written_as_null_and_rejected_when_read) {
  temp_dir dir;
  const std::string path = dir.file("nan.pose.jsonl");
  proxy_pose p;
  p[bone::chest].x = std::numeric_limits<float>::quiet_NaN();
  pose_writer w;
  ASSERT_TRUE(w.open(path, {}).ok());
  ASSERT_TRUE(w.write(p).ok());
  ASSERT_TRUE(w.commit().ok());
  EXPECT_NE(read_text(path).find("\"chest\":[null,0,0,1]"), std::string::npos);
  pose_reader r;
  ASSERT_TRUE(r.open(path).ok());
  proxy_pose q;
  ASSERT_EQ(r.next(q), read_result::error);
  EXPECT_NE(r.error().find("bone \"chest\" has a null value"), std::string::npos) << r.error();
}

TEST(pose_file, header_rules) {
  struct {
    std::string line;
    const char* expected;
  } bad[] = {
      {"{\"format\":\"avatarmap.landmarks\"}", "wrong format \"avatarmap.landmarks\""},
      {"{\"format\":\"avatarmap.pose\",\"version\":3}", "version 3 is newer"},
      {"{\"format\":\"avatarmap.pose\",\"fps\":null}", "\"fps\" must be"},
  };
  for (auto& b : bad) {
    pose_reader r;
    status s = r.open_memory(b.line.data(), b.line.size(), "h.pose.jsonl");
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.message().rfind("h.pose.jsonl:1: bad header line", 0), 0u) << s.message();
    EXPECT_NE(s.message().find(b.expected), std::string::npos) << s.message();
  }
}

TEST(pose_file, uncommitted_writer_leaves_the_target_untouched) {
  temp_dir dir;
  const std::string path = dir.file("t.pose.jsonl");
  std::ofstream(path) << "old\n";
  {
    pose_writer w;
    ASSERT_TRUE(w.open(path, {}).ok());
    ASSERT_TRUE(w.write(proxy_pose{}).ok());
  }
  EXPECT_EQ(read_text(path), "old\n");
  EXPECT_EQ(dir.entries().size(), 1u);
}

}  // namespace
}  // namespace avatarmap
