// Resampling a whole clip of proxy poses at a fixed frame rate (batch work for exporters and
// converters; live streams use pose_resampler). Rotations are slerped along the shorter arc,
// hips position and expression weights interpolated linearly, confidence the lower of the two
// frames around each sample.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"

namespace avatarmap {

/// Samples `frames` (times increasing) at t0 + k / fps for every k with t0 + k / fps within
/// the clip (a thousandth of a frame of tolerance, for times that went through float).
/// `rebase`: output times start at 0 (else they keep the clip's clock). fps must be > 0; an
/// empty clip gives an empty result.
inline std::vector<proxy_pose> resample_clip(const std::vector<proxy_pose>& frames, double fps,
                                             bool rebase) {
  std::vector<proxy_pose> out;
  if (frames.empty() || !(fps > 0.0)) return out;
  const double t0 = frames.front().t;
  const double span = frames.back().t - t0;
  const auto count = static_cast<std::size_t>(std::floor(span * fps + 1e-3)) + 1;
  out.resize(count);
  std::size_t seg = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const double t = t0 + static_cast<double>(k) / fps;
    while (seg + 1 < frames.size() && frames[seg + 1].t <= t) ++seg;
    proxy_pose& o = out[k];
    if (seg + 1 >= frames.size()) {
      o = frames.back();
    } else {
      const proxy_pose& a = frames[seg];
      const proxy_pose& b = frames[seg + 1];
      const float u = std::clamp(static_cast<float>((t - a.t) / (b.t - a.t)), 0.f, 1.f);
      o = a;
      for (int i = 0; i < k_bone_count; ++i) {
        o.rotations[i] = slerp_shortest(a.rotations[i], b.rotations[i], u);
        o.confidence[i] = std::min(a.confidence[i], b.confidence[i]);
      }
      o.hips_position = a.hips_position + (b.hips_position - a.hips_position) * u;
      for (int e = 0; e < k_expression_count; ++e)
        o.expressions[e] = a.expressions[e] + (b.expressions[e] - a.expressions[e]) * u;
    }
    o.t = rebase ? static_cast<double>(k) / fps : t;
  }
  return out;
}

}  // namespace avatarmap
