#include "avatarmap/rig/avatar_loader.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

int declared_count(const raw_rig& r) {
  return static_cast<int>(std::count_if(r.declared_humanoid.begin(), r.declared_humanoid.end(),
                                        [](int i) { return i >= 0; }));
}

bool has(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Loads a shared avatar file and builds its rig; skips when the data folder is not set.
#define LOAD_SHARED(name, raw, built)                             \
  const std::string path = test::test_data_path("avatars/" name); \
  if (path.empty()) GTEST_SKIP() << test::k_no_test_data;         \
  raw_rig raw;                                                    \
  {                                                               \
    status s_ = load_avatar(path, raw);                           \
    ASSERT_TRUE(s_.ok()) << s_.message();                         \
  }                                                               \
  rig built;                                                      \
  {                                                               \
    status s_ = build_rig(raw, built);                            \
    ASSERT_TRUE(s_.ok()) << s_.message();                         \
  }                                                               \
  EXPECT_EQ(raw.file, path);                                      \
  EXPECT_EQ(built.joint_count(), static_cast<int>(raw.nodes.size()))

int parent_of(const raw_rig& raw, const std::string& name) {
  for (const auto& n : raw.nodes)
    if (n.name == name) return n.parent;
  return -2;
}
std::string name_of(const raw_rig& raw, int i) {
  return i >= 0 && i < static_cast<int>(raw.nodes.size()) ? raw.nodes[i].name : "(none)";
}

// World position of a joint, and whether every world matrix is finite.
glm::vec3 world_position(const rig& r, int joint) { return glm::vec3(r.rest_world[joint][3]); }
bool all_finite(const rig& r) {
  for (const glm::mat4& m : r.rest_world)
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k)
        if (!std::isfinite(m[c][k])) return false;
  return true;
}
float hips_height(const rig& r) {
  const int j = r.declared_humanoid[idx(bone::hips)];
  return j < 0 ? NAN : world_position(r, j).y;
}
// 0.5 to 1.5 m for a VRM avatar; the small sample models stand their hips at 0.5 m exactly,
// which float products of the file's transforms may miss by a few ulps.
void expect_plausible_hips_height(float h) {
  EXPECT_GE(h, 0.5f - 1e-4f);
  EXPECT_LE(h, 1.5f);
}

// ---- shared real files --------------------------------------------------------------------

TEST(avatar_loader, vrm0_sphere) {
  LOAD_SHARED("vrm0_sphere.vrm", raw, r);
  EXPECT_EQ(raw.source, rig_source::vrm0);
  EXPECT_EQ(raw.nodes.size(), 31u);
  EXPECT_EQ(declared_count(raw), 22);
  EXPECT_EQ(name_of(raw, raw.declared_humanoid[idx(bone::hips)]), "Hips");
  EXPECT_EQ(name_of(raw, raw.declared_humanoid[idx(bone::left_upper_arm)]), "UpperArm.L");
  EXPECT_EQ(name_of(raw, raw.declared_humanoid[idx(bone::right_toes)]), "Toes.R");
  EXPECT_EQ(name_of(raw, raw.declared_humanoid[idx(bone::upper_chest)]), "UpperChest");
  EXPECT_EQ(raw.declared_humanoid[idx(bone::left_thumb_metacarpal)], -1);
  EXPECT_EQ(name_of(raw, parent_of(raw, "Hips")), "Armature");
  EXPECT_EQ(name_of(raw, parent_of(raw, "UpperLeg.L")), "Hips");
  EXPECT_EQ(parent_of(raw, "Armature"), -1);
  EXPECT_TRUE(raw.expressions.empty());  // the file's blendShapeGroups is empty
  EXPECT_TRUE(all_finite(r));
  EXPECT_EQ(r.names[r.declared_humanoid[idx(bone::hips)]], "Hips");
  const float h = hips_height(r);
  expect_plausible_hips_height(h);
  EXPECT_NEAR(h, 0.5f, 1e-3f);
}

