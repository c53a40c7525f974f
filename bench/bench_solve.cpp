// Per-frame solve cost: a full frame (pose + world, two hands + world, 478-point face) ->
// proxy pose, one thread, with and without the hand-shape fit. Baseline: copying the landmark
// frame (the memory floor).
#include <benchmark/benchmark.h>

#include <cstring>
#include <random>
#include <vector>

#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/landmark_synth.hpp"
#include "avatarmap/synth/random_pose.hpp"
#include "avatarmap/time/pose_filter.hpp"

namespace {

using namespace avatarmap;

std::vector<landmark_frame> make_frames(bool hands, bool face) {
  synth_options o;
  o.hands_image = o.hands_world = hands;
  o.face = face ? synth_face::mesh_478 : synth_face::none;
  o.body_noise_sigma = 0.005f;
  o.hand_noise_sigma = 0.001f;
  o.face_noise_sigma = 0.001f;
  landmark_synth synth(o);
  std::mt19937 rng(1);
  std::vector<landmark_frame> frames(64);
  for (auto& f : frames) synth.generate(random_pose(rng), f);
  return frames;
}

void run_solve(benchmark::State& state, bool hands, bool face, bool fit_hands = true,
               bool fit_body = true) {
  std::vector<landmark_frame> frames = make_frames(hands, face);
  solver_options o;
  o.image_width = 1280.f;
  o.image_height = 720.f;
  o.fit_hand_shape = fit_hands;
  o.fit_body_to_image = fit_body;
  frame_solver solver(o);
  proxy_pose out;
  size_t i = 0;
  double t = 0.0;
  for (auto _ : state) {
    landmark_frame& f = frames[i++ & 63];
    f.t = (t += 1.0 / 30.0);
    solver.solve(f, out);
    benchmark::DoNotOptimize(out);
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_solve_full_frame(benchmark::State& s) { run_solve(s, true, true); }
void BM_solve_body_only(benchmark::State& s) { run_solve(s, false, false); }
// The same frames with the hands used as they are (solver_options::fit_hand_shape false): the
// difference is the hand-shape stage (learn + fit, two hands).
void BM_solve_full_frame_no_hand_fit(benchmark::State& s) { run_solve(s, true, true, false); }
// Without the body fitted to the image (solver_options::fit_body_to_image false): the
// difference is stage 1c (docs/solver.md "The body in the world"), in the steady state of a
// long take (its lean and field-of-view searches run on every third frame of the first
// ~1,800 only; the first frames of a take cost more).
void BM_solve_full_frame_no_body_fit(benchmark::State& s) { run_solve(s, true, true, true, false); }
void BM_solve_body_only_no_body_fit(benchmark::State& s) {
  run_solve(s, false, false, true, false);
}
// The first 300 frames of a take, over and over (a new solver each round): the searches'
// share at its largest.
void BM_solve_body_only_take_start(benchmark::State& state) {
  std::vector<landmark_frame> frames = make_frames(false, false);
  solver_options o;
  o.image_width = 1280.f;
  o.image_height = 720.f;
  proxy_pose out;
  for (auto _ : state) {
    frame_solver solver(o);
    for (int k = 0; k < 300; ++k) {
      landmark_frame& f = frames[k & 63];
      f.t = k / 30.0;
      solver.solve(f, out);
    }
    benchmark::DoNotOptimize(out);
  }
  state.SetItemsProcessed(state.iterations() * 300);
}

void BM_solve_full_frame_and_filter(benchmark::State& state) {
  std::vector<landmark_frame> frames = make_frames(true, true);
  frame_solver solver;
  pose_filter filter;
  proxy_pose out, filtered;
  size_t i = 0;
  double t = 0.0;
  for (auto _ : state) {
    landmark_frame& f = frames[i++ & 63];
    f.t = (t += 1.0 / 30.0);
    solver.solve(f, out);
    filter.apply(out, filtered);
    benchmark::DoNotOptimize(filtered);
  }
}

void BM_copy_landmark_frame(benchmark::State& state) {
  std::vector<landmark_frame> frames = make_frames(true, true);
  landmark_frame dst;
  size_t i = 0;
  for (auto _ : state) {
    std::memcpy(&dst, &frames[i++ & 63], sizeof dst);
    benchmark::DoNotOptimize(dst);
  }
}

BENCHMARK(BM_solve_full_frame);
BENCHMARK(BM_solve_full_frame_no_hand_fit);
BENCHMARK(BM_solve_full_frame_no_body_fit);
BENCHMARK(BM_solve_body_only);
BENCHMARK(BM_solve_body_only_no_body_fit);
BENCHMARK(BM_solve_body_only_take_start);
BENCHMARK(BM_solve_full_frame_and_filter);
BENCHMARK(BM_copy_landmark_frame);

}  // namespace

BENCHMARK_MAIN();
