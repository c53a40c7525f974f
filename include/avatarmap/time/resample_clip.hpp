// Resampling a whole clip of proxy poses at a fixed frame rate (batch work for exporters and
// converters; live streams use pose_resampler). Rotations are slerped along the shorter arc,
// hips position, expression and blendshape weights and foot contacts interpolated linearly,
// confidence the
// lower of the two frames around each sample.
//
// Clips come from files a user may not trust, so the times are checked before anything is
// allocated: every time finite, in order, the span at most k_max_clip_seconds and the output at
// most k_max_resampled_frames frames. A clip that breaks a rule gets an error naming the frame
// or the limit, never an exception, an abort or an allocation without bound.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "avatarmap/core/rotation.hpp"
#include "avatarmap/core/status.hpp"
#include "avatarmap/skeleton/proxy_pose.hpp"
#include "avatarmap/time/seconds_text.hpp"

namespace avatarmap {

/// Longest span (last frame's time minus the first's) of a clip that is resampled or written:
/// 24 hours. Captures last minutes to hours; a longer span is a broken clock (milliseconds
/// written as seconds, one frame stamped with a wall-clock time), and 1e6 s at 60 fps would
/// need 60 million frames.
inline constexpr double k_max_clip_seconds = 24.0 * 60.0 * 60.0;

/// Most frames a resampled (or written) clip may have: 2^22 = 4,194,304 — 9.7 hours at
/// 120 fps, 19.4 hours at 60 fps — about 5 GB of proxy_pose. Bounds what a hostile clip can
/// make us allocate.
inline constexpr std::size_t k_max_resampled_frames = std::size_t{1} << 22;

/// The number of frames resampling a clip from `t_first` to `t_last` (seconds) at `fps` gives:
/// floor((t_last - t_first) * fps + 1e-3) + 1 (a thousandth of a frame of tolerance, for times
/// that went through float), into `out_count`. Fails, with a message starting with `what`
/// (usually the file name) and out_count 0, when fps is not a positive finite number, a time
/// is not finite, t_last < t_first, the span exceeds k_max_clip_seconds or the count exceeds
/// k_max_resampled_frames.
inline status resampled_frame_count(double t_first, double t_last, double fps,
                                    const std::string& what, std::size_t& out_count) {
  out_count = 0;
  if (!(fps > 0.0) || !std::isfinite(fps))
    return status::error(what + ": the frame rate must be a positive number of frames per " +
                         "second, got " + seconds_text(fps, 6));
  if (!std::isfinite(t_first) || !std::isfinite(t_last))
    return status::error(what + ": a frame time is not finite (t = " + seconds_text(t_first) +
                         " .. " + seconds_text(t_last) + "); every frame needs a time in seconds");
  if (t_last < t_first)
    return status::error(what + ": the last frame's time (t = " + seconds_text(t_last) +
                         " s) is earlier than the first's (t = " + seconds_text(t_first) +
                         " s); resampling needs the frames in time order");
  const double span = t_last - t_first;  // may be +inf for times of opposite huge signs
  if (!(span <= k_max_clip_seconds))
    return status::error(what + ": the frame times span " + seconds_text(span, 2) +
                         " s (t = " + seconds_text(t_first) + " .. " + seconds_text(t_last) +
                         " s), more than a clip may span (" + seconds_text(k_max_clip_seconds, 0) +
                         " s = 24 h); check the times (milliseconds written as seconds?) or "
                         "split the clip");
  const double count = std::floor(span * fps + 1e-3) + 1.0;
  if (!(count <= static_cast<double>(k_max_resampled_frames)))
    return status::error(what + ": " + seconds_text(span, 2) + " s at " + seconds_text(fps, 2) +
                         " fps would be " + seconds_text(count, 0) + " frames, more than the " +
                         std::to_string(k_max_resampled_frames) +
                         " a clip may have; lower the frame rate or split the clip");
  out_count = static_cast<std::size_t>(count);
  return {};
}

/// The time of resampled frame k (0-based, k < resampled_frame_count) of a clip from `t_first`
/// to `t_last` at `fps`: t_first + k / fps, but never past t_last. The count's thousandth of a
/// frame of tolerance would otherwise put the last frame up to 1e-3 / fps past the last key;
/// it is at the last key instead.
inline double resampled_frame_time(double t_first, double t_last, std::size_t k, double fps) {
  return std::min(t_first + static_cast<double>(k) / fps, t_last);
}

/// Sorts `frames` by time, stably (frames with equal times keep their order; non-finite times
/// go last). Returns how many frames had a time earlier than the frame before them: 0 means the
/// clip was already in order and nothing moved.
inline std::size_t sort_clip_by_time(std::vector<proxy_pose>& frames) {
  // NaN compares false with everything, which would break the sort's ordering: rank it as +inf.
  auto key = [](double t) { return std::isnan(t) ? std::numeric_limits<double>::infinity() : t; };
  std::size_t backward = 0;
  for (std::size_t i = 1; i < frames.size(); ++i)
    if (key(frames[i].t) < key(frames[i - 1].t)) ++backward;
  if (backward > 0)
    std::stable_sort(
        frames.begin(), frames.end(),
        [&key](const proxy_pose& a, const proxy_pose& b) { return key(a.t) < key(b.t); });
  return backward;
}

/// Samples `frames` at resampled_frame_time (t0 + k / fps, t0 = the first frame's time, never
/// past the last frame) for every k with the sample within the clip (count from
/// resampled_frame_count) into `out` (cleared first; must not be
/// `frames`). `rebase`: output times start at 0 (else they keep the clip's clock).
/// Times must be finite and must not decrease (sort_clip_by_time puts a clip in order); at equal
/// times the later frame wins. An empty clip gives an empty result. Fails, with a message
/// starting with `what` and naming the frame or the limit, and `out` empty, when fps is not
/// positive and finite, a time is not finite, a time is earlier than the one before it, the
/// span exceeds k_max_clip_seconds or the output would exceed k_max_resampled_frames (or cannot
/// be allocated). Never throws.
inline status resample_clip(const std::vector<proxy_pose>& frames, double fps, bool rebase,
                            std::vector<proxy_pose>& out, const std::string& what = "clip") {
  out.clear();
  if (frames.empty()) {
    if (!(fps > 0.0) || !std::isfinite(fps)) {
      std::size_t unused;
      return resampled_frame_count(0.0, 0.0, fps, what, unused);  // the frame-rate message
    }
    return {};
  }
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!std::isfinite(frames[i].t))
      return status::error(what + ": frame " + std::to_string(i) + " has no finite time (t = " +
                           seconds_text(frames[i].t) + "); every frame needs a time in seconds");
    if (i > 0 && frames[i].t < frames[i - 1].t)
      return status::error(what + ": frame " + std::to_string(i) +
                           " (t = " + seconds_text(frames[i].t) + " s) is earlier than frame " +
                           std::to_string(i - 1) + " (t = " + seconds_text(frames[i - 1].t) +
                           " s); resampling needs the frames in time order (sort them first)");
  }
  const double t0 = frames.front().t, t_last = frames.back().t;
  std::size_t count = 0;
  if (status s = resampled_frame_count(t0, t_last, fps, what, count); !s) return s;
  try {
    out.resize(count);
  } catch (const std::bad_alloc&) {
    std::vector<proxy_pose>().swap(out);
    return status::out_of_memory(what + ": not enough memory for " + std::to_string(count) +
                                 " resampled frames; lower the frame rate or split the clip");
  }
  std::size_t seg = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const double t = resampled_frame_time(t0, t_last, k, fps);
    while (seg + 1 < frames.size() && frames[seg + 1].t <= t) ++seg;
    proxy_pose& o = out[k];
    if (seg + 1 >= frames.size()) {
      o = frames.back();
    } else {
      // frames[seg].t <= t < frames[seg + 1].t here, so the division is by a positive span.
      const proxy_pose& a = frames[seg];
      const proxy_pose& b = frames[seg + 1];
      const float u = std::clamp(static_cast<float>((t - a.t) / (b.t - a.t)), 0.f, 1.f);
      o = a;
      for (int i = 0; i < k_bone_count; ++i) {
        o.rotations[i] = slerp_shortest(a.rotations[i], b.rotations[i], u);
        o.confidence[i] = std::min(a.confidence[i], b.confidence[i]);
      }
      // (1 - u) a + u b rather than a + u (b - a): for u in [0, 1] it cannot overflow, even
      // for values at opposite ends of the float range (b - a would be infinite).
      const float v = 1.f - u;
      o.hips_position = v * a.hips_position + u * b.hips_position;
      for (int e = 0; e < k_expression_count; ++e)
        o.expressions[e] = v * a.expressions[e] + u * b.expressions[e];
      for (int s = 0; s < k_blendshape_count; ++s)
        o.blendshapes[s] = v * a.blendshapes[s] + u * b.blendshapes[s];
      for (int f = 0; f < 2; ++f) o.foot_contact[f] = v * a.foot_contact[f] + u * b.foot_contact[f];
    }
    o.t = rebase ? resampled_frame_time(0.0, t_last - t0, k, fps) : t;
  }
  return {};
}

}  // namespace avatarmap
