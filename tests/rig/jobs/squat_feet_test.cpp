// Real squats (tfjs-models' BlazePose reference landmarks: pose_squats.full.json = image
// pixels, pose_squats_3d.full.json = world metres; 65 frames of a 720x1280 video at 5 fps)
// converted with convert_file_job's defaults (solve, offline filter, foot contacts with root
// motion, retarget, foot locking) onto a Mixamo-shaped BVH skeleton built here and onto the
// built-in avatar. The person squats in place, feet flat: issue 22's figures for the feet on
// the rig (mean horizontal speed <= 1 cm/s and range <= 2 cm per foot joint, toe joints never
// more than 0.5 cm below the floor) and the hips lowered by >= 25 cm at the bottom. Positions
// come from the rig poses through the tests' own forward kinematics (support/rig_fk.hpp).
// Skipped without AVATARMAP_TEST_DATA.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "avatarmap/avatar/builtin_avatar.hpp"
#include "avatarmap/io/tfjs_import.hpp"
#include "avatarmap/jobs/convert_file.hpp"
#include "support/rig_fk.hpp"
#include "support/temp_dir.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

constexpr double k_fps = 5.0;

// A Mixamo BVH export's skeleton (centimetres, "mixamorig:" names, T-pose facing +Z): hips
// 100 cm above the floor, legs 6 + 45 + 43 cm to the ankle, toes 6 cm below and 12 cm ahead
// of the ankle (on the floor), one frame of the rest pose.
std::string mixamo_bvh() {
  auto joint = [](const std::string& name, const std::string& offset) {
    return "JOINT mixamorig:" + name + " { OFFSET " + offset +
           " CHANNELS 3 Zrotation Xrotation Yrotation\n";
  };
  std::string s =
      "HIERARCHY\nROOT mixamorig:Hips\n{ OFFSET 0 100 0 CHANNELS 6 Xposition "
      "Yposition Zposition Zrotation Xrotation Yrotation\n";
  s += joint("Spine", "0 10 0") + joint("Spine1", "0 12 0") + joint("Spine2", "0 12 0");
  s += joint("Neck", "0 16 0") + joint("Head", "0 10 0") + "End Site { OFFSET 0 20 0 } } }\n";
  for (const char* side : {"Left", "Right"}) {
    const std::string n(side), x = n == "Left" ? "" : "-";
    s += joint(n + "Arm", x + "17 10 0") + joint(n + "ForeArm", x + "28 0 0") +
         joint(n + "Hand", x + "25 0 0") + "End Site { OFFSET " + x + "10 0 0 } } } }\n";
  }
  s += "} } }\n";  // Spine2, Spine1, Spine
  for (const char* side : {"Left", "Right"}) {
    const std::string n(side), x = n == "Left" ? "" : "-";
    s += joint(n + "UpLeg", x + "9 -6 0") + joint(n + "Leg", "0 -45 0") +
         joint(n + "Foot", "0 -43 0") + joint(n + "ToeBase", "0 -6 12") +
         "End Site { OFFSET 0 0 8 } } } } }\n";
  }
  s += "}\nMOTION\nFrames: 1\nFrame Time: 0.033333\n";
  for (int c = 0; c < 6 + 3 * (5 + 6 + 8); ++c) s += c == 1 ? "100 " : "0 ";
  return s + "\n";
}

struct feet_figures {
  float speed_cm_s[2]{};      // mean horizontal speed of each foot joint
  float range_cm[2]{};        // larger of its X and Z extents
  float lowest_toe_cm = 0.f;  // lowest toe joint above the rig's floor (negative: below)
  float hips_drop_cm = 0.f;   // highest minus lowest hips joint height
};

