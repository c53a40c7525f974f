// The C API's estimator handle (avm_estimator_*): images -> landmarks -> solved, live-filtered
// poses, the library's capture_pipeline on the caller's thread.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/capture/capture_pipeline.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "c_capture_options.hpp"
#include "c_frames.hpp"
#include "c_guard.hpp"

namespace am = avatarmap;
using namespace avatarmap::c_api;

struct avm_estimator : avatarmap::c_api::error_slot {
  std::unique_ptr<am::capture_pipeline> pipeline;
  am::landmark_frame frame;  // the last image's landmarks
  am::proxy_pose pose;       // and its pose
  frame_storage storage;     // what avm_frame's pointers point into
  // Several people (avm_estimator_process_people): every person's pose and landmarks.
  am::people_poses people;
  std::array<frame_storage, am::k_max_people> people_storage;
};

extern "C" {

// (The name in parentheses: the header also defines avm_estimator_options_init as a macro.)
AVATARMAP_C_API avm_status(avm_estimator_options_init)(avm_estimator_options* options) {
  return avm_estimator_options_init_sized(options, sizeof(avm_estimator_options));
}

AVATARMAP_C_API avm_status avm_estimator_options_init_sized(avm_estimator_options* options,
                                                            size_t size) {
  if (options == nullptr || size < offsetof(avm_estimator_options, models_dir) + sizeof(void*) ||
      size > 4096 || size % 4 != 0)
    return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_estimator_options_init_sized", silently, [&]() -> avm_status {
    const avm_estimator_options d = default_estimator_options();
    // Only the caller's bytes, and of those only the fields this library knows.
    std::memcpy(options, &d, std::min(size, sizeof d));
    options->struct_size = static_cast<std::uint32_t>(size);
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_estimator_create(const avm_estimator_options* options,
                                                const avm_solver_options* solver_options,
                                                avm_estimator** out) {
  set_create_error("");
  if (out == nullptr) {
    set_create_error("avm_estimator_create: out is NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  *out = nullptr;
  return guard("avm_estimator_create", to_create_error, [&]() -> avm_status {
    am::capture_pipeline_options po;
    double extrapolation = 0.0;
    std::string msg;
    const avm_status code = read_capture_options(options, solver_options, po, extrapolation, msg);
    if (code != AVM_OK) return to_create_error(code, msg.c_str());
    std::unique_ptr<avm_estimator> e(new avm_estimator());
    const am::status st = am::capture_pipeline::create(po, e->pipeline);
    if (!st.ok()) return to_create_error(avm_code(st), st.message().c_str());
    e->pose.set_rest();
    e->last_error.reserve(256);  // the image checks' messages fit without allocating
    *out = e.release();
    return AVM_OK;
  });
}

AVATARMAP_C_API void avm_estimator_destroy(avm_estimator* estimator) {
  guard_value(0, [&] {
    delete estimator;
    return 0;
  });
}

AVATARMAP_C_API avm_status avm_estimator_process(avm_estimator* estimator, const avm_image* image,
                                                 double t, avm_frame* out_frame,
                                                 avm_pose* out_pose) {
  if (estimator == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  estimator->last_error.clear();
  return guard("avm_estimator_process", to_handle(estimator), [&]() -> avm_status {
    if (image == nullptr)
      return fail(estimator, AVM_ERROR_INVALID_ARGUMENT, "avm_estimator_process: image is NULL");
    if (!std::isfinite(t))
      return fail(estimator, AVM_ERROR_INVALID_ARGUMENT, "avm_estimator_process: t must be finite");
    am::image_view view;
    char buffer[k_error_capacity];
    if (const char* bad = to_image_view(*image, view, buffer, sizeof buffer))
      return fail(estimator, AVM_ERROR_INVALID_ARGUMENT, bad);
    const am::status st = estimator->pipeline->process(view, t, estimator->frame, estimator->pose);
    if (!st.ok()) return fail(estimator, avm_code(st), st.message().c_str());
    if (out_frame != nullptr) to_c_frame(estimator->frame, estimator->storage, *out_frame);
    if (out_pose != nullptr) to_c_pose(estimator->pose, *out_pose);
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_estimator_process_people(avm_estimator* estimator,
                                                        const avm_image* image, double t,
                                                        avm_person* out_people, int32_t capacity,
                                                        int32_t* out_count) {
  if (estimator == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  estimator->last_error.clear();
  return guard("avm_estimator_process_people", to_handle(estimator), [&]() -> avm_status {
    const char* who = "avm_estimator_process_people: ";
    auto bad = [&](const char* what) {
      char m[k_error_capacity];
      copy_message(m, sizeof m, who);
      std::strncat(m, what, sizeof m - std::strlen(m) - 1);
      return fail(estimator, AVM_ERROR_INVALID_ARGUMENT, m);
    };
    if (image == nullptr) return bad("image is NULL");
    if (out_count == nullptr) return bad("out_count is NULL");
    if (capacity < 0) return bad("capacity must be >= 0");
    if (out_people == nullptr && capacity > 0) return bad("out_people is NULL with capacity > 0");
    if (!std::isfinite(t)) return bad("t must be finite");
    am::image_view view;
    char buffer[k_error_capacity];
    if (const char* why = to_image_view(*image, view, buffer, sizeof buffer))
      return fail(estimator, AVM_ERROR_INVALID_ARGUMENT, why);
    am::capture_pipeline& p = *estimator->pipeline;
    const am::status st = p.estimate(view, t, estimator->frame);
    if (!st.ok()) return fail(estimator, avm_code(st), st.message().c_str());
    p.solve_people(estimator->frame, estimator->people);
    const am::people_poses& people = estimator->people;
    for (int i = 0; i < people.count && i < capacity; ++i) {
      const am::person_pose& pp = people.people[i];
      avm_person& o = out_people[i];
      o.id = pp.id;
      o.slot = pp.slot;
      to_c_frame(*pp.frame, estimator->people_storage[i], o.frame);
      to_c_pose(pp.pose, o.pose);
    }
    *out_count = people.count;
    return AVM_OK;
  });
}

AVATARMAP_C_API const char* avm_estimator_last_error(const avm_estimator* estimator) {
  return guard_value<const char*>(
      "", [&] { return estimator == nullptr ? "" : estimator->last_error.c_str(); });
}

}  // extern "C"