TEST(avatar_loader, vrm1_spec_53bones) {
  LOAD_SHARED("vrm1_spec_53bones.vrm", raw, r);
  EXPECT_EQ(raw.source, rig_source::vrm1);
  EXPECT_EQ(raw.nodes.size(), 58u);
  EXPECT_EQ(declared_count(raw), 53);
  EXPECT_EQ(raw.declared_humanoid[idx(bone::hips)], 52);
  EXPECT_EQ(name_of(raw, raw.declared_humanoid[idx(bone::hips)]), "hips");
  EXPECT_EQ(name_of(raw, parent_of(raw, "head")), "neck");
  EXPECT_EQ(name_of(raw, parent_of(raw, "eye.L")), "head");
  // Every declared bone except hips sits below the hips joint in the hierarchy.
  const int hips = r.declared_humanoid[idx(bone::hips)];
  for (int b = 1; b < k_bone_count; ++b) {
    int j = r.declared_humanoid[b];
    if (j < 0) continue;
    while (j >= 0 && j != hips) j = r.parents[j];
    EXPECT_EQ(j, hips) << bone_name(static_cast<bone>(b));
  }
  EXPECT_TRUE(all_finite(r));
  const float h = hips_height(r);
  expect_plausible_hips_height(h);
  EXPECT_NEAR(h, 0.85f, 1e-3f);
  // The head sits above the hips, the left hand at +X (VRM 1.0 faces +Z).
  EXPECT_GT(world_position(r, r.declared_humanoid[idx(bone::head)]).y, h);
  EXPECT_GT(world_position(r, r.declared_humanoid[idx(bone::left_hand)]).x, 0.3f);
}

TEST(avatar_loader, vrm1_debug_robot) {
  LOAD_SHARED("vrm1_debug_robot.vrm", raw, r);
  EXPECT_EQ(raw.source, rig_source::vrm1);
  EXPECT_EQ(raw.nodes.size(), 77u);
  EXPECT_EQ(declared_count(raw), 53);
  EXPECT_EQ(name_of(raw, raw.declared_humanoid[idx(bone::hips)]), "hips");
  EXPECT_EQ(raw.expressions.size(), 18u);
  EXPECT_TRUE(has(raw.expressions, "aa"));
  EXPECT_TRUE(has(raw.expressions, "blink"));
  EXPECT_TRUE(has(raw.expressions, "blinkLeft"));
  EXPECT_TRUE(all_finite(r));
  const float h = hips_height(r);
  expect_plausible_hips_height(h);
  EXPECT_NEAR(h, 0.75f, 1e-3f);
}

TEST(avatar_loader, vrm1_spec_expressions) {
  LOAD_SHARED("vrm1_spec_expressions.vrm", raw, r);
  EXPECT_EQ(raw.source, rig_source::vrm1);
  EXPECT_EQ(raw.nodes.size(), 27u);
  EXPECT_EQ(declared_count(raw), 22);
  EXPECT_EQ(name_of(raw, raw.declared_humanoid[idx(bone::hips)]), "Hips");
  // The file declares exactly two presets (texture-transform expressions).
  EXPECT_EQ(raw.expressions.size(), 2u);
  EXPECT_TRUE(has(raw.expressions, "happy"));
  EXPECT_TRUE(has(raw.expressions, "blink"));
  EXPECT_TRUE(all_finite(r));
  const float h = hips_height(r);
  expect_plausible_hips_height(h);
  EXPECT_NEAR(h, 0.5f, 1e-3f);
}

