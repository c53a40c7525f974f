// Tests of the .vrma reader and writer (include/avatarmap/export/vrma.hpp): the shared clips
// read -> write -> read, synthetic poses write -> read, interpolation modes, malformed files.
#include "avatarmap/export/vrma.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "avatarmap/core/rotation.hpp"
#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

using namespace avatarmap;

namespace {

glm::quat random_unit_quat(std::mt19937& rng) {
  std::normal_distribution<float> n(0.f, 1.f);
  glm::quat q(n(rng), n(rng), n(rng), n(rng));
  return glm::normalize(q);
}

// Angle (degrees) between two rotations: 2 atan2(|v|, |w|) of a⁻¹ b in double (acos of a
// dot product is ill-conditioned near 0 and would report float rounding as ~0.05 degrees).
double angle_deg(const glm::quat& a, const glm::quat& b) {
  glm::dquat da(a.w, a.x, a.y, a.z), db(b.w, b.x, b.y, b.z);
  glm::dquat r = glm::conjugate(glm::normalize(da)) * glm::normalize(db);
  return 2.0 * std::atan2(glm::length(glm::dvec3(r.x, r.y, r.z)), std::abs(r.w)) * 180.0 /
         3.14159265358979323846;
}

std::uint32_t get_u32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i)
    v |= static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + i])) << (8 * i);
  return v;
}
void put_u32(std::string& s, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xffu));
}

// Splits a GLB into its JSON and BIN chunks (the test's own, independent of the writer).
bool split_glb(const std::string& glb, nlohmann::json& doc, std::string& bin) {
  if (glb.size() < 20 || get_u32(glb, 0) != 0x46546C67u) return false;
  std::uint32_t jl = get_u32(glb, 12);
  doc = nlohmann::json::parse(glb.substr(20, jl));
  std::size_t at = 20 + jl;
  bin.clear();
  if (at + 8 <= glb.size()) bin = glb.substr(at + 8, get_u32(glb, at));
  return true;
}

std::string make_glb(const nlohmann::json& doc, const std::string& bin) {
  std::string text = doc.dump(), b = bin;
  while (text.size() % 4) text.push_back(' ');
  while (b.size() % 4) b.push_back('\0');
  std::string glb;
  put_u32(glb, 0x46546C67u);
  put_u32(glb, 2u);
  put_u32(glb, static_cast<std::uint32_t>(12 + 8 + text.size() + (b.empty() ? 0 : 8 + b.size())));
  put_u32(glb, static_cast<std::uint32_t>(text.size()));
  put_u32(glb, 0x4E4F534Au);
  glb += text;
  if (!b.empty()) {
    put_u32(glb, static_cast<std::uint32_t>(b.size()));
    put_u32(glb, 0x004E4942u);
    glb += b;
  }
  return glb;
}

std::vector<proxy_pose> random_sequence(std::mt19937& rng, int n, double dt) {
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<proxy_pose> frames(n);
  for (int f = 0; f < n; ++f) {
    proxy_pose& p = frames[f];
    p.t = f * dt;
    for (int b = 0; b < k_bone_count; ++b) p.rotations[b] = random_unit_quat(rng);
    p.hips_position = glm::vec3(u(rng) - 0.5f, 0.8f + 0.2f * u(rng), u(rng) - 0.5f);
    for (int e = 0; e < k_expression_count; ++e) p.expressions[e] = u(rng);
    for (int sh = 0; sh < k_blendshape_count; ++sh) p.blendshapes[sh] = u(rng);
  }
  return frames;
}

// Max rotation error (degrees) over all frames and all .vrma bones; checks times, hips and
// expressions on the way.
double compare_clips(const vrma_clip& a, const vrma_clip& b) {
  EXPECT_EQ(a.frames.size(), b.frames.size());
  double worst = 0.0;
  for (std::size_t f = 0; f < std::min(a.frames.size(), b.frames.size()); ++f) {
    const proxy_pose& pa = a.frames[f];
    const proxy_pose& pb = b.frames[f];
    EXPECT_NEAR(pa.t, pb.t, 1e-6) << "frame " << f;
    for (int i = 0; i < k_bone_count; ++i) {
      if (!is_vrma_bone(static_cast<bone>(i))) continue;
      worst = std::max(worst, angle_deg(pa.rotations[i], pb.rotations[i]));
    }
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(pa.hips_position[c], pb.hips_position[c], 1e-5) << "frame " << f;
    for (int e = 0; e < k_expression_count; ++e)
      EXPECT_NEAR(pa.expressions[e], pb.expressions[e], 1e-6) << "frame " << f << " expr " << e;
    for (int sh = 0; sh < k_blendshape_count; ++sh)
      EXPECT_NEAR(pa.blendshapes[sh], pb.blendshapes[sh], 1e-6) << "frame " << f << " shape " << sh;
    EXPECT_EQ(a.has_look_at, b.has_look_at);
    if (a.has_look_at && b.has_look_at)
      worst = std::max(worst, angle_deg(pa[bone::left_eye], pb[bone::left_eye]));
  }
  return worst;
}

}  // namespace

