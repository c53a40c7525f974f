// The solver on Google's reference landmarks of a real squat video (tfjs-models test data:
// pose_squats.full.json = image pixels, pose_squats_3d.full.json = world metres; 65 frames
// of a 720x1280 video at 5 fps). Skipped without AVATARMAP_TEST_DATA.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = k_pi / 180.f;
constexpr float k_width = 720.f, k_height = 1280.f;
constexpr double k_fps = 5.0;

bool load(std::vector<landmark_frame>& frames) {
  std::string img = test::test_data_path("motion/tfjs-models/pose_squats.full.json");
  std::string wld = test::test_data_path("motion/tfjs-models/pose_squats_3d.full.json");
  if (img.empty()) return false;
  std::ifstream fi(img), fw(wld);
  nlohmann::json ji = nlohmann::json::parse(fi), jw = nlohmann::json::parse(fw);
  frames.resize(ji.size());
  for (size_t i = 0; i < ji.size(); ++i) {
    landmark_frame& f = frames[i];
    f.t = double(i) / k_fps;
    for (int k = 0; k < 33; ++k) {
      f.pose[k] = landmark{ji[i][k][0].get<float>() / k_width, ji[i][k][1].get<float>() / k_height,
                           ji[i][k][2].get<float>() / k_width, 1.f, 1.f};
      f.pose_world[k] = landmark{jw[i][k][0].get<float>(), jw[i][k][1].get<float>(),
                                 jw[i][k][2].get<float>(), 1.f, 1.f};
    }
    f.set(frame_part::pose, true);
    f.set(frame_part::pose_world, true);
  }
  return true;
}

TEST(RealSquats, HipsHeightFollowsTheSquatsAndBonesMovePlausibly) {
  std::vector<landmark_frame> frames;
  if (!load(frames)) GTEST_SKIP() << test::k_no_test_data;
  solver_options o;
  o.image_width = k_width;
  o.image_height = k_height;
  frame_solver solver(o);
  proxy_pose prev, out;
  std::vector<double> height, image_hip_y;
  float max_step = 0.f;
  int max_bone = -1;
  for (size_t i = 0; i < frames.size(); ++i) {
    solver.solve(frames[i], out);
    height.push_back(out.hips_position.y);
    image_hip_y.push_back(0.5 * (frames[i].pose[23].y + frames[i].pose[24].y));
    if (i > 0) {
      for (int b = 0; b < k_bone_count; ++b) {
        float step = angle_between(out.rotations[b], prev.rotations[b]) / k_deg;
        if (step > max_step) {
          max_step = step;
          max_bone = b;
        }
      }
    }
    prev = out;
  }
  // Pearson correlation between the hips' height and their image y (down): a squat lowers
  // the hips, i.e. raises their image y.
  double mh = 0, my = 0;
  for (size_t i = 0; i < height.size(); ++i) mh += height[i], my += image_hip_y[i];
  mh /= height.size();
  my /= height.size();
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t i = 0; i < height.size(); ++i) {
    sxy += (height[i] - mh) * (image_hip_y[i] - my);
    sxx += (height[i] - mh) * (height[i] - mh);
    syy += (image_hip_y[i] - my) * (image_hip_y[i] - my);
  }
  double corr = sxy / std::sqrt(sxx * syy);
  double hmin = *std::min_element(height.begin(), height.end());
  double hmax = *std::max_element(height.begin(), height.end());
  std::printf(
      "[figures] hips height %.3f..%.3f m, corr(height, image hip y) = %.3f, "
      "max bone step %.1f deg (%s) between frames at 5 fps\n",
      hmin, hmax, corr, max_step, std::string(bone_name(static_cast<bone>(max_bone))).c_str());
  EXPECT_LT(corr, -0.9);
  EXPECT_GT(hmax - hmin, 0.25);  // a real squat lowers the hips by decimetres
  EXPECT_GT(hmin, 0.2);
  EXPECT_LT(hmax, 1.3);
  // At 5 fps (0.2 s per frame) 90 degrees is 450 deg/s: fast arm swings reach that, flips
  // (180 degrees) and jitter across the rest do not.
  EXPECT_LT(max_step, 90.f);
}

}  // namespace
}  // namespace avatarmap
