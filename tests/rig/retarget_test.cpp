// Retargeting known motions onto rigs with unusual conventions: world bone directions of the
// rig after retargeting must match the proxy's (the issue's retarget-accuracy figure).
#include "avatarmap/rig/retarget.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "avatarmap/core/euler.hpp"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "support/rig_fk.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = k_pi / 180.f;

// Mixamo's joint names for the proxy bones it has (REFERENCE §5).
const char* mixamo_name(bone b) {
  switch (b) {
    case bone::hips:
      return "Hips";
    case bone::spine:
      return "Spine";
    case bone::chest:
      return "Spine1";
    case bone::upper_chest:
      return "Spine2";
    case bone::neck:
      return "Neck";
    case bone::head:
      return "Head";
    case bone::left_shoulder:
      return "LeftShoulder";
    case bone::left_upper_arm:
      return "LeftArm";
    case bone::left_lower_arm:
      return "LeftForeArm";
    case bone::left_hand:
      return "LeftHand";
    case bone::right_shoulder:
      return "RightShoulder";
    case bone::right_upper_arm:
      return "RightArm";
    case bone::right_lower_arm:
      return "RightForeArm";
    case bone::right_hand:
      return "RightHand";
    case bone::left_upper_leg:
      return "LeftUpLeg";
    case bone::left_lower_leg:
      return "LeftLeg";
    case bone::left_foot:
      return "LeftFoot";
    case bone::left_toes:
      return "LeftToeBase";
    case bone::right_upper_leg:
      return "RightUpLeg";
    case bone::right_lower_leg:
      return "RightLeg";
    case bone::right_foot:
      return "RightFoot";
    case bone::right_toes:
      return "RightToeBase";
    default:
      break;
  }
  return nullptr;
}

std::string finger_name(bone b) {
  // leftIndexProximal -> LeftHandIndex1, leftThumbMetacarpal -> LeftHandThumb1, ...
  const std::string n(bone_name(b));
  const bool left = n.rfind("left", 0) == 0;
  if (!left && n.rfind("right", 0) != 0) return {};
  const std::string rest = n.substr(left ? 4 : 5);
  static const char* fingers[] = {"Thumb", "Index", "Middle", "Ring", "Little"};
  for (const char* f : fingers) {
    if (rest.rfind(f, 0) != 0) continue;
    const std::string joint = rest.substr(std::string(f).size());
    int k = joint == "Metacarpal" || joint == "Proximal" ? 1 : joint == "Intermediate" ? 2 : 3;
    if (std::string(f) == "Thumb") k = joint == "Metacarpal" ? 1 : joint == "Proximal" ? 2 : 3;
    return std::string(left ? "Left" : "Right") + "Hand" +
           (std::string(f) == "Little" ? "Pinky" : f) + std::to_string(k);
  }
  return {};
}

struct test_rig {
  raw_rig raw;
  bone_binding binding;
};

