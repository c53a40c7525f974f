// Start-up of the ONNX capture backend (issue 11: all models <= 150 ms): creating each model's
// ONNX Runtime session, and the whole "onnx" estimator with body, hands and face, in three
// ways (capture/onnx/model_cache.hpp):
//   off  - the converted .onnx, optimised at load (what every start did before the cache)
//   made - the same, and its optimised copy written to an empty cache folder (a first start)
//   hit  - the optimised copy loaded with the optimisers off (every later start)
// Times cover session creation only (not destroying it). They are the second and later
// creations in one process; a fresh process pays more for its first sessions (`avatarmap
// capture` prints its own "start-up" line). Built with AVATARMAP_WITH_ONNX. Models:
// $AVATARMAP_MODELS/onnx (scripts/prepare_capture.sh).
//   build/bench/bench_startup --benchmark_repetitions=5 --benchmark_report_aggregates_only
#include <benchmark/benchmark.h>
#include <onnxruntime_cxx_api.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "avatarmap/capture/estimator.hpp"
#include "capture/onnx/model_cache.hpp"
#include "capture/onnx/ort_model.hpp"

namespace avatarmap {
namespace {

namespace fs = std::filesystem;

std::string models_dir() {
  const char* m = std::getenv("AVATARMAP_MODELS");
  return m && *m ? std::string(m) + "/onnx" : ".cache/avatarmap/models/onnx";
}

// The models `avatarmap capture --hands --face` loads, in its order.
const char* const k_models[] = {
    "pose_detection",     "pose_landmark_full",         "palm_detection_full",
    "hand_landmark_full", "face_detection_short_range", "face_landmark"};

enum mode { off = 0, made = 1, hit = 2 };
const char* const k_mode_names[] = {"off", "made", "hit"};

// A cache folder of this process, emptied for every "made" iteration.
fs::path scratch_cache() {
  return fs::temp_directory_path() / ("avatarmap_bench_startup_" + std::to_string(::getpid()));
}

using clock_type = std::chrono::steady_clock;
double seconds_since(clock_type::time_point t0) {
  return std::chrono::duration<double>(clock_type::now() - t0).count();
}

// One model's session: args model index, mode.
void BM_session(benchmark::State& state) {
  const std::string name = k_models[state.range(0)];
  const mode m = static_cast<mode>(state.range(1));
  const std::string path = models_dir() + "/" + name + ".onnx";
  if (!std::ifstream(path).good()) return state.SkipWithError("set AVATARMAP_MODELS");
  state.SetLabel(name + " " + k_mode_names[m]);
  const fs::path cache = scratch_cache();
  const Ort::SessionOptions so = make_session_options(2, false);
  const std::string dir = m == off ? std::string() : cache.string();
  if (m == hit) open_cached_session(ort_env(), path, so, dir);  // makes the copy once
  for (auto _ : state) {
    if (m == made) fs::remove_all(cache);
    const auto t0 = clock_type::now();
    cached_session s = open_cached_session(ort_env(), path, so, dir);
    state.SetIterationTime(seconds_since(t0));
    if (m != off && s.use != (m == hit ? model_cache_use::hit : model_cache_use::made))
      return state.SkipWithError("the cache did not do what this row measures");
  }
  fs::remove_all(cache);
}
BENCHMARK(BM_session)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5}, {off, made, hit}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// The whole estimator (body, hands, face; full models, 2 threads), as `avatarmap capture
// --hands --face` creates it: arg mode.
void BM_startup(benchmark::State& state) {
  const mode m = static_cast<mode>(state.range(0));
  if (!std::ifstream(models_dir() + "/pose_detection.onnx").good())
    return state.SkipWithError("set AVATARMAP_MODELS");
  state.SetLabel(k_mode_names[m]);
  const fs::path cache = scratch_cache();
  const char* old = std::getenv("AVATARMAP_ORT_CACHE");
  const std::string saved = old ? old : "";
  ::setenv("AVATARMAP_ORT_CACHE", m == off ? "off" : cache.c_str(), 1);
  estimator_options o;
  o.source = models_dir();
  o.threads = 2;
  o.hands = o.face = true;
  std::unique_ptr<estimator> est;
  if (m == hit && !create_estimator("onnx", o, est).ok()) state.SkipWithError("models");
  for (auto _ : state) {
    est.reset();
    if (m == made) fs::remove_all(cache);
    const auto t0 = clock_type::now();
    const status s = create_estimator("onnx", o, est);
    state.SetIterationTime(seconds_since(t0));
    if (!s.ok()) {
      state.SkipWithError(s.message().c_str());
      break;
    }
  }
  est.reset();
  if (old)
    ::setenv("AVATARMAP_ORT_CACHE", saved.c_str(), 1);
  else
    ::unsetenv("AVATARMAP_ORT_CACHE");
  fs::remove_all(cache);
}
BENCHMARK(BM_startup)
    ->Arg(off)
    ->Arg(made)
    ->Arg(hit)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace avatarmap

BENCHMARK_MAIN();