// ---- shared clips: read -> write -> read ------------------------------------------------

class vrma_shared_clip : public ::testing::TestWithParam<const char*> {};

TEST_P(vrma_shared_clip, round_trip_within_a_tenth_of_a_degree) {
  std::string path = test::test_data_path(std::string("avatars/") + GetParam() + ".vrma");
  if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
  vrma_clip first;
  status s = read_vrma(path, first);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_FALSE(first.frames.empty());
  EXPECT_TRUE(first.has_bone[idx(bone::hips)]);
  EXPECT_GT(first.duration, 0.0);
  for (const proxy_pose& p : first.frames)
    for (int b = 0; b < k_bone_count; ++b) {
      ASSERT_TRUE(is_finite(p.rotations[b]));
      ASSERT_NEAR(glm::length(p.rotations[b]), 1.f, 1e-5f);
    }

  test::temp_dir dir("vrma");
  std::string out = dir.file("copy.vrma");
  s = write_vrma(out, first.frames, {});
  ASSERT_TRUE(s.ok()) << s.message();
  vrma_clip second;
  s = read_vrma(out, second);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(second.generator, "avatarmap");
  double worst = compare_clips(first, second);
  std::printf("[ round trip ] %s: %zu frames, %d bones, max rotation error %.3g degrees\n",
              GetParam(), first.frames.size(),
              static_cast<int>(std::count(first.has_bone.begin(), first.has_bone.end(), true)),
              worst);
  RecordProperty("max_error_degrees", std::to_string(worst));
  EXPECT_LT(worst, 0.1);
  EXPECT_EQ(dir.entries().size(), 1u);  // no temporary file left behind
}

INSTANTIATE_TEST_SUITE_P(shared, vrma_shared_clip,
                         ::testing::Values("clip_test", "clip_idle_loop",
                                           "clip_hips_spine_twisting"));

TEST(vrma_read, clip_test_content) {
  std::string path = test::test_data_path("avatars/clip_test.vrma");
  if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
  vrma_clip clip;
  ASSERT_TRUE(read_vrma(path, clip).ok());
  // 51 bones mapped; "happy" is listed but has no proxy slot.
  EXPECT_EQ(std::count(clip.has_bone.begin(), clip.has_bone.end(), true), 51);
  ASSERT_EQ(clip.expression_names.size(), 1u);
  EXPECT_EQ(clip.expression_names[0], "happy");
  EXPECT_NEAR(clip.rest_hips_height, 0.85f, 1e-5f);
  EXPECT_NEAR(clip.duration, 3.0, 1e-6);
  // Resampling at 10 fps covers 0 .. 3 s.
  vrma_clip resampled;
  vrma_read_options opt;
  opt.fps = 10.0;
  ASSERT_TRUE(read_vrma(path, resampled, opt).ok());
  ASSERT_EQ(resampled.frames.size(), 31u);
  EXPECT_NEAR(resampled.frames.back().t, 3.0, 1e-9);
  // Hips scaling to another skeleton.
  vrma_clip scaled;
  opt.fps = 0.0;
  opt.hips_height = 1.7f;
  ASSERT_TRUE(read_vrma(path, scaled, opt).ok());
  for (std::size_t f = 0; f < clip.frames.size(); ++f)
    EXPECT_NEAR(scaled.frames[f].hips_position.y, 2.f * clip.frames[f].hips_position.y, 1e-4f);
}

TEST(vrma_read, idle_loop_in_centimetres_under_a_scale_node) {
  std::string path = test::test_data_path("avatars/clip_idle_loop.vrma");
  if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
  vrma_clip clip;
  ASSERT_TRUE(read_vrma(path, clip).ok());
  EXPECT_NEAR(clip.rest_hips_height, 0.9057f, 1e-3f);  // 90.57 cm under a 0.01 scale
  for (const proxy_pose& p : clip.frames) EXPECT_NEAR(p.hips_position.y, 0.9f, 0.15f);
}