// A Mixamo-shaped rig: "mixamorig:" names, centimetres under an Armature node scaled 0.01,
// every joint with an arbitrary rest rotation (so local axes differ from the world's), in the
// synthetic skeleton's T-pose, or an A-pose (arms 45 degrees down) when `a_pose`.
test_rig make_mixamo_like(bool a_pose, bool skip_chest, uint32_t seed) {
  test_rig t;
  t.binding.fill(-1);
  const proxy_skeleton sk = make_proxy_skeleton(1.70f);
  proxy_pose rest;
  rest.hips_position = glm::vec3(0.f, standing_hips_height(sk), 0.f);
  if (a_pose) {
    rest[bone::left_upper_arm] = axis_angle({0, 0, 1}, -45.f * k_deg);
    rest[bone::right_upper_arm] = axis_angle({0, 0, 1}, 45.f * k_deg);
  }
  std::array<glm::vec3, k_bone_count> joints;
  joint_world_positions(sk, rest, joints);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  auto random_rotation = [&] { return glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng))); };
  // Root: the Armature, 0.01 scale (joints below are in centimetres).
  raw_rig::node armature;
  armature.name = "Armature";
  armature.rest.scale = glm::vec3(0.01f);
  t.raw.nodes.push_back(armature);
  std::vector<glm::quat> world_rot(1, identity_quat());
  std::vector<glm::vec3> world_pos(1, glm::vec3(0.f));  // metres
  std::array<int, k_bone_count> node_of{};
  node_of.fill(-1);
  for (int b = 0; b < k_bone_count; ++b) {
    const bone bb = static_cast<bone>(b);
    std::string name = mixamo_name(bb) ? mixamo_name(bb) : finger_name(bb);
    if (name.empty()) continue;  // eyes, jaw
    if (skip_chest && bb == bone::chest) continue;
    int parent_bone = bone_parent(b);
    while (parent_bone >= 0 && node_of[parent_bone] < 0) parent_bone = bone_parent(parent_bone);
    const int parent = parent_bone < 0 ? 0 : node_of[parent_bone];
    const glm::quat wr = random_rotation();
    raw_rig::node node;
    node.name = "mixamorig:" + name;
    node.parent = parent;
    const glm::quat pr = world_rot[parent];
    node.rest.rotation = glm::normalize(glm::conjugate(pr) * wr);
    // Parent scale: 0.01 for everything below the Armature (centimetres).
    node.rest.translation = glm::conjugate(pr) * (joints[b] - world_pos[parent]) * 100.f;
    node_of[b] = static_cast<int>(t.raw.nodes.size());
    t.raw.nodes.push_back(node);
    world_rot.push_back(wr);
    world_pos.push_back(joints[b]);
  }
  // Bind by name through build_rig's order.
  t.raw.source = rig_source::test;
  for (int b = 0; b < k_bone_count; ++b) t.binding[b] = node_of[b];  // raw indices for now
  return t;
}

bone_binding to_rig_binding(const rig& r, const bone_binding& raw_binding) {
  bone_binding out;
  out.fill(-1);
  for (int b = 0; b < k_bone_count; ++b) {
    if (raw_binding[b] < 0) continue;
    for (int j = 0; j < r.joint_count(); ++j)
      if (r.source_index[j] == raw_binding[b]) out[b] = j;
  }
  return out;
}

using test::posed_positions;

struct direction_errors {
  double sum = 0, max = 0;
  long n = 0;
};

// Angle between each bound joint's posed direction (to its bound primary child) and the
// proxy bone's world direction.
void compare(const rig& r, const bone_binding& binding, const proxy_pose& p, const rig_pose& rp,
             direction_errors& e) {
  std::array<glm::quat, k_bone_count> proxy_world;
  compute_world_rotations(p, proxy_world);
  const std::vector<glm::vec3> pos = posed_positions(r, rp);
  const std::pair<bone, bone> segments[] = {
      {bone::left_upper_arm, bone::left_lower_arm},
      {bone::left_lower_arm, bone::left_hand},
      {bone::right_upper_arm, bone::right_lower_arm},
      {bone::right_lower_arm, bone::right_hand},
      {bone::left_upper_leg, bone::left_lower_leg},
      {bone::left_lower_leg, bone::left_foot},
      {bone::right_upper_leg, bone::right_lower_leg},
      {bone::right_lower_leg, bone::right_foot},
      {bone::left_index_proximal, bone::left_index_intermediate},
      {bone::right_middle_proximal, bone::right_middle_intermediate},
      {bone::left_thumb_proximal, bone::left_thumb_distal},
      {bone::upper_chest, bone::neck},
      {bone::neck, bone::head}};
  for (auto [a, c] : segments) {
    if (binding[idx(a)] < 0 || binding[idx(c)] < 0) continue;
    const glm::vec3 rig_dir = glm::normalize(pos[binding[idx(c)]] - pos[binding[idx(a)]]);
    const glm::vec3 proxy_dir = proxy_world[idx(a)] * bone_rest_direction(a);
    const double err =
        std::atan2(glm::length(glm::cross(rig_dir, proxy_dir)), glm::dot(rig_dir, proxy_dir)) /
        k_deg;
    e.sum += err;
    e.max = std::max(e.max, err);
    ++e.n;
  }
}

