// Face solving against the synthetic generator's known expressions, and on Google's face mesh
// of a real portrait: blink per eye with 468 and 478 points and several aspect ratios, each
// viseme reachable, gaze direction, brows.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "support/test_data.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = k_pi / 180.f;

proxy_pose standing(const landmark_synth& s) {
  proxy_pose p;
  p.hips_position = glm::vec3(0.f, standing_hips_height(s.skeleton()), 0.f);
  return p;
}

proxy_pose solve_one(landmark_synth& synth, const proxy_pose& truth) {
  landmark_frame f;
  synth.generate(truth, f);
  solver_options o;
  o.image_width = float(synth.options().image_width);
  o.image_height = float(synth.options().image_height);
  frame_solver solver(o);
  proxy_pose out;
  solver.solve(f, out);
  return out;
}

TEST(Face, BlinkPerEyeWith468And478PointsAndAnyAspect) {
  for (synth_face mesh : {synth_face::mesh_468, synth_face::mesh_478}) {
    for (int size : {0, 1, 2}) {
      synth_options so;
      so.face = mesh;
      so.image_width = size == 0 ? 1280 : size == 1 ? 720 : 1000;
      so.image_height = size == 0 ? 720 : size == 1 ? 1280 : 1000;
      landmark_synth synth(so);
      proxy_pose p = standing(synth);
      proxy_pose open = solve_one(synth, p);
      EXPECT_LT(open[expression::blink], 0.05f);
      EXPECT_LT(open[expression::blink_left], 0.05f);
      p[expression::blink_left] = 1.f;  // only the left eye closes
      proxy_pose left = solve_one(synth, p);
      EXPECT_GT(left[expression::blink_left], 0.9f) << int(mesh) << " " << size;
      EXPECT_LT(left[expression::blink_right], 0.05f);
      EXPECT_LT(left[expression::blink], 0.05f);
      p[expression::blink_left] = 0.f;
      p[expression::blink] = 1.f;
      proxy_pose both = solve_one(synth, p);
      EXPECT_GT(both[expression::blink], 0.9f);
      p[expression::blink] = 0.5f;
      proxy_pose half = solve_one(synth, p);
      EXPECT_NEAR(half[expression::blink], 0.5f, 0.1f);
    }
  }
}

TEST(Face, EveryVisemeCanBeReached) {
  landmark_synth synth;
  for (expression e :
       {expression::aa, expression::ih, expression::ou, expression::ee, expression::oh}) {
    proxy_pose p = standing(synth);
    p[e] = 1.f;
    proxy_pose out = solve_one(synth, p);
    EXPECT_GE(out[e], 0.9f) << expression_name(e);
    for (expression other :
         {expression::aa, expression::ih, expression::ou, expression::ee, expression::oh})
      if (other != e)
        EXPECT_LT(out[other], 0.1f) << expression_name(e) << " vs " << expression_name(other);
  }
  proxy_pose closed = solve_one(synth, standing(synth));
  for (expression e :
       {expression::aa, expression::ih, expression::ou, expression::ee, expression::oh})
    EXPECT_LT(closed[e], 0.05f) << expression_name(e);
}

TEST(Face, GazeFollowsTheIrisAndBrowsMove) {
  landmark_synth synth;
  proxy_pose p = standing(synth);
  // Both eyes 20 degrees toward the avatar's left (+X) and 10 degrees up.
  glm::quat eye = axis_angle({0, 1, 0}, 20.f * k_deg) * axis_angle({1, 0, 0}, -10.f * k_deg);
  p[bone::left_eye] = p[bone::right_eye] = eye;
  p[expression::brow_up_left] = 1.f;
  proxy_pose out = solve_one(synth, p);
  glm::vec3 gaze = out[bone::left_eye] * glm::vec3(0, 0, 1);
  glm::vec3 want = eye * glm::vec3(0, 0, 1);
  EXPECT_LT(std::acos(std::min(1.f, glm::dot(gaze, want))) / k_deg, 1.5f);
  EXPECT_GT(out[expression::look_left], 0.5f);
  EXPECT_EQ(out[expression::look_right], 0.f);
  EXPECT_GT(out[expression::look_up], 0.3f);
  EXPECT_GT(out[expression::brow_up_left], 0.8f);
  EXPECT_LT(out[expression::brow_up_right], 0.1f);
}

// Google's face mesh (478 points with iris) of a real portrait: eyes open, looking roughly at
// the camera, head roughly frontal.
TEST(Face, RealPortraitFaceMesh) {
  std::string path = test::test_data_path("golden/portrait_facemesh.json");
  if (path.empty()) GTEST_SKIP() << test::k_no_test_data;
  std::ifstream in(path);
  nlohmann::json j = nlohmann::json::parse(in);
  const float w = j["w"].get<float>(), h = j["h"].get<float>();
  const auto& pts = j["faces_px"][0];
  ASSERT_EQ(pts.size(), 478u);
  landmark_frame f;
  f.face_count = 478;
  for (int i = 0; i < 478; ++i)
    f.face[i] = landmark{pts[i][0].get<float>() / w, pts[i][1].get<float>() / h,
                         pts[i][2].get<float>() / w, 1.f, 1.f};
  f.set(frame_part::face, true);
  solver_options o;
  o.image_width = w;
  o.image_height = h;
  frame_solver solver(o);
  proxy_pose out;
  solver.solve(f, out);
  std::array<glm::quat, k_bone_count> world;
  compute_world_rotations(out, world);
  const float head_deg = rotation_angle(world[idx(bone::head)]) / k_deg;
  const float gaze_deg = rotation_angle(out[bone::left_eye]) / k_deg;
  std::printf(
      "[figures] portrait: head %.1f deg from frontal, gaze %.1f deg, blink L %.2f R %.2f\n",
      head_deg, gaze_deg, out[expression::blink] + out[expression::blink_left],
      out[expression::blink] + out[expression::blink_right]);
  EXPECT_LT(head_deg, 20.f);
  EXPECT_LT(gaze_deg, 15.f);
  EXPECT_LT(out[expression::blink] + out[expression::blink_left], 0.3f);
  EXPECT_LT(out[expression::blink] + out[expression::blink_right], 0.3f);
}

}  // namespace
}  // namespace avatarmap
