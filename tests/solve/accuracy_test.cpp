// Solver accuracy against ground truth: random poses with known rotations are turned into the
// landmarks they would yield by the synthetic generator (an independent forward model), solved,
// and compared. Figures are printed with a "[figures]" prefix for the note.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = k_pi / 180.f;

// Bones whose direction is observable from landmarks (both ends carry a landmark).
const bone k_body_bones[] = {bone::left_upper_arm,  bone::left_lower_arm,  bone::right_upper_arm,
                             bone::right_lower_arm, bone::left_upper_leg,  bone::left_lower_leg,
                             bone::right_upper_leg, bone::right_lower_leg, bone::left_foot,
                             bone::right_foot};
const bone k_hand_bones[] = {bone::left_hand, bone::right_hand};

bool is_finger(int b) { return b >= idx(bone::left_thumb_metacarpal); }

float dir_error(const std::array<glm::quat, k_bone_count>& truth,
                const std::array<glm::quat, k_bone_count>& solved, int b) {
  glm::vec3 r = bone_rest_direction(static_cast<bone>(b));
  glm::vec3 a = truth[b] * r, s = solved[b] * r;
  return std::atan2(glm::length(glm::cross(a, s)), glm::dot(a, s)) / k_deg;
}

struct error_stats {
  double sum = 0;
  double max = 0;
  long n = 0;
  void add(double e) {
    sum += e;
    max = std::max(max, e);
    ++n;
  }
  double mean() const { return n ? sum / n : 0; }
};

struct run_result {
  error_stats body, hands, fingers, head;
  int worst_finger = -1;
};

run_result run(int poses, float body_noise, float hand_noise, float face_noise, uint32_t seed) {
  synth_options so;
  so.body_noise_sigma = body_noise;
  so.hand_noise_sigma = hand_noise;
  so.face_noise_sigma = face_noise;
  so.seed = seed;
  landmark_synth synth(so);
  solver_options o;
  // The solver's geometry on single random poses: the close-up rule (docs/solver.md, "Bodies
  // that are not followed") is off here. With it on, 2 of the 500 noise-free random poses
  // (both knees far above the hips) are held at rest: its documented cost.
  o.lower_body_rest = body_rest::off;
  o.image_width = float(so.image_width);
  o.image_height = float(so.image_height);
  std::mt19937 rng(seed);
  landmark_frame frame;
  proxy_pose solved;
  std::array<glm::quat, k_bone_count> sw;
  run_result r;
  for (int i = 0; i < poses; ++i) {
    proxy_pose truth = random_pose(rng);
    ground_pose(synth.skeleton(), truth);
    synth.generate(truth, frame);
    frame_solver solver(o);  // one frame each: no history
    solver.solve(frame, solved);
    compute_world_rotations(solved, sw);
    const auto& tw = synth.fk().world;
    for (bone b : k_body_bones) r.body.add(dir_error(tw, sw, idx(b)));
    for (bone b : k_hand_bones) r.hands.add(dir_error(tw, sw, idx(b)));
    for (int b = 0; b < k_bone_count; ++b) {
      if (!is_finger(b)) continue;
      double e = dir_error(tw, sw, b);
      if (e > r.fingers.max) r.worst_finger = b;
      r.fingers.add(e);
    }
    r.head.add(angle_between(sw[idx(bone::head)], tw[idx(bone::head)]) / k_deg);
  }
  return r;
}

void print(const char* what, const run_result& r) {
  std::printf(
      "[figures] %s: body limbs mean %.3f max %.3f deg | hands mean %.3f max %.3f | fingers "
      "mean %.3f max %.3f (%s) | head orientation mean %.3f max %.3f (n=%ld poses)\n",
      what, r.body.mean(), r.body.max, r.hands.mean(), r.hands.max, r.fingers.mean(), r.fingers.max,
      r.worst_finger < 0 ? "-" : std::string(bone_name(static_cast<bone>(r.worst_finger))).c_str(),
      r.head.mean(), r.head.max, r.head.n);
}

TEST(Accuracy, NoiseFreeRandomPoses) {
  run_result r = run(500, 0.f, 0.f, 0.f, 7);
  print("noise-free", r);
  EXPECT_LE(r.body.mean(), 1.0);
  EXPECT_LE(r.hands.mean(), 1.0);
  EXPECT_LE(r.fingers.mean(), 1.0);
  EXPECT_LE(r.head.max, 2.0);
}

TEST(Accuracy, TenMillimetreNoiseOnTheBody) {
  run_result r = run(500, 0.010f, 0.002f, 0.002f, 11);
  print("body 10 mm, hands/face 2 mm noise", r);
  EXPECT_LE(r.body.mean(), 4.0);
  EXPECT_LE(r.head.mean(), 4.0);
  run_result all = run(200, 0.010f, 0.010f, 0.010f, 13);
  print("10 mm noise everywhere", all);
  EXPECT_LE(all.body.mean(), 4.0);
}

