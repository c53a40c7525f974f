// Internal: what the VRMA and BVH writers share: checking and cleaning the caller's frames,
// and choosing the written key times (the frames' own or a fixed rate, resampled).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <new>
#include <string>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/time/resample_clip.hpp"
#include "avatarmap/time/seconds_text.hpp"

namespace avatarmap::export_detail {

/// Checks the frame times (finite, strictly increasing, spanning at most k_max_clip_seconds),
/// the frame count (at most k_max_resampled_frames, also after resampling) and `fps` (0 or
/// positive finite), so that frames_to_write() cannot be driven into an unbounded allocation.
inline status check_frames(const std::string& path, const std::vector<proxy_pose>& frames,
                           double fps) {
  if (frames.empty()) return status::error(path + ": no frames to write");
  if (!std::isfinite(fps) || fps < 0.0)
    return status::error(path + ": fps must be 0 (frames' own times) or positive, got " +
                         seconds_text(fps, 6));
  if (frames.size() > k_max_resampled_frames)
    return status::error(path + ": " + std::to_string(frames.size()) + " frames, more than the " +
                         std::to_string(k_max_resampled_frames) +
                         " a clip may have; split the clip");
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!std::isfinite(frames[i].t))
      return status::error(path + ": frame " + std::to_string(i) + " has a non-finite time");
    if (i > 0 && !(frames[i].t > frames[i - 1].t))
      return status::error(path + ": frame times must increase strictly; frame " +
                           std::to_string(i) + " (t = " + seconds_text(frames[i].t, 6) +
                           ") is not after frame " + std::to_string(i - 1));
  }
  // The span and, when resampling, the output frame count: the same rule resample_clip applies
  // (any positive rate gives a valid count check; 1 fps stands for "own times").
  std::size_t count = 0;
  return resampled_frame_count(frames.front().t, frames.back().t, fps > 0.0 ? fps : 1.0, path,
                               count);
}

/// Copy of `in` whose non-finite values are replaced by `prev`'s (the rest pose's for the
/// first frame); rotations normalised, weights clamped to [0, 1].
inline void clean_frame(const proxy_pose& in, const proxy_pose* prev, proxy_pose& out) {
  proxy_pose rest;
  const proxy_pose& fallback = prev ? *prev : rest;
  out = in;
  for (int b = 0; b < k_bone_count; ++b) {
    const glm::quat& q = in.rotations[b];
    float n2 = glm::dot(q, q);
    out.rotations[b] =
        is_finite(q) && n2 > 1e-20f ? q * (1.f / std::sqrt(n2)) : fallback.rotations[b];
  }
  if (!is_finite(in.hips_position)) out.hips_position = fallback.hips_position;
  for (int e = 0; e < k_expression_count; ++e) {
    float w = in.expressions[e];
    out.expressions[e] = std::isfinite(w) ? std::clamp(w, 0.f, 1.f) : fallback.expressions[e];
  }
  for (int s = 0; s < k_blendshape_count; ++s) {
    float w = in.blendshapes[s];
    out.blendshapes[s] = std::isfinite(w) ? std::clamp(w, 0.f, 1.f) : fallback.blendshapes[s];
  }
}

/// The frames to write, into `out`: cleaned copies at the frames' own times (fps == 0) or
/// resampled at t_first + k / fps (fps > 0). Times are rebased so that the first is 0 when
/// `rebase`. `frames` must have passed check_frames(); fails (naming `path`) only when memory
/// runs out.
inline status frames_to_write(const std::string& path, const std::vector<proxy_pose>& frames,
                              double fps, bool rebase, std::vector<proxy_pose>& out) {
  out.clear();
  std::vector<proxy_pose> clean;
  try {
    clean.resize(frames.size());
  } catch (const std::bad_alloc&) {
    return status::out_of_memory(path + ": not enough memory for " + std::to_string(frames.size()) +
                                 " frames; split the clip");
  }
  for (std::size_t i = 0; i < frames.size(); ++i)
    clean_frame(frames[i], i ? &clean[i - 1] : nullptr, clean[i]);
  if (fps > 0.0) return resample_clip(clean, fps, rebase, out, path);
  const double t0 = frames.front().t;
  if (rebase)
    for (proxy_pose& p : clean) p.t -= t0;
  out = std::move(clean);
  return {};
}

/// Appends `v` as fixed-point text with 6 decimals ("-0.000000" normalised to "0.000000"),
/// the number format of both BVH writers.
inline void append_fixed(std::string& s, double v) {
  char buf[64];
  if (std::abs(v) < 5e-7) v = 0.0;
  int len = std::snprintf(buf, sizeof buf, "%.6f", v);
  if (len > 0) s.append(buf, static_cast<std::size_t>(len));
}

/// Appends "x y z" of `v` times `scale` with append_fixed.
template <class vec>
inline void append_vec(std::string& s, const vec& v, double scale) {
  append_fixed(s, double(v.x) * scale);
  s.push_back(' ');
  append_fixed(s, double(v.y) * scale);
  s.push_back(' ');
  append_fixed(s, double(v.z) * scale);
}

}  // namespace avatarmap::export_detail
