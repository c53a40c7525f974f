// avm_solver_options as the library's options (c_solver_options.hpp).
#include "c_solver_options.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>

#include "avatarmap/core/option_table.hpp"

namespace am = avatarmap;

// The prefix copy in read_options() relies on every field being 4 bytes wide.
static_assert(sizeof(avm_solver_options) % 4 == 0 && alignof(avm_solver_options) == 4,
              "avm_solver_options must hold only 4-byte fields");

namespace avatarmap::c_api {

namespace {

// The fields of avm_solver_options after struct_size, each by its name in the option tables
// (the token is the name: the two cannot drift apart) and whether it is a float (else an
// int32_t). The static_assert below checks that the list covers the whole struct.
struct c_field {
  const char* name;
  std::size_t offset;
  bool is_float;
};
#define AVM_FIELD(f)                                                                              \
  c_field {                                                                                       \
#f, offsetof(avm_solver_options, f), std::is_same_v < decltype(avm_solver_options::f), float> \
  }
constexpr c_field k_fields[] = {
    AVM_FIELD(mirror),
    AVM_FIELD(image_width),
    AVM_FIELD(image_height),
    AVM_FIELD(solve_body),
    AVM_FIELD(solve_hands),
    AVM_FIELD(solve_face),
    AVM_FIELD(solve_hips_translation),
    AVM_FIELD(confidence_lost_below),
    AVM_FIELD(confidence_found_above),
    AVM_FIELD(confidence_hold_seconds),
    AVM_FIELD(confidence_ease_seconds),
    AVM_FIELD(confidence_regain_seconds),
    AVM_FIELD(hips_lean_share),
    AVM_FIELD(forearm_twist_share),
    AVM_FIELD(horizontal_fov_degrees),
    AVM_FIELD(rest_hips_height),
    AVM_FIELD(filter_rotations),
    AVM_FIELD(rotation_min_cutoff),
    AVM_FIELD(rotation_beta),
    AVM_FIELD(rotation_d_cutoff),
    AVM_FIELD(filter_position),
    AVM_FIELD(position_min_cutoff),
    AVM_FIELD(position_beta),
    AVM_FIELD(position_d_cutoff),
    AVM_FIELD(filter_expressions),
    AVM_FIELD(expression_min_cutoff),
    AVM_FIELD(expression_beta),
    AVM_FIELD(expression_d_cutoff),
    AVM_FIELD(max_extrapolation_seconds),
    AVM_FIELD(file_filter),
    AVM_FIELD(file_smoothing),
    AVM_FIELD(file_threads),
    AVM_FIELD(fit_hand_shape),
    AVM_FIELD(fit_body_to_image),
    AVM_FIELD(foot_contacts),
    AVM_FIELD(root_follows_contacts),
    AVM_FIELD(lower_body_rest),
    AVM_FIELD(person),
};
#undef AVM_FIELD
static_assert(sizeof(k_fields) / sizeof(k_fields[0]) * 4 + 4 == sizeof(avm_solver_options),
              "k_fields must list every field of avm_solver_options");

double field_value(const avm_solver_options& o, const c_field& f) {
  const char* p = reinterpret_cast<const char*>(&o) + f.offset;
  if (f.is_float) {
    float v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  std::int32_t v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

void set_field_value(avm_solver_options& o, const c_field& f, double value) {
  char* p = reinterpret_cast<char*>(&o) + f.offset;
  if (f.is_float) {
    const float v = static_cast<float>(value);
    std::memcpy(p, &v, sizeof v);
  } else {
    const std::int32_t v = static_cast<std::int32_t>(value);
    std::memcpy(p, &v, sizeof v);
  }
}

// The library's options the C struct is read into: each C field is a row of one of these
// tables (the solver's, the solve-file job's, the resampler's).
struct library_options {
  am::solver_options solver;
  am::solve_file_job file;
  am::pose_resampler_options resampler;
};

// Calls `visit(row)` with the row named `name`, from whichever table has it; false if none.
template <class Visit>
bool with_row(const char* name, Visit&& visit) {
  if (const auto* r = am::find_option(am::k_solver_option_table, name)) return visit(*r), true;
  if (const auto* r = am::find_option(am::k_solve_file_option_table, name)) return visit(*r), true;
  if (const auto* r = am::find_option(am::k_pose_resampler_option_table, name))
    return visit(*r), true;
  return false;
}

template <class O>
O& part(library_options& l);
template <>
am::solver_options& part(library_options& l) {
  return l.solver;
}
template <>
am::solve_file_job& part(library_options& l) {
  return l.file;
}
template <>
am::pose_resampler_options& part(library_options& l) {
  return l.resampler;
}

}  // namespace

avm_solver_options default_options() {
  avm_solver_options o;
  std::memset(&o, 0, sizeof o);
  o.struct_size = sizeof o;
  for (const c_field& f : k_fields)
    with_row(f.name, [&](const auto& row) { set_field_value(o, f, am::option_default(row)); });
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
  // Each field through its row: the range check and its message come from the table. A C
  // boolean is 0 or non-zero (the header's rule), so booleans are not range-checked.
  library_options lib;
  for (const c_field& f : k_fields) {
    const double v = field_value(o, f);
    bool ok = true;
    with_row(f.name, [&](const auto& row) {
      auto& target = part<typename std::decay_t<decltype(row)>::options_type>(lib);
      if (row.kind == am::option_kind::boolean) {
        row.set(target, v != 0.0 ? 1.0 : 0.0);
      } else if (!am::option_accepts(row, v)) {
        msg = am::option_range_message(row, std::string("avm_solver_options.") + f.name, v);
        ok = false;
      } else {
        row.set(target, v);
      }
    });
    if (!ok) return false;
  }
  // What a single field's range cannot say.
  if (am::status st = lib.solver.validate(); !st) {
    msg = "avm_solver_options: " + st.message();
    return false;
  }
  out.solver = lib.solver;
  out.filter = lib.file.filter;
  out.channels = lib.file.filter_channels;
  out.filter.enabled = out.channels.rotations || out.channels.position || out.channels.expressions;
  out.resampler = lib.resampler;
  out.file_filter = lib.file.filter_mode;
  out.file_smoothing = lib.file.offline.strength;
  out.file_threads = lib.file.threads;
  out.foot_contacts = lib.file.foot_contacts;
  out.person = lib.file.person;
  return true;
}

solve_file_job file_job(const core_options& o) {
  solve_file_job job;
  job.options = o.solver;
  // Non-zero options.image_width/height win over the file's header (0 = the header's).
  job.image_width = o.solver.image_width;
  job.image_height = o.solver.image_height;
  job.filter_mode = o.file_filter;
  job.offline.strength = o.file_smoothing;
  job.filter = o.filter;
  job.filter_channels = o.channels;
  job.threads = o.file_threads;
  job.foot_contacts = o.foot_contacts;
  job.person = o.person;
  return job;
}

}  // namespace avatarmap::c_api