void run_case(bool a_pose, bool skip_chest, const char* label) {
  test_rig t = make_mixamo_like(a_pose, skip_chest, 5);
  rig r;
  ASSERT_TRUE(build_rig(t.raw, r).ok());
  const bone_binding binding = to_rig_binding(r, t.binding);
  retargeter rt;
  ASSERT_TRUE(rt.build(r, binding).ok());
  rig_pose rp;
  rt.prepare(rp);
  std::mt19937 rng(9);
  direction_errors e;
  for (int i = 0; i < 300; ++i) {
    proxy_pose p = random_pose(rng);
    rt.apply(p, rp);
    compare(r, binding, p, rp, e);
  }
  std::printf(
      "[figures] retarget onto a Mixamo-shaped rig (%s): bone directions mean %.4f max "
      "%.4f deg over %ld segments\n",
      label, e.sum / e.n, e.max, e.n);
  EXPECT_LT(e.max, 1.0) << label;
}

TEST(Retarget, MixamoShapedRigTPose) {
  run_case(false, false, "T-pose, cm, 0.01 scale, random rest rotations");
}
TEST(Retarget, MixamoShapedRigAPose) { run_case(true, false, "A-pose"); }
TEST(Retarget, MissingChestFoldsIntoTheChain) { run_case(false, true, "no chest"); }

TEST(Retarget, RestPoseGivesTheRigsTPoseAndHipsHeightScales) {
  test_rig t = make_mixamo_like(false, false, 3);
  rig r;
  ASSERT_TRUE(build_rig(t.raw, r).ok());
  const bone_binding binding = to_rig_binding(r, t.binding);
  retargeter rt;
  retarget_options o;
  o.performer_hips_height = 0.95f;
  ASSERT_TRUE(rt.build(r, binding, o).ok());
  rig_pose rp;
  rt.prepare(rp);
  proxy_pose rest;  // hips at 0.95 m = the performer standing
  rt.apply(rest, rp);
  for (int j = 0; j < r.joint_count(); ++j)
    EXPECT_LT(angle_between(rp.local_rotations[j], r.rest_local[j].rotation) / k_deg, 0.05f)
        << r.names[j];
  const std::vector<glm::vec3> pos = posed_positions(r, rp);
  // Standing performer -> the rig's own standing hips height.
  EXPECT_NEAR(pos[binding[idx(bone::hips)]].y, r.rest_world[binding[idx(bone::hips)]][3].y, 1e-3f);
  proxy_pose squat;
  squat.hips_position.y = 0.95f * 0.5f;
  rt.apply(squat, rp);
  const std::vector<glm::vec3> pos2 = posed_positions(r, rp);
  // Half the performer's standing height -> half the rig's hips height above its lowest foot
  // joint (the rig's floor reference).
  const float rest_y = r.rest_world[binding[idx(bone::hips)]][3].y;
  const float floor = rest_y - rt.rig_hips_height();
  EXPECT_NEAR(pos2[binding[idx(bone::hips)]].y, floor + 0.5f * rt.rig_hips_height(), 1e-3f);
}

TEST(Retarget, BadBindingsAreErrors) {
  test_rig t = make_mixamo_like(false, false, 1);
  rig r;
  ASSERT_TRUE(build_rig(t.raw, r).ok());
  bone_binding b = to_rig_binding(r, t.binding);
  retargeter rt;
  bone_binding no_hips = b;
  no_hips[idx(bone::hips)] = -1;
  EXPECT_NE(rt.build(r, no_hips).message().find("hips"), std::string::npos);
  bone_binding dup = b;
  dup[idx(bone::left_hand)] = dup[idx(bone::right_hand)];
  EXPECT_NE(rt.build(r, dup).message().find("both"), std::string::npos);
  bone_binding out_of_range = b;
  out_of_range[idx(bone::head)] = 10000;
  EXPECT_FALSE(rt.build(r, out_of_range).ok());
  bone_binding crossed = b;
  std::swap(crossed[idx(bone::left_upper_arm)], crossed[idx(bone::left_upper_leg)]);
  EXPECT_FALSE(rt.build(r, crossed).ok());
}

}  // namespace
}  // namespace avatarmap

