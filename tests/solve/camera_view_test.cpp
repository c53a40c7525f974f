// The camera's view learnt by the body fit (docs/solver.md, "The body in the world"): the
// vertical from a straight walk's floor line, the floor's level kept along a turning vertical,
// a long time "in the air" read as a floor seen higher, and a held view that learns nothing
// more. Known answers from geometry written out here (a pitched camera's floor line) and from
// the synthetic generator (an independent forward model of a person on a floor).
#include <gtest/gtest.h>

#include <cmath>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "solve/solve_fit.hpp"

namespace avatarmap {
namespace {

using solve_detail::camera_gravity;
constexpr double k_rad = 3.14159265358979 / 180.0;

// The feet's resting points of a walk along `direction` (camera axes: x right, y down, z away)
// on the floor 1.2 m below a camera pitched `pitch` degrees down and rolled `roll` degrees,
// `count` points over `length` metres, with a sideways sway of `sway` metres.
void walk_points(camera_gravity& g, double pitch, double roll, const glm::dvec3& along_level,
                 double length, double sway, int count) {
  // Level-camera axes turned by the pitch (about x) then the roll (about z).
  const double cp = std::cos(pitch * k_rad), sp = std::sin(pitch * k_rad);
  const double cr = std::cos(roll * k_rad), sr = std::sin(roll * k_rad);
  auto to_camera = [&](glm::dvec3 v) {  // a level camera's vector into the tilted camera's axes
    v = glm::dvec3(v.x, cp * v.y - sp * v.z, sp * v.y + cp * v.z);
    return glm::dvec3(cr * v.x - sr * v.y, sr * v.x + cr * v.y, v.z);
  };
  const glm::dvec3 side = glm::normalize(glm::cross(along_level, glm::dvec3(0, 1, 0)));
  const glm::dvec3 start(0.0, 1.2, 3.0);  // level camera: 1.2 m above the floor, 3 m ahead
  for (int i = 0; i < count; ++i) {
    const double s = length * (double(i) / (count - 1) - 0.5);
    const double w = sway * ((i % 2) ? 1.0 : -1.0);
    g.add_floor_point(to_camera(start + s * along_level + w * side));
  }
}

TEST(CameraView, AStraightWalkTowardTheCameraTellsThePitch) {
  for (double pitch : {-8.0, 5.0, 20.0}) {
    SCOPED_TRACE(pitch);
    camera_gravity g;  // the legs' prior: a level camera
    // 3 m toward the camera, the feet 10 cm either side of the line: too narrow for a plane.
    walk_points(g, pitch, 0.0, glm::dvec3(0, 0, 1), 3.0, 0.10, 60);
    glm::vec3 n;
    ASSERT_TRUE(g.floor_normal(n));
    EXPECT_NEAR(g.pitch_degrees(), pitch, 0.3);
    EXPECT_NEAR(g.roll_degrees(), 0.0, 0.3);  // about the line: the legs' (level)
  }
}

TEST(CameraView, AWalkAcrossTellsTheRollOnly) {
  camera_gravity g;
  walk_points(g, 15.0, 6.0, glm::dvec3(1, 0, 0), 3.0, 0.05, 60);
  glm::vec3 n;
  ASSERT_TRUE(g.floor_normal(n));
  // Across the image the line is level: the roll is told; the pitch (about the line) is the
  // legs' prior's, a level camera.
  EXPECT_NEAR(g.pitch_degrees(), 0.0, 0.5);
  EXPECT_GT(std::fabs(g.roll_degrees()), 4.0);
}

TEST(CameraView, FeetInOnePlaceTellNothing) {
  camera_gravity g;
  walk_points(g, 20.0, 0.0, glm::dvec3(0, 0, 1), 0.2, 0.05, 60);
  glm::vec3 n;
  EXPECT_FALSE(g.floor_normal(n));
  EXPECT_NEAR(g.pitch_degrees(), 0.0, 1e-3);
}

// A person standing on the synthetic generator's floor, seen by its camera; frames of `seconds`
// from `t0`, the whole body raised by `raise` metres (a step up, or a jump).
struct standing_take {
  standing_take() : synth(options()) {
    solver_options o;
    o.image_width = float(synth.options().image_width);
    o.image_height = float(synth.options().image_height);
    solver = std::make_unique<frame_solver>(o);
    truth.set_rest();
    truth[bone::left_upper_arm] = glm::angleAxis(-1.3f, glm::vec3(0.f, 0.f, 1.f));
    truth[bone::right_upper_arm] = glm::angleAxis(1.3f, glm::vec3(0.f, 0.f, 1.f));
    ground_pose(synth.skeleton(), truth);
    standing = truth.hips_position.y;
  }
  static synth_options options() {
    synth_options so;
    so.face = synth_face::none;
    so.horizontal_fov_degrees = 70.f;
    return so;
  }
  // Solves the frames; returns the last solved hips height.
  float run(double t0, double seconds, float raise) {
    landmark_frame frame;
    for (double t = t0; t < t0 + seconds - 1e-9; t += 1.0 / 30.0) {
      proxy_pose p = truth;
      p.t = t;
      p.hips_position.y = standing + raise;
      synth.generate(p, frame);
      solver->solve(frame, solved);
      max_height = std::max(max_height, solved.hips_position.y);
    }
    return solved.hips_position.y;
  }
  landmark_synth synth;
  std::unique_ptr<frame_solver> solver;
  proxy_pose truth, solved;
  float standing = 0.f;
  float max_height = 0.f;
};

TEST(CameraView, AJumpGoesUpAndComesDown) {
  standing_take take;
  const float ground = take.run(0.0, 3.0, 0.f);
  take.max_height = 0.f;
  take.run(3.0, 0.4, 0.25f);  // a hop: 0.4 s, 25 cm up
  EXPECT_GT(take.max_height, ground + 0.12f);
  EXPECT_NEAR(take.run(3.4, 1.0, 0.f), ground, 0.03f);
}

TEST(CameraView, FeetAboveTheFloorForLongStandOnAHigherFloor) {
  standing_take take;
  const float ground = take.run(0.0, 3.0, 0.f);
  // Up a 25 cm step for 3 s: a jump at first, then (after 0.8 s) the floor.
  take.max_height = 0.f;
  take.run(3.0, 0.5, 0.25f);
  EXPECT_GT(take.max_height, ground + 0.12f);
  EXPECT_NEAR(take.run(3.5, 2.5, 0.25f), ground, 0.03f);
}

TEST(CameraView, AHeldViewLearnsNothingMore) {
  for (bool hold : {false, true}) {
    SCOPED_TRACE(hold);
    synth_options so;
    so.face = synth_face::none;
    so.horizontal_fov_degrees = 80.f;
    landmark_synth synth(so);
    solver_options o;
    o.image_width = float(so.image_width);
    o.image_height = float(so.image_height);
    frame_solver solver(o);
    proxy_pose truth, solved;
    truth.set_rest();
    ground_pose(synth.skeleton(), truth);
    landmark_frame frame;
    auto run = [&](int from, int to) {
      for (int i = from; i < to; ++i) {
        truth.t = i / 30.0;
        synth.generate(truth, frame);
        solver.solve(frame, solved);
      }
    };
    run(0, 9);  // the first fits: the estimate still on its way from 60 to 80 degrees
    const float early = solver.horizontal_fov_degrees();
    if (hold) solver.hold_view();
    run(9, 150);
    if (hold)
      EXPECT_EQ(solver.horizontal_fov_degrees(), early);
    else
      EXPECT_GT(std::fabs(solver.horizontal_fov_degrees() - early), 1.f);
    // reset() releases the hold: the estimate moves again.
    solver.reset();
    run(150, 300);
    EXPECT_NEAR(solver.horizontal_fov_degrees(), 80.f, 2.f);
  }
}

}  // namespace
}  // namespace avatarmap
