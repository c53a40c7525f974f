// The C API (bindings/c/include/avatarmap/avatarmap.h) over the C++ core. Rules kept here:
// no exception leaves an avm_* function (each body that can throw runs in guard()); quaternions are
// copied component by component through store_xyzw (never memcpy'd); the per-frame calls
// (push, get_pose, sample) allocate nothing on success.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include "avatarmap/avatarmap.h"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/jobs/clip_output.hpp"
#include "avatarmap/jobs/solve_file.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/rig/avatar_loader.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/rig/rig_binding.hpp"
#include "avatarmap/skeleton/bone.hpp"
#include "avatarmap/skeleton/expression.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/solve/frame_solver.hpp"
#include "avatarmap/solve/solver_options.hpp"
#include "avatarmap/time/offline_smoother.hpp"
#include "avatarmap/time/pose_filter.hpp"
#include "avatarmap/time/pose_resampler.hpp"
#include "avatarmap/version.hpp"

namespace am = avatarmap;

static_assert(AVM_VERSION_MAJOR == AVATARMAP_VERSION_MAJOR &&
                  AVM_VERSION_MINOR == AVATARMAP_VERSION_MINOR &&
                  AVM_VERSION_PATCH == AVATARMAP_VERSION_PATCH,
              "avatarmap.h and avatarmap/version.hpp disagree on the version");
static_assert(AVM_BONE_COUNT == am::k_bone_count, "bone count");
static_assert(AVM_EXPRESSION_COUNT == am::k_expression_count, "expression count");
static_assert(AVM_POSE_LANDMARK_COUNT == am::k_pose_landmark_count, "pose landmark count");
static_assert(AVM_HAND_LANDMARK_COUNT == am::k_hand_landmark_count, "hand landmark count");
static_assert(AVM_FACE_LANDMARK_COUNT == am::k_face_mesh_count, "face landmark count");
static_assert(AVM_FACE_IRIS_LANDMARK_COUNT == am::k_face_mesh_iris_count, "face+iris count");
static_assert(AVM_BONE_RIGHT_LITTLE_DISTAL == am::idx(am::bone::right_little_distal) &&
                  AVM_BONE_LEFT_HAND == am::idx(am::bone::left_hand) &&
                  AVM_BONE_RIGHT_TOES == am::idx(am::bone::right_toes) &&
                  AVM_BONE_JAW == am::idx(am::bone::jaw),
              "avm_bone must follow avatarmap::bone");
static_assert(AVM_EXPRESSION_BROW_DOWN_RIGHT == am::idx(am::expression::brow_down_right) &&
                  AVM_EXPRESSION_LOOK_UP == am::idx(am::expression::look_up),
              "avm_expression must follow avatarmap::expression");
// The prefix copy in read_options() relies on every field being 4 bytes wide.
static_assert(sizeof(avm_solver_options) % 4 == 0 && alignof(avm_solver_options) == 4,
              "avm_solver_options must hold only 4-byte fields");

// The handle. Everything a frame needs is preallocated here.
struct avm_solver {
  am::frame_solver solver;
  am::pose_filter filter;
  am::pose_resampler resampler;
  am::pose_filter_channels channels;
  am::landmark_frame frame;  // scratch: the C frame converted
  am::proxy_pose raw;        // scratch: solved, before filtering
  am::proxy_pose latest;     // solved and filtered
  am::proxy_pose sampled;    // scratch for sample()
  mutable std::string last_error;

  avm_solver(const am::solver_options& s, const am::pose_filter_options& f,
             const am::pose_resampler_options& r)
      : solver(s), filter(f), resampler(r) {}
};

