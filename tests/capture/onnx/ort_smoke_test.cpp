// Smoke test of the ONNX Runtime build the project links (AVATARMAP_WITH_ONNX): loads the
// third-party ONNX conversion of MediaPipe's hand_landmark_lite from the shared data
// (reference-onnx/zaru_hand_landmark_lite.onnx), prints its inputs and outputs, runs it on a
// deterministic image and checks the outputs are finite and shaped as MediaPipe's model is
// ([1,63] landmarks, [1,1] presence, [1,1] handedness, [1,63] world landmarks), then prints
// the median latency of 100 runs with 1 and 2 intra-op threads. Timings are printed, never
// asserted. Skipped without AVATARMAP_TEST_DATA.
#include <gtest/gtest.h>
#include <onnxruntime_cxx_api.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "support/test_data.hpp"

namespace avatarmap {
namespace {

const char* const k_model = "reference-onnx/zaru_hand_landmark_lite.onnx";

std::string shape_string(const std::vector<int64_t>& shape) {
  std::string s = "[";
  for (size_t i = 0; i < shape.size(); ++i) {
    if (i) s += ",";
    s += shape[i] < 0 ? std::string("?") : std::to_string(shape[i]);
  }
  return s + "]";
}

// The model path, or "" (with the reason in out_why) when the data is not there.
std::string model_path(std::string& out_why) {
  const std::string path = test::test_data_path(k_model);
  if (path.empty()) {
    out_why = test::k_no_test_data;
  } else if (!std::ifstream(path).good()) {
    out_why = path + " is missing from the shared data";
    return "";
  }
  return path;
}

Ort::Env& ort_env() {
  static Ort::Env env(ORT_LOGGING_LEVEL_WARNING, "avatarmap_ort_smoke");
  return env;
}

Ort::Session make_session(const std::string& path, int threads, bool allow_spinning = true) {
  Ort::SessionOptions options;
  options.SetIntraOpNumThreads(threads);
  options.SetInterOpNumThreads(1);
  options.SetExecutionMode(ExecutionMode::ORT_SEQUENTIAL);
  options.SetGraphOptimizationLevel(GraphOptimizationLevel::ORT_ENABLE_ALL);
  if (!allow_spinning) options.AddConfigEntry("session.intra_op.allow_spinning", "0");
  return Ort::Session(ort_env(), path.c_str(), options);
}

struct io_names {
  std::vector<std::string> inputs, outputs;
  std::vector<const char*> input_ptrs, output_ptrs;
};

io_names names_of(const Ort::Session& session) {
  Ort::AllocatorWithDefaultOptions allocator;
  io_names n;
  for (size_t i = 0; i < session.GetInputCount(); ++i)
    n.inputs.push_back(session.GetInputNameAllocated(i, allocator).get());
  for (size_t i = 0; i < session.GetOutputCount(); ++i)
    n.outputs.push_back(session.GetOutputNameAllocated(i, allocator).get());
  for (const auto& s : n.inputs) n.input_ptrs.push_back(s.c_str());
  for (const auto& s : n.outputs) n.output_ptrs.push_back(s.c_str());
  return n;
}

// A smooth, deterministic image in [0, 1] (no RNG, so every platform feeds the same bytes),
// laid out as the model's input shape says; dynamic dimensions are taken as 1.
std::vector<float> deterministic_input(const std::vector<int64_t>& shape) {
  size_t count = 1;
  for (int64_t d : shape) count *= static_cast<size_t>(d > 0 ? d : 1);
  std::vector<float> data(count);
  for (size_t i = 0; i < count; ++i)
    data[i] = 0.5f + 0.5f * std::sin(0.001f * static_cast<float>(i) +
                                     0.3f * std::cos(0.017f * static_cast<float>(i)));
  return data;
}

struct run_result {
  std::vector<std::vector<int64_t>> shapes;
  std::vector<std::vector<float>> values;
};

run_result run_once(Ort::Session& session, const io_names& names, std::vector<float>& input,
                    const std::vector<int64_t>& input_shape) {
  const Ort::MemoryInfo memory = Ort::MemoryInfo::CreateCpu(OrtArenaAllocator, OrtMemTypeDefault);
  Ort::Value tensor = Ort::Value::CreateTensor<float>(memory, input.data(), input.size(),
                                                      input_shape.data(), input_shape.size());
  std::vector<Ort::Value> outputs =
      session.Run(Ort::RunOptions{nullptr}, names.input_ptrs.data(), &tensor, 1,
                  names.output_ptrs.data(), names.output_ptrs.size());
  run_result r;
  for (Ort::Value& v : outputs) {
    const auto info = v.GetTensorTypeAndShapeInfo();
    r.shapes.push_back(info.GetShape());
    const float* p = v.GetTensorData<float>();
    r.values.emplace_back(p, p + info.GetElementCount());
  }
  return r;
}

// Median milliseconds per inference over `runs` runs, after a few warm-up runs.
double median_ms(Ort::Session& session, const io_names& names, std::vector<float>& input,
                 const std::vector<int64_t>& input_shape, int runs) {
  for (int i = 0; i < 5; ++i) run_once(session, names, input, input_shape);
  std::vector<double> ms;
  ms.reserve(runs);
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    run_once(session, names, input, input_shape);
    const auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  std::nth_element(ms.begin(), ms.begin() + runs / 2, ms.end());
  return ms[runs / 2];
}

std::vector<int64_t> input_shape_of(const Ort::Session& session) {
  // The shape info is a view into the type info: keep that alive while reading it.
  const Ort::TypeInfo type = session.GetInputTypeInfo(0);
  std::vector<int64_t> shape = type.GetTensorTypeAndShapeInfo().GetShape();
  for (int64_t& d : shape)
    if (d < 0) d = 1;
  return shape;
}

TEST(OrtSmoke, PrintsVersionAndModelSignature) {
  std::printf("ONNX Runtime %s (headers ORT_API_VERSION %d)\n", Ort::GetVersionString().c_str(),
              ORT_API_VERSION);
  std::string why;
  const std::string path = model_path(why);
  if (path.empty()) GTEST_SKIP() << why;
  Ort::Session session = make_session(path, 1);
  const io_names names = names_of(session);
  for (size_t i = 0; i < names.inputs.size(); ++i) {
    const Ort::TypeInfo type = session.GetInputTypeInfo(i);
    const auto info = type.GetTensorTypeAndShapeInfo();
    std::printf("  input  %zu %-12s %s type %d\n", i, names.inputs[i].c_str(),
                shape_string(info.GetShape()).c_str(), static_cast<int>(info.GetElementType()));
  }
  for (size_t i = 0; i < names.outputs.size(); ++i) {
    const Ort::TypeInfo type = session.GetOutputTypeInfo(i);
    const auto info = type.GetTensorTypeAndShapeInfo();
    std::printf("  output %zu %-12s %s type %d\n", i, names.outputs[i].c_str(),
                shape_string(info.GetShape()).c_str(), static_cast<int>(info.GetElementType()));
  }
  ASSERT_EQ(names.inputs.size(), 1u);
  const Ort::TypeInfo in = session.GetInputTypeInfo(0);
  EXPECT_EQ(in.GetTensorTypeAndShapeInfo().GetElementType(), ONNX_TENSOR_ELEMENT_DATA_TYPE_FLOAT);
  // 224 x 224 RGB, channels first or last depending on the conversion.
  const std::vector<int64_t> shape = input_shape_of(session);
  ASSERT_EQ(shape.size(), 4u);
  EXPECT_EQ(shape[0] * shape[1] * shape[2] * shape[3], 224 * 224 * 3);
}

TEST(OrtSmoke, HandLandmarkOutputsAreFiniteAndShaped) {
  std::string why;
  const std::string path = model_path(why);
  if (path.empty()) GTEST_SKIP() << why;
  Ort::Session session = make_session(path, 1);
  const io_names names = names_of(session);
  const std::vector<int64_t> shape = input_shape_of(session);
  std::vector<float> input = deterministic_input(shape);

  const run_result r = run_once(session, names, input, shape);
  // MediaPipe's order: screen landmarks, presence, handedness, world landmarks.
  const std::vector<std::vector<int64_t>> expected = {{1, 63}, {1, 1}, {1, 1}, {1, 63}};
  ASSERT_EQ(r.shapes.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(r.shapes[i], expected[i]) << "output " << names.outputs[i];
    for (float v : r.values[i]) ASSERT_TRUE(std::isfinite(v)) << "output " << names.outputs[i];
  }
  std::printf("  presence %.4f handedness %.4f wrist (%.2f, %.2f, %.2f) px\n", r.values[1][0],
              r.values[2][0], r.values[0][0], r.values[0][1], r.values[0][2]);

  // Same input, same session: same bytes. Another thread count: same values within
  // rounding (a reduction may be split differently).
  const run_result again = run_once(session, names, input, shape);
  EXPECT_EQ(again.values, r.values);
  Ort::Session two = make_session(path, 2);
  const run_result r2 = run_once(two, names, input, shape);
  for (size_t i = 0; i < r.values.size(); ++i)
    for (size_t j = 0; j < r.values[i].size(); ++j)
      EXPECT_NEAR(r2.values[i][j], r.values[i][j], 1e-3f * (1.f + std::fabs(r.values[i][j])));
}

TEST(OrtSmoke, PrintsLatency) {
  std::string why;
  const std::string path = model_path(why);
  if (path.empty()) GTEST_SKIP() << why;
  constexpr int k_runs = 100;
  struct config {
    int threads;
    bool spinning;
    const char* label;
  };
  for (const config c : {config{1, true, "1 thread"}, config{2, true, "2 threads"},
                         config{2, false, "2 threads, no spinning"}}) {
    Ort::Session session = make_session(path, c.threads, c.spinning);
    const io_names names = names_of(session);
    const std::vector<int64_t> shape = input_shape_of(session);
    std::vector<float> input = deterministic_input(shape);
    const double ms = median_ms(session, names, input, shape, k_runs);
    std::printf("  hand_landmark_lite (zaru), %s: median %.2f ms over %d runs\n", c.label, ms,
                k_runs);
    RecordProperty(
        std::string("median_ms_") + std::to_string(c.threads) + (c.spinning ? "" : "_nospin"),
        std::to_string(ms));
    EXPECT_GT(ms, 0.0);
  }
}

}  // namespace
}  // namespace avatarmap