TEST(avatar_loader, vrma_clips) {
  struct expected {
    const char* file;
    size_t nodes;
    int bones;
    const char* hips;
  };
  for (const expected& e : {expected{"clip_test.vrma", 53, 51, "hips"},
                            expected{"clip_idle_loop.vrma", 33, 22, nullptr},
                            expected{"clip_hips_spine_twisting.vrma", 18, 17, "Hips"}}) {
    SCOPED_TRACE(e.file);
    const std::string path = test::test_data_path(std::string("avatars/") + e.file);
    if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
    raw_rig raw;
    status s = load_avatar(path, raw);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(raw.source, rig_source::vrm1);
    EXPECT_EQ(raw.nodes.size(), e.nodes);
    EXPECT_EQ(declared_count(raw), e.bones);
    EXPECT_GE(raw.declared_humanoid[idx(bone::hips)], 0);
    if (e.hips) EXPECT_EQ(name_of(raw, raw.declared_humanoid[idx(bone::hips)]), e.hips);
    EXPECT_EQ(raw.declared_humanoid[idx(bone::left_eye)], -1);  // VRMA has no eye bones
    rig r;
    s = build_rig(raw, r);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_TRUE(all_finite(r));
    EXPECT_TRUE(std::isfinite(hips_height(r)));
  }
}

TEST(avatar_loader, vrma_expressions) {
  LOAD_SHARED("clip_test.vrma", raw, r);
  EXPECT_TRUE(has(raw.expressions, "happy"));
}

TEST(avatar_loader, gltf_files_declare_no_humanoid) {
  struct expected {
    const char* file;
    size_t nodes;
    const char* joint;
    const char* parent;
  };
  for (const expected& e :
       {expected{"gltf_rigged_simple.glb", 5, "Bone_001", "Bone"},
        expected{"gltf_rigged_figure.glb", 22, "torso_joint_2", "torso_joint_1"},
        expected{"gltf_cesium_man.glb", 22, "torso_joint_3", "Skeleton_torso_joint_2"}}) {
    SCOPED_TRACE(e.file);
    const std::string path = test::test_data_path(std::string("avatars/") + e.file);
    if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
    raw_rig raw;
    status s = load_avatar(path, raw);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_EQ(raw.source, rig_source::gltf);
    EXPECT_EQ(raw.nodes.size(), e.nodes);
    EXPECT_EQ(declared_count(raw), 0);
    EXPECT_TRUE(raw.expressions.empty());
    EXPECT_EQ(name_of(raw, parent_of(raw, e.joint)), e.parent);
    EXPECT_EQ(parent_of(raw, "Scene"), -1);
    rig r;
    s = build_rig(raw, r);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_TRUE(all_finite(r));
    const int j = r.find(e.joint);
    ASSERT_GE(j, 0);
    const glm::vec3 p = world_position(r, j);
    EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  }
}

// Each Khronos figure has one node given as a matrix (a rotation of the Z-up export to Y up):
// its decomposition is a unit rotation and a positive scale.
TEST(avatar_loader, matrix_nodes_are_decomposed) {
  LOAD_SHARED("gltf_rigged_figure.glb", raw, r);
  bool any_rotated = false;
  for (const raw_rig::node& n : raw.nodes) {
    EXPECT_NEAR(glm::length(n.rest.rotation), 1.f, 1e-5f) << n.name;
    EXPECT_GT(n.rest.scale.x, 0.f) << n.name;
    any_rotated = any_rotated || std::abs(n.rest.rotation.w) < 0.999f;
  }
  EXPECT_TRUE(any_rotated);
}

// ---- written by the test ------------------------------------------------------------------

// A minimal text glTF: `nodes` and `extensions` are JSON fragments.
std::string gltf_json(const std::string& nodes, const std::string& extensions = "") {
  std::string j = R"({"asset": {"version": "2.0"}, "nodes": [)" + nodes + "]";
  if (!extensions.empty()) j += R"(, "extensions": {)" + extensions + "}";
  return j + "}";
}

const char* k_three_nodes =
    R"({"name": "root", "children": [1]}, {"name": "hips", "children": [2],
        "translation": [0, 1, 0]}, {"name": "spine", "translation": [0, 0.1, 0]})";

