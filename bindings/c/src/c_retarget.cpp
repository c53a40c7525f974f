// The C API's retargeter handle (avm_retargeter_*): an avatar loaded and bound once, then
// proxy poses applied to its joints.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>

#include "avatarmap/avatarmap.h"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/rig/foot_lock.hpp"
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
  am::foot_lock lock;         // anchors kept across apply calls (off when options said so)
  double last_t = -HUGE_VAL;  // the previous applied pose's time (foot locking's clip start)
  am::rig_pose pose;          // scratch: the applied pose
  am::proxy_pose proxy;       // scratch: the C pose converted
};

namespace {

// Larger than any plausible future avm_retargeter_options: a bigger struct_size is taken as an
// uninitialised struct rather than a newer caller.
constexpr std::uint32_t k_max_struct_size = 4096;
constexpr std::size_t k_min_struct_size = 8;  // struct_size and foot_lock

avm_retargeter_options default_retargeter_options() {
  avm_retargeter_options o;
  std::memset(&o, 0, sizeof o);
  o.struct_size = sizeof o;
  const am::foot_lock_options f;
  o.foot_lock = f.enabled ? 1 : 0;
  o.foot_lock_align_foot = f.align_foot ? 1 : 0;
  o.foot_lock_lower_hips = f.lower_hips ? 1 : 0;
  o.foot_lock_keep_above_floor = f.keep_above_floor ? 1 : 0;
  return o;
}

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
  for (int s = 0; s < 2; ++s)
    p.foot_contact[s] =
        std::isfinite(pose.foot_contact[s]) ? std::clamp(pose.foot_contact[s], 0.f, 1.f) : 0.f;
  r.retargeter.apply(p, r.pose);
  // Foot locking needs the frames in time order: a pose that is not later than the previous
  // one starts a new clip (the anchors are forgotten), so re-applying a clip from its start
  // gives the same rig poses again.
  if (!(p.t > r.last_t)) r.lock.reset();
  r.last_t = std::isfinite(p.t) ? p.t : -HUGE_VAL;
  r.lock.apply(p.foot_contact, r.pose);  // a no-op when foot locking is off
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
  return avm_retargeter_create_with_options(avatar_path, mapping, nullptr, out);
}

// (The name in parentheses: the header also defines avm_retargeter_options_init as a macro.)
AVATARMAP_C_API avm_status(avm_retargeter_options_init)(avm_retargeter_options* options) {
  return avm_retargeter_options_init_sized(options, sizeof(avm_retargeter_options));
}

AVATARMAP_C_API avm_status avm_retargeter_options_init_sized(avm_retargeter_options* options,
                                                             size_t size) {
  if (options == nullptr || size < k_min_struct_size || size > k_max_struct_size || size % 4 != 0)
    return AVM_ERROR_INVALID_ARGUMENT;
  return guard("avm_retargeter_options_init_sized", silently, [&]() -> avm_status {
    const avm_retargeter_options d = default_retargeter_options();
    std::memcpy(options, &d, std::min(size, sizeof d));
    options->struct_size = static_cast<std::uint32_t>(size);
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_retargeter_create_with_options(const char* avatar_path,
                                                              const char* mapping,
                                                              const avm_retargeter_options* options,
                                                              avm_retargeter** out) {
  if (out != nullptr) *out = nullptr;
  if (avatar_path == nullptr || out == nullptr) {
    set_create_error("avm_retargeter_create: avatar_path and out must not be NULL");
    return AVM_ERROR_INVALID_ARGUMENT;
  }
  avm_retargeter_options o = default_retargeter_options();
  if (options != nullptr) {
    const std::uint32_t size = options->struct_size;
    if (size < k_min_struct_size || size > k_max_struct_size) {
      set_create_error(("avm_retargeter_create_with_options: avm_retargeter_options.struct_size "
                        "is " +
                        std::to_string(size) +
                        ": initialise the options with avm_retargeter_options_init()")
                           .c_str());
      return AVM_ERROR_INVALID_ARGUMENT;
    }
    // The known prefix of a newer caller's struct; defaults for what an older one lacks.
    std::memcpy(&o, options, std::min<std::size_t>(size, sizeof o));
    o.struct_size = sizeof o;
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
    am::foot_lock_options fo;
    fo.enabled = o.foot_lock != 0;
    fo.align_foot = o.foot_lock_align_foot != 0;
    fo.lower_hips = o.foot_lock_lower_hips != 0;
    fo.keep_above_floor = o.foot_lock_keep_above_floor != 0;
    st = r->lock.build(r->retargeter, fo);
    if (!st.ok()) {
      set_create_error(st.message().c_str());
      return avm_code(st);
    }
    if (fo.enabled && !r->lock.warning().empty()) r->choice.description += "; " + r->lock.warning();
    r->retargeter.prepare(r->pose);
    set_create_error("");
    *out = r.release();
    return AVM_OK;
  });
}

AVATARMAP_C_API void avm_retargeter_reset(avm_retargeter* retargeter) {
  guard_value(0, [&] {
    if (retargeter != nullptr) retargeter->lock.reset();
    return 0;
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
