// The VMC bundle of a proxy pose: message order and names, counts, Unity's left-handed
// conversion on known motions, rest positions from the proxy skeleton and from real avatars,
// rotations composed over bones a model lacks, expressions by VRM 0.x names. Bundles are read
// back with the tests' own OSC decoder (osc_test_reader.hpp).
#include "avatarmap/stream/vmc_bundle.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/stream/unity_space.hpp"
#include "avatarmap/stream/vmc_names.hpp"
#include "osc_test_reader.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

constexpr float k_pi = 3.14159265358979f;

struct decoded {
  test::osc_packet packet;
  std::map<std::string, const test::osc_message*> bones;  // by Unity name
  std::map<std::string, float> blends;                    // by VRM 0.x name
};

// Builds the bundle and decodes it; fails the test when either step fails.
void build(const vmc_skeleton& s, const proxy_pose& pose, float time, decoded& out,
           vmc_blend_set blends = vmc_blend_set::vrm0) {
  std::array<std::uint8_t, k_vmc_bundle_capacity> buf{};
  osc_writer w(buf.data(), buf.size());
  ASSERT_TRUE(write_vmc_bundle(s, pose, time, w, blends));
  ASSERT_TRUE(test::read_osc_packet(w.data(), w.size(), out.packet));
  for (const auto& m : out.packet.messages) {
    if (m.address == "/VMC/Ext/Bone/Pos") out.bones[m.args[0].s] = &m;
    if (m.address == "/VMC/Ext/Blend/Val") out.blends[m.args[0].s] = m.args[1].f;
  }
}

glm::vec3 position_of(const test::osc_message& m) {
  return {m.args[1].f, m.args[2].f, m.args[3].f};
}
glm::quat rotation_of(const test::osc_message& m) {  // message order x y z w
  return glm::quat(m.args[7].f, m.args[4].f, m.args[5].f, m.args[6].f);
}

void expect_quat_near(const glm::quat& a, const glm::quat& b, float tol = 1e-5f) {
  const float d = std::abs(glm::dot(a, b));  // q and -q are the same rotation
  EXPECT_NEAR(d, 1.f, tol) << "got {" << a.x << ", " << a.y << ", " << a.z << ", " << a.w
                           << "} want {" << b.x << ", " << b.y << ", " << b.z << ", " << b.w << "}";
}

TEST(vmc_bundle, messages_in_order_with_every_bone_and_preset) {
  const vmc_skeleton s = make_vmc_skeleton(make_proxy_skeleton());
  proxy_pose pose;
  decoded d;
  build(s, pose, 2.5f, d);
  const auto& msgs = d.packet.messages;
  ASSERT_TRUE(d.packet.is_bundle);
  EXPECT_EQ(d.packet.time_tag, 1u);  // immediately
  ASSERT_EQ(msgs.size(), 1u + 55u + 16u + 3u);
  EXPECT_EQ(msgs[0].address, "/VMC/Ext/Root/Pos");
  EXPECT_EQ(msgs[0].types, "sfffffff");
  EXPECT_EQ(msgs[0].args[0].s, "root");
  for (int k = 1; k <= 6; ++k) EXPECT_EQ(msgs[0].args[k].f, 0.f);
  EXPECT_EQ(msgs[0].args[7].f, 1.f);
  for (int b = 0; b < k_bone_count; ++b) {
    const auto& m = msgs[1 + b];
    EXPECT_EQ(m.address, "/VMC/Ext/Bone/Pos");
    EXPECT_EQ(m.types, "sfffffff");
    EXPECT_EQ(m.args[0].s, unity_bone_name(static_cast<bone>(b)));
  }
  // VRM 0.x's preset names (UniVRM's BlendShapePreset), in the proxy's expression order.
  const char* presets[] = {"Blink", "Blink_L", "Blink_R", "A",        "I",        "U",
                           "E",     "O",       "LookUp",  "LookDown", "LookLeft", "LookRight",
                           "Joy",   "Angry",   "Sorrow",  "Fun"};
  for (int k = 0; k < 16; ++k) {
    const auto& m = msgs[56 + k];
    EXPECT_EQ(m.address, "/VMC/Ext/Blend/Val");
    EXPECT_EQ(m.types, "sf");
    EXPECT_EQ(m.args[0].s, presets[k]);
  }
  EXPECT_EQ(msgs[72].address, "/VMC/Ext/Blend/Apply");
  EXPECT_EQ(msgs[72].types, "");
  EXPECT_EQ(msgs[73].address, "/VMC/Ext/OK");
  ASSERT_EQ(msgs[73].types, "i");
  EXPECT_EQ(msgs[73].args[0].i, 1);
  EXPECT_EQ(msgs[74].address, "/VMC/Ext/T");
  ASSERT_EQ(msgs[74].types, "f");
  EXPECT_EQ(msgs[74].args[0].f, 2.5f);
  EXPECT_EQ(vmc_blend_count(), 16);
  EXPECT_EQ(vmc_blend_count(vmc_blend_set::arkit), 52);
  EXPECT_EQ(vmc_blend_count(vmc_blend_set::both), 68);
}