// ---- synthetic poses: write -> read ------------------------------------------------------

TEST(vrma_write, random_poses_round_trip) {
  std::mt19937 rng(7);
  std::vector<proxy_pose> frames = random_sequence(rng, 40, 1.0 / 30.0);
  test::temp_dir dir("vrma");
  std::string path = dir.file("random.vrma");
  status s = write_vrma(path, frames);
  ASSERT_TRUE(s.ok()) << s.message();
  vrma_clip clip;
  s = read_vrma(path, clip);
  ASSERT_TRUE(s.ok()) << s.message();
  ASSERT_EQ(clip.frames.size(), frames.size());
  double worst = 0.0;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    EXPECT_NEAR(clip.frames[f].t, frames[f].t, 1e-6);
    for (int b = 0; b < k_bone_count; ++b) {
      if (!is_vrma_bone(static_cast<bone>(b))) {
        EXPECT_FALSE(clip.has_bone[b]);
        continue;
      }
      worst = std::max(worst, angle_deg(clip.frames[f].rotations[b], frames[f].rotations[b]));
    }
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(clip.frames[f].hips_position[c], frames[f].hips_position[c], 1e-6f);
    for (int e = 0; e < k_expression_count; ++e) {
      const auto ex = static_cast<expression>(e);
      if (ex == expression::brow_down_left || ex == expression::brow_down_right) {
        // The name is ARKit's too: the node carries ARKit's weight, read into both.
        const auto sh = *blendshape_from_name(expression_name(ex));
        EXPECT_NEAR(clip.frames[f].expressions[e], frames[f][sh], 1e-6f);
      } else if (is_vrma_expression(ex)) {
        EXPECT_NEAR(clip.frames[f].expressions[e], frames[f].expressions[e], 1e-6f);
      } else {
        EXPECT_EQ(clip.frames[f].expressions[e], 0.f);  // gaze is lookAt's, not written
      }
    }
    for (int sh = 0; sh < k_blendshape_count; ++sh)
      EXPECT_NEAR(clip.frames[f].blendshapes[sh], frames[f].blendshapes[sh], 1e-6f);
    // The gaze: the mean of the two eyes, into both.
    const glm::quat gaze =
        slerp_shortest(frames[f][bone::left_eye], frames[f][bone::right_eye], 0.5f);
    worst = std::max(worst, angle_deg(clip.frames[f][bone::left_eye], gaze));
    worst = std::max(worst, angle_deg(clip.frames[f][bone::right_eye], gaze));
  }
  EXPECT_LT(worst, 0.01);
  std::printf("[ synthetic ] max rotation error %.3g degrees\n", worst);
  // 17 .vrma-able expressions + 52 ARKit shapes, browDownLeft/Right shared.
  EXPECT_EQ(clip.expression_names.size(), 17u + 52u - 2u);
  EXPECT_TRUE(clip.has_look_at);
  for (bool has : clip.has_blendshape) EXPECT_TRUE(has);
  EXPECT_TRUE(clip.has_expression[idx(expression::surprised)]);
  EXPECT_NEAR(clip.rest_hips_height, standing_hips_height(make_proxy_skeleton()), 1e-5f);
}

