#include "avatarmap/jobs/retarget_clip.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "avatarmap/time/seconds_text.hpp"

namespace avatarmap {

status standing_hips_height(const std::vector<proxy_pose>& frames, const std::string& what,
                            float& out_height) {
  out_height = 0.f;
  if (frames.empty())
    return status::error(what + ": no frames to retarget (the standing hips height needs some)");
  std::vector<float> heights;
  heights.reserve(frames.size());
  // NaN would break the sort's ordering: it ranks as +inf (last), as sort_clip_by_time does.
  for (const proxy_pose& p : frames)
    heights.push_back(std::isnan(p.hips_position.y) ? std::numeric_limits<float>::infinity()
                                                    : p.hips_position.y);
  const std::size_t k = heights.size() * k_standing_hips_percentile / 100;
  std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(k),
                   heights.end());
  const float h = heights[k];
  if (!(std::isfinite(h) && h > 0.f))
    return status::error(
        what + ": the performer's standing hips height (the " +
        std::to_string(k_standing_hips_percentile) + "th percentile of hips_position.y over " +
        std::to_string(frames.size()) + " frames) is " + seconds_text(h, 3) +
        " m; root motion needs the hips' height above the floor in metres (give poses with "
        "hips positions, or turn root motion off)");
  out_height = h;
  return {};
}

status retarget_clip_job::validate() const {
  if (frames == nullptr) return status::error("retarget_clip_job.frames is not set");
  if (frames->empty()) return status::error(what + ": no frames to retarget");
  if (target == nullptr) return status::error("retarget_clip_job.target (the rig) is not set");
  const int n = target->joint_count();
  for (int b = 0; b < k_bone_count; ++b) {
    const int j = binding[static_cast<std::size_t>(b)];
    if (j < -1 || j >= n)
      return status::error(
          "retarget_clip_job.binding[" + std::string(bone_name(static_cast<bone>(b))) + "] is " +
          std::to_string(j) + ": give -1 (unbound) or a joint index below " + std::to_string(n));
  }
  if (status st = foot_lock.validate(); !st.ok())
    return status::invalid_argument("retarget_clip_job." + st.message());
  return {};
}

status retarget_clip_job::run(std::vector<rig_pose>& out_poses, float* out_standing_height,
                              std::string* out_warning) const {
  out_poses.clear();
  if (out_standing_height != nullptr) *out_standing_height = 0.f;
  if (out_warning != nullptr) out_warning->clear();
  if (status st = validate(); !st.ok()) return st;
  retarget_options ro;
  ro.keep_feet_on_ground = keep_feet_on_ground;
  ro.root_motion = root_motion;
  if (root_motion) {
    float h = 0.f;
    if (status st = standing_hips_height(*frames, what, h); !st.ok()) return st;
    ro.performer_hips_height = h;
    if (out_standing_height != nullptr) *out_standing_height = h;
  }
  // On the heap: the retargeter's constants are sized by the rig, and a C API caller's stack
  // may be small.
  auto rt = std::make_unique<retargeter>();
  if (status st = rt->build(*target, binding, ro, table); !st.ok()) return st;  // parse
  auto lock = std::make_unique<avatarmap::foot_lock>();
  if (foot_lock.enabled) {
    if (status st = lock->build(*rt, foot_lock); !st.ok()) return st;  // invalid_argument
    if (out_warning != nullptr) *out_warning = lock->warning();
  }
  out_poses.resize(frames->size());
  for (std::size_t i = 0; i < frames->size(); ++i) {
    rt->prepare(out_poses[i]);
    rt->apply((*frames)[i], out_poses[i]);
    if (foot_lock.enabled) lock->apply((*frames)[i].foot_contact, out_poses[i]);
  }
  return {};
}

}  // namespace avatarmap