TEST(vmc_bundle, unity_bone_names_are_humanbodybones) {
  // Spot checks against Unity's HumanBodyBones; the thumb's three joints are Unity's
  // Proximal/Intermediate/Distal (VRM 1.0's Metacarpal/Proximal/Distal).
  EXPECT_EQ(unity_bone_name(bone::hips), "Hips");
  EXPECT_EQ(unity_bone_name(bone::upper_chest), "UpperChest");
  EXPECT_EQ(unity_bone_name(bone::left_thumb_metacarpal), "LeftThumbProximal");
  EXPECT_EQ(unity_bone_name(bone::left_thumb_proximal), "LeftThumbIntermediate");
  EXPECT_EQ(unity_bone_name(bone::right_thumb_distal), "RightThumbDistal");
  EXPECT_EQ(unity_bone_name(bone::right_little_intermediate), "RightLittleIntermediate");
  EXPECT_EQ(unity_bone_name(bone::left_toes), "LeftToes");
  // Every other name is the VRM 1.0 name with a capital first letter.
  for (int b = 0; b < k_bone_count; ++b) {
    const std::string vrm(bone_name(static_cast<bone>(b)));
    if (vrm.find("Thumb") != std::string::npos) continue;
    std::string want = vrm;
    want[0] = static_cast<char>(want[0] - 'a' + 'A');
    EXPECT_EQ(unity_bone_name(static_cast<bone>(b)), want);
  }
}

TEST(vmc_bundle, raising_the_left_arm_in_unity_space) {
  // In VRM space the left arm rests along +X and R_z(+90 deg) raises it to +Y. A Unity model
  // faces +Z with its left arm along -X: raising it to +Y is the shortest turn from -X to +Y,
  // about -Z: {0, 0, -sin 45, cos 45} (x y z w). Its rest offset from the shoulder, +X in VRM
  // space, is -X in Unity's.
  const proxy_skeleton ps = make_proxy_skeleton();
  const vmc_skeleton s = make_vmc_skeleton(ps);
  proxy_pose pose;
  pose[bone::left_upper_arm] = glm::angleAxis(k_pi / 2, glm::vec3(0, 0, 1));
  decoded d;
  build(s, pose, 0.f, d);
  const auto& m = *d.bones.at("LeftUpperArm");
  const float r = std::sqrt(0.5f);
  expect_quat_near(rotation_of(m), glm::quat(r, 0.f, 0.f, -r));
  EXPECT_NEAR(m.args[7].f, r, 1e-6f);  // written as x y z w
  EXPECT_NEAR(m.args[6].f, -r, 1e-6f);
  const glm::vec3 rest = ps.offsets[idx(bone::left_upper_arm)];
  ASSERT_GT(rest.x, 0.f);
  EXPECT_FLOAT_EQ(position_of(m).x, -rest.x);
  EXPECT_FLOAT_EQ(position_of(m).y, rest.y);
  EXPECT_FLOAT_EQ(position_of(m).z, rest.z);
  // The Unity rotation carries Unity's rest arm (-X) to Unity's up.
  const glm::vec3 up = rotation_of(m) * glm::vec3(-1, 0, 0);
  EXPECT_NEAR(up.x, 0.f, 1e-6f);
  EXPECT_NEAR(up.y, 1.f, 1e-6f);
}

