// The ONNX Runtime plumbing shared by the capture pipelines (internal to src/capture/onnx):
// one process-wide Ort::Env, session options, and a session whose input and chosen outputs
// are bound to buffers it owns, so inference writes straight into them and the steady state
// allocates nothing outside ORT.
#pragma once

#include <onnxruntime_cxx_api.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/capture/estimator.hpp"
#include "avatarmap/capture/image_crop.hpp"
#include "avatarmap/capture/low_light.hpp"
#include "model_cache.hpp"

namespace avatarmap {

/// Milliseconds since t0.
inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

inline float sigmoid(float x) { return 1.f / (1.f + std::exp(-x)); }

/// What to do about a model file that is missing, for the pipelines' error messages: int8
/// models are built by scripts/prepare_capture.sh, float ones converted by it.
inline std::string missing_model_hint(model_precision precision) {
  return precision == model_precision::int8
             ? " (int8 models are built from the float ones by scripts/prepare_capture.sh; "
               "docs/convert.md)"
             : " (convert it with tools/convert/tflite2onnx.py, docs/convert.md)";
}

/// How many bound_model::run() calls are under way on this thread (0 or 1): lets a test
/// count the heap allocations of the pipelines outside ONNX Runtime.
int ort_run_depth() noexcept;
/// Whether this thread has called bound_model::run(): the pipelines' threads (the caller's,
/// the lanes' worker) have; ONNX Runtime's own threads never do, so a test can leave out their
/// allocations (inside ONNX Runtime, whenever its threads make them).
bool ort_thread_has_run() noexcept;

/// Checks the options every detect-then-track pipeline has (threads >= 1, detection score in
/// (0, 1), NMS threshold in (0, 1], presence in [0, 1]); the message starts with `who`, or
/// "" when they are fine.
std::string check_pipeline_options(const char* who, int threads, float min_detection_score,
                                   float nms_iou_threshold, float min_presence);

/// The process-wide ORT environment (created on first use, by make_session_options with its
/// thread settings when that comes first).
Ort::Env& ort_env();

/// Sequential execution, full graph optimisation, `threads` intra-op threads, spinning as
/// asked. The first call creates the environment with a global intra-op pool of these
/// settings; every session asking for the same settings shares that pool, so the threads of
/// idle models never compete with the running one (with per-session pools, five models'
/// spinning threads halve the speed on 2 cores). Sessions with other settings get their own.
Ort::SessionOptions make_session_options(int threads, bool allow_spinning);

// One ORT session with its input and (a chosen subset of) outputs bound to buffers owned
// here, so Run() writes straight into them.
struct bound_model {
  std::unique_ptr<Ort::Session> session;
  std::string input_name;
  std::vector<std::string> output_names;  // chosen outputs only, in buffer order
  std::vector<const char*> output_name_ptrs;
  std::vector<float> input;
  std::vector<std::vector<float>> outputs;
  std::vector<Ort::Value> output_values;
  Ort::Value input_value{nullptr};
  model_cache_use cache_use = model_cache_use::off;  // where load() took the graph from

  // Loads `path` and binds the outputs whose element counts are `counts` (each must match
  // exactly one output). Throws Ort::Exception; returns a message on a shape mismatch.
  // `optional` outputs are bound when present (their buffers then follow the required ones);
  // optional_found tells which were.
  // Loads `path` and binds the outputs whose element counts are `counts` (each must match
  // exactly one output). Throws Ort::Exception; returns a message on a shape mismatch.
  // `optional` outputs are bound when present (their buffers then follow the required ones);
  // optional_found tells which were.
  std::string load(const std::string& path, const Ort::SessionOptions& so,
                   const std::vector<int64_t>& input_shape, const std::vector<int64_t>& counts,
                   const std::vector<int64_t>& optional = {},
                   std::vector<bool>* optional_found = nullptr);

  /// Like load(), for a model whose outputs cannot be told apart by size: binds outputs
  /// 0..counts.size()-1 in the model's order, each with its given element count.
  std::string load_in_order(const std::string& path, const Ort::SessionOptions& so,
                            const std::vector<int64_t>& input_shape,
                            const std::vector<int64_t>& counts);

  /// When set, crop_input() lifts a dim, low-contrast crop with these options (low_light.hpp).
  const low_light_options* lift = nullptr;

  /// Crops `roi` of `image` into `input` (MediaPipe's ImageToTensor, image_crop.hpp), lifted
  /// when `lift` is set; the transform back to the image goes to `transform` when non-null.
  /// False when the image cannot be cropped.
  bool crop_input(const image_view& image, const normalized_rect& roi, const crop_options& options,
                  crop_transform* transform);

  /// Runs the session on `input` into `outputs`. Throws Ort::Exception.
  void run();

 private:
  std::string open(const std::string& path, const Ort::SessionOptions& so,
                   const std::vector<int64_t>& input_shape);
  int64_t output_count(size_t index, std::vector<int64_t>* shape = nullptr) const;
  void bind_output(size_t index);
  void finish_binding();
};

}  // namespace avatarmap
