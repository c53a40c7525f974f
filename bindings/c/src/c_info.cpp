// The C API's library-wide functions: version, status strings, bone, expression and blendshape
// names, the create error, the shipped folders (bindings/c/include/avatarmap/avatarmap.h).
#include <cstring>
#include <string>
#include <string_view>

#include "avatarmap/avatarmap.h"
#include "avatarmap/core/limits.hpp"
#include "avatarmap/io/resources.hpp"
#include "avatarmap/landmarks/landmark_frame.hpp"
#include "avatarmap/skeleton/blendshape.hpp"
#include "avatarmap/skeleton/bone.hpp"
#include "avatarmap/skeleton/expression.hpp"
#include "avatarmap/version.hpp"
#include "c_avatar.hpp"
#include "c_guard.hpp"

namespace am = avatarmap;
using namespace avatarmap::c_api;

static_assert(AVM_VERSION_MAJOR == AVATARMAP_VERSION_MAJOR &&
                  AVM_VERSION_MINOR == AVATARMAP_VERSION_MINOR &&
                  AVM_VERSION_PATCH == AVATARMAP_VERSION_PATCH,
              "avatarmap.h and avatarmap/version.hpp disagree on the version");
static_assert(AVM_MAX_FPS == am::k_max_fps, "AVM_MAX_FPS must be core/limits.hpp's k_max_fps");
static_assert(AVM_MAX_MODEL_THREADS == am::k_max_model_threads,
              "AVM_MAX_MODEL_THREADS must be core/limits.hpp's k_max_model_threads");
static_assert(AVM_BONE_COUNT == am::k_bone_count, "bone count");
static_assert(AVM_EXPRESSION_COUNT == am::k_expression_count, "expression count");
static_assert(AVM_BLENDSHAPE_COUNT == am::k_blendshape_count, "blendshape count");
static_assert(AVM_POSE_LANDMARK_COUNT == am::k_pose_landmark_count, "pose landmark count");
static_assert(AVM_HAND_LANDMARK_COUNT == am::k_hand_landmark_count, "hand landmark count");
static_assert(AVM_FACE_LANDMARK_COUNT == am::k_face_mesh_count, "face landmark count");
static_assert(AVM_FACE_IRIS_LANDMARK_COUNT == am::k_face_mesh_iris_count, "face+iris count");
static_assert(AVM_RESOURCE_MAPPINGS == static_cast<int>(am::resource::mappings) &&
                  AVM_RESOURCE_MODELS == static_cast<int>(am::resource::models) &&
                  AVM_RESOURCE_VIEWER_PAGE == static_cast<int>(am::resource::viewer_page) &&
                  AVM_RESOURCE_VIEWER_MODULES == static_cast<int>(am::resource::viewer_modules),
              "avm_resource must follow avatarmap::resource");
static_assert(AVM_BONE_RIGHT_LITTLE_DISTAL == am::idx(am::bone::right_little_distal) &&
                  AVM_BONE_LEFT_HAND == am::idx(am::bone::left_hand) &&
                  AVM_BONE_RIGHT_TOES == am::idx(am::bone::right_toes) &&
                  AVM_BONE_JAW == am::idx(am::bone::jaw),
              "avm_bone must follow avatarmap::bone");
static_assert(AVM_EXPRESSION_BROW_DOWN_RIGHT == am::idx(am::expression::brow_down_right) &&
                  AVM_EXPRESSION_LOOK_UP == am::idx(am::expression::look_up) &&
                  AVM_EXPRESSION_HAPPY == am::idx(am::expression::happy) &&
                  AVM_EXPRESSION_SURPRISED == am::idx(am::expression::surprised) &&
                  AVM_EXPRESSION_SURPRISED + 1 == AVM_EXPRESSION_COUNT,
              "avm_expression must follow avatarmap::expression");
static_assert(AVM_BLENDSHAPE_BROW_DOWN_LEFT == am::idx(am::blendshape::brow_down_left) &&
                  AVM_BLENDSHAPE_EYE_BLINK_LEFT == am::idx(am::blendshape::eye_blink_left) &&
                  AVM_BLENDSHAPE_JAW_OPEN == am::idx(am::blendshape::jaw_open) &&
                  AVM_BLENDSHAPE_MOUTH_SMILE_RIGHT == am::idx(am::blendshape::mouth_smile_right) &&
                  AVM_BLENDSHAPE_TONGUE_OUT == am::idx(am::blendshape::tongue_out) &&
                  AVM_BLENDSHAPE_TONGUE_OUT + 1 == AVM_BLENDSHAPE_COUNT,
              "avm_blendshape must follow avatarmap::blendshape");