TEST(vrma_write, file_structure_follows_the_spec) {
  std::mt19937 rng(3);
  std::vector<proxy_pose> frames = random_sequence(rng, 5, 0.1);
  for (proxy_pose& p : frames) {
    p.expressions.fill(0.f);
    p.blendshapes.fill(0.f);  // no face, no gaze: no ARKit names, no lookAt
    p[bone::left_eye] = p[bone::right_eye] = identity_quat();
  }
  frames[2][expression::aa] = 0.5f;
  frames[3][expression::brow_up_left] = 0.25f;
  frames[1][expression::look_up] = 1.f;
  test::temp_dir dir("vrma");
  std::string path = dir.file("s.vrma");
  ASSERT_TRUE(write_vrma(path, frames).ok());
  nlohmann::json doc;
  std::string bin;
  ASSERT_TRUE(split_glb(test::read_text(path), doc, bin));
  EXPECT_EQ(doc["asset"]["generator"], "avatarmap");
  EXPECT_EQ(doc["asset"]["version"], "2.0");
  EXPECT_EQ(doc["extensionsUsed"], nlohmann::json::array({"VRMC_vrm_animation"}));
  const auto& ext = doc["extensions"]["VRMC_vrm_animation"];
  EXPECT_EQ(ext["specVersion"], "1.0");
  EXPECT_EQ(ext["humanoid"]["humanBones"].size(), 53u);
  EXPECT_FALSE(ext["humanoid"]["humanBones"].contains("leftEye"));
  EXPECT_TRUE(ext["expressions"]["preset"].contains("aa"));
  EXPECT_FALSE(ext["expressions"]["preset"].contains("lookUp"));
  EXPECT_TRUE(ext["expressions"]["custom"].contains("browUpLeft"));
  EXPECT_EQ(ext["expressions"]["preset"].size(), 1u);
  EXPECT_EQ(ext["expressions"]["custom"].size(), 1u);
  EXPECT_FALSE(ext.contains("lookAt"));
  ASSERT_EQ(doc["animations"].size(), 1u);
  EXPECT_EQ(doc["animations"][0]["channels"].size(), 53u + 1u + 2u);
  for (const auto& node : doc["nodes"]) {
    EXPECT_FALSE(node.contains("rotation"));  // identity rest rotations
    EXPECT_FALSE(node.contains("scale"));
  }
  // Quaternions are stored {x, y, z, w}: check bone "spine" at key 0 against the input.
  int spine_node = ext["humanoid"]["humanBones"]["spine"]["node"];
  for (const auto& ch : doc["animations"][0]["channels"]) {
    if (ch["target"]["node"] != spine_node || ch["target"]["path"] != "rotation") continue;
    int acc = doc["animations"][0]["samplers"][ch["sampler"].get<int>()]["output"];
    int view = doc["accessors"][acc]["bufferView"];
    std::size_t off = doc["bufferViews"][view]["byteOffset"];
    float q[4];
    std::memcpy(q, bin.data() + off, 16);
    glm::quat expect = frames[0][bone::spine];
    float sign = (q[3] * expect.w + q[0] * expect.x >= 0.f) ? 1.f : -1.f;  // either sign
    EXPECT_NEAR(q[0], sign * expect.x, 1e-6f);
    EXPECT_NEAR(q[1], sign * expect.y, 1e-6f);
    EXPECT_NEAR(q[2], sign * expect.z, 1e-6f);
    EXPECT_NEAR(q[3], sign * expect.w, 1e-6f);
  }
}