namespace avatarmap {
namespace {

// A table's formulas replace the rest-aware conversion for their bone, SysMocap's way:
// rig local = quat_from_euler(rest Euler + f(proxy Euler), order).
TEST(Retarget, TableFormulasApplySysMocapSemantics) {
  raw_rig raw;
  const char* names[] = {"Hips", "Spine", "LeftArm"};
  for (int i = 0; i < 3; ++i) {
    raw_rig::node n;
    n.name = names[i];
    n.parent = i - 1;
    n.rest.translation = glm::vec3(0.f, i == 0 ? 1.f : 0.2f, 0.f);
    if (i == 2) n.rest.rotation = axis_angle({0, 0, 1}, 0.3f);  // a non-zero rest to add to
    raw.nodes.push_back(n);
  }
  rig r;
  ASSERT_TRUE(build_rig(raw, r).ok());
  mapping_table table;
  status st = load_mapping_json(R"({"format_version": 1, "name": "formula-test",
      "bones": {"hips": {"rig": "Hips"}, "spine": {"rig": "Spine"},
                "leftUpperArm": {"rig": "LeftArm", "order": "ZXY", "f": ["-x", "y * 0.5", "-z"]}}})",
                                "formula-test", table);
  ASSERT_TRUE(st.ok()) << st.message();
  bone_binding binding;
  binding.fill(-1);
  binding[idx(bone::hips)] = r.find("Hips");
  binding[idx(bone::spine)] = r.find("Spine");
  binding[idx(bone::left_upper_arm)] = r.find("LeftArm");
  retargeter rt;
  ASSERT_TRUE(rt.build(r, binding, {}, &table).ok());
  rig_pose out;
  rt.prepare(out);
  proxy_pose p;
  p[bone::left_upper_arm] = quat_from_euler({0.2f, -0.4f, 0.6f}, euler_order::zxy);
  rt.apply(p, out);
  const glm::vec3 e = euler_from_quat(p[bone::left_upper_arm], euler_order::zxy);
  const glm::vec3 rest = euler_from_quat(axis_angle({0, 0, 1}, 0.3f), euler_order::zxy);
  const glm::quat want =
      quat_from_euler(rest + glm::vec3(-e.x, 0.5f * e.y, -e.z), euler_order::zxy);
  EXPECT_LT(angle_between(out.local_rotations[binding[idx(bone::left_upper_arm)]], want), 1e-5f);
}

}  // namespace
}  // namespace avatarmap

namespace avatarmap {
namespace {

// "target_order": the proxy's angles are read in `order`, the rig's composed in another.
TEST(Retarget, TableFormulasWithATargetOrder) {
  raw_rig raw;
  for (int i = 0; i < 2; ++i) {
    raw_rig::node n;
    n.name = i == 0 ? "Hips" : "Arm";
    n.parent = i - 1;
    n.rest.translation = glm::vec3(0.f, 1.f, 0.f);
    raw.nodes.push_back(n);
  }
  rig r;
  ASSERT_TRUE(build_rig(raw, r).ok());
  mapping_table table;
  ASSERT_TRUE(load_mapping_json(R"({"format_version": 1, "name": "t", "bones": {
      "hips": {"rig": "Hips"},
      "leftUpperArm": {"rig": "Arm", "order": "ZXY", "target_order": "XYZ",
                       "f": ["z", "-x", "y"]}}})",
                                "t", table)
                  .ok());
  bone_binding binding;
  binding.fill(-1);
  binding[idx(bone::hips)] = 0;
  binding[idx(bone::left_upper_arm)] = 1;
  retargeter rt;
  ASSERT_TRUE(rt.build(r, binding, {}, &table).ok());
  rig_pose out;
  rt.prepare(out);
  proxy_pose p;
  p[bone::left_upper_arm] = quat_from_euler({0.3f, 0.2f, -0.5f}, euler_order::zxy);
  rt.apply(p, out);
  const glm::vec3 e = euler_from_quat(p[bone::left_upper_arm], euler_order::zxy);
  const glm::quat want = quat_from_euler(glm::vec3(e.z, -e.x, e.y), euler_order::xyz);
  EXPECT_LT(angle_between(out.local_rotations[1], want), 1e-5f);
}

}  // namespace
}  // namespace avatarmap
