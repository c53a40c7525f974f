// Mapping-table formulas (avatarmap/rig/formula.hpp): cost of one eval of compiled formulas
// typical of SysMocap bindings ("-z", "x*0.5+sin(y)") next to the same arithmetic written
// in C++ (the floor an interpreter cannot beat), plus compile cost (load time only).
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>

#include "avatarmap/rig/formula.hpp"

namespace {

using namespace avatarmap;

// Varying inputs so nothing folds away.
struct inputs {
  static constexpr int k_count = 256;
  std::array<float, k_count * 3> v;
  inputs() {
    for (int i = 0; i < k_count * 3; ++i) v[i] = std::sin(0.37f * static_cast<float>(i));
  }
};
const inputs k_in;

void run_formula(benchmark::State& state, const char* text) {
  formula f;
  if (!compile_formula(text, f).ok()) {
    state.SkipWithError("compile failed");
    return;
  }
  int i = 0;
  for (auto _ : state) {
    const float* p = &k_in.v[static_cast<std::size_t>(i) * 3];
    benchmark::DoNotOptimize(f.eval(p[0], p[1], p[2]));
    i = (i + 1) & (inputs::k_count - 1);
  }
}

void bm_eval_neg_z(benchmark::State& state) { run_formula(state, "-z"); }
void bm_eval_x_half_plus_sin_y(benchmark::State& state) { run_formula(state, "x*0.5+sin(y)"); }
void bm_eval_atan2_clamp(benchmark::State& state) {
  run_formula(state, "Math.atan2(x, -y) + clamp(z * 2, -Math.PI / 2, Math.PI / 2)");
}

void bm_native_x_half_plus_sin_y(benchmark::State& state) {
  int i = 0;
  for (auto _ : state) {
    const float* p = &k_in.v[static_cast<std::size_t>(i) * 3];
    float x = p[0], y = p[1];
    benchmark::DoNotOptimize(x);
    benchmark::DoNotOptimize(y);
    benchmark::DoNotOptimize(x * 0.5f + std::sin(y));
    i = (i + 1) & (inputs::k_count - 1);
  }
}

void bm_compile_x_half_plus_sin_y(benchmark::State& state) {
  formula f;
  for (auto _ : state) {
    benchmark::DoNotOptimize(compile_formula("x*0.5+sin(y)", f));
    benchmark::ClobberMemory();
  }
}

}  // namespace

BENCHMARK(bm_eval_neg_z);
BENCHMARK(bm_eval_x_half_plus_sin_y);
BENCHMARK(bm_eval_atan2_clamp);
BENCHMARK(bm_native_x_half_plus_sin_y);
BENCHMARK(bm_compile_x_half_plus_sin_y);
BENCHMARK_MAIN();