namespace {
// `value` is the caller's avm_status read as an int: a C caller may pass any int, and an
// out-of-range value is not an avm_status in C++ (loading or switching on it would be
// undefined).
const char* status_text(int value) noexcept {
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

}  // namespace

extern "C" {

AVATARMAP_C_API void avm_version(int* out_major, int* out_minor, int* out_patch) {
  guard_value(0, [&] {
    if (out_major != nullptr) *out_major = AVATARMAP_VERSION_MAJOR;
    if (out_minor != nullptr) *out_minor = AVATARMAP_VERSION_MINOR;
    if (out_patch != nullptr) *out_patch = AVATARMAP_VERSION_PATCH;
    return 0;
  });
}

AVATARMAP_C_API const char* avm_version_string(void) {
  return guard_value<const char*>("", [] { return AVATARMAP_VERSION_STRING; });
}

AVATARMAP_C_API const char* avm_status_string(avm_status status) {
  int value = 0;
  static_assert(sizeof value == sizeof status, "avm_status is an int");
  std::memcpy(&value, &status, sizeof value);  // never loaded as an avm_status
  return guard_value<const char*>("unknown status", [value] { return status_text(value); });
}

AVATARMAP_C_API const char* avm_last_create_error(void) {
  return guard_value<const char*>("", [] { return create_error(); });
}

AVATARMAP_C_API const char* avm_bone_name(int bone) {
  return guard_value<const char*>(nullptr, [&]() -> const char* {
    if (bone < 0 || bone >= AVM_BONE_COUNT) return nullptr;
    // The names are string_views over string literals: NUL-terminated.
    return am::bone_name(static_cast<am::bone>(bone)).data();
  });
}

AVATARMAP_C_API int avm_bone_parent(int bone) {
  return guard_value(
      -1, [&] { return bone < 0 || bone >= AVM_BONE_COUNT ? -1 : am::bone_parent(bone); });
}

AVATARMAP_C_API int avm_bone_from_name(const char* name) {
  return guard_value(-1, [&] {
    if (name == nullptr) return -1;
    auto b = am::bone_from_name(std::string_view(name));
    return b ? am::idx(*b) : -1;
  });
}

AVATARMAP_C_API const char* avm_expression_name(int expression) {
  return guard_value<const char*>(nullptr, [&]() -> const char* {
    if (expression < 0 || expression >= AVM_EXPRESSION_COUNT) return nullptr;
    return am::expression_name(static_cast<am::expression>(expression)).data();
  });
}

AVATARMAP_C_API int avm_expression_from_name(const char* name) {
  return guard_value(-1, [&] {
    if (name == nullptr) return -1;
    auto e = am::expression_from_name(std::string_view(name));
    return e ? am::idx(*e) : -1;
  });
}

AVATARMAP_C_API const char* avm_blendshape_name(int blendshape) {
  return guard_value<const char*>(nullptr, [&]() -> const char* {
    if (blendshape < 0 || blendshape >= AVM_BLENDSHAPE_COUNT) return nullptr;
    return am::blendshape_name(static_cast<am::blendshape>(blendshape)).data();
  });
}

AVATARMAP_C_API int avm_blendshape_from_name(const char* name) {
  return guard_value(-1, [&] {
    if (name == nullptr) return -1;
    auto s = am::blendshape_from_name(std::string_view(name));
    return s ? am::idx(*s) : -1;
  });
}

AVATARMAP_C_API avm_status avm_find_resource(int kind, const char* explicit_folder,
                                             char* out_folder, size_t folder_size, char* out_rule,
                                             size_t rule_size, char* err, size_t err_size) {
  copy_message(err, err_size, "");
  copy_message(out_folder, folder_size, "");
  copy_message(out_rule, rule_size, "");
  auto report = [&](avm_status code, const char* msg) {
    copy_message(err, err_size, msg);
    return code;
  };
  return guard("avm_find_resource", report, [&]() -> avm_status {
    if (kind < AVM_RESOURCE_MAPPINGS || kind > AVM_RESOURCE_VIEWER_MODULES)
      return report(AVM_ERROR_INVALID_ARGUMENT, ("avm_find_resource: kind " + std::to_string(kind) +
                                                 " is not an avm_resource (0 .. 3)")
                                                    .c_str());
    const auto which = static_cast<am::resource>(kind);
    std::string given = explicit_folder != nullptr ? explicit_folder : "";
    if (explicit_folder == nullptr && which == am::resource::mappings)
      given = given_mappings_folder();
    const am::resource_lookup found = am::find_resource(which, given);
    if (found.folder.empty()) {
      std::string msg = std::string("avm_find_resource: no ") + am::resource_name(which) +
                        " folder found; looked in:";
      for (const std::string& t : found.tried) msg += " " + t + ";";
      return report(AVM_ERROR_IO, msg.c_str());
    }
    // A NULL buffer of size 0 is not wanted; any other must hold the whole text.
    auto fits = [&](const std::string& text, const char* buffer, size_t size, const char* what) {
      if ((buffer == nullptr && size == 0) || text.size() < size) return true;
      report(AVM_ERROR_INVALID_ARGUMENT,
             ("avm_find_resource: " + std::string(what) + " needs " +
              std::to_string(text.size() + 1) + " bytes, got " + std::to_string(size))
                 .c_str());
      return false;
    };
    if (!fits(found.folder, out_folder, folder_size, "out_folder") ||
        !fits(found.source, out_rule, rule_size, "out_rule"))
      return AVM_ERROR_INVALID_ARGUMENT;
    copy_message(out_folder, folder_size, found.folder.c_str());
    copy_message(out_rule, rule_size, found.source.c_str());
    return AVM_OK;
  });
}

}  // extern "C"
