// The body in the world (solver stage 1c, docs/solver.md): the body's metric points fitted to
// the image points through the camera. Known answers from the synthetic generator (an
// independent forward model): world points that lean toward the camera as BlazePose's do
// are straightened by the image, a body that truly leans keeps its lean, and the field of
// view is estimated through the lean.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = k_pi / 180.f;

// Turns the world points about the hips (their origin) by `degrees` about the camera's x axis,
// the top toward the camera (MediaPipe world axes: y down, z away from the camera).
void lean_world_toward_camera(landmark_frame& f, float degrees) {
  const float c = std::cos(degrees * k_deg), s = std::sin(degrees * k_deg);
  for (auto& w : f.pose_world) {
    const float y = w.y * c - w.z * s, z = w.y * s + w.z * c;
    w.y = y;
    w.z = z;
  }
}

// Forward lean of the solved torso (degrees, + = toward +Z, the avatar's front): the angle of
// the hips -> upper chest direction from the vertical, in the Y-Z plane.
float torso_lean(const proxy_pose& p) {
  std::array<glm::quat, k_bone_count> w;
  compute_world_rotations(p, w);
  const glm::vec3 up = w[idx(bone::upper_chest)] * glm::vec3(0.f, 1.f, 0.f);
  return std::atan2(up.z, up.y) / k_deg;
}

// A person standing with the torso leaning `lean` degrees forward from the hips (legs
// vertical), seen by the generator's default level camera at 1 m, 3.5 m in front.
proxy_pose leaning_pose(float lean) {
  proxy_pose p;
  p.set_rest();
  p[bone::hips] = glm::angleAxis(lean * k_deg, glm::vec3(1.f, 0.f, 0.f));
  const glm::quat undo = glm::angleAxis(-lean * k_deg, glm::vec3(1.f, 0.f, 0.f));
  p[bone::left_upper_leg] = undo;
  p[bone::right_upper_leg] = undo;
  // Arms down, so the shoulders' line is all the torso shows.
  p[bone::left_upper_arm] = glm::angleAxis(-75.f * k_deg, glm::vec3(0.f, 0.f, 1.f));
  p[bone::right_upper_arm] = glm::angleAxis(75.f * k_deg, glm::vec3(0.f, 0.f, 1.f));
  return p;
}

struct run_out {
  float lean = 0.f;
  float fov = 0.f;
};

run_out solve_take(float truth_lean, float world_lean, bool fit, float fov = 60.f) {
  synth_options so;
  so.face = synth_face::none;
  so.horizontal_fov_degrees = fov;
  landmark_synth synth(so);
  solver_options o;
  o.image_width = float(so.image_width);
  o.image_height = float(so.image_height);
  o.fit_body_to_image = fit;
  frame_solver solver(o);
  proxy_pose truth = leaning_pose(truth_lean), solved;
  ground_pose(synth.skeleton(), truth);
  landmark_frame frame;
  for (int i = 0; i < 150; ++i) {  // 5 s: the field of view settles over a few seconds
    truth.t = i / 30.0;
    synth.generate(truth, frame);
    lean_world_toward_camera(frame, world_lean);
    solver.solve(frame, solved);
  }
  return {torso_lean(solved), solver.horizontal_fov_degrees()};
}

TEST(BodyFit, ExactPointsStayExact) {
  for (float lean : {0.f, 20.f, 40.f, -15.f}) {
    SCOPED_TRACE(lean);
    EXPECT_NEAR(solve_take(lean, 0.f, true).lean, lean, 1.0f);
  }
}

TEST(BodyFit, WorldPointsLeaningTowardTheCameraAreStraightenedByTheImage) {
  for (float world_lean : {12.f, 20.f, 28.f}) {
    SCOPED_TRACE(world_lean);
    // Without the fit the solver reproduces the world points' lean...
    EXPECT_GT(solve_take(0.f, world_lean, false).lean, world_lean - 2.f);
    // ... with it the upright body stands upright.
    EXPECT_NEAR(solve_take(0.f, world_lean, true).lean, 0.f, 2.f);
  }
}

TEST(BodyFit, ATrueLeanSurvivesTheWorldPointsBias) {
  // A torso truly leaning 35 degrees forward whose world points lean 20 degrees more: the
  // image's foreshortening gives the angle, the world points only the side.
  EXPECT_NEAR(solve_take(35.f, 20.f, true).lean, 35.f, 2.f);
}

TEST(BodyFit, FieldOfViewEstimatedThroughTheLean) {
  for (float fov : {45.f, 60.f, 80.f}) {
    SCOPED_TRACE(fov);
    EXPECT_NEAR(solve_take(0.f, 20.f, true, fov).fov, fov, 2.f);
  }
}

TEST(BodyFit, UnseenAndNonFinitePointsNeverMakeANonFinitePose) {
  synth_options so;
  so.face = synth_face::none;
  landmark_synth synth(so);
  solver_options o;
  o.image_width = float(so.image_width);
  o.image_height = float(so.image_height);
  frame_solver solver(o);
  proxy_pose truth = leaning_pose(10.f), solved;
  ground_pose(synth.skeleton(), truth);
  landmark_frame frame;
  const float nan = std::nanf("");
  for (int i = 0; i < 60; ++i) {
    truth.t = i / 30.0;
    synth.generate(truth, frame);
    // An elbow that is not finite, a knee never seen, every third frame the whole world set
    // broken, every fifth the image points.
    frame.pose_world[idx(pose_landmark::left_elbow)].x = nan;
    frame.pose[idx(pose_landmark::right_knee)].visibility = 0.f;
    if (i % 3 == 0)
      for (auto& w : frame.pose_world) w.y = std::numeric_limits<float>::infinity();
    if (i % 5 == 0)
      for (auto& p : frame.pose) p.x = nan;
    solver.solve(frame, solved);
    for (const auto& q : solved.rotations)
      ASSERT_TRUE(std::isfinite(q.x + q.y + q.z + q.w)) << "frame " << i;
    ASSERT_TRUE(
        std::isfinite(solved.hips_position.x + solved.hips_position.y + solved.hips_position.z))
        << "frame " << i;
  }
  // What was seen is still measured: the other arm, the other leg.
  EXPECT_GT(solved.confidence[idx(bone::right_lower_arm)], 0.f);
  EXPECT_GT(solved.confidence[idx(bone::left_lower_leg)], 0.f);
}

}  // namespace
}  // namespace avatarmap
