// Latency of each converted MediaPipe model under ONNX Runtime, 1 and 2 threads, and the
// share of the CPU's peak floating-point rate it reaches. Built with AVATARMAP_WITH_ONNX.
//
// Models: $AVATARMAP_MODELS/onnx (scripts/prepare_capture.sh; float and int8); FLOPs per
// inference from the flops.json it writes there (tools/models/count_flops.py: 2 per
// multiply-add of the Conv, Gemm and MatMul layers). Peak: BM_fma_peak measures one core's
// FMA throughput (8 independent 8-wide accumulator chains); the share is the model's FLOP rate
// over threads x that peak (peak_pct, percent). Inputs are random; outputs are bound once (no
// allocation per run).
#include <benchmark/benchmark.h>
#include <immintrin.h>
#include <onnxruntime_cxx_api.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "capture/onnx/ort_model.hpp"

namespace avatarmap {
namespace {

std::string models_dir() {
  const char* m = std::getenv("AVATARMAP_MODELS");
  std::string d = m && *m ? std::string(m) + "/onnx" : ".cache/avatarmap/models/onnx";
  return d;
}

const std::map<std::string, double>& model_flops() {
  static const std::map<std::string, double> flops = [] {
    std::map<std::string, double> f;
    std::ifstream in(models_dir() + "/flops.json");
    if (!in) return f;
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (!j.is_object()) return f;
    for (auto it = j.begin(); it != j.end(); ++it)
      if (it.value().is_number()) f[it.key()] = it.value().get<double>();
    return f;
  }();
  return flops;
}

// ---- one core's peak --------------------------------------------------------------------------

__attribute__((target("avx2,fma"), noinline)) float fma_loop(long iterations) {
  __m256 a[8];
  for (int i = 0; i < 8; ++i) a[i] = _mm256_set1_ps(1.0f + 0.001f * i);
  const __m256 m = _mm256_set1_ps(0.999999f), c = _mm256_set1_ps(1e-7f);
  for (long it = 0; it < iterations; ++it)
    for (int i = 0; i < 8; ++i) a[i] = _mm256_fmadd_ps(a[i], m, c);
  __m256 s = a[0];
  for (int i = 1; i < 8; ++i) s = _mm256_add_ps(s, a[i]);
  float out[8];
  _mm256_storeu_ps(out, s);
  return out[0];
}
constexpr double k_flops_per_iteration = 8 * 8 * 2;  // 8 chains x 8 lanes x (mul + add)

double measured_peak_gflops() {
  static const double peak = [] {
    if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) return 0.0;
    double best = 0.0;
    for (int rep = 0; rep < 5; ++rep) {
      long n = 20'000'000;
      benchmark::DoNotOptimize(n);
      const auto t0 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(fma_loop(n));
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      best = std::max(best, n * k_flops_per_iteration / s / 1e9);
    }
    return best;
  }();
  return peak;
}

void BM_fma_peak(benchmark::State& state) {
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) {
    state.SkipWithError("no AVX2/FMA on this CPU");
    return;
  }
  long n = 1'000'000;
  benchmark::DoNotOptimize(n);
  for (auto _ : state) {
    benchmark::DoNotOptimize(n);  // opaque each time: the call cannot be hoisted
    benchmark::DoNotOptimize(fma_loop(n));
  }
  state.counters["GFLOP_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * n * k_flops_per_iteration / 1e9,
                         benchmark::Counter::kIsRate);
}
BENCHMARK(BM_fma_peak)->Unit(benchmark::kMillisecond);

// ---- the models -----------------------------------------------------------------------------

struct model_run {
  std::unique_ptr<Ort::Session> session;
  std::vector<std::string> names;  // input first, then outputs
  std::vector<std::vector<float>> buffers;
  std::vector<Ort::Value> values;
  std::vector<const char*> out_names;
  Ort::Value input{nullptr};

  std::string load(const std::string& path, int threads) {
    const Ort::SessionOptions so = make_session_options(threads, false);
    session = std::make_unique<Ort::Session>(ort_env(), path.c_str(), so);
    Ort::AllocatorWithDefaultOptions alloc;
    const Ort::MemoryInfo mem = Ort::MemoryInfo::CreateCpu(OrtArenaAllocator, OrtMemTypeDefault);
    auto make = [&](const std::vector<int64_t>& shape) {
      size_t n = 1;
      for (int64_t d : shape) n *= static_cast<size_t>(d < 1 ? 1 : d);
      buffers.emplace_back(n);
      return Ort::Value::CreateTensor<float>(mem, buffers.back().data(), n, shape.data(),
                                             shape.size());
    };
    buffers.reserve(1 + session->GetOutputCount());
    names.push_back(session->GetInputNameAllocated(0, alloc).get());
    input = make(session->GetInputTypeInfo(0).GetTensorTypeAndShapeInfo().GetShape());
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (float& v : buffers[0]) v = u(rng);
    for (size_t i = 0; i < session->GetOutputCount(); ++i) {
      names.push_back(session->GetOutputNameAllocated(i, alloc).get());
      values.push_back(make(session->GetOutputTypeInfo(i).GetTensorTypeAndShapeInfo().GetShape()));
    }
    for (size_t i = 1; i < names.size(); ++i) out_names.push_back(names[i].c_str());
    return {};
  }
  void run() {
    const char* in = names[0].c_str();
    session->Run(Ort::RunOptions{nullptr}, &in, &input, 1, out_names.data(), values.data(),
                 values.size());
  }
};

void BM_model(benchmark::State& state, const std::string& name) {
  const int threads = static_cast<int>(state.range(0));
  const std::string path = models_dir() + "/" + name + ".onnx";
  if (!std::ifstream(path).good()) {
    state.SkipWithError(("no " + path + " (scripts/prepare_capture.sh)").c_str());
    return;
  }
  model_run m;
  try {
    m.load(path, threads);
    m.run();  // warm up
  } catch (const Ort::Exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) m.run();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto& flops = model_flops();
  const auto it = flops.find(name + ".onnx");
  if (it != flops.end() && seconds > 0) {
    const double gflops = static_cast<double>(state.iterations()) * it->second / 1e9 / seconds;
    state.counters["GFLOP"] = it->second / 1e9;
    state.counters["GFLOP_per_s"] = gflops;
    const double peak = measured_peak_gflops();
    if (peak > 0) state.counters["peak_pct"] = 100.0 * gflops / (peak * threads);
  }
}

const char* const k_models[] = {
    "pose_detection",      "pose_landmark_lite",          "pose_landmark_full",
    "pose_landmark_heavy", "palm_detection_lite",         "palm_detection_full",
    "hand_landmark_lite",  "hand_landmark_full",          "face_detection_short_range",
    "face_landmark",       "face_landmark_with_attention"};

// Each model in float and, next to it, its int8 version (<name>.int8.onnx, docs/capture.md
// "int8 models"; no FLOP counters: the peak above is a float one).
const bool k_registered = [] {
  for (const char* n : k_models)
    for (const std::string name : {std::string(n), std::string(n) + ".int8"})
      benchmark::RegisterBenchmark(("BM_model/" + name).c_str(),
                                   [name](benchmark::State& s) { BM_model(s, name); })
          ->Arg(1)
          ->Arg(2)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  return true;
}();

}  // namespace
}  // namespace avatarmap

BENCHMARK_MAIN();