status load_text(const test::temp_dir& dir, const std::string& name, const std::string& text,
                 raw_rig& raw) {
  test::write_text(dir.file(name), text);
  return load_avatar(dir.file(name), raw);
}

TEST(avatar_loader, missing_file) {
  raw_rig raw;
  status s = load_avatar("/no/such/dir/avatar.vrm", raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "/no/such/dir/avatar.vrm")) << s.message();
  EXPECT_TRUE(raw.nodes.empty());
}

TEST(avatar_loader, empty_file) {
  test::temp_dir dir("avatar");
  raw_rig raw;
  status s = load_text(dir, "empty.vrm", "", raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), dir.file("empty.vrm"))) << s.message();
  EXPECT_TRUE(contains(s.message(), "empty")) << s.message();
}

TEST(avatar_loader, random_bytes) {
  test::temp_dir dir("avatar");
  std::mt19937 rng(7);
  for (int round = 0; round < 20; ++round) {
    std::string bytes(static_cast<size_t>(1 + rng() % 4000), '\0');
    for (char& c : bytes) c = static_cast<char>(rng());
    if (round % 4 == 1) bytes.replace(0, 4, "glTF");  // binary magic, garbage header
    if (round % 4 == 2) bytes[0] = '{';               // looks like JSON, is not
    raw_rig raw;
    status s = load_text(dir, "random.glb", bytes, raw);
    ASSERT_FALSE(s.ok()) << "round " << round;
    EXPECT_TRUE(contains(s.message(), dir.file("random.glb"))) << s.message();
  }
  raw_rig raw;
  status s = load_text(dir, "text.gltf", "hello, world", raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "not a glTF file")) << s.message();
}

TEST(avatar_loader, malformed_json) {
  test::temp_dir dir("avatar");
  raw_rig raw;
  status s = load_text(dir, "bad.gltf", R"({"asset": {"version": "2.0"}, "nodes": [)", raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), dir.file("bad.gltf"))) << s.message();
}

TEST(avatar_loader, minimal_text_gltf) {
  test::temp_dir dir("avatar");
  raw_rig raw;
  // Leading whitespace, an unnamed node and a matrix node (translation 1, 2, 3; scale 2).
  const std::string nodes =
      std::string(k_three_nodes) + R"(, {}, {"matrix": [2,0,0,0, 0,2,0,0, 0,0,2,0, 1,2,3,1]})";
  status s = load_text(dir, "ok.vrm", "\n  " + gltf_json(nodes), raw);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(raw.source, rig_source::gltf);  // the extension is not what decides
  ASSERT_EQ(raw.nodes.size(), 5u);
  EXPECT_EQ(raw.nodes[0].parent, -1);
  EXPECT_EQ(raw.nodes[1].parent, 0);
  EXPECT_EQ(raw.nodes[2].parent, 1);
  EXPECT_EQ(raw.nodes[3].name, "node3");
  EXPECT_EQ(raw.nodes[4].rest.translation, glm::vec3(1, 2, 3));
  EXPECT_NEAR(raw.nodes[4].rest.scale.y, 2.f, 1e-6f);
  EXPECT_NEAR(raw.nodes[4].rest.rotation.w, 1.f, 1e-6f);
  rig r;
  s = build_rig(raw, r);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_NEAR(world_position(r, r.find("spine")).y, 1.1f, 1e-6f);
}

TEST(avatar_loader, parent_cycle_fails_in_build_rig) {
  test::temp_dir dir("avatar");
  raw_rig raw;
  status s =
      load_text(dir, "cycle.gltf", gltf_json(R"({"name": "root"}, {"name": "a", "children": [2]},
                                    {"name": "b", "children": [3]}, {"name": "c", "children": [1]})"),
                raw);
  ASSERT_TRUE(s.ok()) << s.message();
  rig r;
  s = build_rig(raw, r);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "cycle")) << s.message();
  EXPECT_TRUE(contains(s.message(), "'a'") || contains(s.message(), "'b'") ||
              contains(s.message(), "'c'"))
      << s.message();
}