// Emotions as presets, ARKit's shapes as custom expressions by ARKit name, the gaze as a
// lookAt node, laid out as docs/export.md says; read back (a second reader: the test's own
// JSON walk).
TEST(vrma_write, emotions_blendshapes_and_look_at_follow_the_spec) {
  std::vector<proxy_pose> frames(3);
  for (int k = 0; k < 3; ++k) frames[k].t = 0.1 * k;
  frames[1][expression::happy] = 0.75f;
  frames[2][expression::surprised] = 1.f;
  frames[2][expression::brow_down_left] = 0.5f;  // the avatarmap brow...
  frames[1][blendshape::jaw_open] = 0.25f;
  frames[2][blendshape::brow_down_left] = 0.125f;  // ...and ARKit's shape of the same name
  const glm::quat look_left = axis_angle(glm::vec3(0, 1, 0), glm::radians(20.f));
  const glm::quat look_down = axis_angle(glm::vec3(1, 0, 0), glm::radians(10.f));
  frames[1][bone::left_eye] = frames[1][bone::right_eye] = look_left;
  frames[2][bone::left_eye] = frames[2][bone::right_eye] = look_down * look_left;
  test::temp_dir dir("vrma");
  const std::string path = dir.file("face.vrma");
  ASSERT_TRUE(write_vrma(path, frames).ok());
  nlohmann::json doc;
  std::string bin;
  ASSERT_TRUE(split_glb(test::read_text(path), doc, bin));
  const auto& ext = doc["extensions"]["VRMC_vrm_animation"];
  const auto& preset = ext["expressions"]["preset"];
  const auto& custom = ext["expressions"]["custom"];
  EXPECT_TRUE(preset.contains("happy"));
  EXPECT_TRUE(preset.contains("surprised"));
  EXPECT_FALSE(preset.contains("sad"));  // 0 in every frame: not written
  EXPECT_EQ(preset.size(), 2u);
  EXPECT_TRUE(custom.contains("jawOpen"));
  EXPECT_TRUE(custom.contains("browDownLeft"));
  EXPECT_EQ(custom.size(), 2u);  // only shapes some frame moves; browDownLeft once
  ASSERT_TRUE(ext.contains("lookAt"));
  const int look = ext["lookAt"]["node"];
  // The lookAt node hangs under a pivot under the head; only rotations are animated on them
  // (three-vrm rejects any other channel on the lookAt node).
  const int head = ext["humanoid"]["humanBones"]["head"]["node"];
  int pivot = -1;
  for (std::size_t i = 0; i < doc["nodes"].size(); ++i)
    for (const auto& c : doc["nodes"][i].value("children", nlohmann::json::array()))
      if (c == look) pivot = static_cast<int>(i);
  ASSERT_GE(pivot, 0);
  bool pivot_under_head = false;
  for (const auto& c : doc["nodes"][head]["children"]) pivot_under_head |= c == pivot;
  EXPECT_TRUE(pivot_under_head);
  int look_channels = 0;
  for (const auto& ch : doc["animations"][0]["channels"])
    if (ch["target"]["node"] == look || ch["target"]["node"] == pivot) {
      EXPECT_EQ(ch["target"]["path"], "rotation");
      ++look_channels;
    }
  EXPECT_EQ(look_channels, 2);

  vrma_clip clip;
  ASSERT_TRUE(read_vrma(path, clip).ok());
  ASSERT_EQ(clip.frames.size(), 3u);
  EXPECT_TRUE(clip.has_look_at);
  EXPECT_NEAR(clip.frames[1][expression::happy], 0.75f, 1e-6f);
  EXPECT_NEAR(clip.frames[2][expression::surprised], 1.f, 1e-6f);
  EXPECT_NEAR(clip.frames[1][blendshape::jaw_open], 0.25f, 1e-6f);
  EXPECT_NEAR(clip.frames[2][blendshape::brow_down_left], 0.125f, 1e-6f);
  EXPECT_NEAR(clip.frames[2][expression::brow_down_left], 0.125f, 1e-6f);  // ARKit's weight
  EXPECT_LT(angle_deg(clip.frames[0][bone::left_eye], identity_quat()), 1e-3);
  EXPECT_LT(angle_deg(clip.frames[1][bone::right_eye], look_left), 1e-3);
  EXPECT_LT(angle_deg(clip.frames[2][bone::left_eye], look_down * look_left), 1e-3);
  EXPECT_EQ(clip.frames[2].confidence[idx(bone::left_eye)], 1.f);

  // The spec's reading: without the lookAt node's rotation channel the gaze comes from the
  // node's model-space position. With the pivot moved onto the head the target lies exactly
  // along the gaze, 1 m ahead: the read eye looks the same way.
  nlohmann::json edited = doc;
  auto& channels = edited["animations"][0]["channels"];
  for (std::size_t i = 0; i < channels.size(); ++i)
    if (channels[i]["target"]["node"] == look) {
      channels.erase(i);
      break;
    }
  edited["nodes"][pivot]["translation"] = {0.0, 0.0, 0.0};
  const std::string spec_path = dir.file("spec_look.vrma");
  test::write_text(spec_path, make_glb(edited, bin));
  vrma_clip by_position;
  ASSERT_TRUE(read_vrma(spec_path, by_position).ok());
  EXPECT_TRUE(by_position.has_look_at);
  for (int k = 0; k < 3; ++k) {
    const glm::vec3 want = frames[k][bone::left_eye] * glm::vec3(0, 0, 1);
    const glm::vec3 got = by_position.frames[k][bone::left_eye] * glm::vec3(0, 0, 1);
    EXPECT_GT(glm::dot(want, got), 0.f) << k;
    // sin of the angle between them: < sin(0.01 degrees).
    EXPECT_LT(glm::length(glm::cross(want, got)), 1.75e-4f) << k;
  }

  // blendshapes = false, look_at = false: neither ARKit names nor lookAt; the brow keeps
  // avatarmap's own weight.
  vrma_write_options plain;
  plain.blendshapes = false;
  plain.look_at = false;
  ASSERT_TRUE(write_vrma(path, frames, plain).ok());
  ASSERT_TRUE(read_vrma(path, clip).ok());
  EXPECT_FALSE(clip.has_look_at);
  EXPECT_FALSE(clip.has_blendshape[idx(blendshape::jaw_open)]);
  EXPECT_EQ(clip.frames[1][blendshape::jaw_open], 0.f);
  EXPECT_NEAR(clip.frames[2][expression::brow_down_left], 0.5f, 1e-6f);
  EXPECT_EQ(clip.frames[1][bone::left_eye], identity_quat());
}