TEST(vmc_bundle, turning_the_head_to_the_left_in_unity_space) {
  // R_y(+30 deg) turns the face (+Z) toward the avatar's left (+X in VRM space). In Unity the
  // model faces +Z and its left is -X: the same turn must take +Z toward -X.
  const vmc_skeleton s = make_vmc_skeleton(make_proxy_skeleton());
  proxy_pose pose;
  pose[bone::head] = glm::angleAxis(k_pi / 6, glm::vec3(0, 1, 0));
  decoded d;
  build(s, pose, 0.f, d);
  const glm::quat q = rotation_of(*d.bones.at("Head"));
  expect_quat_near(q, glm::quat(std::cos(k_pi / 12), 0.f, -std::sin(k_pi / 12), 0.f));
  const glm::vec3 face = q * glm::vec3(0, 0, 1);
  EXPECT_NEAR(face.x, -0.5f, 1e-6f);
  EXPECT_NEAR(face.z, std::sqrt(3.f) / 2, 1e-6f);
}

TEST(vmc_bundle, conversion_matches_mirroring_positions_through_x) {
  // For random rotations and vectors, rotating in VRM space then converting equals converting
  // both then rotating in Unity space (the conversion is a change of basis by the mirror X).
  std::uint32_t seed = 12345;
  auto next = [&] {
    seed = seed * 1664525u + 1013904223u;
    return static_cast<float>(seed >> 8) / 16777216.f * 2.f - 1.f;
  };
  for (int i = 0; i < 200; ++i) {
    const glm::quat q = glm::normalize(glm::quat(next(), next(), next(), next()));
    const glm::vec3 v(next(), next(), next());
    const glm::vec3 a = vrm_to_unity_position(q * v);
    const glm::vec3 b = vrm_to_unity_rotation(q) * vrm_to_unity_position(v);
    EXPECT_NEAR(a.x, b.x, 1e-5f);
    EXPECT_NEAR(a.y, b.y, 1e-5f);
    EXPECT_NEAR(a.z, b.z, 1e-5f);
  }
}

TEST(vmc_bundle, hips_position_and_rest_offsets_of_the_proxy) {
  const proxy_skeleton ps = make_proxy_skeleton();
  const vmc_skeleton s = make_vmc_skeleton(ps);
  proxy_pose pose;
  pose.hips_position = glm::vec3(0.1f, 0.9f, -0.2f);
  decoded d;
  build(s, pose, 0.f, d);
  const glm::vec3 hips = position_of(*d.bones.at("Hips"));
  EXPECT_FLOAT_EQ(hips.x, -0.1f);
  EXPECT_FLOAT_EQ(hips.y, 0.9f);
  EXPECT_FLOAT_EQ(hips.z, -0.2f);
  // Real proportions, not zeros: spine 8 cm above the hips, the right thigh at +X in Unity.
  const glm::vec3 spine = position_of(*d.bones.at("Spine"));
  EXPECT_FLOAT_EQ(spine.y, ps.offsets[idx(bone::spine)].y);
  EXPECT_GT(spine.y, 0.05f);
  EXPECT_GT(position_of(*d.bones.at("RightUpperLeg")).x, 0.05f);
  EXPECT_LT(position_of(*d.bones.at("LeftUpperLeg")).x, -0.05f);
  int zero = 0;
  for (const auto& [name, m] : d.bones) zero += glm::length(position_of(*m)) == 0.f;
  EXPECT_EQ(zero, 0);
}

TEST(vmc_bundle, rotations_compose_over_bones_not_sent) {
  // A model without upperChest: the neck's and shoulders' rotations are relative to the chest,
  // so the upperChest's rotation is folded into them; offsets skip it too.
  const proxy_skeleton ps = make_proxy_skeleton();
  vmc_skeleton s = make_vmc_skeleton(ps);
  s.sent[idx(bone::upper_chest)] = false;
  s.sent_count = k_bone_count - 1;
  s.offsets[idx(bone::neck)] = ps.offsets[idx(bone::upper_chest)] + ps.offsets[idx(bone::neck)];
  proxy_pose pose;
  const glm::quat uc = glm::angleAxis(0.3f, glm::normalize(glm::vec3(1, 2, 0)));
  const glm::quat neck = glm::angleAxis(-0.4f, glm::vec3(0, 0, 1));
  pose[bone::upper_chest] = uc;
  pose[bone::neck] = neck;
  decoded d;
  build(s, pose, 0.f, d);
  EXPECT_EQ(d.bones.count("UpperChest"), 0u);
  EXPECT_EQ(d.bones.size(), 54u);
  expect_quat_near(rotation_of(*d.bones.at("Neck")), vrm_to_unity_rotation(uc * neck));
  expect_quat_near(rotation_of(*d.bones.at("LeftShoulder")), vrm_to_unity_rotation(uc));
  expect_quat_near(rotation_of(*d.bones.at("Chest")), glm::quat(1, 0, 0, 0));
}

