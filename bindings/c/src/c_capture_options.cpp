// avm_estimator_options and avm_image as the library's (c_capture_options.hpp).
#include "c_capture_options.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "c_guard.hpp"
#include "c_solver_options.hpp"

namespace avatarmap::c_api {

namespace {
// Larger than any plausible future avm_estimator_options: a bigger struct_size is taken as an
// uninitialised struct rather than a newer caller.
constexpr std::uint32_t k_max_struct_size = 4096;

bool has_backend(const char* name) {
  const estimator_backend_list list = estimator_backends();
  for (int i = 0; i < list.count; ++i)
    if (list.items[i].name == name) return true;
  return false;
}
}  // namespace

avm_estimator_options default_estimator_options() {
  avm_estimator_options o;
  std::memset(&o, 0, sizeof o);
  o.struct_size = sizeof o;
  o.models_dir = nullptr;
  const estimator_options e{};
  o.model_complexity = e.model_complexity;
  o.hands = 1;
  o.face = 1;
  o.hand_model_complexity = e.hand_model_complexity;
  o.threads = 2;
  o.mirrored = e.mirrored_input ? 1 : 0;
  o.static_images = e.static_images ? 1 : 0;
  return o;
}

avm_status read_capture_options(const avm_estimator_options* in,
                                const avm_solver_options* solver_in, capture_pipeline_options& out,
                                double& max_extrapolation_seconds, std::string& msg) {
  avm_estimator_options o = default_estimator_options();
  if (in != nullptr) {
    const std::uint32_t size = in->struct_size;
    if (size < offsetof(avm_estimator_options, models_dir) + sizeof(const char*) ||
        size > k_max_struct_size) {
      msg = "avm_estimator_options.struct_size is " + std::to_string(size) +
            ": initialise the options with avm_estimator_options_init()";
      return AVM_ERROR_INVALID_ARGUMENT;
    }
    // The known prefix of a newer caller's struct; defaults for what an older one lacks.
    std::memcpy(&o, in, std::min<std::size_t>(size, sizeof o));
    o.struct_size = sizeof o;
  }
  core_options solver;
  if (!read_options(solver_in, solver, msg)) return AVM_ERROR_INVALID_ARGUMENT;
  auto range = [&](const char* name, int v, int lo, int hi) {
    if (v >= lo && v <= hi) return true;
    msg = std::string("avm_estimator_options.") + name + " is " + std::to_string(v) +
          ": it must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    return false;
  };
  if (!range("model_complexity", o.model_complexity, 0, 2) ||
      !range("hand_model_complexity", o.hand_model_complexity, 0, 1) ||
      !range("threads", o.threads, 1, 64))
    return AVM_ERROR_INVALID_ARGUMENT;
  if (!has_backend("onnx")) {
    msg =
        "this avatarmap library was built without the ONNX Runtime backend "
        "(AVATARMAP_WITH_ONNX=OFF): it cannot estimate landmarks";
    return AVM_ERROR_UNSUPPORTED;
  }
  std::string models = o.models_dir != nullptr ? o.models_dir : "";
  if (models.empty()) {
    const char* env = std::getenv("AVATARMAP_MODELS");
    if (env == nullptr || *env == '\0') {
      msg =
          "avm_estimator_options.models_dir is not set and neither is AVATARMAP_MODELS: give the "
          "folder of the converted models (scripts/prepare_capture.sh makes them)";
      return AVM_ERROR_INVALID_ARGUMENT;
    }
    models = std::string(env) + "/onnx";
  }
  out = capture_pipeline_options{};
  out.backend = "onnx";
  estimator_options& e = out.estimator;
  e.source = models;
  e.threads = o.threads;
  e.model_complexity = o.model_complexity;
  e.hand_model_complexity = o.hand_model_complexity;
  e.hands = o.hands != 0;
  e.face = o.face != 0;
  e.mirrored_input = o.mirrored != 0;
  e.static_images = o.static_images != 0;
  out.solver = solver.solver;
  out.filter = solver.filter;
  out.filter.enabled =
      solver.channels.rotations || solver.channels.position || solver.channels.expressions;
  max_extrapolation_seconds = solver.resampler.max_extrapolation_seconds;
  return AVM_OK;
}

const char* to_image_view(const avm_image& in, image_view& out, char* buffer, size_t size) {
  switch (in.format) {
    case AVM_PIXEL_RGB8:
      out.format = pixel_format::rgb8;
      break;
    case AVM_PIXEL_BGR8:
      out.format = pixel_format::bgr8;
      break;
    case AVM_PIXEL_RGBA8:
      out.format = pixel_format::rgba8;
      break;
    case AVM_PIXEL_BGRA8:
      out.format = pixel_format::bgra8;
      break;
    default:
      return "avm_image.format must be an avm_pixel_format (AVM_PIXEL_RGB8, _BGR8, _RGBA8, "
             "_BGRA8)";
  }
  out.data = in.data;
  out.width = in.width;
  out.height = in.height;
  out.stride_bytes = in.stride_bytes;
  const status st = check_image(out);
  if (st.ok()) return nullptr;
  copy_message(buffer, size, ("avm_image: " + st.message()).c_str());
  return buffer;
}

avm_status capture_create_code(const status& st) { return code_for(st, AVM_ERROR_IO); }

}  // namespace avatarmap::c_api
