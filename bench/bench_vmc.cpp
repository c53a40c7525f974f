// The VMC output's per-frame cost: building one bundle (55 bones, 12 blend values, ~5 KB) into
// a fixed buffer, against memcpy of the same bytes (the physical floor), and building plus
// sending it over loopback UDP to a port where nobody listens (the kernel's share).
#include <benchmark/benchmark.h>

#include <array>
#include <cstring>

#include "avatarmap/stream/vmc_bundle.hpp"
#include "avatarmap/stream/vmc_stream.hpp"

namespace {

using namespace avatarmap;

proxy_pose sample_pose() {
  proxy_pose pose;
  for (int b = 0; b < k_bone_count; ++b)
    pose.rotations[b] = glm::angleAxis(0.01f * static_cast<float>(b), glm::vec3(0.f, 0.6f, 0.8f));
  pose[expression::aa] = 0.4f;
  return pose;
}

void bench_vmc_bundle_build(benchmark::State& state) {
  const vmc_skeleton skeleton = make_vmc_skeleton(make_proxy_skeleton());
  const proxy_pose pose = sample_pose();
  std::array<std::uint8_t, k_vmc_bundle_capacity> buf{};
  osc_writer w(buf.data(), buf.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(write_vmc_bundle(skeleton, pose, 1.f, w));
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(w.size()));
}
BENCHMARK(bench_vmc_bundle_build);

void bench_vmc_bundle_memcpy_floor(benchmark::State& state) {
  const vmc_skeleton skeleton = make_vmc_skeleton(make_proxy_skeleton());
  std::array<std::uint8_t, k_vmc_bundle_capacity> src{}, dst{};
  osc_writer w(src.data(), src.size());
  write_vmc_bundle(skeleton, sample_pose(), 1.f, w);
  for (auto _ : state) {
    std::memcpy(dst.data(), src.data(), w.size());
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(w.size()));
}
BENCHMARK(bench_vmc_bundle_memcpy_floor);

void bench_vmc_build_and_send_loopback(benchmark::State& state) {
  vmc_stream stream;
  if (!stream.open({"127.0.0.1", 9}, make_vmc_skeleton(make_proxy_skeleton())).ok()) {
    state.SkipWithError("cannot open a UDP socket");
    return;
  }
  const proxy_pose pose = sample_pose();
  for (auto _ : state) benchmark::DoNotOptimize(stream.send(pose, 1.f));
  state.counters["refused"] = static_cast<double>(stream.stats().refused);
}
BENCHMARK(bench_vmc_build_and_send_loopback);

}  // namespace

BENCHMARK_MAIN();
