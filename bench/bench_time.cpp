// Time filtering and resampling (avatarmap/time/*): cost per frame of pose_filter on a full
// proxy_pose (55 rotations + hips + 16 expressions), landmark_filter on a full frame
// (33 + 33 + 4 x 21 + 478 points), and pose_resampler::sample() (interpolating and
// extrapolating), with a proxy_pose copy as the floor.
#include <benchmark/benchmark.h>

#include <cstring>
#include <memory>
#include <random>

#include "avatarmap/time/pose_filter.hpp"
#include "avatarmap/time/pose_resampler.hpp"

namespace {

using namespace avatarmap;

// A small cycle of random poses so the filters see motion, not a constant.
struct pose_cycle {
  static constexpr int k_count = 64;
  std::array<proxy_pose, k_count> poses;
  pose_cycle() {
    std::mt19937 rng(1);
    std::normal_distribution<float> n(0.f, 0.05f);
    proxy_pose p;
    for (int i = 0; i < k_count; ++i) {
      for (auto& q : p.rotations) q = glm::normalize(q * glm::quat(1.f, n(rng), n(rng), n(rng)));
      p.hips_position += glm::vec3(n(rng), n(rng), n(rng)) * 0.1f;
      for (auto& e : p.expressions) e = std::fmin(1.f, std::fabs(e + n(rng)));
      poses[i] = p;
    }
  }
};

void bm_proxy_pose_copy(benchmark::State& state) {
  pose_cycle c;
  proxy_pose out;
  int i = 0;
  for (auto _ : state) {
    std::memcpy(static_cast<void*>(&out), &c.poses[i++ & (pose_cycle::k_count - 1)],
                sizeof(proxy_pose));
    benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(bm_proxy_pose_copy);

void bm_pose_filter_apply(benchmark::State& state) {
  pose_cycle c;
  pose_filter f;
  proxy_pose in, out;
  double t = 0.0;
  int i = 0;
  for (auto _ : state) {
    const proxy_pose& src = c.poses[i++ & (pose_cycle::k_count - 1)];
    t += 1.0 / 30.0;
    in = src;
    in.t = t;
    f.apply(in, out);
    benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(bm_pose_filter_apply);

void bm_landmark_filter_apply(benchmark::State& state) {
  auto frame = std::make_unique<landmark_frame>();
  auto out = std::make_unique<landmark_frame>();
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (auto* part : {&frame->pose, &frame->pose_world})
    for (auto& l : *part) l = {u(rng), u(rng), u(rng), 1.f, 1.f};
  for (auto* part :
       {&frame->left_hand, &frame->left_hand_world, &frame->right_hand, &frame->right_hand_world})
    for (auto& l : *part) l = {u(rng), u(rng), u(rng), 1.f, 1.f};
  for (auto& l : frame->face) l = {u(rng), u(rng), u(rng), 1.f, 1.f};
  frame->parts = (1u << k_frame_part_count) - 1;
  frame->face_count = k_face_mesh_iris_count;
  landmark_filter f;
  std::normal_distribution<float> jitter(0.f, 0.002f);
  int i = 0;
  for (auto _ : state) {
    frame->t += 1.0 / 30.0;
    frame->pose[i++ % k_pose_landmark_count].x += jitter(rng);
    f.apply(*frame, *out);
    benchmark::DoNotOptimize(out->face[0]);
    benchmark::ClobberMemory();
  }
  state.counters["points"] = 2 * 33 + 4 * 21 + 478;
}
BENCHMARK(bm_landmark_filter_apply);

void bm_resampler_push(benchmark::State& state) {
  pose_cycle c;
  pose_resampler r;
  double t = 0.0;
  int i = 0;
  for (auto _ : state) {
    proxy_pose& p = c.poses[i++ & (pose_cycle::k_count - 1)];
    t += 0.04;
    p.t = t;
    benchmark::DoNotOptimize(r.push(p));
  }
}
BENCHMARK(bm_resampler_push);

// Render at 60 fps between 25 fps captures (arg 0) or past the newest capture (arg 1).
void bm_resampler_sample(benchmark::State& state) {
  pose_cycle c;
  pose_resampler r;
  for (int k = 0; k < 4; ++k) {
    proxy_pose p = c.poses[k];
    p.t = 0.04 * k;
    r.push(p);
  }
  const bool extrapolate = state.range(0) != 0;
  proxy_pose out;
  int i = 0;
  for (auto _ : state) {
    const double t = extrapolate ? 0.12 + 0.001 * (i++ % 50) : 0.0005 + 0.0017 * (i++ % 70);
    benchmark::DoNotOptimize(r.sample(t, out));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(bm_resampler_sample)->Arg(0)->Arg(1)->ArgName("extrapolate");

}  // namespace

BENCHMARK_MAIN();