TEST(vmc_bundle, expressions_by_vrm0_names_clamped) {
  const vmc_skeleton s = make_vmc_skeleton(make_proxy_skeleton());
  proxy_pose pose;
  pose[expression::aa] = 0.7f;
  pose[expression::blink_left] = 0.3f;
  pose[expression::look_right] = 1.5f;
  pose[expression::oh] = std::numeric_limits<float>::quiet_NaN();
  pose[expression::ee] = -0.2f;
  pose[expression::brow_up_left] = 0.9f;  // no VRM 0.x preset: not sent
  pose[expression::surprised] = 0.8f;     // likewise
  pose[expression::happy] = 0.6f;         // VRM 0.x's Joy
  pose[expression::sad] = 0.25f;          // Sorrow
  pose[blendshape::jaw_open] = 0.5f;      // ARKit: not in the vrm0 set
  decoded d;
  build(s, pose, 0.f, d);
  EXPECT_EQ(d.blends.size(), 16u);
  EXPECT_FLOAT_EQ(d.blends.at("Joy"), 0.6f);
  EXPECT_FLOAT_EQ(d.blends.at("Sorrow"), 0.25f);
  EXPECT_FLOAT_EQ(d.blends.at("Angry"), 0.f);
  EXPECT_FLOAT_EQ(d.blends.at("Fun"), 0.f);
  EXPECT_EQ(d.blends.count("jawOpen"), 0u);
  EXPECT_FLOAT_EQ(d.blends.at("A"), 0.7f);
  EXPECT_FLOAT_EQ(d.blends.at("Blink_L"), 0.3f);
  EXPECT_FLOAT_EQ(d.blends.at("LookRight"), 1.f);
  EXPECT_FLOAT_EQ(d.blends.at("O"), 0.f);
  EXPECT_FLOAT_EQ(d.blends.at("E"), 0.f);
  EXPECT_FLOAT_EQ(d.blends.at("Blink"), 0.f);
  for (const auto& [name, w] : d.blends) EXPECT_EQ(name.find("brow"), std::string::npos);
}

// Perfect Sync: ARKit's 52 by Apple's names (checked against Apple's list written out here, not
// the library's table), in ARKit's alphabetical order, after the VRM 0.x presets with `both`.
TEST(vmc_bundle, arkit_blendshapes_by_apple_names) {
  const char* apple[] = {
      "browDownLeft",      "browDownRight",      "browInnerUp",         "browOuterUpLeft",
      "browOuterUpRight",  "cheekPuff",          "cheekSquintLeft",     "cheekSquintRight",
      "eyeBlinkLeft",      "eyeBlinkRight",      "eyeLookDownLeft",     "eyeLookDownRight",
      "eyeLookInLeft",     "eyeLookInRight",     "eyeLookOutLeft",      "eyeLookOutRight",
      "eyeLookUpLeft",     "eyeLookUpRight",     "eyeSquintLeft",       "eyeSquintRight",
      "eyeWideLeft",       "eyeWideRight",       "jawForward",          "jawLeft",
      "jawOpen",           "jawRight",           "mouthClose",          "mouthDimpleLeft",
      "mouthDimpleRight",  "mouthFrownLeft",     "mouthFrownRight",     "mouthFunnel",
      "mouthLeft",         "mouthLowerDownLeft", "mouthLowerDownRight", "mouthPressLeft",
      "mouthPressRight",   "mouthPucker",        "mouthRight",          "mouthRollLower",
      "mouthRollUpper",    "mouthShrugLower",    "mouthShrugUpper",     "mouthSmileLeft",
      "mouthSmileRight",   "mouthStretchLeft",   "mouthStretchRight",   "mouthUpperUpLeft",
      "mouthUpperUpRight", "noseSneerLeft",      "noseSneerRight",      "tongueOut"};
  const vmc_skeleton s = make_vmc_skeleton(make_proxy_skeleton());
  proxy_pose pose;
  for (int b = 0; b < k_blendshape_count; ++b) pose.blendshapes[b] = 0.01f * float(b + 1);
  pose[blendshape::tongue_out] = 2.f;                                      // clamped
  pose[blendshape::cheek_puff] = std::numeric_limits<float>::quiet_NaN();  // sent as 0
  pose[expression::aa] = 0.4f;
  for (vmc_blend_set set : {vmc_blend_set::arkit, vmc_blend_set::both}) {
    decoded d;
    build(s, pose, 0.f, d, set);
    std::vector<std::string> names;
    for (const auto& m : d.packet.messages)
      if (m.address == "/VMC/Ext/Blend/Val") names.push_back(m.args[0].s);
    const std::size_t first = set == vmc_blend_set::both ? 16u : 0u;
    ASSERT_EQ(names.size(), first + 52u);
    for (std::size_t k = 0; k < 52; ++k) EXPECT_EQ(names[first + k], apple[k]);
    EXPECT_FLOAT_EQ(d.blends.at("browDownLeft"), 0.01f);
    EXPECT_FLOAT_EQ(d.blends.at("jawOpen"), 0.25f);
    EXPECT_FLOAT_EQ(d.blends.at("tongueOut"), 1.f);
    EXPECT_FLOAT_EQ(d.blends.at("cheekPuff"), 0.f);
    EXPECT_EQ(d.blends.count("A"), set == vmc_blend_set::both ? 1u : 0u);
    if (set == vmc_blend_set::both) {
      EXPECT_FLOAT_EQ(d.blends.at("A"), 0.4f);
      EXPECT_EQ(names[0], "Blink");
    }
  }
  EXPECT_EQ(vmc_blend_set_from_name("arkit"), vmc_blend_set::arkit);
  EXPECT_EQ(vmc_blend_set_from_name("both"), vmc_blend_set::both);
  EXPECT_EQ(vmc_blend_set_from_name("vrm0"), vmc_blend_set::vrm0);
  EXPECT_FALSE(vmc_blend_set_from_name("ARKit").has_value());
  EXPECT_FALSE(vmc_blend_set_from_name("").has_value());
}