TEST(avatar_loader, bad_hierarchy) {
  test::temp_dir dir("avatar");
  raw_rig raw;
  status s = load_text(dir, "x.gltf", gltf_json(R"({"name": "a", "children": [5]})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "'a'") && contains(s.message(), "5")) << s.message();
  s = load_text(dir, "x.gltf", gltf_json(R"({"name": "a", "children": [0]})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "itself")) << s.message();
  s = load_text(dir, "x.gltf",
                gltf_json(R"({"name": "a", "children": [2]}, {"name": "b", "children": [2]},
                             {"name": "c"})"),
                raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "'c'") && contains(s.message(), "two")) << s.message();
  // tinygltf drops non-integer children by itself; the loader must not let them pass.
  for (const char* children : {"[1e12]", "[1, 0.5]", "[\"b\"]", "1"}) {
    s = load_text(
        dir, "x.gltf",
        gltf_json(std::string(R"({"name": "a", "children": )") + children + R"(}, {"name": "b"})"),
        raw);
    EXPECT_TRUE(!s.ok() && contains(s.message(), "children")) << children << ": " << s.message();
  }
  s = load_text(dir, "x.gltf", gltf_json(R"({"name": "a", "rotation": [0, 0, 1]})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "rotation")) << s.message();
}

TEST(avatar_loader, vrm1_humanoid_errors) {
  test::temp_dir dir("avatar");
  auto vrm1 = [](const std::string& bones) {
    return gltf_json(
        k_three_nodes,
        R"("VRMC_vrm": {"specVersion": "1.0", "humanoid": {"humanBones": {)" + bones + "}}}");
  };
  raw_rig raw;
  status s = load_text(dir, "ok.vrm", vrm1(R"("hips": {"node": 1}, "spine": {"node": 2})"), raw);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(raw.source, rig_source::vrm1);
  EXPECT_EQ(raw.declared_humanoid[idx(bone::hips)], 1);
  EXPECT_EQ(raw.declared_humanoid[idx(bone::spine)], 2);
  EXPECT_EQ(declared_count(raw), 2);

  s = load_text(dir, "range.vrm", vrm1(R"("hips": {"node": 3})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), dir.file("range.vrm"))) << s.message();
  EXPECT_TRUE(contains(s.message(), "out of range")) << s.message();
  EXPECT_EQ(declared_count(raw), 0);  // nothing half-filled on failure
  s = load_text(dir, "neg.vrm", vrm1(R"("hips": {"node": -1})"), raw);
  EXPECT_TRUE(!s.ok() && contains(s.message(), "out of range")) << s.message();
  s = load_text(dir, "frac.vrm", vrm1(R"("hips": {"node": 1.5})"), raw);
  EXPECT_TRUE(!s.ok() && contains(s.message(), "'hips'")) << s.message();
  s = load_text(dir, "huge.vrm", vrm1(R"("hips": {"node": 1e300})"), raw);
  EXPECT_FALSE(s.ok());
  s = load_text(dir, "nonode.vrm", vrm1(R"("hips": {"node": 1}, "spine": {"nodes": 2})"), raw);
  EXPECT_TRUE(!s.ok() && contains(s.message(), "'spine'")) << s.message();
  s = load_text(dir, "string.vrm", vrm1(R"("hips": 1)"), raw);
  EXPECT_FALSE(s.ok());

  s = load_text(dir, "name.vrm", vrm1(R"("hips": {"node": 1}, "tail": {"node": 2})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "'tail'")) << s.message();

  s = load_text(dir, "dup.vrm", vrm1(R"("hips": {"node": 1}, "spine": {"node": 1})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "two humanoid bones")) << s.message();
  EXPECT_TRUE(contains(s.message(), "'hips'")) << s.message();  // the node's name

  s = load_text(dir, "nobones.vrm", gltf_json(k_three_nodes, R"("VRMC_vrm": {"humanoid": 3})"),
                raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "humanBones")) << s.message();
}

TEST(avatar_loader, vrm0_humanoid) {
  test::temp_dir dir("avatar");
  auto vrm0 = [](const std::string& bones, const std::string& groups = "") {
    return gltf_json(std::string(k_three_nodes) + R"(, {"name": "t1"}, {"name": "t2"})",
                     R"("VRM": {"humanoid": {"humanBones": [)" + bones +
                         R"(]}, "blendShapeMaster": {"blendShapeGroups": [)" + groups + "]}}");
  };
  raw_rig raw;
  status s = load_text(
      dir, "ok.vrm",
      vrm0(R"({"bone": "hips", "node": 1}, {"bone": "leftThumbProximal", "node": 3},
              {"bone": "leftThumbIntermediate", "node": 4})",
           R"({"name": "A", "presetName": "a"}, {"name": "Smile", "presetName": "unknown"},
              {"name": "Blink", "presetName": "blink"}, {"name": "A2", "presetName": "a"})"),
      raw);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(raw.source, rig_source::vrm0);
  EXPECT_EQ(raw.declared_humanoid[idx(bone::hips)], 1);
  EXPECT_EQ(raw.declared_humanoid[idx(bone::left_thumb_metacarpal)], 3);
  EXPECT_EQ(raw.declared_humanoid[idx(bone::left_thumb_proximal)], 4);
  EXPECT_EQ(raw.declared_humanoid[idx(bone::left_thumb_distal)], -1);
  EXPECT_EQ(raw.expressions, (std::vector<std::string>{"a", "Smile", "blink"}));

  s = load_text(dir, "name.vrm",
                vrm0(R"({"bone": "hips", "node": 1}, {"bone": "tail", "node": 2})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "'tail'")) << s.message();
  s = load_text(dir, "range.vrm", vrm0(R"({"bone": "hips", "node": 99})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "99") && contains(s.message(), "out of range")) << s.message();
  s = load_text(dir, "twice.vrm",
                vrm0(R"({"bone": "hips", "node": 1}, {"bone": "hips", "node": 2})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "declared twice")) << s.message();
  s = load_text(dir, "shared.vrm",
                vrm0(R"({"bone": "spine", "node": 2}, {"bone": "chest", "node": 2})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "two humanoid bones")) << s.message();
  s = load_text(dir, "noname.vrm", vrm0(R"({"node": 2})"), raw);
  ASSERT_FALSE(s.ok());
  EXPECT_TRUE(contains(s.message(), "humanBones[0]")) << s.message();
}

TEST(avatar_loader, vrma_humanoid_and_vrm1_precedence) {
  test::temp_dir dir("avatar");
  raw_rig raw;
  status s = load_text(dir, "a.vrma",
                       gltf_json(k_three_nodes,
                                 R"("VRMC_vrm_animation": {"specVersion": "1.0",
                   "humanoid": {"humanBones": {"hips": {"node": 1}}},
                   "expressions": {"preset": {"happy": {"node": 2}}}})"),
                       raw);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(raw.source, rig_source::vrm1);
  EXPECT_EQ(raw.declared_humanoid[idx(bone::hips)], 1);
  EXPECT_EQ(raw.expressions, (std::vector<std::string>{"happy"}));

  s = load_text(dir, "both.vrm",
                gltf_json(k_three_nodes,
                          R"("VRM": {"humanoid": {"humanBones": [{"bone": "hips", "node": 2}]}},
                             "VRMC_vrm": {"humanoid": {"humanBones": {"hips": {"node": 1}}}})"),
                raw);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(raw.source, rig_source::vrm1);
  EXPECT_EQ(raw.declared_humanoid[idx(bone::hips)], 1);
}

}  // namespace
}  // namespace avatarmap
