// avm_solver_options as the library's options (c_solver_options.hpp).
#include "c_solver_options.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "avatarmap/time/offline_smoother.hpp"

namespace am = avatarmap;

// The prefix copy in read_options() relies on every field being 4 bytes wide.
static_assert(sizeof(avm_solver_options) % 4 == 0 && alignof(avm_solver_options) == 4,
              "avm_solver_options must hold only 4-byte fields");

namespace avatarmap::c_api {

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
  o.file_threads = 2;
  o.fit_hand_shape = s.fit_hand_shape ? 1 : 0;
  return o;
}

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
  s.fit_hand_shape = o.fit_hand_shape != 0;
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
  if (o.file_threads != 1 && o.file_threads != 2) {
    msg = "avm_solver_options.file_threads is " + std::to_string(o.file_threads) +
          ": use 1 (the calling thread only) or 2 (parse ahead on a second thread; default)";
    return false;
  }
  out.file_threads = o.file_threads;
  return true;
}

}  // namespace avatarmap::c_api