namespace {

constexpr std::size_t k_error_capacity = 512;
// avm_last_create_error(): a fixed buffer so that reporting cannot itself fail to allocate.
thread_local char t_create_error[k_error_capacity] = "";

void copy_message(char* dst, std::size_t size, const char* msg) {
  if (dst == nullptr || size == 0) return;
  if (msg == nullptr) msg = "";
  std::size_t n = std::strlen(msg);
  if (n >= size) n = size - 1;
  std::memcpy(dst, msg, n);
  dst[n] = '\0';
}

void set_create_error(const char* msg) { copy_message(t_create_error, k_error_capacity, msg); }

// Sets the handle's message; a failure to allocate it leaves a truncated or empty message
// rather than turning the real error into another one.
void set_error(const avm_solver* s, const char* msg) noexcept {
  if (s == nullptr) return;
  try {
    s->last_error.assign(msg);
  } catch (...) {
    s->last_error.clear();
  }
}

avm_status fail(const avm_solver* s, avm_status code, const char* msg) noexcept {
  set_error(s, msg);
  return code;
}

void set_error(const avm_retargeter* r, const char* msg) noexcept;  // defined with the handle
void set_error(const avm_clip* c, const char* msg) noexcept;        // defined with the handle

// The status code for a failed library call: AVM_ERROR_OUT_OF_MEMORY when memory ran out,
// else `otherwise` (the entry point's code for that step: I/O, parse, invalid argument).
avm_status code_for(const am::status& st, avm_status otherwise) {
  return st.is_out_of_memory() ? AVM_ERROR_OUT_OF_MEMORY : otherwise;
}

// The status code for why a library job (avatarmap/jobs/*) failed.
avm_status job_code(am::job_failure why) {
  switch (why) {
    case am::job_failure::invalid_argument:
      return AVM_ERROR_INVALID_ARGUMENT;
    case am::job_failure::input_io:
    case am::job_failure::output_io:
      return AVM_ERROR_IO;
    case am::job_failure::input_parse:
      return AVM_ERROR_PARSE;
    case am::job_failure::none:
      break;
  }
  return AVM_ERROR_INTERNAL;
}

// Reporters for guard(): where an entry point's error message goes. None of them throws or
// allocates beyond the handle's own message string.
avm_status to_create_error(avm_status code, const char* msg) noexcept {
  set_create_error(msg);
  return code;
}
avm_status silently(avm_status code, const char*) noexcept { return code; }
template <class Handle>
auto to_handle(const Handle* h) noexcept {
  return [h](avm_status code, const char* msg) noexcept {
    set_error(h, msg);
    return code;
  };
}

// The one exception boundary of the C API: every avm_* function that can throw runs its body
// here. Each exception becomes a status and a message in our words (composed in a fixed
// buffer, so reporting out of memory cannot itself fail) handed to `report(code, message)`;
// `fn` names the entry point in the message.
template <class Report, class Body>
avm_status guard(const char* fn, Report&& report, Body&& body) noexcept {
  char msg[k_error_capacity];
  try {
    return body();
  } catch (const std::bad_alloc&) {
    std::snprintf(msg, sizeof msg,
                  "%s: out of memory (the input is too large for this process; split it or "
                  "free memory)",
                  fn);
    return report(AVM_ERROR_OUT_OF_MEMORY, msg);
  } catch (const std::exception& e) {
    std::snprintf(msg, sizeof msg, "%s: internal error (%s); please report it with the input", fn,
                  e.what());
    return report(AVM_ERROR_INTERNAL, msg);
  } catch (...) {
    std::snprintf(msg, sizeof msg, "%s: unknown internal error; please report it with the input",
                  fn);
    return report(AVM_ERROR_INTERNAL, msg);
  }
}

avm_solver_options default_options() {
  avm_solver_options o;
  std::memset(&o, 0, sizeof o);
  o.struct_size = sizeof o;
  const am::solver_options s{};
  o.mirror = s.mirror ? 1 : 0;
  o.image_width = s.image_width;
  o.image_height = s.image_height;
  o.solve_body = s.parts.body ? 1 : 0;
  o.solve_hands = s.parts.hands ? 1 : 0;
  o.solve_face = s.parts.face ? 1 : 0;
  o.solve_hips_translation = s.parts.hips_translation ? 1 : 0;
  o.confidence_lost_below = s.confidence.lost_below;
  o.confidence_found_above = s.confidence.found_above;
  o.confidence_hold_seconds = s.confidence.hold_seconds;
  o.confidence_ease_seconds = s.confidence.ease_seconds;
  o.confidence_regain_seconds = s.confidence.regain_seconds;
  o.hips_lean_share = s.hips_lean_share;
  o.forearm_twist_share = s.forearm_twist_share;
  o.horizontal_fov_degrees = s.horizontal_fov_degrees;
  o.rest_hips_height = s.rest_hips_height;
  const am::pose_filter_options f{};
  o.filter_rotations = f.enabled ? 1 : 0;
  o.rotation_min_cutoff = f.rotation.min_cutoff;
  o.rotation_beta = f.rotation.beta;
  o.rotation_d_cutoff = f.rotation.d_cutoff;
  o.filter_position = f.enabled ? 1 : 0;
  o.position_min_cutoff = f.position.min_cutoff;
  o.position_beta = f.position.beta;
  o.position_d_cutoff = f.position.d_cutoff;
  o.filter_expressions = f.enabled ? 1 : 0;
  o.expression_min_cutoff = f.expression.min_cutoff;
  o.expression_beta = f.expression.beta;
  o.expression_d_cutoff = f.expression.d_cutoff;
  const am::pose_resampler_options r{};
  o.max_extrapolation_seconds = static_cast<float>(r.max_extrapolation_seconds);
  o.file_filter = AVM_FILE_FILTER_OFFLINE;
  o.file_smoothing = am::offline_smoother_options{}.strength;
  return o;
}

// Options as the core wants them, after the checks the core does not do itself.
struct core_options {
  am::solver_options solver;
  am::pose_filter_options filter;
  am::pose_resampler_options resampler;
  am::pose_filter_channels channels;
  am::pose_filter_mode file_filter = am::pose_filter_mode::offline;  // avm_solve_file only
  float file_smoothing = 1.f;
};

// Larger than any plausible future avm_solver_options: a bigger struct_size is taken as an
// uninitialised struct rather than a newer caller.
constexpr std::uint32_t k_max_struct_size = 4096;

// Reads caller options (NULL = defaults) into `out`; on failure writes a message naming the
// field and its range into `msg` and returns false.
bool read_options(const avm_solver_options* in, core_options& out, std::string& msg) {
  avm_solver_options o = default_options();
  if (in != nullptr) {
    const std::uint32_t size = in->struct_size;
    if (size < offsetof(avm_solver_options, mirror) + sizeof(std::int32_t) ||
        size > k_max_struct_size) {
      msg = "avm_solver_options.struct_size is " + std::to_string(size) +
            ": initialise the options with avm_solver_options_init()";
      return false;
    }
    // Known prefix of a newer caller's struct; defaults for fields an older caller lacks.
    // Whole fields only (all are 4 bytes wide).
    std::size_t n = std::min<std::size_t>(size, sizeof o) / 4 * 4;
    std::memcpy(&o, in, n);
    o.struct_size = sizeof o;
  }
  auto& s = out.solver;
  s.mirror = o.mirror != 0;
  s.image_width = o.image_width;
  s.image_height = o.image_height;
  s.parts.body = o.solve_body != 0;
  s.parts.hands = o.solve_hands != 0;
  s.parts.face = o.solve_face != 0;
  s.parts.hips_translation = o.solve_hips_translation != 0;
  s.confidence.lost_below = o.confidence_lost_below;
  s.confidence.found_above = o.confidence_found_above;
  s.confidence.hold_seconds = o.confidence_hold_seconds;
  s.confidence.ease_seconds = o.confidence_ease_seconds;
  s.confidence.regain_seconds = o.confidence_regain_seconds;
  s.hips_lean_share = o.hips_lean_share;
  s.forearm_twist_share = o.forearm_twist_share;
  s.horizontal_fov_degrees = o.horizontal_fov_degrees;
  s.rest_hips_height = o.rest_hips_height;
  am::status st = s.validate();
  if (!st) {
    msg = "avm_solver_options: " + st.message();
    return false;
  }

  struct param_check {
    const char* name;
    float min_cutoff, beta, d_cutoff;
  };
  const param_check checks[] = {
      {"rotation", o.rotation_min_cutoff, o.rotation_beta, o.rotation_d_cutoff},
      {"position", o.position_min_cutoff, o.position_beta, o.position_d_cutoff},
      {"expression", o.expression_min_cutoff, o.expression_beta, o.expression_d_cutoff}};
  for (const param_check& c : checks) {
    if (!(std::isfinite(c.min_cutoff) && c.min_cutoff > 0.f)) {
      msg = std::string("avm_solver_options.") + c.name + "_min_cutoff must be finite and > 0";
      return false;
    }
    if (!(std::isfinite(c.beta) && c.beta >= 0.f)) {
      msg = std::string("avm_solver_options.") + c.name + "_beta must be finite and >= 0";
      return false;
    }
    if (!(std::isfinite(c.d_cutoff) && c.d_cutoff > 0.f)) {
      msg = std::string("avm_solver_options.") + c.name + "_d_cutoff must be finite and > 0";
      return false;
    }
  }
  if (!(std::isfinite(o.max_extrapolation_seconds) && o.max_extrapolation_seconds >= 0.f)) {
    msg = "avm_solver_options.max_extrapolation_seconds must be finite and >= 0";
    return false;
  }
  out.filter.rotation = {o.rotation_min_cutoff, o.rotation_beta, o.rotation_d_cutoff};
  out.filter.position = {o.position_min_cutoff, o.position_beta, o.position_d_cutoff};
  out.filter.expression = {o.expression_min_cutoff, o.expression_beta, o.expression_d_cutoff};
  out.channels.rotations = o.filter_rotations != 0;
  out.channels.position = o.filter_position != 0;
  out.channels.expressions = o.filter_expressions != 0;
  out.filter.enabled = out.channels.rotations || out.channels.position || out.channels.expressions;
  out.resampler.max_extrapolation_seconds = o.max_extrapolation_seconds;
  switch (o.file_filter) {
    case AVM_FILE_FILTER_OFFLINE:
      out.file_filter = am::pose_filter_mode::offline;
      break;
    case AVM_FILE_FILTER_LIVE:
      out.file_filter = am::pose_filter_mode::live;
      break;
    case AVM_FILE_FILTER_NONE:
      out.file_filter = am::pose_filter_mode::none;
      break;
    default:
      msg =
          "avm_solver_options.file_filter is " + std::to_string(o.file_filter) +
          ": use AVM_FILE_FILTER_OFFLINE (0), AVM_FILE_FILTER_LIVE (1) or AVM_FILE_FILTER_NONE (2)";
      return false;
  }
  if (!(std::isfinite(o.file_smoothing) && o.file_smoothing >= 0.f && o.file_smoothing <= 10.f)) {
    msg = "avm_solver_options.file_smoothing must be finite and in [0, 10] (1 = default)";
    return false;
  }
  out.file_smoothing = o.file_smoothing;
  return true;
}

// Checks a C frame; on failure returns a static message.
const char* check_frame(const avm_frame& f) {
  if (!std::isfinite(f.t)) return "avm_frame.t must be finite";
  if (f.face != nullptr && f.face_count != AVM_FACE_LANDMARK_COUNT &&
      f.face_count != AVM_FACE_IRIS_LANDMARK_COUNT)
    return "avm_frame.face_count must be 468 or 478 when face is not NULL";
  return nullptr;
}

void copy_part(am::landmark_frame& dst, am::frame_part part, const avm_landmark* src, int n,
               am::landmark* out) {
  dst.set(part, src != nullptr);
  if (src == nullptr) return;
  for (int i = 0; i < n; ++i) {
    out[i].x = src[i].x;
    out[i].y = src[i].y;
    out[i].z = src[i].z;
    out[i].visibility = src[i].visibility;
    out[i].presence = src[i].presence;
  }
}

void convert_frame(const avm_frame& f, am::landmark_frame& out) {
  out.clear();
  out.t = f.t;
  using fp = am::frame_part;
  copy_part(out, fp::pose, f.pose, AVM_POSE_LANDMARK_COUNT, out.pose.data());
  copy_part(out, fp::pose_world, f.pose_world, AVM_POSE_LANDMARK_COUNT, out.pose_world.data());
  copy_part(out, fp::left_hand, f.left_hand, AVM_HAND_LANDMARK_COUNT, out.left_hand.data());
  copy_part(out, fp::left_hand_world, f.left_hand_world, AVM_HAND_LANDMARK_COUNT,
            out.left_hand_world.data());
  copy_part(out, fp::right_hand, f.right_hand, AVM_HAND_LANDMARK_COUNT, out.right_hand.data());
  copy_part(out, fp::right_hand_world, f.right_hand_world, AVM_HAND_LANDMARK_COUNT,
            out.right_hand_world.data());
  copy_part(out, fp::face, f.face, f.face != nullptr ? f.face_count : 0, out.face.data());
  out.face_count = f.face != nullptr ? f.face_count : 0;
}

void to_c_pose(const am::proxy_pose& p, avm_pose& out) {
  out.t = p.t;
  out.hips_position[0] = p.hips_position.x;
  out.hips_position[1] = p.hips_position.y;
  out.hips_position[2] = p.hips_position.z;
  for (int b = 0; b < AVM_BONE_COUNT; ++b) {
    am::store_xyzw(p.rotations[b], out.rotations[b]);
    out.confidence[b] = p.confidence[b];
  }
  for (int e = 0; e < AVM_EXPRESSION_COUNT; ++e) out.expressions[e] = p.expressions[e];
}

}  // namespace

