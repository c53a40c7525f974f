// The C API's clip handle (avm_clip_*): poses collected in memory, then written as a file by
// the library's clip-output job (the CLI's `convert` runs it too).
#include "c_clip.hpp"

#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "avatarmap/avatarmap.h"
#include "avatarmap/core/rotation.hpp"
#include "avatarmap/jobs/clip_output.hpp"
#include "avatarmap/jobs/convert_file.hpp"
#include "avatarmap/rig/bound_avatar.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "c_avatar.hpp"
#include "c_frames.hpp"
#include "c_guard.hpp"

namespace am = avatarmap;
using namespace avatarmap::c_api;

namespace {

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
  for (int s = 0; s < am::k_blendshape_count; ++s) {
    const auto si = static_cast<std::size_t>(s);
    const float w = in.blendshapes[s];
    out.blendshapes[si] =
        std::isfinite(w) ? clamp01(w) : (prev != nullptr ? prev->blendshapes[si] : 0.f);
  }
  for (int f = 0; f < 2; ++f) {
    const float c = in.foot_contact[f];
    out.foot_contact[static_cast<std::size_t>(f)] = std::isfinite(c) ? clamp01(c) : 0.f;
  }
}

// Writes `frames` to `path` with the library's clip-output job (the CLI's `convert` runs it
// too): the job's checks first, then the avatar (loaded and bound only when the format uses
// it), then the write. On failure returns the status and sets `msg`.
avm_status write_clip(const std::vector<am::proxy_pose>& frames, double source_fps,
                      const std::string& path, double fps, const char* avatar_path,
                      const char* mapping, std::string& msg) {
  am::clip_output_job job;
  job.path = path;
  job.frames = &frames;
  job.fps = fps;
  job.source_fps = source_fps;
  job.avatar_path = avatar_path != nullptr ? avatar_path : "";
  if (am::status st = job.validate(); !st.ok()) {
    msg = st.message();
    return avm_code(st);
  }
  // An avatar with its binding (large: kept on the heap), as the library binds it.
  std::unique_ptr<am::bound_avatar> avatar;
  if (avatar_path != nullptr && am::find_clip_format(path)->uses_avatar) {
    avatar = std::make_unique<am::bound_avatar>();
    const avm_status code = bind_c_avatar(avatar_path, mapping, *avatar, msg);
    if (code != AVM_OK) return code;
    job.avatar_rig = &avatar->rig;
    job.avatar_binding = avatar->binding;
    job.avatar_table = avatar->table();
  }
  am::clip_output_summary summary;
  if (am::status st = job.run(summary); !st.ok()) {
    msg = st.message();
    return avm_code(st);
  }
  return AVM_OK;
}

}  // namespace

extern "C" {

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

AVATARMAP_C_API void avm_clip_destroy(avm_clip* clip) {
  guard_value(0, [&] {
    delete clip;
    return 0;
  });
}

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

AVATARMAP_C_API avm_status avm_clip_add_poses(avm_clip* clip, const avm_pose* poses,
                                              int64_t count) {
  if (clip == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  clip->last_error.clear();
  if (count < 0) return fail(clip, AVM_ERROR_INVALID_ARGUMENT, "avm_clip_add_poses: count < 0");
  if (count > 0 && poses == nullptr)
    return fail(clip, AVM_ERROR_INVALID_ARGUMENT, "avm_clip_add_poses: poses is NULL");
  return guard("avm_clip_add_poses", to_handle(clip), [&]() -> avm_status {
    // Every time checked before anything is added: all or nothing.
    double prev_t = clip->frames.empty() ? 0.0 : clip->frames.back().t;
    bool have_prev = !clip->frames.empty();
    for (int64_t i = 0; i < count; ++i) {
      const double t = poses[i].t;
      if (!std::isfinite(t) || (have_prev && !(t > prev_t))) {
        const std::string msg =
            "avm_clip_add_poses: poses[" + std::to_string(i) + "].t (" + std::to_string(t) +
            (std::isfinite(t) ? ") must be after the previous frame's (" + std::to_string(prev_t) +
                                    "); nothing was added"
                              : ") must be finite; nothing was added");
        set_error(clip, msg.c_str());
        return AVM_ERROR_INVALID_ARGUMENT;
      }
      prev_t = t;
      have_prev = true;
    }
    const std::size_t old_size = clip->frames.size();
    clip->frames.reserve(old_size + static_cast<std::size_t>(count));  // may throw: unchanged
    clip->frames.resize(old_size + static_cast<std::size_t>(count));
    for (int64_t i = 0; i < count; ++i) {
      const std::size_t k = old_size + static_cast<std::size_t>(i);
      sanitized_pose(poses[i], k > 0 ? &clip->frames[k - 1] : nullptr, clip->frames[k]);
    }
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_clip_get_poses(const avm_clip* clip, int64_t first, int64_t count,
                                              avm_pose* out) {
  if (clip == nullptr) return AVM_ERROR_INVALID_ARGUMENT;
  clip->last_error.clear();
  return guard("avm_clip_get_poses", to_handle(clip), [&]() -> avm_status {
    const auto size = static_cast<int64_t>(clip->frames.size());
    if (first < 0 || count < 0 || first > size || count > size - first) {
      const std::string msg = "avm_clip_get_poses: frames [" + std::to_string(first) + ", " +
                              std::to_string(first) + " + " + std::to_string(count) +
                              ") are not within the clip's " + std::to_string(size) + " frames";
      return fail(clip, AVM_ERROR_INVALID_ARGUMENT, msg.c_str());
    }
    if (count > 0 && out == nullptr)
      return fail(clip, AVM_ERROR_INVALID_ARGUMENT, "avm_clip_get_poses: out is NULL");
    for (int64_t i = 0; i < count; ++i)
      to_c_pose(clip->frames[static_cast<std::size_t>(first + i)], out[i]);
    return AVM_OK;
  });
}

AVATARMAP_C_API avm_status avm_clip_read(const char* path, avm_clip** out, char* err,
                                         size_t err_size) {
  copy_message(err, err_size, "");
  if (out != nullptr) *out = nullptr;
  auto report = [&](avm_status code, const char* msg) {
    copy_message(err, err_size, msg);
    return code;
  };
  if (path == nullptr || out == nullptr)
    return report(AVM_ERROR_INVALID_ARGUMENT, "avm_clip_read: path and out must not be NULL");
  return guard("avm_clip_read", report, [&]() -> avm_status {
    // The library's reader of motion files (the one `avatarmap convert` and avm_convert_file
    // use): a pose file or a .vrma, the frames put in time order by its one rule.
    am::motion_clip read;
    if (am::status st = am::read_motion(path, nullptr, read); !st.ok())
      return report(avm_code(st), st.message().c_str());
    std::unique_ptr<avm_clip> clip(new avm_clip());
    clip->source_fps = read.source_fps;
    clip->frames = std::move(read.frames);
    *out = clip.release();
    return AVM_OK;
  });
}

AVATARMAP_C_API int avm_clip_frame_count(const avm_clip* clip) {
  return guard_value(0,
                     [&] { return clip == nullptr ? 0 : static_cast<int>(clip->frames.size()); });
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
    const avm_status code =
        write_clip(clip->frames, clip->source_fps, path, fps, avatar_path, mapping, msg);
    if (code != AVM_OK) return report(code, msg.c_str());
    return AVM_OK;
  });
}

AVATARMAP_C_API const char* avm_clip_last_error(const avm_clip* clip) {
  return guard_value<const char*>("",
                                  [&] { return clip == nullptr ? "" : clip->last_error.c_str(); });
}

}  // extern "C"
