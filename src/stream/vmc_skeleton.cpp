#include "avatarmap/stream/vmc_skeleton.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace avatarmap {

namespace {

// The nearest ancestor of `b` that is sent, or k_no_parent.
int sent_ancestor(const std::array<bool, k_bone_count>& sent, int b) {
  int a = bone_parent(b);
  while (a != k_no_parent && !sent[a]) a = bone_parent(a);
  return a;
}

}  // namespace

vmc_skeleton make_vmc_skeleton(const proxy_skeleton& s) {
  vmc_skeleton out;
  out.sent.fill(true);
  out.offsets = s.offsets;
  out.offsets[idx(bone::hips)] = glm::vec3(0.f);
  out.sent_count = k_bone_count;
  return out;
}

status make_vmc_skeleton(const rig& r, const bone_binding& binding, float performer_hips_height,
                         vmc_skeleton& out) {
  out = vmc_skeleton{};
  const std::string where = r.file.empty() ? std::string("rig") : r.file;
  if (!(performer_hips_height > 0.f) || !std::isfinite(performer_hips_height))
    return status::error(where + ": the performer's hips height must be positive and finite");
  const int n = r.joint_count();
  for (int b = 0; b < k_bone_count; ++b) {
    if (binding[b] >= n)
      return status::error(where + ": bone " + std::string(bone_name(static_cast<bone>(b))) +
                           " is bound to joint " + std::to_string(binding[b]) + ", out of range");
    out.sent[b] = binding[b] >= 0;
  }
  if (!out.sent[idx(bone::hips)])
    return status::error(where + ": no joint is bound to the hips (required for VMC output)");
  // VRM 0.x models face -Z: a half turn about Y brings them to VRM space (rig/retarget.hpp).
  const bool half_turn = r.source == rig_source::vrm0;
  auto rest_vrm = [&](int b) {
    const glm::vec3 p(r.rest_world[binding[b]][3]);
    return half_turn ? glm::vec3(-p.x, p.y, -p.z) : p;
  };
  for (int b = 0; b < k_bone_count; ++b) {
    if (!out.sent[b]) continue;
    ++out.sent_count;
    const int a = sent_ancestor(out.sent, b);
    out.offsets[b] = a == k_no_parent ? glm::vec3(0.f) : rest_vrm(b) - rest_vrm(a);
  }
  out.offsets[idx(bone::hips)] = glm::vec3(0.f);
  out.hips_rest = rest_vrm(idx(bone::hips));
  bool have_feet = false;
  float floor = 0.f;
  for (bone fb : {bone::left_foot, bone::right_foot, bone::left_toes, bone::right_toes}) {
    if (!out.sent[idx(fb)]) continue;
    const float y = rest_vrm(idx(fb)).y;
    floor = have_feet ? std::min(floor, y) : y;
    have_feet = true;
  }
  out.floor = floor;
  float height = out.hips_rest.y - floor;
  if (!(height > 0.f)) height = std::abs(out.hips_rest.y) > 0.f ? std::abs(out.hips_rest.y) : 1.f;
  out.hips_scale = height / performer_hips_height;
  return {};
}

}  // namespace avatarmap