// A clip without a face writes no expression node at all: the file is no bigger than one of
// the bones alone.
TEST(vrma_write, a_clip_without_a_face_adds_nothing) {
  std::mt19937 rng(9);
  std::vector<proxy_pose> frames = random_sequence(rng, 30, 1.0 / 30.0);
  for (proxy_pose& p : frames) {
    p.expressions.fill(0.f);
    p.blendshapes.fill(0.f);
    p[bone::left_eye] = p[bone::right_eye] = identity_quat();
  }
  test::temp_dir dir("vrma");
  const std::string path = dir.file("body.vrma");
  ASSERT_TRUE(write_vrma(path, frames).ok());
  nlohmann::json doc;
  std::string bin;
  ASSERT_TRUE(split_glb(test::read_text(path), doc, bin));
  EXPECT_FALSE(doc["extensions"]["VRMC_vrm_animation"].contains("expressions"));
  EXPECT_FALSE(doc["extensions"]["VRMC_vrm_animation"].contains("lookAt"));
  EXPECT_EQ(doc["nodes"].size(), 53u);
  // Times + hips + 53 rotations.
  EXPECT_EQ(bin.size(), 30u * 4u + 30u * 12u + 53u * 30u * 16u);
  // Non-finite shapes are cleaned like every weight (previous key's; 0 for the first).
  frames[0][blendshape::cheek_puff] = NAN;
  frames[1][blendshape::cheek_puff] = 0.5f;
  frames[2][blendshape::cheek_puff] = INFINITY;
  frames[3][blendshape::cheek_puff] = 7.f;
  ASSERT_TRUE(write_vrma(path, frames).ok());
  vrma_clip clip;
  ASSERT_TRUE(read_vrma(path, clip).ok());
  EXPECT_EQ(clip.frames[0][blendshape::cheek_puff], 0.f);
  EXPECT_EQ(clip.frames[2][blendshape::cheek_puff], 0.5f);
  EXPECT_EQ(clip.frames[3][blendshape::cheek_puff], 1.f);
}

TEST(vrma_write, resamples_at_fixed_fps) {
  std::vector<proxy_pose> frames(2);
  frames[0].t = 1.0;
  frames[1].t = 2.0;
  frames[1][bone::spine] = axis_angle(glm::vec3(0, 1, 0), 1.f);
  frames[1].hips_position.x = 1.f;
  vrma_write_options opt;
  opt.fps = 4.0;
  test::temp_dir dir("vrma");
  std::string path = dir.file("r.vrma");
  ASSERT_TRUE(write_vrma(path, frames, opt).ok());
  vrma_clip clip;
  ASSERT_TRUE(read_vrma(path, clip).ok());
  ASSERT_EQ(clip.frames.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR(clip.frames[k].t, k * 0.25, 1e-6);  // rebased to start at 0
    EXPECT_NEAR(rotation_angle(clip.frames[k][bone::spine]), 0.25f * k, 1e-5f);
    EXPECT_NEAR(clip.frames[k].hips_position.x, 0.25f * k, 1e-6f);
  }
}

