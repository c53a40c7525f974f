// Time filtering and resampling (avatarmap/time/*): cost per frame of pose_filter on a full
// proxy_pose (55 rotations + hips + 16 expressions), landmark_filter on a full frame
// (33 + 33 + 4 x 21 + 478 points), offline_smoother (push + pop) on solved poses of the
// synthetic noisy scenario, pose_resampler::sample() (interpolating and extrapolating) and
// the foot contact stage (causal and both-sided: FK of both feet, contacts, root motion, one
// pose copy in and one out), with a proxy_pose copy as the floor.
#include <benchmark/benchmark.h>

#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/synth/synth_recording.hpp"
#include "avatarmap/time/foot_contacts.hpp"
#include "avatarmap/time/offline_smoother.hpp"
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

// 20 s of the noisy scenario at 30 fps (noise, low-visibility bursts that leave gaps) solved
// as `solve` does for the offline smoother (the smoother, not the causal gate, decides what
// was observed).
const std::vector<proxy_pose>& solved_noisy_poses() {
  static const std::vector<proxy_pose> poses = [] {
    const synth_options so = synth_scenario_options(synth_scenario::noisy, 7);
    synth_recording rec(so);
    solver_options o;
    o.image_width = static_cast<float>(so.image_width);
    o.image_height = static_cast<float>(so.image_height);
    o.confidence.lost_below = 0.f;
    o.confidence.found_above = 0.f;
    frame_solver solver(o);
    auto frame = std::make_unique<landmark_frame>();
    proxy_pose truth, solved;
    std::vector<proxy_pose> out;
    for (int i = 0; i < 600; ++i) {
      rec.generate(i / 30.0, truth, *frame);
      solver.solve(*frame, solved);
      out.push_back(solved);
    }
    return out;
  }();
  return poses;
}

// One pose in, one out (the window full): arg 1 = noise-adaptive widths (the default), 0 =
// the sigmas as given.
void bm_offline_smoother(benchmark::State& state) {
  const std::vector<proxy_pose>& poses = solved_noisy_poses();
  offline_smoother_options o;
  o.adapt_to_noise = state.range(0) != 0;
  offline_smoother s(o);
  proxy_pose in, out;
  long i = 0;
  for (auto _ : state) {
    in = poses[static_cast<size_t>(i % static_cast<long>(poses.size()))];
    in.t = static_cast<double>(i++) / 30.0;
    s.push(in);
    while (s.pop(out)) benchmark::DoNotOptimize(out);
    benchmark::ClobberMemory();
  }
}
BENCHMARK(bm_offline_smoother)->Arg(1)->Arg(0)->ArgName("adapt");

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

void bm_foot_contacts(benchmark::State& state) {
  pose_cycle c;
  for (auto& p : c.poses) p.confidence.fill(1.f);
  foot_contact_stage stage({}, state.range(0) != 0);
  proxy_pose out;
  double t = 0.0;
  int i = 0;
  for (auto _ : state) {
    proxy_pose& in = c.poses[i++ & (pose_cycle::k_count - 1)];
    in.t = t;
    t += 1.0 / 30.0;
    benchmark::DoNotOptimize(stage.push(in, out));
    benchmark::ClobberMemory();
  }
}
BENCHMARK(bm_foot_contacts)->Arg(0)->Arg(1)->ArgName("both_sided");

}  // namespace

BENCHMARK_MAIN();
