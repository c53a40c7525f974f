// BVH skeletons as avatars and BVH motion as input (include/avatarmap/rig/bvh_rig.hpp,
// include/avatarmap/rig/retarget_inverse.hpp): the rig is the file's HIERARCHY (names,
// OFFSETs, units by height, lifted onto the floor); the motion is read by the inverse of the
// retargeter, checked as its inverse (proxy -> rig -> proxy, in memory and through a written
// rig BVH); the CMU mocap binds every key bone and walks on the floor; broken files fail with
// the file and line.
#include "avatarmap/rig/bvh_rig.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/export/bvh.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/rig/bound_avatar.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/retarget_inverse.hpp"
#include "support/rig_fk.hpp"
#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

// A small CMU-named skeleton in CMU units (legs, spine, neck, head, arms hanging down, one
// finger segment), at rest and one frame; `toes` false leaves the toes out, `legs` false the
// legs, `mixamo` names it as a Mixamo BVH export ("mixamorig:" names, T-pose arms).
std::string skeleton_text(bool toes = true, bool legs = true) {
  std::string leg;
  for (const char* side : {"Left", "Right"}) {
    const std::string s(side);
    const std::string x = s == "Left" ? "1.2" : "-1.2";
    const std::string hj = s == "Left" ? "LHipJoint" : "RHipJoint";
    leg += "JOINT " + hj + " { OFFSET 0 0 0 CHANNELS 3 Zrotation Yrotation Xrotation\n";
    leg += " JOINT " + s + "Hip { OFFSET " + x +
           " -1.6 0.7 CHANNELS 3 Zrotation Yrotation Xrotation\n";
    leg += "  JOINT " + s + "Knee { OFFSET 0 -7.2 0 CHANNELS 3 Zrotation Yrotation Xrotation\n";
    leg += "   JOINT " + s + "Ankle { OFFSET 0 -6.9 0 CHANNELS 3 Zrotation Yrotation Xrotation\n";
    if (toes)
      leg += "    JOINT " + s +
             "Toe { OFFSET 0 -0.4 2.2 CHANNELS 3 Zrotation Yrotation Xrotation\n"
             "     End Site { OFFSET 0 0 1.1 } }\n";
    else
      leg += "    End Site { OFFSET 0 -0.4 2.2 }\n";
    leg += "} } } }\n";
  }
  std::string arms;
  for (const char* side : {"Left", "Right"}) {
    const std::string s(side);
    const std::string x = s == "Left" ? "3.0" : "-3.0";
    const std::string l = s == "Left" ? "l" : "r";
    const std::string L = s == "Left" ? "L" : "R";
    arms += "JOINT " + s + "Collar { OFFSET 0 0 0 CHANNELS 3 Zrotation Yrotation Xrotation\n";
    arms += " JOINT " + s + "Shoulder { OFFSET " + x +
            " 1.5 0 CHANNELS 3 Zrotation Xrotation Yrotation\n";
    arms += "  JOINT " + s + "Elbow { OFFSET 0 -4.2 0 CHANNELS 3 Zrotation Xrotation Yrotation\n";
    arms += "   JOINT " + s + "Wrist { OFFSET 0 -3.3 0 CHANNELS 3 Zrotation Xrotation Yrotation\n";
    arms += "    JOINT " + l + "hand { OFFSET 0 0 0 CHANNELS 3 Zrotation Xrotation Yrotation\n";
    arms +=
        "     JOINT " + L + "Fingers { OFFSET 0 -0.66 0 CHANNELS 3 Zrotation Xrotation Yrotation\n";
    arms += "      End Site { OFFSET 0 -0.53 0 } }\n";
    arms += "     JOINT " + L + "Thumb { OFFSET 0 0 0 CHANNELS 3 Zrotation Xrotation Yrotation\n";
    arms += "      End Site { OFFSET 0 -0.54 0.54 } } } } } } }\n";
  }
  return "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n"
         " CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n" +
         (legs ? leg : std::string()) +
         "JOINT lowerback { OFFSET 0 0 0 CHANNELS 3 Zrotation Yrotation Xrotation\n"
         " JOINT Chest { OFFSET 0 2.0 0 CHANNELS 3 Zrotation Yrotation Xrotation\n"
         "  JOINT Chest2 { OFFSET 0 2.0 0 CHANNELS 3 Zrotation Yrotation Xrotation\n"
         "   JOINT lowerneck { OFFSET 0 0 0 CHANNELS 3 Zrotation Yrotation Xrotation\n"
         "    JOINT Neck { OFFSET 0 1.6 0.1 CHANNELS 3 Zrotation Yrotation Xrotation\n"
         "     JOINT Head { OFFSET 0 1.6 0 CHANNELS 3 Zrotation Yrotation Xrotation\n"
         "      End Site { OFFSET 0 1.6 0 } } } }\n" +
         arms + "} } }\n}\n";
}

