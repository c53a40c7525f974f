// The face's accuracy on the synthetic generator's recordings (synth_recording.hpp): each seed
// its own face (synth_face_shape drawn per seed), random camera, random motion with blinks,
// jaw, smiles, O shapes, brows and gaze, solved frame by frame with default options (the
// calibration learns live). Seeds 1-5 tune, 101-105 report (docs/accuracy.md, "The face").
// Figures are printed with a "[figures]" prefix.
#include <gtest/gtest.h>

#include <cstdio>
#include <glm/glm.hpp>

#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/pose_accuracy.hpp"
#include "avatarmap/synth/synth_recording.hpp"

namespace avatarmap {
namespace {

// Frames of the live calibration's window (and the gate's blend-in) left out of the figures.
constexpr double k_skip_seconds = 1.0;
// Solves one recording into `acc` (and `also`); returns the frames left out (face turned away).
long run(synth_scenario scenario, synth_motion motion, std::uint32_t seed, double seconds,
         pose_accuracy& acc, pose_accuracy* also = nullptr) {
  long turned_away = 0;
  synth_options so = synth_scenario_options(scenario, seed);
  so.motion = motion;
  synth_recording rec(so);
  solver_options o;
  o.image_width = float(so.image_width);
  o.image_height = float(so.image_height);
  frame_solver solver(o);
  proxy_pose truth, solved;
  landmark_frame frame;
  for (int i = 0; i < static_cast<int>(seconds * 30.0); ++i) {
    const double t = i / 30.0;
    rec.generate(t, truth, frame);
    solver.solve(frame, solved);
    if (t < k_skip_seconds) continue;
    // Frames whose face turns more than 60 degrees from the camera are left out: MediaPipe
    // finds no face mesh there, and the solver does not read expressions past 65 degrees.
    const auto& fk = rec.landmarks().fk();
    const glm::vec3 to_camera =
        glm::normalize(rec.landmarks().camera_position() - fk.joints[idx(bone::head)]);
    if (glm::dot(fk.world[idx(bone::head)] * glm::vec3(0.f, 0.f, 1.f), to_camera) < 0.5f) {
      ++turned_away;
      continue;
    }
    accumulate_pose_accuracy(truth, solved, acc);
    if (also) accumulate_pose_accuracy(truth, solved, *also);
  }
  return turned_away;
}

void print(const char* what, const pose_accuracy& acc, long left_out) {
  const face_accuracy& f = acc.face;
  std::printf(
      "[figures] face %-18s blink %.3f jawOpen %.3f aa %.3f ih %.3f ou %.3f ee %.3f oh %.3f "
      "gaze %.2f deg (p95 %.2f) head %.2f deg (p95 %.2f)\n",
      what, f.blink.mean(), f.jaw_open.mean(), f.visemes[0].mean(), f.visemes[1].mean(),
      f.visemes[2].mean(), f.visemes[3].mean(), f.visemes[4].mean(), f.gaze.mean(),
      f.gaze_histogram.quantile(0.95), acc.all.head.mean(), acc.all.head_histogram.quantile(0.95));
  std::printf("[figures] face %-18s %ld frames, %ld more left out (face turned away)\n", what,
              acc.frames, left_out);
}

void print_shapes(const pose_accuracy& acc) {
  std::printf("[figures] face per-shape mean abs error:");
  for (int i = 0; i < k_blendshape_count; ++i)
    if (acc.face.shapes[i].max > 0.0)
      std::printf(" %s %.3f", std::string(blendshape_name(static_cast<blendshape>(i))).c_str(),
                  acc.face.shapes[i].mean());
  std::printf("\n");
  std::printf("[figures] face per-shape mean abs error where the truth is >= 0.2 (frames):");
  for (int i = 0; i < k_blendshape_count; ++i)
    if (acc.face.shapes_active[i].count > 0)
      std::printf(" %s %.3f (%ld)",
                  std::string(blendshape_name(static_cast<blendshape>(i))).c_str(),
                  acc.face.shapes_active[i].mean(), acc.face.shapes_active[i].count);
  std::printf("\n");
}

// The tuning seeds: printed only (the solver's constants were set on these).
TEST(FaceAccuracy, TuningSeedsPrinted) {
  pose_accuracy all;
  long left_out = 0;
  for (std::uint32_t seed : {1u, 2u, 3u, 4u, 5u}) {
    left_out += run(synth_scenario::clean, synth_motion::random, seed, 20.0, all);
  }
  print("tune 1-5", all, left_out);
  print_shapes(all);
  pose_accuracy noisy;
  long noisy_out = 0;
  for (std::uint32_t seed : {1u, 2u, 3u, 4u, 5u})
    noisy_out += run(synth_scenario::noisy, synth_motion::random, seed, 20.0, noisy);
  print("tune 1-5 noisy", noisy, noisy_out);
}

TEST(FaceAccuracy, HeldOutSeedsCleanRandomMotion) {
  pose_accuracy all;
  long left_out = 0;
  for (std::uint32_t seed : {101u, 102u, 103u, 104u, 105u}) {
    pose_accuracy one;
    const long n = run(synth_scenario::clean, synth_motion::random, seed, 20.0, one, &all);
    left_out += n;
    char name[32];
    std::snprintf(name, sizeof name, "clean seed %u", seed);
    print(name, one, n);
  }
  print("clean 101-105", all, left_out);
  print_shapes(all);
  const face_accuracy& f = all.face;
  EXPECT_LE(f.blink.mean(), 0.1);
  EXPECT_LE(f.jaw_open.mean(), 0.1);
  for (int v = 0; v < 5; ++v) EXPECT_LE(f.visemes[v].mean(), 0.1) << v;
  EXPECT_LE(f.gaze.mean(), 3.0);
}

TEST(FaceAccuracy, HeldOutSeedsNoisyAndHeadSweep) {
  pose_accuracy noisy, sweep;
  long noisy_out = 0, sweep_out = 0;
  for (std::uint32_t seed : {101u, 102u, 103u, 104u, 105u}) {
    noisy_out += run(synth_scenario::noisy, synth_motion::random, seed, 20.0, noisy);
    sweep_out += run(synth_scenario::clean, synth_motion::head, seed, 20.0, sweep);
  }
  print("noisy 101-105", noisy, noisy_out);
  print("head sweep 101-105", sweep, sweep_out);
  // The sweep (clean landmarks, the head over pitch -70..+40, yaw +-70, roll +-35) is held
  // to the clean figures' bounds. Noisy is reported with looser bounds: 1 mm of face noise is
  // a sixth of the lid gap (docs/accuracy.md, "The face").
  const face_accuracy& f = sweep.face;
  EXPECT_LE(f.blink.mean(), 0.1);
  EXPECT_LE(f.jaw_open.mean(), 0.1);
  for (int v = 0; v < 5; ++v) EXPECT_LE(f.visemes[v].mean(), 0.1) << v;
  EXPECT_LE(f.gaze.mean(), 3.0);
  EXPECT_LE(noisy.face.blink.mean(), 0.15);
  EXPECT_LE(noisy.face.jaw_open.mean(), 0.15);
  EXPECT_LE(noisy.face.gaze.mean(), 8.0);
}

}  // namespace
}  // namespace avatarmap
