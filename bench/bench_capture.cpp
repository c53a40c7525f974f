// Per-frame cost of capture through the library and through the C API on the same frames
// (issue 10: the C API's estimator within 5 % of the pipeline the CLI runs). Both run the
// full models (body, hands, face) on tfjs-models' pose.jpg tracked frame after frame, one
// ONNX Runtime thread. Needs AVATARMAP_MODELS (converted models) and AVATARMAP_TEST_DATA;
// without them each benchmark reports an error and skips. Compare the two rows of one run:
//   build/bench/bench_capture --benchmark_repetitions=5 --benchmark_report_aggregates_only
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "../tests/capture/onnx/onnx_support.hpp"
#include "avatarmap/avatarmap.h"
#include "avatarmap/capture/capture_pipeline.hpp"
#include "support/test_data.hpp"

namespace {

using namespace avatarmap;

bool have_inputs(benchmark::State& state, test::loaded_image& img) {
  if (test::models_dir().empty() || test::test_data_dir().empty()) {
    state.SkipWithError("set AVATARMAP_MODELS and AVATARMAP_TEST_DATA");
    return false;
  }
  if (!test::load_image(test::test_data_path("motion/tfjs-models/pose.jpg"), img)) {
    state.SkipWithError("pose.jpg could not be decoded");
    return false;
  }
  return true;
}

// The library's pipeline: estimator + solver + live filter (the CLI's live loop does these).
void BM_capture_pipeline(benchmark::State& state) {
  test::loaded_image img;
  if (!have_inputs(state, img)) return;
  capture_pipeline_options o;
  o.estimator.source = test::models_dir();
  o.estimator.threads = 1;
  o.estimator.hands = o.estimator.face = true;
  std::unique_ptr<capture_pipeline> p;
  if (!capture_pipeline::create(o, p).ok()) return state.SkipWithError("models");
  landmark_frame f;
  proxy_pose pose;
  double t = 0.0;
  for (int i = 0; i < 5; ++i) p->process(img.view(), t += 1.0 / 30, f, pose);  // warm-up
  for (auto _ : state) {
    p->process(img.view(), t += 1.0 / 30, f, pose);
    benchmark::DoNotOptimize(pose);
  }
}
BENCHMARK(BM_capture_pipeline)->Unit(benchmark::kMillisecond)->MinTime(3.0);

// The same through the C API's estimator handle (copies out the frame and the pose too).
void BM_c_api_estimator(benchmark::State& state) {
  test::loaded_image img;
  if (!have_inputs(state, img)) return;
  avm_estimator_options eo;
  avm_estimator_options_init(&eo);
  const std::string models = test::models_dir();
  eo.models_dir = models.c_str();
  eo.threads = 1;
  avm_estimator* est = nullptr;
  if (avm_estimator_create(&eo, nullptr, &est) != AVM_OK) return state.SkipWithError("models");
  const image_view v = img.view();
  avm_image image{v.data, v.width, v.height, v.stride_bytes,
                  v.format == pixel_format::bgr8 ? AVM_PIXEL_BGR8 : AVM_PIXEL_RGB8};
  avm_frame frame;
  avm_pose pose;
  double t = 0.0;
  for (int i = 0; i < 5; ++i) avm_estimator_process(est, &image, t += 1.0 / 30, &frame, &pose);
  for (auto _ : state) {
    avm_estimator_process(est, &image, t += 1.0 / 30, &frame, &pose);
    benchmark::DoNotOptimize(pose);
  }
  avm_estimator_destroy(est);
}
BENCHMARK(BM_c_api_estimator)->Unit(benchmark::kMillisecond)->MinTime(3.0);

}  // namespace

BENCHMARK_MAIN();