// Converts `landmarks` with the defaults onto `avatar` (writing `output`) and measures.
feet_figures convert_and_measure(const std::string& landmarks, const std::string& avatar,
                                 const std::string& output, const char* what, bool lock = true) {
  feet_figures f;
  std::vector<rig_pose> poses;
  convert_file_job j;
  j.input = landmarks;
  j.output = output;
  j.avatar = avatar;
  j.out_rig_poses = &poses;
  j.foot_lock.enabled = lock;
  convert_file_summary s;
  const status st = j.run(s);
  EXPECT_TRUE(st.ok()) << st.message();
  if (!st.ok() || !s.avatar) return f;
  // Avatar outputs are resampled (12.8 s at the rig rate, k_default_rig_fps).
  EXPECT_EQ(s.frames_read, 65u);
  EXPECT_GT(s.output.fps, 0.0);
  EXPECT_EQ(poses.size(), s.output.frames_written);
  if (poses.size() < 2 || !(s.output.fps > 0.0)) return f;
  const rig& r = s.avatar->rig;
  const bone_binding& b = s.avatar->binding;
  const int foot[2] = {b[idx(bone::left_foot)], b[idx(bone::right_foot)]};
  const int toes[2] = {b[idx(bone::left_toes)], b[idx(bone::right_toes)]};
  const int hips = b[idx(bone::hips)];
  EXPECT_GE(std::min({foot[0], foot[1], toes[0], toes[1], hips}), 0);
  // Metres: the rig's rest hips height against the skeleton's own (the BVH is in centimetres
  // with the hips at 100; the built-in avatar is in metres).
  float floor = 1e9f;
  for (int k : {foot[0], foot[1], toes[0], toes[1]})
    floor = std::min(floor, glm::vec3(r.rest_world[k][3]).y);
  std::vector<std::vector<glm::vec3>> at;
  for (const rig_pose& p : poses) at.push_back(test::posed_positions(r, p));
  const float unit = s.avatar->rig.names[hips] == "mixamorig:Hips"
                         ? 1.f / glm::vec3(r.rest_world[hips][3]).y
                         : 1.f;
  const float dt = static_cast<float>(1.0 / s.output.fps);
  float hi = -1e9f, lo = 1e9f, toe_lo = 1e9f;
  for (int side = 0; side < 2; ++side) {
    float path = 0.f, x0 = 1e9f, x1 = -1e9f, z0 = 1e9f, z1 = -1e9f;
    for (size_t i = 0; i < at.size(); ++i) {
      const glm::vec3 p = at[i][foot[side]] * unit;
      x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), z0 = std::min(z0, p.z),
      z1 = std::max(z1, p.z);
      if (i > 0) {
        const glm::vec3 d = p - at[i - 1][foot[side]] * unit;
        path += std::hypot(d.x, d.z);
      }
      toe_lo = std::min(toe_lo, (at[i][toes[side]].y - floor) * unit);
    }
    f.speed_cm_s[side] = 100.f * path / (dt * static_cast<float>(at.size() - 1));
    f.range_cm[side] = 100.f * std::max(x1 - x0, z1 - z0);
  }
  for (const auto& a : at) hi = std::max(hi, a[hips].y * unit), lo = std::min(lo, a[hips].y * unit);
  f.lowest_toe_cm = 100.f * toe_lo;
  f.hips_drop_cm = 100.f * (hi - lo);
  std::printf(
      "%s (%zu poses at %.0f fps): feet speed %.2f / %.2f cm/s, range %.2f / %.2f cm, lowest "
      "toe %.2f cm, hips lowered %.1f cm\n",
      what, poses.size(), s.output.fps, f.speed_cm_s[0], f.speed_cm_s[1], f.range_cm[0],
      f.range_cm[1], f.lowest_toe_cm, f.hips_drop_cm);
  return f;
}

void expect_issue_figures(const feet_figures& f) {
  for (int side = 0; side < 2; ++side) {
    EXPECT_LE(f.speed_cm_s[side], 1.f) << side;
    EXPECT_LE(f.range_cm[side], 2.f) << side;
  }
  EXPECT_GE(f.lowest_toe_cm, -0.5f);
  EXPECT_GE(f.hips_drop_cm, 25.f);
}

TEST(SquatFeet, RealSquatsKeepTheFeetStillOnAMixamoSkeletonAndTheBuiltinAvatar) {
  const std::string img = test::test_data_path("motion/tfjs-models/pose_squats.full.json");
  const std::string wld = test::test_data_path("motion/tfjs-models/pose_squats_3d.full.json");
  if (img.empty() || wld.empty()) GTEST_SKIP() << test::k_no_test_data;
  test::temp_dir dir("squat_feet");
  const std::string landmarks = dir.file("squats.landmarks.jsonl");
  ASSERT_TRUE(import_tfjs_pose(img, wld, 720, 1280, k_fps, landmarks).ok());

  const std::string mixamo = dir.file("mixamo.bvh");
  {
    std::ofstream out(mixamo);
    out << mixamo_bvh();
  }
  expect_issue_figures(
      convert_and_measure(landmarks, mixamo, dir.file("squats.bvh"), "Mixamo skeleton"));
  // The same without foot locking: the contacts' root motion alone leaves the legs' own
  // noise on the feet (the measure tells the two apart).
  const feet_figures free = convert_and_measure(landmarks, mixamo, dir.file("free.bvh"),
                                                "Mixamo skeleton, --no-foot-lock", false);
  EXPECT_GT(std::max(free.speed_cm_s[0], free.speed_cm_s[1]), 1.f);

  const std::string builtin = dir.file("builtin.vrm");
  ASSERT_TRUE(write_builtin_avatar(builtin).ok());
  expect_issue_figures(
      convert_and_measure(landmarks, builtin, dir.file("squats.glb"), "built-in avatar"));
}

}  // namespace
}  // namespace avatarmap
