// avm_estimator_options and avm_image as the library's (c_capture_options.hpp).
#include "c_capture_options.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "avatarmap/io/resources.hpp"
#include "c_guard.hpp"
#include "c_solver_options.hpp"

namespace avatarmap::c_api {

static_assert(AVM_MAX_PEOPLE == k_max_people,
              "AVM_MAX_PEOPLE must be estimator.hpp's k_max_people");

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

namespace {

// The int32_t fields of avm_estimator_options (all but struct_size and models_dir), each by
// its name in k_estimator_option_table (the token is the name).
struct c_field {
  const char* name;
  std::size_t offset;
};
#define AVM_FIELD(f) \
  c_field { #f, offsetof(avm_estimator_options, f) }
constexpr c_field k_fields[] = {
    AVM_FIELD(model_complexity),      AVM_FIELD(hands),      AVM_FIELD(face),
    AVM_FIELD(hand_model_complexity), AVM_FIELD(threads),    AVM_FIELD(mirrored),
    AVM_FIELD(static_images),         AVM_FIELD(max_people),
};
#undef AVM_FIELD
// Every field from model_complexity to the end (past it only the struct's padding).
constexpr std::size_t k_fields_end = offsetof(avm_estimator_options, max_people) + 4;
static_assert(offsetof(avm_estimator_options, model_complexity) +
                          sizeof(k_fields) / sizeof(k_fields[0]) * sizeof(std::int32_t) ==
                      k_fields_end &&
                  sizeof(avm_estimator_options) - k_fields_end < alignof(avm_estimator_options),
              "k_fields must list every field of avm_estimator_options");

std::int32_t field_value(const avm_estimator_options& o, const c_field& f) {
  std::int32_t v;
  std::memcpy(&v, reinterpret_cast<const char*>(&o) + f.offset, sizeof v);
  return v;
}

const option_row<estimator_options>& row_of(const c_field& f) {
  // Every name of k_fields is a row (tests/python/test_options.py checks the table's C rows
  // against the struct); a missing one is a programming error caught on the first call.
  const option_row<estimator_options>* r = find_option(k_estimator_option_table, f.name);
  if (r == nullptr) std::abort();
  return *r;
}

}  // namespace

avm_estimator_options default_estimator_options() {
  avm_estimator_options o;
  std::memset(&o, 0, sizeof o);
  o.struct_size = sizeof o;
  o.models_dir = nullptr;  // find_resource(resource::models)
  for (const c_field& f : k_fields) {
    const std::int32_t v = static_cast<std::int32_t>(option_default(row_of(f)));
    std::memcpy(reinterpret_cast<char*>(&o) + f.offset, &v, sizeof v);
  }
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
  // Each field through its row: the range and its message come from the table. A C boolean is
  // 0 or non-zero (the header's rule), so booleans are not range-checked.
  estimator_options e;
  apply_option_defaults(k_estimator_option_table, e);
  for (const c_field& f : k_fields) {
    const option_row<estimator_options>& row = row_of(f);
    const double v = field_value(o, f);
    if (row.kind == option_kind::boolean) {
      row.set(e, v != 0.0 ? 1.0 : 0.0);
    } else if (!option_accepts(row, v)) {
      msg = option_range_message(row, std::string("avm_estimator_options.") + f.name, v);
      return AVM_ERROR_INVALID_ARGUMENT;
    } else {
      row.set(e, v);
    }
  }
  if (!has_backend("onnx")) {
    msg =
        "this avatarmap library was built without the ONNX Runtime backend "
        "(AVATARMAP_WITH_ONNX=OFF): it cannot estimate landmarks";
    return AVM_ERROR_UNSUPPORTED;
  }
  const resource_lookup found =
      find_resource(resource::models, o.models_dir != nullptr ? o.models_dir : "");
  if (found.folder.empty()) {
    msg =
        "avm_estimator_options.models_dir is not set and no models folder was found (looked "
        "in:";
    for (const std::string& t : found.tried) msg += " " + t + ";";
    msg +=
        " set AVATARMAP_MODELS): give the folder of the converted models "
        "(scripts/prepare_capture.sh makes them)";
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  const std::string& models = found.folder;
  out = capture_pipeline_options{};
  out.backend = "onnx";
  e.source = models;
  out.estimator = e;
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

}  // namespace avatarmap::c_api