extern "C" {

AVATARMAP_C_API void avm_version(int* out_major, int* out_minor, int* out_patch) {
  if (out_major != nullptr) *out_major = AVATARMAP_VERSION_MAJOR;
  if (out_minor != nullptr) *out_minor = AVATARMAP_VERSION_MINOR;
  if (out_patch != nullptr) *out_patch = AVATARMAP_VERSION_PATCH;
}

AVATARMAP_C_API const char* avm_version_string(void) { return AVATARMAP_VERSION_STRING; }

AVATARMAP_C_API const char* avm_status_string(avm_status status) {
  // A C caller may pass any int: read it as one (an out-of-range value is not an avm_status in
  // C++, and switching on it would be undefined).
  int value = 0;
  static_assert(sizeof value == sizeof status, "avm_status is an int");
  std::memcpy(&value, &status, sizeof value);
  switch (value) {
    case AVM_OK:
      return "ok";
    case AVM_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case AVM_ERROR_IO:
      return "input/output error";
    case AVM_ERROR_PARSE:
      return "parse error";
    case AVM_ERROR_END_OF_FILE:
      return "end of file";
    case AVM_ERROR_UNSUPPORTED:
      return "unsupported";
    case AVM_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case AVM_ERROR_INTERNAL:
      return "internal error";
  }
  return "unknown status";
}

AVATARMAP_C_API const char* avm_bone_name(int bone) {
  if (bone < 0 || bone >= AVM_BONE_COUNT) return nullptr;
  // The names are string_views over string literals: NUL-terminated.
  return am::bone_name(static_cast<am::bone>(bone)).data();
}

AVATARMAP_C_API int avm_bone_parent(int bone) {
  if (bone < 0 || bone >= AVM_BONE_COUNT) return -1;
  return am::bone_parent(bone);
}

AVATARMAP_C_API int avm_bone_from_name(const char* name) {
  if (name == nullptr) return -1;
  auto b = am::bone_from_name(std::string_view(name));
  return b ? am::idx(*b) : -1;
}

AVATARMAP_C_API const char* avm_expression_name(int expression) {
  if (expression < 0 || expression >= AVM_EXPRESSION_COUNT) return nullptr;
  return am::expression_name(static_cast<am::expression>(expression)).data();
}

AVATARMAP_C_API int avm_expression_from_name(const char* name) {
  if (name == nullptr) return -1;
  auto e = am::expression_from_name(std::string_view(name));
  return e ? am::idx(*e) : -1;
}

AVATARMAP_C_API avm_status avm_solver_options_init(avm_solver_options* options) {
  if (options == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_solver_options_init", silently, [&]() -> avm_status {
    *options = default_options();
    return AVM_OK;
  });
}