// The eye bones go out as LeftEye/RightEye with the solver's gaze rotation (the proxy sends
// every bone; an avatar without eye bones sends none: the bone-subset tests).
TEST(vmc_bundle, eye_bones_carry_the_gaze) {
  const vmc_skeleton s = make_vmc_skeleton(make_proxy_skeleton());
  proxy_pose pose;
  // Looking 20 degrees to the avatar's left (about +Y in VRM space), both eyes.
  const glm::quat gaze = glm::angleAxis(20.f * k_pi / 180.f, glm::vec3(0, 1, 0));
  pose[bone::left_eye] = gaze;
  pose[bone::right_eye] = gaze;
  pose[bone::head] = glm::angleAxis(0.2f, glm::vec3(1, 0, 0));
  decoded d;
  build(s, pose, 0.f, d);
  ASSERT_EQ(d.bones.count("LeftEye"), 1u);
  ASSERT_EQ(d.bones.count("RightEye"), 1u);
  // Local to the head (the eyes' parent), Unity space: a turn about Y reverses its sense.
  const float h = std::sin(10.f * k_pi / 180.f), c = std::cos(10.f * k_pi / 180.f);
  expect_quat_near(rotation_of(*d.bones.at("LeftEye")), glm::quat(c, 0.f, -h, 0.f));
  expect_quat_near(rotation_of(*d.bones.at("RightEye")), glm::quat(c, 0.f, -h, 0.f));
}

TEST(vmc_bundle, small_buffer_fails_cleanly) {
  const vmc_skeleton s = make_vmc_skeleton(make_proxy_skeleton());
  proxy_pose pose;
  std::array<std::uint8_t, 1024> buf{};
  osc_writer w(buf.data(), buf.size());
  EXPECT_FALSE(write_vmc_bundle(s, pose, 0.f, w));
  EXPECT_FALSE(w.complete());
  // The largest bundle fits k_vmc_bundle_capacity with room to spare.
  std::array<std::uint8_t, k_vmc_bundle_capacity> big{};
  osc_writer w2(big.data(), big.size());
  ASSERT_TRUE(write_vmc_bundle(s, pose, 0.f, w2));
  EXPECT_LT(w2.size(), 6000u);
  EXPECT_GT(w2.size(), 5000u);
  std::array<std::uint8_t, k_vmc_bundle_capacity> all{};
  osc_writer w3(all.data(), all.size());
  ASSERT_TRUE(write_vmc_bundle(s, pose, 0.f, w3, vmc_blend_set::both));
  EXPECT_LT(w3.size(), 9000u);
  EXPECT_GT(w3.size(), 7500u);
}