// Rewrites a written file's samplers to STEP or CUBICSPLINE and checks the sampling.
TEST(vrma_read, step_and_cubic_interpolation) {
  std::vector<proxy_pose> frames(2);
  frames[0].t = 0.0;
  frames[1].t = 1.0;
  frames[1][bone::spine] = axis_angle(glm::vec3(0, 1, 0), 1.f);
  frames[1].hips_position.x = 1.f;
  test::temp_dir dir("vrma");
  std::string path = dir.file("i.vrma");
  ASSERT_TRUE(write_vrma(path, frames).ok());
  nlohmann::json doc;
  std::string bin;
  ASSERT_TRUE(split_glb(test::read_text(path), doc, bin));
  // An extra key at 0.5 s in between (the union of times gives a frame there).
  nlohmann::json step = doc;
  std::string step_bin = bin;
  std::size_t off = step_bin.size();
  float extra_times[3] = {0.f, 0.5f, 1.f};
  step_bin.append(reinterpret_cast<const char*>(extra_times), sizeof extra_times);
  step["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", off}, {"byteLength", 12}});
  step["accessors"].push_back({{"bufferView", step["bufferViews"].size() - 1},
                               {"componentType", 5126},
                               {"count", 3},
                               {"type", "SCALAR"},
                               {"min", {0.0}},
                               {"max", {1.0}}});
  float extra_vals[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  off = step_bin.size();
  step_bin.append(reinterpret_cast<const char*>(extra_vals), sizeof extra_vals);
  step["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", off}, {"byteLength", 36}});
  step["accessors"].push_back({{"bufferView", step["bufferViews"].size() - 1},
                               {"componentType", 5126},
                               {"count", 3},
                               {"type", "VEC3"}});
  step["nodes"].push_back({{"name", "extra"}});
  int extra_node = static_cast<int>(step["nodes"].size()) - 1;
  step["animations"][0]["samplers"].push_back(
      {{"input", step["accessors"].size() - 2}, {"output", step["accessors"].size() - 1}});
  step["animations"][0]["channels"].push_back(
      {{"sampler", step["animations"][0]["samplers"].size() - 1},
       {"target", {{"node", extra_node}, {"path", "translation"}}}});
  step["buffers"][0]["byteLength"] = step_bin.size();
  for (auto& s : step["animations"][0]["samplers"]) s["interpolation"] = "STEP";
  std::string step_path = dir.file("step.vrma");
  test::write_text(step_path, make_glb(step, step_bin));
  vrma_clip clip;
  status st = read_vrma(step_path, clip);
  ASSERT_TRUE(st.ok()) << st.message();
  ASSERT_EQ(clip.frames.size(), 3u);
  EXPECT_NEAR(clip.frames[1].t, 0.5, 1e-9);
  EXPECT_NEAR(rotation_angle(clip.frames[1][bone::spine]), 0.f, 1e-6f);  // holds key 0
  EXPECT_NEAR(clip.frames[1].hips_position.x, 0.f, 1e-6f);
  EXPECT_NEAR(rotation_angle(clip.frames[2][bone::spine]), 1.f, 1e-5f);

  // LINEAR: halfway.
  for (auto& s : step["animations"][0]["samplers"]) s["interpolation"] = "LINEAR";
  test::write_text(step_path, make_glb(step, step_bin));
  ASSERT_TRUE(read_vrma(step_path, clip).ok());
  EXPECT_NEAR(rotation_angle(clip.frames[1][bone::spine]), 0.5f, 1e-5f);
  EXPECT_NEAR(clip.frames[1].hips_position.x, 0.5f, 1e-6f);

  // CUBICSPLINE with zero tangents on the hips translation: Hermite at u = 0.5 is halfway
  // too; the value component sits between the tangents.
  nlohmann::json cubic = step;
  std::string cubic_bin = step_bin;
  float hips_cubic[18] = {0, 0, 0, 0, 0.95f, 0, 0, 0, 0, 0, 0, 0, 1, 0.95f, 0, 0, 0, 0};
  off = cubic_bin.size();
  cubic_bin.append(reinterpret_cast<const char*>(hips_cubic), sizeof hips_cubic);
  cubic["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", off}, {"byteLength", 72}});
  cubic["accessors"].push_back({{"bufferView", cubic["bufferViews"].size() - 1},
                                {"componentType", 5126},
                                {"count", 6},
                                {"type", "VEC3"}});
  cubic["buffers"][0]["byteLength"] = cubic_bin.size();
  cubic["animations"][0]["samplers"][0]["output"] = cubic["accessors"].size() - 1;
  cubic["animations"][0]["samplers"][0]["interpolation"] = "CUBICSPLINE";
  test::write_text(step_path, make_glb(cubic, cubic_bin));
  st = read_vrma(step_path, clip);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_NEAR(clip.frames[0].hips_position.x, 0.f, 1e-6f);
  EXPECT_NEAR(clip.frames[1].hips_position.x, 0.5f, 1e-6f);
  EXPECT_NEAR(clip.frames[2].hips_position.x, 1.f, 1e-6f);
  EXPECT_NEAR(clip.frames[2].hips_position.y, 0.95f, 1e-6f);
}

// ---- malformed input ----------------------------------------------------------------------