// Finger flexion swept over 0..110 degrees: the solver's flexion of every finger joint equals
// the generator's, including past 90 degrees (where 2-D projections fold back).
TEST(Accuracy, FingerFlexionOverTheFullRange) {
  synth_options so;
  landmark_synth synth(so);
  solver_options o;
  o.image_width = 1280.f;
  o.image_height = 720.f;
  landmark_frame frame;
  proxy_pose solved;
  double worst = 0;
  for (float flex = 0.f; flex <= 110.f; flex += 5.f) {
    proxy_pose truth;
    truth.hips_position = glm::vec3(0.f, standing_hips_height(synth.skeleton()), 0.f);
    // Arms down at the sides so the hands face the camera from several angles.
    truth[bone::left_upper_arm] = axis_angle({0, 0, 1}, -70.f * k_deg);
    truth[bone::right_upper_arm] = axis_angle({0, 0, 1}, 70.f * k_deg);
    for (int side = 0; side < 2; ++side) {
      int first = side == 0 ? idx(bone::left_index_proximal) : idx(bone::right_index_proximal);
      for (int f = 0; f < 4; ++f) {
        for (int j = 0; j < 3; ++j) {
          // Each joint gets a different share so the three are not equal.
          float a = flex * (j == 0 ? 1.f : j == 1 ? 0.8f : 0.5f) * k_deg;
          glm::quat q = axis_angle({0, 0, -1}, a);
          truth.rotations[first + 3 * f + j] = side == 0 ? q : mirror_x(q);
        }
      }
    }
    synth.generate(truth, frame);
    frame_solver solver(o);
    solver.solve(frame, solved);
    for (int side = 0; side < 2; ++side) {
      int first = side == 0 ? idx(bone::left_index_proximal) : idx(bone::right_index_proximal);
      for (int k = 0; k < 12; ++k) {
        auto flexion = [&](const glm::quat& q) {
          glm::vec3 v = (side == 0 ? q : mirror_x(q)) * glm::vec3(1, 0, 0);
          return std::atan2(-v.y, v.x) / k_deg;
        };
        double e =
            std::abs(flexion(solved.rotations[first + k]) - flexion(truth.rotations[first + k]));
        worst = std::max(worst, e);
        EXPECT_LE(e, 3.0) << "flex " << flex << " bone " << bone_name(static_cast<bone>(first + k));
      }
    }
  }
  std::printf("[figures] finger flexion 0..110 deg: worst error %.4f deg\n", worst);
}

}  // namespace
}  // namespace avatarmap

namespace avatarmap {
namespace {

// The wrist turned through a full pronation sweep, palm down -> facing the camera -> up: the
// solved hand orientation follows the truth at every step (no flip when the palm faces the
// camera, unlike 2-D projection solvers).
TEST(Accuracy, WristTwistSweepNeverFlips) {
  landmark_synth synth;
  solver_options o;
  o.image_width = 1280.f;
  o.image_height = 720.f;
  frame_solver solver(o);
  landmark_frame frame;
  proxy_pose solved;
  std::array<glm::quat, k_bone_count> sw;
  double worst = 0;
  int i = 0;
  for (float twist = -90.f; twist <= 180.f; twist += 5.f, ++i) {
    proxy_pose truth;
    truth.hips_position = glm::vec3(0.f, standing_hips_height(synth.skeleton()), 0.f);
    // Left arm forward at shoulder height, the hand turning about the forearm.
    truth[bone::left_upper_arm] = axis_angle({0, 1, 0}, -80.f * k_deg);
    truth[bone::left_hand] = axis_angle({1, 0, 0}, twist * k_deg);
    synth.generate(truth, frame);
    frame.t = i / 30.0;
    solver.solve(frame, solved);
    compute_world_rotations(solved, sw);
    const double e =
        angle_between(sw[idx(bone::left_hand)], synth.fk().world[idx(bone::left_hand)]) / k_deg;
    worst = std::max(worst, e);
    EXPECT_LT(e, 0.5) << "twist " << twist;
  }
  std::printf("[figures] wrist twist sweep -90..180 deg: worst hand orientation error %.3f deg\n",
              worst);
}

// Without a face mesh the head comes from the pose's ears, eyes and mouth.
TEST(Accuracy, HeadFromPosePointsWithoutFaceMesh) {
  synth_options so;
  so.face = synth_face::none;
  landmark_synth synth(so);
  std::mt19937 rng(21);
  landmark_frame frame;
  proxy_pose solved;
  std::array<glm::quat, k_bone_count> sw;
  error_stats head;
  for (int i = 0; i < 300; ++i) {
    proxy_pose truth = random_pose(rng);
    ground_pose(synth.skeleton(), truth);
    synth.generate(truth, frame);
    frame_solver solver;
    solver.solve(frame, solved);
    compute_world_rotations(solved, sw);
    head.add(angle_between(sw[idx(bone::head)], synth.fk().world[idx(bone::head)]) / k_deg);
  }
  std::printf("[figures] head from pose points (no mesh): mean %.3f max %.3f deg\n", head.mean(),
              head.max);
  EXPECT_LE(head.max, 2.0);
}

}  // namespace
}  // namespace avatarmap
