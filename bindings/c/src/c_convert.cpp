// avm_convert_file and avm_motion_input_kind: `avatarmap convert IN -o OUT` as a library call,
// the library's convert_file_job (the CLI's `convert` runs it too) with its arguments read
// from avm_convert_options.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/jobs/convert_file.hpp"
#include "c_avatar.hpp"
#include "c_guard.hpp"
#include "c_solver_options.hpp"

namespace am = avatarmap;
using namespace avatarmap::c_api;

namespace {

// Larger than any plausible future avm_convert_options: a bigger struct_size is taken as an
// uninitialised struct rather than a newer caller.
constexpr std::uint32_t k_max_struct_size = 4096;
// The known prefix every caller has: struct_size and fps.
constexpr std::size_t k_min_struct_size = offsetof(avm_convert_options, fps) + sizeof(double);

avm_convert_options default_convert_options() {
  avm_convert_options o;
  std::memset(&o, 0, sizeof o);
  o.struct_size = sizeof o;
  const am::convert_file_job job;
  o.fps = job.fps;
  o.avatar = nullptr;
  o.mapping = nullptr;
  o.keep_feet_on_ground = job.keep_feet_on_ground ? 1 : 0;
  o.root_motion = job.root_motion ? 1 : 0;
  o.solver = nullptr;
  o.warning = nullptr;
  o.user = nullptr;
  o.foot_lock = job.foot_lock.enabled ? 1 : 0;
  return o;
}

int kind_code(am::motion_input kind) {
  switch (kind) {
    case am::motion_input::landmarks:
      return AVM_MOTION_INPUT_LANDMARKS;
    case am::motion_input::poses:
      return AVM_MOTION_INPUT_POSES;
    case am::motion_input::vrma:
      return AVM_MOTION_INPUT_VRMA;
    case am::motion_input::bvh:
      return AVM_MOTION_INPUT_BVH;
  }
  return AVM_MOTION_INPUT_NONE;
}

void fill_summary(const am::convert_file_summary& s, avm_convert_summary& out) {
  out.input_kind = s.input != nullptr ? kind_code(s.input->kind) : AVM_MOTION_INPUT_NONE;
  out.frames_read = static_cast<int64_t>(s.frames_read);
  out.frames_out_of_order = static_cast<int64_t>(s.out_of_order);
  out.frames_written = static_cast<int64_t>(s.output.frames_written);
  out.fps = s.output.fps;
  out.seconds = s.seconds;
}

}  // namespace

extern "C" {

AVATARMAP_C_API int avm_motion_input_kind(const char* path, size_t* out_stem_length) {
  if (out_stem_length != nullptr) *out_stem_length = 0;
  if (path == nullptr) return AVM_MOTION_INPUT_NONE;
  return guard_value(static_cast<int>(AVM_MOTION_INPUT_NONE), [&] {
    const am::motion_input_info* info = nullptr;
    std::string stem;
    if (!am::find_motion_input(path, info, &stem).ok() || info == nullptr)
      return static_cast<int>(AVM_MOTION_INPUT_NONE);
    if (out_stem_length != nullptr) *out_stem_length = stem.size();
    return kind_code(info->kind);
  });
}

// (The name in parentheses: the header also defines avm_convert_options_init as a macro.)
AVATARMAP_C_API avm_status(avm_convert_options_init)(avm_convert_options* options) {
  return avm_convert_options_init_sized(options, sizeof(avm_convert_options));
}

AVATARMAP_C_API avm_status avm_convert_options_init_sized(avm_convert_options* options,
                                                          size_t size) {
  if (options == nullptr || size < k_min_struct_size || size > k_max_struct_size || size % 4 != 0)
    return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_convert_options_init_sized", silently, [&]() -> avm_status {
    const avm_convert_options d = default_convert_options();
    // Only the caller's bytes, and of those only the fields this library knows.
    std::memcpy(options, &d, std::min(size, sizeof d));
    options->struct_size = static_cast<std::uint32_t>(size);
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_convert_file(const char* input, const char* output,
                                            const avm_convert_options* options,
                                            avm_convert_summary* out_summary, char* err,
                                            size_t err_size) {
  copy_message(err, err_size, "");
  auto report = [&](avm_status code, const char* msg) {
    copy_message(err, err_size, msg);
    return code;
  };
  if (input == nullptr || output == nullptr)
    return report(AVM_ERROR_INVALID_ARGUMENT,
                  "avm_convert_file: input and output must not be NULL");
  if (out_summary != nullptr && out_summary->struct_size < sizeof(avm_convert_summary))
    return report(AVM_ERROR_INVALID_ARGUMENT,
                  "avm_convert_file: set out_summary->struct_size = sizeof(avm_convert_summary)");
  return guard("avm_convert_file", report, [&]() -> avm_status {
    avm_convert_options o = default_convert_options();
    if (options != nullptr) {
      const std::uint32_t size = options->struct_size;
      if (size < k_min_struct_size || size > k_max_struct_size)
        return report(
            AVM_ERROR_INVALID_ARGUMENT,
            ("avm_convert_file: avm_convert_options.struct_size is " + std::to_string(size) +
             ": initialise the options with avm_convert_options_init()")
                .c_str());
      // The known prefix of a newer caller's struct; defaults for what an older one lacks.
      std::memcpy(&o, options, std::min<std::size_t>(size, sizeof o));
      o.struct_size = sizeof o;
    }
    core_options solver;
    std::string msg;
    if (!read_options(o.solver, solver, msg))
      return report(AVM_ERROR_INVALID_ARGUMENT, ("avm_convert_file: " + msg).c_str());

    am::convert_file_job job;
    job.input = input;
    job.output = output;
    job.fps = o.fps;
    job.solve = file_job(solver);
    if (o.avatar != nullptr) job.avatar = o.avatar;
    job.binding.rig = o.mapping != nullptr ? o.mapping : "auto";
    // io/resources.hpp's order, the folder of avm_set_mappings_folder() first (c_avatar.hpp).
    job.binding.mappings_folder = given_mappings_folder();
    job.keep_feet_on_ground = o.keep_feet_on_ground != 0;
    job.root_motion = o.root_motion != 0;
    job.foot_lock.enabled = o.foot_lock != 0;
    job.avatar_name = "options->avatar";
    if (o.warning != nullptr) {
      const avm_warning_fn warn = o.warning;
      void* user = o.user;
      job.warning = [warn, user](const std::string& w) { warn(user, w.c_str()); };
    }
    if (am::status st = job.validate(); !st.ok()) return report(avm_code(st), st.message().c_str());
    if (o.solver != nullptr) {
      // Solver options say how landmarks are solved: for another input they are a mistake.
      const am::motion_input_info* kind = nullptr;
      if (am::status st = am::find_motion_input(input, kind); !st.ok())
        return report(avm_code(st), st.message().c_str());
      if (kind->kind != am::motion_input::landmarks)
        return report(AVM_ERROR_INVALID_ARGUMENT,
                      ("avm_convert_file: options->solver applies to a *.landmarks.jsonl input "
                       "only; " +
                       std::string(input) + " is " + std::string(kind->description))
                          .c_str());
    }
    am::convert_file_summary s;
    const am::status st = job.run(s);
    if (out_summary != nullptr) fill_summary(s, *out_summary);
    if (!st.ok()) return report(avm_code(st), st.message().c_str());
    return AVM_OK;
  });
}

}  // extern "C"
