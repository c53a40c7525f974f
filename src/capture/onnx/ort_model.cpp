#include "ort_model.hpp"

#include <mutex>

namespace avatarmap {

namespace {

// The process-wide environment and its global intra-op thread pool. ORT allows one Env per
// process; the first call decides the pool's size and spinning. Sessions asking for exactly
// that share the pool (one set of threads for every model, so that spinning threads of
// idle sessions never compete with the running one); others get their own threads.
struct env_state {
  std::mutex m;
  std::unique_ptr<Ort::Env> env;
  int pool_threads = 0;
  bool pool_spinning = false;
};

env_state& state() {
  static env_state s;
  return s;
}

void create_env_locked(env_state& s, int threads, bool spinning) {
  Ort::ThreadingOptions tp;
  tp.SetGlobalIntraOpNumThreads(threads);
  tp.SetGlobalInterOpNumThreads(1);
  tp.SetGlobalSpinControl(spinning ? 1 : 0);
  s.env = std::make_unique<Ort::Env>(tp, ORT_LOGGING_LEVEL_WARNING, "avatarmap");
  s.pool_threads = threads;
  s.pool_spinning = spinning;
}

}  // namespace

std::string check_pipeline_options(const char* who, int threads, float min_detection_score,
                                   float nms_iou_threshold, float min_presence) {
  const std::string w = who;
  if (threads < 1) return w + ": intra_op_threads must be >= 1";
  if (!(min_detection_score > 0.f && min_detection_score < 1.f))
    return w + ": min_detection_score must be in (0, 1)";
  if (!(nms_iou_threshold > 0.f && nms_iou_threshold <= 1.f))
    return w + ": nms_iou_threshold must be in (0, 1]";
  if (!(min_presence >= 0.f && min_presence <= 1.f)) return w + ": min_presence must be in [0, 1]";
  return {};
}

Ort::Env& ort_env() {
  env_state& s = state();
  std::lock_guard<std::mutex> lock(s.m);
  if (!s.env) create_env_locked(s, 1, false);
  return *s.env;
}

Ort::SessionOptions make_session_options(int threads, bool allow_spinning) {
  env_state& s = state();
  std::lock_guard<std::mutex> lock(s.m);
  if (!s.env) create_env_locked(s, threads, allow_spinning);
  Ort::SessionOptions so;
  so.SetExecutionMode(ExecutionMode::ORT_SEQUENTIAL);
  so.SetGraphOptimizationLevel(GraphOptimizationLevel::ORT_ENABLE_ALL);
  if (threads == s.pool_threads && allow_spinning == s.pool_spinning) {
    so.DisablePerSessionThreads();
  } else {
    so.SetIntraOpNumThreads(threads);
    so.SetInterOpNumThreads(1);
    so.AddConfigEntry("session.intra_op.allow_spinning", allow_spinning ? "1" : "0");
  }
  return so;
}

std::string bound_model::open(const std::string& path, const Ort::SessionOptions& so,
                              const std::vector<int64_t>& input_shape) {
  cached_session cs = open_cached_session(ort_env(), path, so, model_cache_dir(path));
  session = std::move(cs.session);
  cache_use = cs.use;
  Ort::AllocatorWithDefaultOptions alloc;
  if (session->GetInputCount() != 1) return path + ": expected one input";
  input_name = session->GetInputNameAllocated(0, alloc).get();
  if (session->GetInputTypeInfo(0).GetTensorTypeAndShapeInfo().GetShape() != input_shape)
    return path + ": unexpected input shape";
  const Ort::MemoryInfo mem = Ort::MemoryInfo::CreateCpu(OrtArenaAllocator, OrtMemTypeDefault);
  size_t in_count = 1;
  for (int64_t d : input_shape) in_count *= static_cast<size_t>(d);
  input.assign(in_count, 0.f);
  input_value = Ort::Value::CreateTensor<float>(mem, input.data(), input.size(), input_shape.data(),
                                                input_shape.size());
  return {};
}

int64_t bound_model::output_count(size_t index, std::vector<int64_t>* shape) const {
  std::vector<int64_t> s = session->GetOutputTypeInfo(index).GetTensorTypeAndShapeInfo().GetShape();
  int64_t n = 1;
  for (int64_t d : s) n *= d;
  if (shape) *shape = std::move(s);
  return n;
}

void bound_model::bind_output(size_t index) {
  Ort::AllocatorWithDefaultOptions alloc;
  const Ort::MemoryInfo mem = Ort::MemoryInfo::CreateCpu(OrtArenaAllocator, OrtMemTypeDefault);
  std::vector<int64_t> shape;
  const int64_t n = output_count(index, &shape);
  output_names.push_back(session->GetOutputNameAllocated(index, alloc).get());
  outputs.emplace_back(static_cast<size_t>(n), 0.f);
  output_values.push_back(Ort::Value::CreateTensor<float>(
      mem, outputs.back().data(), outputs.back().size(), shape.data(), shape.size()));
}

void bound_model::finish_binding() {
  output_name_ptrs.clear();
  for (const std::string& n : output_names) output_name_ptrs.push_back(n.c_str());
}

std::string bound_model::load(const std::string& path, const Ort::SessionOptions& so,
                              const std::vector<int64_t>& input_shape,
                              const std::vector<int64_t>& counts,
                              const std::vector<int64_t>& optional,
                              std::vector<bool>* optional_found) {
  if (std::string e = open(path, so, input_shape); !e.empty()) return e;
  std::vector<int64_t> all = counts;
  all.insert(all.end(), optional.begin(), optional.end());
  if (optional_found) optional_found->assign(optional.size(), false);
  for (size_t w = 0; w < all.size(); ++w) {
    const int64_t want = all[w];
    const bool is_optional = w >= counts.size();
    int found = -1;
    for (size_t i = 0; i < session->GetOutputCount(); ++i) {
      if (output_count(i) != want) continue;
      if (found >= 0) return path + ": two outputs with " + std::to_string(want) + " values";
      found = static_cast<int>(i);
    }
    if (found < 0) {
      if (is_optional) continue;
      return path + ": no output with " + std::to_string(want) + " values";
    }
    if (is_optional) (*optional_found)[w - counts.size()] = true;
    bind_output(static_cast<size_t>(found));
  }
  finish_binding();
  return {};
}

std::string bound_model::load_in_order(const std::string& path, const Ort::SessionOptions& so,
                                       const std::vector<int64_t>& input_shape,
                                       const std::vector<int64_t>& counts) {
  if (std::string e = open(path, so, input_shape); !e.empty()) return e;
  if (session->GetOutputCount() < counts.size())
    return path + ": expected " + std::to_string(counts.size()) + " outputs";
  for (size_t i = 0; i < counts.size(); ++i) {
    const int64_t n = output_count(i);
    if (n != counts[i])
      return path + ": output " + std::to_string(i) + " has " + std::to_string(n) +
             " values, expected " + std::to_string(counts[i]);
    bind_output(i);
  }
  finish_binding();
  return {};
}

bool bound_model::crop_input(const image_view& image, const normalized_rect& roi,
                             const crop_options& options, crop_transform* transform) {
  crop_transform local;
  image_crop_job job;
  job.image = image;
  job.roi = roi;
  job.options = options;
  job.output = input.data();
  job.output_size = input.size();
  job.out_transform = transform != nullptr ? transform : &local;
  if (!job.run()) return false;
  if (lift != nullptr) lift_low_light(input.data(), options, *job.out_transform, *lift);
  return true;
}

namespace {
thread_local int t_run_depth = 0;
thread_local bool t_has_run = false;
}  // namespace

int ort_run_depth() noexcept { return t_run_depth; }
bool ort_thread_has_run() noexcept { return t_has_run; }

void bound_model::run() {
  struct depth_guard {
    depth_guard() {
      ++t_run_depth;
      t_has_run = true;
    }
    ~depth_guard() { --t_run_depth; }
  } guard;
  const char* in = input_name.c_str();
  session->Run(Ort::RunOptions{nullptr}, &in, &input_value, 1, output_name_ptrs.data(),
               output_values.data(), output_values.size());
}

}  // namespace avatarmap