// The motion block for `clip`'s channel count: `frames` frames, each value `v`.
std::string motion_text(int channels, int frames, const std::string& v = "0") {
  std::string m = "MOTION\nFrames: " + std::to_string(frames) + "\nFrame Time: 0.0083333\n";
  for (int f = 0; f < frames; ++f) {
    for (int c = 0; c < channels; ++c) m += (c == 1 ? std::string("17") : v) + " ";
    m += "\n";
  }
  return m;
}

int channel_count(const std::string& hierarchy) {
  int n = 0;
  for (std::size_t at = hierarchy.find("CHANNELS"); at != std::string::npos;
       at = hierarchy.find("CHANNELS", at + 1))
    n += std::stoi(hierarchy.substr(at + 9, 1));
  return n;
}

std::string write_file(const test::temp_dir& dir, const std::string& name,
                       const std::string& text) {
  const std::string path = dir.file(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string small_bvh(const test::temp_dir& dir, bool toes = true, bool legs = true) {
  const std::string h = skeleton_text(toes, legs);
  return write_file(dir, "small.bvh", h + motion_text(channel_count(h), 3));
}

TEST(BvhRig, HierarchyIsTheRigNamesOffsetsUnitsAndFloor) {
  test::temp_dir dir("bvh_rig");
  const std::string path = small_bvh(dir);
  bvh_clip clip;
  ASSERT_TRUE(read_bvh(path, clip).ok());
  // Rest height: toe end (-7.2-6.9-1.6-0.4 = -16.1) to head end (2+2+1.6+1.6+1.6 = 8.8).
  EXPECT_NEAR(bvh_rest_height(clip), 24.9f, 1e-4f);
  EXPECT_EQ(detect_bvh_units(clip).metres_per_unit, k_cmu_metres_per_unit);  // 1.41 m
  raw_rig raw;
  ASSERT_TRUE(load_avatar(path, raw).ok());  // the .bvh dispatch
  ASSERT_EQ(raw.nodes.size(), clip.joints.size());
  // The lowest joints (the toes, -1.6 - 7.2 - 6.9 - 0.4 = -16.1 units below the hips) stand
  // on the floor: the root is lifted by 16.1 units.
  const float k = k_cmu_metres_per_unit;
  for (std::size_t i = 0; i < clip.joints.size(); ++i) {
    EXPECT_EQ(raw.nodes[i].name, clip.joints[i].name);
    EXPECT_EQ(raw.nodes[i].parent, clip.joints[i].parent);
    glm::vec3 expect = clip.joints[i].offset * k;
    if (clip.joints[i].parent < 0) expect.y += 16.1f * k;
    EXPECT_NEAR(glm::length(raw.nodes[i].rest.translation - expect), 0.f, 1e-6f) << i;
    EXPECT_EQ(raw.nodes[i].rest.rotation, identity_quat());
    // End Sites are the joints' tips (the toes' tips: where the sole ends), in metres.
    if (clip.joints[i].has_end_site)
      EXPECT_NEAR(glm::length(raw.nodes[i].tip - clip.joints[i].end_site * k), 0.f, 1e-6f) << i;
    else
      EXPECT_TRUE(std::isnan(raw.nodes[i].tip.x)) << i;
  }
  EXPECT_EQ(raw.floor_y, 0.f);
  // Units given win over detection; centimetres and metres are detected too.
  ASSERT_TRUE(load_bvh_avatar(path, raw, {0.01f}).ok());
  EXPECT_NEAR(raw.nodes[3].rest.translation.y, -0.072f, 1e-6f);     // LeftKnee
  for (const auto& [scale, unit] : {std::pair{7.f, 0.01f},          // 174 units: cm
                                    std::pair{1.75f / 24.9f, 1.f},  // 1.75 units: metres
                                    std::pair{70.f, 0.001f}}) {     // 1743 units: mm
    bvh_clip scaled = clip;
    for (bvh_joint& j : scaled.joints) {
      j.offset *= scale;
      j.end_site *= scale;
    }
    EXPECT_EQ(detect_bvh_units(scaled).metres_per_unit, unit) << scale;
  }
}

TEST(BvhRig, BindsByTheTablesWithAndWithoutToes) {
  test::temp_dir dir("bvh_rig");
  bound_avatar a;
  ASSERT_TRUE(bind_avatar(small_bvh(dir), {}, a).ok()) << a.description;
  EXPECT_EQ(a.choice.table.name, "cmu");
  EXPECT_EQ(a.rig.names[a.binding[idx(bone::left_toes)]], "LeftToe");
  EXPECT_EQ(a.rig.names[a.binding[idx(bone::left_hand)]], "lhand");
  EXPECT_EQ(a.rig.names[a.binding[idx(bone::neck)]], "Neck");
  // A rig without toes binds without toes.
  test::temp_dir dir2("bvh_rig");
  bound_avatar b;
  ASSERT_TRUE(bind_avatar(small_bvh(dir2, false), {}, b).ok()) << b.description;
  EXPECT_EQ(b.binding[idx(bone::left_toes)], -1);
  EXPECT_EQ(b.binding[idx(bone::right_toes)], -1);
  EXPECT_GE(b.binding[idx(bone::left_foot)], 0);
  EXPECT_EQ(b.bound, a.bound - 2);
  // A Mixamo BVH export ("mixamorig:" names) binds by mixamo.json.
  // Hips > Spine > Spine1 > Spine2 > (Neck > Head, the arms); the legs under the hips.
  auto joint = [](const std::string& name, const std::string& offset) {
    return "JOINT mixamorig:" + name + " { OFFSET " + offset +
           " CHANNELS 3 Zrotation Xrotation Yrotation\n";
  };
  std::string mixamo =
      "HIERARCHY\nROOT mixamorig:Hips\n{ OFFSET 0 100 0 CHANNELS 6 Xposition "
      "Yposition Zposition Zrotation Xrotation Yrotation\n";
  mixamo += joint("Spine", "0 10 0") + joint("Spine1", "0 10 0") + joint("Spine2", "0 10 0");
  mixamo += joint("Neck", "0 15 0") + joint("Head", "0 10 0") + "End Site { OFFSET 0 20 0 } } }\n";
  for (const char* side : {"Left", "Right"}) {
    const std::string s(side), x = s == "Left" ? "" : "-";
    mixamo += joint(s + "Arm", x + "15 10 0") + joint(s + "ForeArm", x + "28 0 0") +
              joint(s + "Hand", x + "25 0 0") + "End Site { OFFSET " + x + "10 0 0 } } } }\n";
  }
  mixamo += "} } }\n";  // Spine2, Spine1, Spine
  for (const char* side : {"Left", "Right"}) {
    const std::string s(side), x = s == "Left" ? "" : "-";
    mixamo += joint(s + "UpLeg", x + "10 -5 0") + joint(s + "Leg", "0 -45 0") +
              joint(s + "Foot", "0 -42 0") + "End Site { OFFSET 0 -6 12 } } } }\n";
  }
  mixamo += "}\nMOTION\nFrames: 1\nFrame Time: 0.033333\n";
  for (int c = 0; c < 6 + 3 * (5 + 6 + 6); ++c) mixamo += c == 1 ? "100 " : "0 ";

  bound_avatar m;
  ASSERT_TRUE(bind_avatar(write_file(dir, "mixamo.bvh", mixamo + "\n"), {}, m).ok())
      << m.description;
  EXPECT_EQ(m.choice.table.name, "mixamo");
  EXPECT_EQ(m.rig.names[m.binding[idx(bone::left_hand)]], "mixamorig:LeftHand");
  retargeter r;
  EXPECT_TRUE(r.build(m.rig, m.binding).ok());
  // Its motion: centimetres (rest height: head end 175 - foot end 2 = 173 units), the root's
  // position channels taken as they are (Y 100 cm: hips 1 m above the floor), the rest pose
  // (a T-pose facing +Z) read as the proxy's rest.
  std::vector<proxy_pose> poses;
  bvh_motion_summary s;
  ASSERT_TRUE(read_bvh_motion(m.path, {}, poses, &s).ok());
  EXPECT_STREQ(s.unit.name, "centimetres");
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_LT(glm::length(poses[0].hips_position - glm::vec3(0.f, 1.f, 0.f)), 1e-6f);
  for (int b = 0; b < k_bone_count; ++b)
    EXPECT_LT(rotation_angle(poses[0].rotations[b]), 1e-5f) << bone_name(static_cast<bone>(b));
}

// Random rotations on the bound bones (identity on the others: their rotation would land in
// their bound descendants), the hips anywhere.
proxy_pose random_bound_pose(std::mt19937& rng, const bone_binding& binding) {
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  proxy_pose p;
  p.set_rest();
  for (int b = 0; b < k_bone_count; ++b)
    if (binding[b] >= 0)
      p.rotations[b] = axis_angle(
          normalize_or(glm::vec3(u(rng), u(rng), u(rng)), glm::vec3(1.f, 0.f, 0.f)), 1.2f * u(rng));
  p.hips_position = glm::vec3(0.5f * u(rng), 0.9f + 0.2f * u(rng), 0.5f * u(rng));
  return p;
}

void expect_same_pose(const proxy_pose& a, const proxy_pose& b, const bone_binding& binding,
                      float rad, float metres) {
  for (int k = 0; k < k_bone_count; ++k) {
    if (binding[k] < 0) continue;
    EXPECT_LT(angle_between(a.rotations[k], b.rotations[k]), rad)
        << bone_name(static_cast<bone>(k));
    EXPECT_EQ(b.confidence[k], 1.f);
  }
  EXPECT_LT(glm::length(a.hips_position - b.hips_position), metres);
}

TEST(RetargetInverse, IsTheRetargetersInverseOnBoundBones) {
  test::temp_dir dir("bvh_rig");
  bound_avatar a;
  ASSERT_TRUE(bind_avatar(small_bvh(dir), {}, a).ok());
  std::mt19937 rng(7);
  for (float performer : {0.f, 0.8f}) {  // 0: the rig's own hips height (scale 1)
    retarget_options o;
    retargeter fwd;
    ASSERT_TRUE(fwd.build(a.rig, a.binding, o).ok());
    o.performer_hips_height = performer > 0.f ? performer : fwd.rig_hips_height();
    ASSERT_TRUE(fwd.build(a.rig, a.binding, o).ok());
    inverse_retargeter inv;
    ASSERT_TRUE(inv.build(fwd, o).ok());
    rig_pose rp;
    fwd.prepare(rp);
    for (int i = 0; i < 20; ++i) {
      const proxy_pose p = random_bound_pose(rng, a.binding);
      fwd.apply(p, rp);
      proxy_pose back;
      inv.apply(rp, back);
      expect_same_pose(p, back, a.binding, 1e-4f, 1e-5f);
    }
  }
  // Without root motion the hips cannot be read back: 0.
  retarget_options still;
  still.root_motion = false;
  retargeter fwd;
  ASSERT_TRUE(fwd.build(a.rig, a.binding, still).ok());
  inverse_retargeter inv;
  ASSERT_TRUE(inv.build(fwd, still).ok());
  rig_pose rp;
  fwd.prepare(rp);
  fwd.apply(random_bound_pose(rng, a.binding), rp);
  proxy_pose back;
  inv.apply(rp, back);
  EXPECT_EQ(back.hips_position, glm::vec3(0.f));
}

// proxy -> rig -> write_rig_bvh -> read_bvh_motion (reads the written file on its own skeleton)
// -> proxy: the identity on bound bones within 1e-4 rad, the hips within 1e-4 m.
void round_trip_through_file(const std::string& source, const test::temp_dir& dir) {
  bound_avatar a;
  ASSERT_TRUE(bind_avatar(source, {}, a).ok()) << a.description;
  retarget_options o;
  retargeter fwd;
  ASSERT_TRUE(fwd.build(a.rig, a.binding, o).ok());
  o.performer_hips_height = fwd.rig_hips_height();  // the performer's own skeleton
  ASSERT_TRUE(fwd.build(a.rig, a.binding, o).ok());
  std::mt19937 rng(11);
  std::vector<proxy_pose> poses;
  std::vector<rig_pose> rig_poses;
  for (int i = 0; i < 8; ++i) {
    poses.push_back(random_bound_pose(rng, a.binding));
    rig_pose rp;
    fwd.prepare(rp);
    fwd.apply(poses.back(), rp);
    rig_poses.push_back(rp);
  }
  const std::string out = dir.file("written.bvh");
  ASSERT_TRUE(write_rig_bvh(out, a.rig, rig_poses, {}).ok());
  // The written skeleton: the input's joint names, its offsets in centimetres.
  bvh_clip in_clip, out_clip;
  ASSERT_TRUE(read_bvh(source, in_clip).ok());
  ASSERT_TRUE(read_bvh(out, out_clip).ok());
  ASSERT_EQ(in_clip.joints.size(), out_clip.joints.size());
  const float to_cm = detect_bvh_units(in_clip).metres_per_unit * 100.f;
  for (std::size_t i = 0; i < in_clip.joints.size(); ++i) {
    EXPECT_EQ(out_clip.joints[i].name, in_clip.joints[i].name);
    EXPECT_EQ(out_clip.joints[i].parent, in_clip.joints[i].parent);
    if (in_clip.joints[i].parent >= 0)
      EXPECT_LT(glm::length(out_clip.joints[i].offset - in_clip.joints[i].offset * to_cm), 2e-5f)
          << in_clip.joints[i].name;
    // The avatar's own End Sites, not invented ones (a toe's tip is where the sole ends).
    EXPECT_EQ(out_clip.joints[i].has_end_site, in_clip.joints[i].has_end_site);
    if (in_clip.joints[i].has_end_site)
      EXPECT_LT(glm::length(out_clip.joints[i].end_site - in_clip.joints[i].end_site * to_cm),
                2e-5f)
          << in_clip.joints[i].name;
  }
  std::vector<proxy_pose> back;
  bvh_motion_summary summary;
  ASSERT_TRUE(read_bvh_motion(out, {}, back, &summary).ok());
  EXPECT_STREQ(summary.unit.name, "centimetres");
  ASSERT_EQ(back.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR(back[i].t, i / 30.0, 1e-9);
    expect_same_pose(poses[i], back[i], a.binding, 1e-4f, 1e-4f);
  }
}

TEST(BvhMotion, RoundTripThroughAWrittenRigBvh) {
  test::temp_dir dir("bvh_rig");
  round_trip_through_file(small_bvh(dir), dir);
}

TEST(BvhMotion, RoundTripOnTheCmuSkeleton) {
  const std::string path = test::test_data_path("motion/cmu-bvh/131_02.bvh");
  if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
  test::temp_dir dir("bvh_rig");
  round_trip_through_file(path, dir);
}

TEST(BvhMotion, CmuBindsEveryKeyBone) {
  const std::string path = test::test_data_path("motion/cmu-bvh/131_02.bvh");
  if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
  bound_avatar a;
  ASSERT_TRUE(bind_avatar(path, {}, a).ok()) << a.description;
  EXPECT_EQ(a.choice.table.name, "cmu");
  for (bone b : {bone::hips,           bone::spine,
                 bone::chest,          bone::upper_chest,
                 bone::neck,           bone::head,
                 bone::left_shoulder,  bone::right_shoulder,
                 bone::left_upper_arm, bone::right_upper_arm,
                 bone::left_lower_arm, bone::right_lower_arm,
                 bone::left_hand,      bone::right_hand,
                 bone::left_upper_leg, bone::right_upper_leg,
                 bone::left_lower_leg, bone::right_lower_leg,
                 bone::left_foot,      bone::right_foot,
                 bone::left_toes,      bone::right_toes})
    EXPECT_GE(a.binding[idx(b)], 0) << bone_name(b);
}

// The mocap read as proxy poses: a person of plausible size walking forward (+Z, the way the
// performer faces) on the floor, at the file's 120 fps.
TEST(BvhMotion, CmuWalkIsOnTheFloorFacingAndStepping) {
  const std::string path = test::test_data_path("motion/cmu-bvh/131_02.bvh");
  if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
  std::vector<proxy_pose> poses;
  bvh_motion_summary s;
  ASSERT_TRUE(read_bvh_motion(path, {}, poses, &s).ok());
  ASSERT_EQ(poses.size(), 1247u);
  EXPECT_EQ(s.unit.metres_per_unit, k_cmu_metres_per_unit);
  EXPECT_EQ(s.frame_time, 1.0 / 120.0);  // "Frame Time: .0083333"
  EXPECT_NEAR(poses.back().t, 1246.0 / 120.0, 1e-12);
  // Hips height: 0.85 .. 1.05 m standing (a 1.6 .. 1.9 m person).
  std::vector<float> heights;
  for (const proxy_pose& p : poses) heights.push_back(p.hips_position.y);
  std::sort(heights.begin(), heights.end());
  const float standing = heights[heights.size() * 9 / 10];
  EXPECT_GT(standing, 0.85f);
  EXPECT_LT(standing, 1.05f);
  // Walks: travels more than 2 m; the hips face the way it travels (the proxy's forward, +Z,
  // turned by the hips rotation, within 45° of the horizontal displacement).
  const glm::vec3 d = poses.back().hips_position - poses.front().hips_position;
  const glm::vec2 travel(d.x, d.z);
  EXPECT_GT(glm::length(travel), 1.5f);  // 131_02: 29.7 CMU units along +Z
  const proxy_pose& mid = poses[poses.size() / 2];
  const glm::vec3 fwd = mid.rotations[idx(bone::hips)] * glm::vec3(0.f, 0.f, 1.f);
  EXPECT_GT(glm::dot(glm::normalize(glm::vec2(fwd.x, fwd.z)), glm::normalize(travel)), 0.7f);
  // Feet on the floor: the poses put back on the performer's own skeleton (the retargeter with
  // its hips height) have their lowest foot or toe joint just above the floor through the whole
  // clip (0 .. 12 cm: joints sit above the soles; 131_02: 0.3 .. 10.2 cm, median 6.7 cm), never
  // below it; and the feet take turns: each foot is the lower one for at least a fifth of it.
  bound_avatar a;
  ASSERT_TRUE(bind_avatar(path, {}, a).ok());
  retarget_options o;
  retargeter fwd_rig;
  ASSERT_TRUE(fwd_rig.build(a.rig, a.binding, o).ok());
  o.performer_hips_height = fwd_rig.rig_hips_height();
  ASSERT_TRUE(fwd_rig.build(a.rig, a.binding, o).ok());
  rig_pose rp;
  fwd_rig.prepare(rp);
  std::vector<float> lowest;
  int left_lower = 0;
  for (const proxy_pose& p : poses) {
    fwd_rig.apply(p, rp);
    const std::vector<glm::vec3> at = test::posed_positions(a.rig, rp);
    float side[2] = {1e9f, 1e9f};
    for (int k = 0; k < 2; ++k)
      for (bone b : {k == 0 ? bone::left_foot : bone::right_foot,
                     k == 0 ? bone::left_toes : bone::right_toes})
        side[k] = std::min(side[k], at[static_cast<std::size_t>(a.binding[idx(b)])].y);
    lowest.push_back(std::min(side[0], side[1]));
    left_lower += side[0] < side[1];
  }
  std::sort(lowest.begin(), lowest.end());
  std::printf("lowest foot: min %.3f median %.3f max %.3f; left lower %d of %zu\n", lowest.front(),
              lowest[lowest.size() / 2], lowest.back(), left_lower, poses.size());
  EXPECT_GT(lowest.front(), -0.01f);
  EXPECT_LT(lowest.back(), 0.12f);
  EXPECT_GT(left_lower, static_cast<int>(poses.size() / 5));
  EXPECT_LT(left_lower, static_cast<int>(poses.size() * 4 / 5));
}

TEST(BvhMotion, BrokenFilesFailWithFileAndLine) {
  test::temp_dir dir("bvh_rig");
  const std::string h = skeleton_text();
  const int n = channel_count(h);
  std::vector<proxy_pose> poses;
  // Truncated: fewer values than Frames x channels.
  std::string text = h + motion_text(n, 3);
  const std::string cut = write_file(dir, "cut.bvh", text.substr(0, text.size() - 40));
  status st = read_bvh_motion(cut, {}, poses);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.code(), status_code::parse);
  EXPECT_NE(st.message().find(cut + ":"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("truncated"), std::string::npos) << st.message();
  // NaN in the motion: named with its line.
  std::string nan_text = h + motion_text(n, 2);
  nan_text.replace(nan_text.rfind("17"), 2, "nan");
  const std::string nan = write_file(dir, "nan.bvh", nan_text);
  st = read_bvh_motion(nan, {}, poses);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find(nan + ":"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("\"nan\""), std::string::npos) << st.message();
  EXPECT_TRUE(poses.empty());
  // No legs: no table binds it; the message names the file and the missing bones.
  test::temp_dir dir2("bvh_rig");
  const std::string legless = small_bvh(dir2, true, false);
  st = read_bvh_motion(legless, {}, poses);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find(legless), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("leftUpperLeg"), std::string::npos) << st.message();
  // A legless skeleton bound by an explicit table fails on the legs.
  st = read_bvh_motion(legless, {0.f, "cmu", ""}, poses);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find(legless), std::string::npos) << st.message();
  // As an avatar: the same file:line errors through load_avatar.
  raw_rig raw;
  st = load_avatar(cut, raw);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find(cut + ":"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace avatarmap
