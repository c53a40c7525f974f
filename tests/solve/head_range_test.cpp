// The head at every angle: head sweeps over the whole range people use (pitch -70..+40, yaw
// +-70, roll +-35 degrees relative to the torso; synth_motion::head) seen through perspective
// cameras (field of view 50-90 degrees, 0.7-1.5 m away, off the optical axis), solved frame
// by frame with default options and compared with the known head rotation. The generator is
// the reference: its landmarks are projections of a known pose through a pinhole camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/proxy_skeleton.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/head_sweep.hpp"
#include "avatarmap/synth/synth_recording.hpp"

namespace avatarmap {
namespace {

constexpr float k_deg = k_pi / 180.f;
constexpr double k_fps = 30.0;
constexpr double k_seconds = 20.0;

struct head_run {
  std::vector<double> error;  // head orientation error per frame, degrees
  std::vector<float> pitch;   // true pitch per frame, degrees
  float fov = 0.f;
};

synth_options near_camera(synth_scenario scenario, std::uint32_t seed) {
  synth_options o = synth_scenario_options(scenario, seed);
  o.motion = synth_motion::head;
  // Close to a webcam: the face large in the image, perspective strong.
  o.distance_min = 0.7f;
  o.distance_max = 1.5f;
  o.camera_height_min = 1.35f;
  o.camera_height_max = 1.6f;
  return o;
}

// Solves `seconds` of a head sweep frame by frame; `edit(t, frame)` may change each frame's
// landmarks first (none by default).
template <class Edit>
head_run run(const synth_options& so, double seconds, Edit&& edit) {
  synth_recording rec(so);
  head_sweep sweep(so.seed);
  solver_options o;
  o.image_width = float(so.image_width);
  o.image_height = float(so.image_height);
  frame_solver solver(o);
  landmark_frame frame;
  proxy_pose truth, solved;
  std::array<glm::quat, k_bone_count> tw, sw;
  head_run r;
  r.fov = rec.landmarks().horizontal_fov_degrees();
  const int frames = int(seconds * k_fps);
  for (int i = 0; i < frames; ++i) {
    const double t = i / k_fps;
    rec.generate(t, truth, frame);
    edit(t, frame);
    solver.solve(frame, solved);
    compute_world_rotations(truth, tw);
    compute_world_rotations(solved, sw);
    r.error.push_back(angle_between(sw[idx(bone::head)], tw[idx(bone::head)]) / k_deg);
    r.pitch.push_back(sweep.at(t).pitch);
  }
  return r;
}

head_run run(const synth_options& so) {
  return run(so, k_seconds, [](double, landmark_frame&) {});
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / double(v.size());
}

double p95(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[std::min(v.size() - 1, size_t(0.95 * double(v.size())))];
}

TEST(HeadRange, SweepCoversTheRange) {
  head_sweep s(7);
  float lo = 0, hi = 0, ylo = 0, yhi = 0, rlo = 0, rhi = 0;
  for (int i = 0; i < 120 * 30; ++i) {
    const head_angles a = s.at(i / 30.0);
    lo = std::min(lo, a.pitch), hi = std::max(hi, a.pitch);
    ylo = std::min(ylo, a.yaw), yhi = std::max(yhi, a.yaw);
    rlo = std::min(rlo, a.roll), rhi = std::max(rhi, a.roll);
    EXPECT_GE(a.pitch, -70.f);
    EXPECT_LE(a.pitch, 40.f);
    EXPECT_LE(std::fabs(a.yaw), 70.f);
    EXPECT_LE(std::fabs(a.roll), 35.f);
  }
  EXPECT_LT(lo, -60.f);
  EXPECT_GT(hi, 25.f);
  EXPECT_LT(ylo, -50.f);
  EXPECT_GT(yhi, 50.f);
  EXPECT_LT(rlo, -20.f);
  EXPECT_GT(rhi, 20.f);
  // A pure function of time: going back replays the same angles.
  const head_angles a = s.at(3.0), b = head_sweep(7).at(3.0);
  EXPECT_EQ(a.pitch, b.pitch);
  EXPECT_EQ(a.yaw, b.yaw);
}

// The recording's true head is the sweep's turn (torso upright): pitch down is -X rotation.
TEST(HeadRange, TruthIsTheSweep) {
  synth_options so = near_camera(synth_scenario::clean, 3);
  synth_recording rec(so);
  head_sweep sweep(3);
  landmark_frame frame;
  proxy_pose truth;
  std::array<glm::quat, k_bone_count> tw;
  for (double t : {0.5, 2.0, 7.3}) {
    rec.generate(t, truth, frame);
    compute_world_rotations(truth, tw);
    EXPECT_LT(angle_between(tw[idx(bone::head)], head_turn(sweep.at(t))), 1e-3f);
  }
  // Pitch down: the face's forward axis (+Z) tips toward -Y.
  const glm::vec3 fwd = head_turn({0.f, -30.f, 0.f}) * glm::vec3(0.f, 0.f, 1.f);
  EXPECT_NEAR(fwd.y, -0.5f, 1e-5f);
}

// Every frame within 3 degrees on clean landmarks, mean <= 1 and 95th percentile <= 3; no
// latching: once the head is back above -45 degrees after looking down below -60, within 2
// degrees. Before the per-point perspective and the head's world-anchored gate this failed
// with 5-15 degree errors at combined yaw and pitch.
TEST(HeadRange, CleanHeadHoldsAtEveryAngle) {
  for (std::uint32_t seed : {11u, 12u, 13u}) {
    const head_run r = run(near_camera(synth_scenario::clean, seed));
    const double worst = *std::max_element(r.error.begin(), r.error.end());
    std::printf("[figures] head sweep clean seed %u (fov %.0f): mean %.2f p95 %.2f max %.2f deg\n",
                seed, r.fov, mean(r.error), p95(r.error), worst);
    EXPECT_LE(mean(r.error), 1.0) << "seed " << seed;
    EXPECT_LE(p95(r.error), 3.0) << "seed " << seed;
    int deep = -1000;  // last frame below -60 degrees of pitch
    for (size_t i = 0; i < r.error.size(); ++i) {
      EXPECT_LE(r.error[i], 3.0) << "seed " << seed << " frame " << i << " pitch " << r.pitch[i];
      if (r.pitch[i] < -60.f) deep = int(i);
      if (r.pitch[i] > -45.f && int(i) - deep <= int(k_fps))
        EXPECT_LT(r.error[i], 2.0) << "seed " << seed << " frame " << i << " after a look down";
    }
  }
}

TEST(HeadRange, NoisyHeadHoldsOnAverage) {
  for (std::uint32_t seed : {21u, 22u}) {
    const head_run r = run(near_camera(synth_scenario::noisy, seed));
    std::printf("[figures] head sweep noisy seed %u (fov %.0f): mean %.2f p95 %.2f deg\n", seed,
                r.fov, mean(r.error), p95(r.error));
    EXPECT_LE(mean(r.error), 1.5) << "seed " << seed;
    EXPECT_LE(p95(r.error), 3.5) << "seed " << seed;
  }
}

// The face mesh lost (a hand in front, a look far down): the head comes from the pose's face
// points, whose frame differs from the mesh's by a person- and model-dependent rotation (43
// degrees mean on pose_squats.mp4). Here the pose's eyes sit 3 cm behind where the mesh's
// are, along the head's own backward axis (a rigid offset of about 20 degrees of pitch). A
// solver that saw both for 6 s turns the pose's head by the offset it learnt; one that never
// saw the mesh has nothing to learn from and shows the raw offset (the reference that the
// perturbation is large).
TEST(HeadRange, LostMeshFallsBackOnThePoseFacePointsTurnedByTheLearntOffset) {
  const synth_options so = near_camera(synth_scenario::clean, 31);
  auto errors = [&](bool mesh_at_start) {
    // Lost: every frame without the mesh at start, else every other second from 6 s on.
    auto lost = [&](double t) { return !mesh_at_start || (t >= 6.0 && std::fmod(t, 2.0) < 1.0); };
    const head_run r = run(so, 12.0, [&](double t, landmark_frame& frame) {
      auto w = [&](int k) {
        const landmark& l = frame.pose_world[k];
        return glm::vec3(l.x, l.y, l.z);
      };
      const glm::vec3 back = glm::normalize(0.5f * (w(7) + w(8)) - w(0));
      for (int k = 1; k <= 6; ++k) {
        frame.pose_world[k].x += 0.03f * back.x;
        frame.pose_world[k].y += 0.03f * back.y;
        frame.pose_world[k].z += 0.03f * back.z;
      }
      if (lost(t)) frame.set(frame_part::face, false);
    });
    std::vector<double> out;  // the frames of the lost spans after 6 s
    for (size_t i = 0; i < r.error.size(); ++i) {
      const double t = double(i) / k_fps;
      if (t >= 6.0 && std::fmod(t, 2.0) < 1.0) out.push_back(r.error[i]);
    }
    return out;
  };
  const std::vector<double> learnt = errors(true), never = errors(false);
  std::printf(
      "[figures] head from the pose's face points, mesh lost: mean %.2f p95 %.2f deg "
      "(offset never learnt: mean %.2f)\n",
      mean(learnt), p95(learnt), mean(never));
  EXPECT_GT(mean(never), 10.0);
  EXPECT_LT(mean(learnt), 4.0);
  EXPECT_LT(p95(learnt), 8.0);
}

}  // namespace
}  // namespace avatarmap