AVATARMAP_C_API const char* avm_last_create_error(void) { return t_create_error; }

AVATARMAP_C_API avm_status avm_solver_create(const avm_solver_options* options,
                                             avm_solver** out_solver) {
  set_create_error("");
  if (out_solver == nullptr) {
    set_create_error("avm_solver_create: out_solver is NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  *out_solver = nullptr;
  return guard("avm_solver_create", to_create_error, [&]() -> avm_status {
    core_options o;
    std::string msg;
    if (!read_options(options, o, msg)) {
      set_create_error(msg.c_str());
      return AVM_ERROR_INVALID_ARGUMENT;
    }
    auto* s = new avm_solver(o.solver, o.filter, o.resampler);
    s->channels = o.channels;
    s->latest.set_rest();
    s->last_error.reserve(128);
    *out_solver = s;
    return AVM_OK;
  });
}

AVATARMAP_C_API void avm_solver_destroy(avm_solver* solver) { delete solver; }

AVATARMAP_C_API avm_status avm_solver_reset(avm_solver* solver) {
  if (solver == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  solver->last_error.clear();
  return guard("avm_solver_reset", to_handle(solver), [&]() -> avm_status {
    solver->solver.reset();
    solver->filter.reset();
    solver->resampler.reset();
    solver->latest.set_rest();
    solver->latest.t = 0.0;
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_solver_push(avm_solver* solver, const avm_frame* frame) {
  if (solver == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  solver->last_error.clear();
  if (frame == nullptr)
    return fail(solver, AVM_ERROR_INVALID_ARGUMENT, "avm_solver_push: frame is NULL");
  if (const char* bad = check_frame(*frame)) return fail(solver, AVM_ERROR_INVALID_ARGUMENT, bad);
  return guard("avm_solver_push", to_handle(solver), [&]() -> avm_status {
    convert_frame(*frame, solver->frame);
    solver->solver.solve(solver->frame, solver->raw);
    am::filter_pose_channels(solver->filter, solver->channels, solver->raw, solver->latest);
    solver->latest.t = frame->t;
    if (!solver->resampler.push(solver->latest))
      return fail(solver, AVM_ERROR_INTERNAL, "avm_solver_push: the resampler refused the pose");
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_solver_get_pose(const avm_solver* solver, avm_pose* out_pose) {
  if (solver == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  solver->last_error.clear();
  if (out_pose == nullptr)
    return fail(solver, AVM_ERROR_INVALID_ARGUMENT, "avm_solver_get_pose: out_pose is NULL");
  to_c_pose(solver->latest, *out_pose);
  return AVM_OK;
}

AVATARMAP_C_API avm_status avm_solver_sample(avm_solver* solver, double t, avm_pose* out_pose) {
  if (solver == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  solver->last_error.clear();
  if (out_pose == nullptr)
    return fail(solver, AVM_ERROR_INVALID_ARGUMENT, "avm_solver_sample: out_pose is NULL");
  if (!std::isfinite(t))
    return fail(solver, AVM_ERROR_INVALID_ARGUMENT, "avm_solver_sample: t must be finite");
  return guard("avm_solver_sample", to_handle(solver), [&]() -> avm_status {
    if (!solver->resampler.sample(t, solver->sampled)) {
      solver->sampled.set_rest();  // nothing pushed yet
      solver->sampled.t = t;
    }
    to_c_pose(solver->sampled, *out_pose);
    return AVM_OK;
  });
}

AVATARMAP_C_API const char* avm_solver_last_error(const avm_solver* solver) {
  if (solver == nullptr) return "";
  return solver->last_error.c_str();
}

AVATARMAP_C_API avm_status avm_solve_file(const char* in_landmarks, const char* out_pose,
                                          const avm_solver_options* options, char* err,
                                          size_t err_size) {
  copy_message(err, err_size, "");
  set_create_error("");
  auto report = [&](avm_status code, const char* msg) {
    copy_message(err, err_size, msg);
    return code;
  };
  if (in_landmarks == nullptr || out_pose == nullptr)
    return report(AVM_ERROR_INVALID_ARGUMENT, "avm_solve_file: a path is NULL");
  return guard("avm_solve_file", report, [&]() -> avm_status {
    core_options o;
    std::string msg;
    if (!read_options(options, o, msg)) {
      set_create_error(msg.c_str());
      return report(AVM_ERROR_INVALID_ARGUMENT, msg.c_str());
    }
    // The library's solve-file job (the CLI's `solve` runs it too), on this thread.
    am::solve_file_job job;
    job.input = in_landmarks;
    job.output = out_pose;
    job.options = o.solver;
    // Non-zero options.image_width/height win over the file's header (0 = the header's).
    job.image_width = o.solver.image_width;
    job.image_height = o.solver.image_height;
    job.filter_mode = o.file_filter;
    job.offline.strength = o.file_smoothing;
    job.filter = o.filter;
    job.filter_channels = o.channels;
    job.threads = 1;
    am::solve_file_summary summary;
    const am::status st = job.run(summary);
    if (!st) return report(code_for(st, job_code(summary.failure)), st.message().c_str());
    return AVM_OK;
  });
}

}  // extern "C"

// ---- mapping tables ----------------------------------------------------------------------

namespace {

// The folder given to avm_set_mappings_folder(); function-local statics so that a call made
// during another translation unit's static initialisation still finds them constructed.
std::mutex& mappings_mutex() {
  static std::mutex m;
  return m;
}
std::string& mappings_folder_slot() {
  static std::string folder;
  return folder;
}

// $AVATARMAP_MAPPINGS when set and not empty, else the folder given to
// avm_set_mappings_folder() ("" when none).
std::string current_mappings_folder() {
  if (const char* env = std::getenv("AVATARMAP_MAPPINGS"); env != nullptr && *env != '\0')
    return env;
  std::lock_guard<std::mutex> lock(mappings_mutex());
  return mappings_folder_slot();
}

avm_status binding_status(am::rig_binding_failure f) {
  switch (f) {
    case am::rig_binding_failure::io:
      return AVM_ERROR_IO;
    case am::rig_binding_failure::unknown_name:
      return AVM_ERROR_INVALID_ARGUMENT;
    case am::rig_binding_failure::bad_table:
    case am::rig_binding_failure::no_fit:
      return AVM_ERROR_PARSE;
    case am::rig_binding_failure::none:
      break;
  }
  return AVM_ERROR_INTERNAL;
}

bool file_readable(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return false;
  std::fclose(f);
  return true;
}

// Loads the avatar at `avatar_path` into `out_rig` and binds it as `mapping` says (NULL =
// "auto"). On failure returns the status and sets `msg` (naming the file).
avm_status load_bound_avatar(const char* avatar_path, const char* mapping, am::rig& out_rig,
                             am::rig_binding_choice& out_choice, std::string& msg) {
  am::raw_rig raw;
  am::status st = am::load_avatar(avatar_path, raw);
  if (!st.ok()) {
    msg = st.message();
    return file_readable(avatar_path) ? AVM_ERROR_PARSE : AVM_ERROR_IO;
  }
  st = am::build_rig(raw, out_rig);
  if (!st.ok()) {
    msg = st.message();
    return AVM_ERROR_PARSE;
  }
  const std::string option = mapping != nullptr ? mapping : "auto";
  const std::string folder = current_mappings_folder();
  st = am::select_binding(out_rig, option, folder, out_choice);
  if (!st.ok()) {
    msg = st.message();
    if (out_choice.failure == am::rig_binding_failure::io && folder.empty())
      msg = std::string(avatar_path) + ": mapping '" + option +
            "' needs the mapping tables: no mappings folder is set (set AVATARMAP_MAPPINGS or "
            "call avm_set_mappings_folder())";
    return binding_status(out_choice.failure);
  }
  return AVM_OK;
}

}  // namespace

AVATARMAP_C_API avm_status avm_set_mappings_folder(const char* folder) {
  return guard("avm_set_mappings_folder", silently, [&]() -> avm_status {
    std::string copy = folder != nullptr ? folder : "";
    std::lock_guard<std::mutex> lock(mappings_mutex());
    mappings_folder_slot().swap(copy);
    return AVM_OK;
  });
}

// ---- retargeting ------------------------------------------------------------------------

struct avm_retargeter {
  am::rig rig;
  am::rig_binding_choice choice;  // how the joints were bound (description, table)
  am::retargeter retargeter;
  am::rig_pose pose;     // scratch: the applied pose
  am::proxy_pose proxy;  // scratch: the C pose converted
  mutable std::string last_error;
};

namespace {
void set_error(const avm_retargeter* r, const char* msg) noexcept {
  if (r == nullptr) return;
  try {
    r->last_error.assign(msg);
  } catch (...) {
    r->last_error.clear();
  }
}
}  // namespace

AVATARMAP_C_API avm_status avm_retargeter_create(const char* avatar_path, const char* mapping,
                                                 avm_retargeter** out) {
  if (out != nullptr) *out = nullptr;
  if (avatar_path == nullptr || out == nullptr) {
    set_create_error("avm_retargeter_create: avatar_path and out must not be NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  return guard("avm_retargeter_create", to_create_error, [&]() -> avm_status {
    std::unique_ptr<avm_retargeter> r(new avm_retargeter());
    std::string msg;
    const avm_status code = load_bound_avatar(avatar_path, mapping, r->rig, r->choice, msg);
    if (code != AVM_OK) {
      set_create_error(msg.c_str());
      return code;
    }
    am::status st = r->retargeter.build(r->rig, r->choice.binding, am::retarget_options{},
                                        r->choice.table_or_null());
    if (!st.ok()) {
      set_create_error(st.message().c_str());
      return AVM_ERROR_PARSE;
    }
    r->retargeter.prepare(r->pose);
    set_create_error("");
    *out = r.release();
    return AVM_OK;
  });
}

AVATARMAP_C_API void avm_retargeter_destroy(avm_retargeter* retargeter) { delete retargeter; }

AVATARMAP_C_API int avm_retargeter_joint_count(const avm_retargeter* retargeter) {
  return retargeter == nullptr ? 0 : retargeter->rig.joint_count();
}

AVATARMAP_C_API const char* avm_retargeter_joint_name(const avm_retargeter* retargeter, int joint) {
  if (retargeter == nullptr || joint < 0 || joint >= retargeter->rig.joint_count()) return nullptr;
  return retargeter->rig.names[static_cast<std::size_t>(joint)].c_str();
}

AVATARMAP_C_API int avm_retargeter_joint_parent(const avm_retargeter* retargeter, int joint) {
  if (retargeter == nullptr || joint < 0 || joint >= retargeter->rig.joint_count()) return -1;
  return retargeter->rig.parents[static_cast<std::size_t>(joint)];
}

AVATARMAP_C_API int avm_retargeter_bone_joint(const avm_retargeter* retargeter, int bone) {
  if (retargeter == nullptr || bone < 0 || bone >= am::k_bone_count) return -1;
  return retargeter->retargeter.binding()[static_cast<std::size_t>(bone)];
}

AVATARMAP_C_API const char* avm_retargeter_binding_description(const avm_retargeter* retargeter) {
  return retargeter == nullptr ? "" : retargeter->choice.description.c_str();
}

AVATARMAP_C_API avm_status avm_retargeter_apply(avm_retargeter* retargeter, const avm_pose* pose,
                                                float* out_rotations, float* out_hips_translation) {
  if (retargeter == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  if (pose == nullptr || out_rotations == nullptr) {
    set_error(retargeter, "pose and out_rotations must not be NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  return guard("avm_retargeter_apply", to_handle(retargeter), [&]() -> avm_status {
    am::proxy_pose& p = retargeter->proxy;
    p.t = pose->t;
    for (int i = 0; i < 3; ++i)
      p.hips_position[i] = std::isfinite(pose->hips_position[i]) ? pose->hips_position[i] : 0.f;
    for (int b = 0; b < am::k_bone_count; ++b) {
      glm::quat q = am::load_xyzw(pose->rotations[b]);
      const float n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
      p.rotations[static_cast<std::size_t>(b)] =
          (n2 > 1e-12f && std::isfinite(n2)) ? q * (1.f / std::sqrt(n2)) : am::identity_quat();
    }
    retargeter->retargeter.apply(p, retargeter->pose);
    const int n = retargeter->rig.joint_count();
    for (int j = 0; j < n; ++j)
      am::store_xyzw(retargeter->pose.local_rotations[static_cast<std::size_t>(j)],
                     out_rotations + 4 * j);
    if (out_hips_translation != nullptr) {
      out_hips_translation[0] = retargeter->pose.hips_translation.x;
      out_hips_translation[1] = retargeter->pose.hips_translation.y;
      out_hips_translation[2] = retargeter->pose.hips_translation.z;
    }
    retargeter->last_error.clear();
    return AVM_OK;
  });
}

AVATARMAP_C_API const char* avm_retargeter_last_error(const avm_retargeter* retargeter) {
  return retargeter == nullptr ? "" : retargeter->last_error.c_str();
}

// ---- clips ------------------------------------------------------------------------------

struct avm_clip {
  std::vector<am::proxy_pose> frames;
  mutable std::string last_error;
};

namespace {

void set_error(const avm_clip* c, const char* msg) noexcept {
  if (c == nullptr) return;
  try {
    c->last_error.assign(msg);
  } catch (...) {
    c->last_error.clear();
  }
}

float clamp01(float v) { return v < 0.f ? 0.f : (v > 1.f ? 1.f : v); }

// The C pose as a proxy pose, non-finite values taken as missing (see avm_clip_add).
void sanitized_pose(const avm_pose& in, const am::proxy_pose* prev, am::proxy_pose& out) {
  out.set_rest();
  out.t = in.t;
  for (int i = 0; i < 3; ++i) {
    const float v = in.hips_position[i];
    out.hips_position[i] =
        std::isfinite(v) ? v : (prev != nullptr ? prev->hips_position[i] : out.hips_position[i]);
  }
  for (int b = 0; b < am::k_bone_count; ++b) {
    const auto bi = static_cast<std::size_t>(b);
    const glm::quat q = am::load_xyzw(in.rotations[b]);
    const float n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
    const bool good = std::isfinite(n2) && n2 > 1e-12f;
    if (good) {
      out.rotations[bi] = q * (1.f / std::sqrt(n2));
      const float c = in.confidence[b];
      out.confidence[bi] = std::isfinite(c) ? clamp01(c) : 0.f;
    } else {
      out.rotations[bi] = prev != nullptr ? prev->rotations[bi] : am::identity_quat();
      out.confidence[bi] = 0.f;
    }
  }
  for (int e = 0; e < am::k_expression_count; ++e) {
    const auto ei = static_cast<std::size_t>(e);
    const float w = in.expressions[e];
    out.expressions[ei] =
        std::isfinite(w) ? clamp01(w) : (prev != nullptr ? prev->expressions[ei] : 0.f);
  }
}

// Writes `frames` to `path` with the library's clip-output job (the CLI's `convert` runs it
// too): the job's checks first, then the avatar (loaded and bound only when the format uses
// it), then the write. On failure returns the status and sets `msg`.
avm_status write_clip(const std::vector<am::proxy_pose>& frames, const std::string& path,
                      double fps, const char* avatar_path, const char* mapping, std::string& msg) {
  am::clip_output_job job;
  job.path = path;
  job.frames = &frames;
  job.fps = fps;
  job.avatar_path = avatar_path != nullptr ? avatar_path : "";
  if (am::status st = job.validate(); !st.ok()) {
    msg = st.message();
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  // An avatar with its binding (large: kept on the heap).
  struct bound_avatar {
    am::rig rig;
    am::rig_binding_choice choice;
  };
  std::unique_ptr<bound_avatar> avatar;
  if (avatar_path != nullptr && am::find_clip_format(path)->uses_avatar) {
    avatar = std::make_unique<bound_avatar>();
    const avm_status code =
        load_bound_avatar(avatar_path, mapping, avatar->rig, avatar->choice, msg);
    if (code != AVM_OK) return code;
    job.avatar_rig = &avatar->rig;
    job.avatar_binding = avatar->choice.binding;
    job.avatar_table = avatar->choice.table_or_null();
  }
  am::clip_output_summary summary;
  if (am::status st = job.run(summary); !st.ok()) {
    msg = st.message();
    return code_for(st, job_code(summary.failure));
  }
  return AVM_OK;
}

}  // namespace

AVATARMAP_C_API avm_status avm_clip_create(avm_clip** out) {
  set_create_error("");
  if (out == nullptr) {
    set_create_error("avm_clip_create: out is NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  *out = nullptr;
  return guard("avm_clip_create", to_create_error, [&]() -> avm_status {
    *out = new avm_clip();
    return AVM_OK;
  });
}

AVATARMAP_C_API void avm_clip_destroy(avm_clip* clip) { delete clip; }

AVATARMAP_C_API avm_status avm_clip_add(avm_clip* clip, const avm_pose* pose) {
  if (clip == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  clip->last_error.clear();
  if (pose == nullptr) {
    set_error(clip, "avm_clip_add: pose is NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  if (!std::isfinite(pose->t)) {
    set_error(clip, "avm_clip_add: pose->t must be finite");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  return guard("avm_clip_add", to_handle(clip), [&]() -> avm_status {
    const am::proxy_pose* prev = clip->frames.empty() ? nullptr : &clip->frames.back();
    if (prev != nullptr && !(pose->t > prev->t)) {
      const std::string msg = "avm_clip_add: pose->t (" + std::to_string(pose->t) +
                              ") must be after the previous frame's (" + std::to_string(prev->t) +
                              ")";
      set_error(clip, msg.c_str());
      return AVM_ERROR_INVALID_ARGUMENT;
    }
    am::proxy_pose p;
    sanitized_pose(*pose, prev, p);
    clip->frames.push_back(p);  // may reallocate: `prev` is not used after this
    return AVM_OK;
  });
}

AVATARMAP_C_API int avm_clip_frame_count(const avm_clip* clip) {
  return clip == nullptr ? 0 : static_cast<int>(clip->frames.size());
}

AVATARMAP_C_API avm_status avm_clip_write(avm_clip* clip, const char* path, double fps,
                                          const char* avatar_path, const char* mapping, char* err,
                                          size_t err_size) {
  copy_message(err, err_size, "");
  if (clip != nullptr) clip->last_error.clear();
  auto report = [&](avm_status code, const char* msg) {
    copy_message(err, err_size, msg);
    set_error(clip, msg);
    return code;
  };
  if (clip == nullptr || path == nullptr)
    return report(AVM_ERROR_INVALID_ARGUMENT, "avm_clip_write: clip and path must not be NULL");
  return guard("avm_clip_write", report, [&]() -> avm_status {
    std::string msg;
    const avm_status code = write_clip(clip->frames, path, fps, avatar_path, mapping, msg);
    if (code != AVM_OK) return report(code, msg.c_str());
    return AVM_OK;
  });
}

AVATARMAP_C_API const char* avm_clip_last_error(const avm_clip* clip) {
  return clip == nullptr ? "" : clip->last_error.c_str();
}
