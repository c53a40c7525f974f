// The C API's retargeter handle (avm_retargeter_*): an avatar loaded and bound once, then
// proxy poses applied to its joints.
#include <cmath>
#include <cstddef>
#include <memory>
#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/rig/retarget.hpp"
#include "avatarmap/rig/rig.hpp"
#include "avatarmap/rig/rig_binding.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "c_avatar.hpp"
#include "c_guard.hpp"

namespace am = avatarmap;
using namespace avatarmap::c_api;

struct avm_retargeter : avatarmap::c_api::error_slot {
  am::rig rig;
  am::rig_binding_choice choice;  // how the joints were bound (description, table)
  am::retargeter retargeter;
  am::rig_pose pose;     // scratch: the applied pose
  am::proxy_pose proxy;  // scratch: the C pose converted
};

namespace {

// avm_retargeter_apply's work for one pose, into the handle's scratch; allocates nothing.
void apply_one(avm_retargeter& r, const avm_pose& pose, float* out_rotations,
               float* out_hips_translation) {
  am::proxy_pose& p = r.proxy;
  p.t = pose.t;
  for (int i = 0; i < 3; ++i)
    p.hips_position[i] = std::isfinite(pose.hips_position[i]) ? pose.hips_position[i] : 0.f;
  for (int b = 0; b < am::k_bone_count; ++b) {
    glm::quat q = am::load_xyzw(pose.rotations[b]);
    const float n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
    p.rotations[static_cast<std::size_t>(b)] =
        (n2 > 1e-12f && std::isfinite(n2)) ? q * (1.f / std::sqrt(n2)) : am::identity_quat();
  }
  r.retargeter.apply(p, r.pose);
  const int n = r.rig.joint_count();
  for (int j = 0; j < n; ++j)
    am::store_xyzw(r.pose.local_rotations[static_cast<std::size_t>(j)], out_rotations + 4 * j);
  if (out_hips_translation != nullptr) {
    out_hips_translation[0] = r.pose.hips_translation.x;
    out_hips_translation[1] = r.pose.hips_translation.y;
    out_hips_translation[2] = r.pose.hips_translation.z;
  }
}

}  // namespace

extern "C" {

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
      return avm_code(st);  // parse: the binding does not fit the rig
    }
    r->retargeter.prepare(r->pose);
    set_create_error("");
    *out = r.release();
    return AVM_OK;
  });
}

AVATARMAP_C_API void avm_retargeter_destroy(avm_retargeter* retargeter) {
  guard_value(0, [&] {
    delete retargeter;
    return 0;
  });
}

AVATARMAP_C_API int avm_retargeter_joint_count(const avm_retargeter* retargeter) {
  return guard_value(0, [&] { return retargeter == nullptr ? 0 : retargeter->rig.joint_count(); });
}

AVATARMAP_C_API const char* avm_retargeter_joint_name(const avm_retargeter* retargeter, int joint) {
  return guard_value<const char*>(nullptr, [&]() -> const char* {
    if (retargeter == nullptr || joint < 0 || joint >= retargeter->rig.joint_count())
      return nullptr;
    return retargeter->rig.names[static_cast<std::size_t>(joint)].c_str();
  });
}

AVATARMAP_C_API int avm_retargeter_joint_parent(const avm_retargeter* retargeter, int joint) {
  return guard_value(-1, [&] {
    if (retargeter == nullptr || joint < 0 || joint >= retargeter->rig.joint_count()) return -1;
    return retargeter->rig.parents[static_cast<std::size_t>(joint)];
  });
}

AVATARMAP_C_API int avm_retargeter_bone_joint(const avm_retargeter* retargeter, int bone) {
  return guard_value(-1, [&] {
    if (retargeter == nullptr || bone < 0 || bone >= am::k_bone_count) return -1;
    return retargeter->retargeter.binding()[static_cast<std::size_t>(bone)];
  });
}

AVATARMAP_C_API const char* avm_retargeter_binding_description(const avm_retargeter* retargeter) {
  return guard_value<const char*>(
      "", [&] { return retargeter == nullptr ? "" : retargeter->choice.description.c_str(); });
}

AVATARMAP_C_API avm_status avm_retargeter_apply(avm_retargeter* retargeter, const avm_pose* pose,
                                                float* out_rotations, float* out_hips_translation) {
  if (retargeter == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  if (pose == nullptr || out_rotations == nullptr) {
    set_error(retargeter, "pose and out_rotations must not be NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  return guard("avm_retargeter_apply", to_handle(retargeter), [&]() -> avm_status {
    apply_one(*retargeter, *pose, out_rotations, out_hips_translation);
    retargeter->last_error.clear();
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_retargeter_apply_poses(avm_retargeter* r, const avm_pose* poses,
                                                      int64_t count, float* out_rotations,
                                                      float* out_hips_translation) {
  if (r == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  if (count < 0) {
    set_error(r, "avm_retargeter_apply_poses: count < 0");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  if (count > 0 && (poses == nullptr || out_rotations == nullptr)) {
    set_error(r, "avm_retargeter_apply_poses: poses and out_rotations must not be NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  return guard("avm_retargeter_apply_poses", to_handle(r), [&]() -> avm_status {
    const auto floats = static_cast<std::ptrdiff_t>(4) * r->rig.joint_count();
    for (int64_t i = 0; i < count; ++i)
      apply_one(*r, poses[i], out_rotations + static_cast<std::ptrdiff_t>(i) * floats,
                out_hips_translation != nullptr
                    ? out_hips_translation + static_cast<std::ptrdiff_t>(i) * 3
                    : nullptr);
    r->last_error.clear();
    return AVM_OK;
  });
}

AVATARMAP_C_API const char* avm_retargeter_last_error(const avm_retargeter* retargeter) {
  return guard_value<const char*>(
      "", [&] { return retargeter == nullptr ? "" : retargeter->last_error.c_str(); });
}

}  // extern "C"
