#include "avatarmap/stream/vmc_bundle.hpp"

#include <algorithm>
#include <array>

#include "avatarmap/skeleton/blendshape.hpp"
#include "avatarmap/stream/unity_space.hpp"
#include "avatarmap/stream/vmc_names.hpp"

namespace avatarmap {

namespace {

void write_transform(osc_writer& out, std::string_view address, std::string_view name,
                     const glm::vec3& p, const glm::quat& q) {
  out.begin_message(address, "sfffffff");
  out.add_string(name);
  out.add_float32(p.x);
  out.add_float32(p.y);
  out.add_float32(p.z);
  out.add_float32(q.x);
  out.add_float32(q.y);
  out.add_float32(q.z);
  out.add_float32(q.w);
  out.end_message();
}

void write_blend(osc_writer& out, std::string_view name, float w) {
  out.begin_message("/VMC/Ext/Blend/Val", "sf");
  out.add_string(name);
  out.add_float32(w >= 0.f ? std::min(w, 1.f) : 0.f);  // NaN -> 0
  out.end_message();
}

}  // namespace

std::string_view vmc_blend_set_name(vmc_blend_set set) {
  switch (set) {
    case vmc_blend_set::arkit:
      return "arkit";
    case vmc_blend_set::both:
      return "both";
    case vmc_blend_set::vrm0:
      break;
  }
  return "vrm0";
}

std::optional<vmc_blend_set> vmc_blend_set_from_name(std::string_view name) {
  for (vmc_blend_set s : {vmc_blend_set::vrm0, vmc_blend_set::arkit, vmc_blend_set::both})
    if (vmc_blend_set_name(s) == name) return s;
  return std::nullopt;
}

int vmc_blend_count(vmc_blend_set set) {
  int n = 0;
  if (set != vmc_blend_set::arkit)
    for (int e = 0; e < k_expression_count; ++e)
      n += !vrm0_blend_name(static_cast<expression>(e)).empty();
  if (set != vmc_blend_set::vrm0) n += k_blendshape_count;
  return n;
}

bool write_vmc_bundle(const vmc_skeleton& skeleton, const proxy_pose& pose, float time,
                      osc_writer& out, vmc_blend_set blends) {
  out.clear();
  out.begin_bundle(k_osc_immediately);
  write_transform(out, "/VMC/Ext/Root/Pos", "root", glm::vec3(0.f), glm::quat(1.f, 0.f, 0.f, 0.f));

  std::array<glm::quat, k_bone_count> world;
  compute_world_rotations(pose, world);
  const glm::vec3 h = pose.hips_position;
  const float s = skeleton.hips_scale;
  const glm::vec3 hips(skeleton.hips_rest.x + s * h.x, skeleton.floor + s * h.y,
                       skeleton.hips_rest.z + s * h.z);
  for (int b = 0; b < k_bone_count; ++b) {
    if (!skeleton.sent[b]) continue;
    int a = bone_parent(b);
    while (a != k_no_parent && !skeleton.sent[a]) a = bone_parent(a);
    // The rotation relative to the nearest sent ancestor: the locals of the bones skipped
    // between them, composed (normalised rest rotations are identity).
    const glm::quat local = a == k_no_parent ? world[b] : glm::conjugate(world[a]) * world[b];
    const glm::vec3 position = b == idx(bone::hips) ? hips : skeleton.offsets[b];
    write_transform(out, "/VMC/Ext/Bone/Pos", unity_bone_name(static_cast<bone>(b)),
                    vrm_to_unity_position(position), vrm_to_unity_rotation(local));
  }

  if (blends != vmc_blend_set::arkit)
    for (int e = 0; e < k_expression_count; ++e) {
      const std::string_view name = vrm0_blend_name(static_cast<expression>(e));
      if (!name.empty()) write_blend(out, name, pose.expressions[e]);
    }
  if (blends != vmc_blend_set::vrm0)
    for (int b = 0; b < k_blendshape_count; ++b)
      write_blend(out, blendshape_name(static_cast<blendshape>(b)), pose.blendshapes[b]);
  out.begin_message("/VMC/Ext/Blend/Apply", "");
  out.end_message();
  out.begin_message("/VMC/Ext/OK", "i");
  out.add_int32(1);
  out.end_message();
  out.begin_message("/VMC/Ext/T", "f");
  out.add_float32(time);
  out.end_message();
  out.end_bundle();
  return out.complete();
}

}  // namespace avatarmap