TEST(vrma_read, malformed_files_give_errors) {
  test::temp_dir dir("vrma");
  vrma_clip clip;
  auto expect_error = [&](const std::string& name, const std::string& content,
                          const std::string& words) {
    std::string path = dir.file(name);
    test::write_text(path, content);
    status s = read_vrma(path, clip);
    EXPECT_FALSE(s.ok()) << name;
    EXPECT_NE(s.message().find(path), std::string::npos) << s.message();
    if (!words.empty()) EXPECT_NE(s.message().find(words), std::string::npos) << s.message();
  };
  EXPECT_FALSE(read_vrma(dir.file("missing.vrma"), clip).ok());
  expect_error("empty.vrma", "", "");
  std::mt19937 rng(1);
  std::string noise(4096, '\0');
  for (char& c : noise) c = static_cast<char>(rng());
  expect_error("noise.vrma", noise, "");
  nlohmann::json plain = {{"asset", {{"version", "2.0"}}}};
  expect_error("plain.vrma", make_glb(plain, ""), "no VRMC_vrm_animation");
  nlohmann::json no_anim = plain;
  no_anim["extensionsUsed"] = {"VRMC_vrm_animation"};
  no_anim["nodes"] = {{{"name", "hips"}}};
  no_anim["extensions"]["VRMC_vrm_animation"] = {
      {"specVersion", "1.0"}, {"humanoid", {{"humanBones", {{"hips", {{"node", 0}}}}}}}};
  expect_error("no_anim.vrma", make_glb(no_anim, ""), "no animation");
  nlohmann::json bad_node = no_anim;
  bad_node["extensions"]["VRMC_vrm_animation"]["humanoid"]["humanBones"]["hips"]["node"] = 7;
  expect_error("bad_node.vrma", make_glb(bad_node, ""), "hips");

  // A valid file with a broken accessor, and truncated / corrupted copies of a valid file.
  std::mt19937 prng(5);
  std::vector<proxy_pose> frames = random_sequence(prng, 6, 0.1);
  std::string good_path = dir.file("good.vrma");
  ASSERT_TRUE(write_vrma(good_path, frames).ok());
  std::string good = test::read_text(good_path);
  nlohmann::json doc;
  std::string bin;
  ASSERT_TRUE(split_glb(good, doc, bin));
  nlohmann::json broken = doc;
  broken["accessors"][1]["count"] = 100000;
  expect_error("count.vrma", make_glb(broken, bin), "accessor 1");
  broken = doc;
  broken["accessors"][1]["type"] = "VEC2";
  expect_error("type.vrma", make_glb(broken, bin), "accessor 1");
  broken = doc;
  broken["animations"][0]["samplers"][0]["input"] = 999;
  expect_error("input.vrma", make_glb(broken, bin), "input");
  broken = doc;
  broken["nodes"][1]["children"] = {0};  // a cycle
  expect_error("cycle.vrma", make_glb(broken, bin), "");
  for (std::size_t len : {std::size_t{12}, std::size_t{40}, good.size() / 2, good.size() - 4})
    expect_error("cut" + std::to_string(len) + ".vrma", good.substr(0, len), "");
  for (int trial = 0; trial < 200; ++trial) {
    std::string bad = good;
    for (int k = 0; k < 8; ++k) bad[rng() % bad.size()] = static_cast<char>(rng());
    std::string path = dir.file("flip.vrma");
    test::write_text(path, bad);
    (void)read_vrma(path, clip);  // may or may not fail; must not crash
  }
}

TEST(vrma_write, rejects_bad_input_and_cleans_values) {
  test::temp_dir dir("vrma");
  std::string path = dir.file("w.vrma");
  EXPECT_FALSE(write_vrma(path, {}).ok());
  std::vector<proxy_pose> frames(3);
  frames[0].t = 0.0;
  frames[1].t = 0.0;
  frames[2].t = 1.0;
  EXPECT_FALSE(write_vrma(path, frames).ok());  // times not increasing
  frames[1].t = 0.5;
  vrma_write_options opt;
  opt.fps = -1.0;
  EXPECT_FALSE(write_vrma(path, frames, opt).ok());
  EXPECT_FALSE(write_vrma(dir.file("no/such/dir/w.vrma"), frames).ok());
  frames[1][bone::spine] = glm::quat(NAN, 0.f, 0.f, 0.f);
  frames[1].hips_position.x = INFINITY;
  ASSERT_TRUE(write_vrma(path, frames).ok());
  vrma_clip clip;
  ASSERT_TRUE(read_vrma(path, clip).ok());
  EXPECT_NEAR(rotation_angle(clip.frames[1][bone::spine]), 0.f, 1e-6f);
  EXPECT_EQ(clip.frames[1].hips_position.x, 0.f);
}