// Loads a shared avatar into a rig (skips without the data folder).
#define LOAD_RIG(name, r)                                         \
  const std::string path = test::test_data_path("avatars/" name); \
  if (path.empty()) GTEST_SKIP() << test::k_no_test_data;         \
  rig r;                                                          \
  {                                                               \
    raw_rig raw_;                                                 \
    status s_ = load_avatar(path, raw_);                          \
    ASSERT_TRUE(s_.ok()) << s_.message();                         \
    s_ = build_rig(raw_, r);                                      \
    ASSERT_TRUE(s_.ok()) << s_.message();                         \
  }

TEST(vmc_skeleton, vrm1_avatar_rest_positions) {
  LOAD_RIG("vrm1_spec_53bones.vrm", r);
  vmc_skeleton s;
  ASSERT_TRUE(make_vmc_skeleton(r, r.declared_humanoid, 0.95f, s).ok());
  EXPECT_EQ(s.sent_count, 53);
  // The avatar's own numbers: hips 0.85 m above its feet reference when standing.
  const glm::vec3 hips_world(r.rest_world[r.declared_humanoid[idx(bone::hips)]][3]);
  EXPECT_FLOAT_EQ(s.hips_rest.y, hips_world.y);
  const int ua = r.declared_humanoid[idx(bone::left_upper_arm)];
  const int sh = r.declared_humanoid[idx(bone::left_shoulder)];
  const glm::vec3 want = glm::vec3(r.rest_world[ua][3]) - glm::vec3(r.rest_world[sh][3]);
  EXPECT_FLOAT_EQ(s.offsets[idx(bone::left_upper_arm)].x, want.x);
  EXPECT_GT(s.offsets[idx(bone::left_upper_arm)].x, 0.f);  // the avatar's left is +X
  // A performer standing (hips at the performer's standing height) puts the model's hips at
  // their rest height.
  proxy_pose pose;
  pose.hips_position = glm::vec3(0.f, 0.95f, 0.f);
  decoded d;
  build(s, pose, 0.f, d);
  EXPECT_EQ(d.bones.size(), 53u);
  EXPECT_NEAR(position_of(*d.bones.at("Hips")).y, hips_world.y, 1e-5f);
  EXPECT_LT(position_of(*d.bones.at("LeftUpperArm")).x, 0.f);  // Unity: left is -X
}

TEST(vmc_skeleton, vrm0_avatar_is_turned_to_face_plus_z) {
  // VRM 0.x files face -Z, their left arm along -X; in VRM space (and so in the offsets) the
  // left arm must be at +X, as for a VRM 1.0 file.
  LOAD_RIG("vrm0_sphere.vrm", r);
  vmc_skeleton s;
  ASSERT_TRUE(make_vmc_skeleton(r, r.declared_humanoid, 0.95f, s).ok());
  EXPECT_EQ(s.sent_count, 22);
  const int ua = r.declared_humanoid[idx(bone::left_upper_arm)];
  ASSERT_GE(ua, 0);
  EXPECT_LT(r.rest_world[ua][3].x, 0.f);  // in the file: -X
  EXPECT_GT(s.offsets[idx(bone::left_upper_arm)].x, 0.f);
  EXPECT_GT(s.offsets[idx(bone::left_hand)].x, 0.f);
}

TEST(vmc_skeleton, refuses_what_it_cannot_use) {
  rig r;  // no joints
  bone_binding none;
  none.fill(-1);
  vmc_skeleton s;
  status st = make_vmc_skeleton(r, none, 0.95f, s);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("hips"), std::string::npos) << st.message();
  LOAD_RIG("vrm1_spec_53bones.vrm", avatar);
  EXPECT_FALSE(make_vmc_skeleton(avatar, avatar.declared_humanoid, 0.f, s).ok());
  EXPECT_FALSE(make_vmc_skeleton(avatar, avatar.declared_humanoid, std::nanf(""), s).ok());
  bone_binding bad = avatar.declared_humanoid;
  bad[idx(bone::head)] = avatar.joint_count();
  EXPECT_FALSE(make_vmc_skeleton(avatar, bad, 0.95f, s).ok());
}

}  // namespace
}  // namespace avatarmap
